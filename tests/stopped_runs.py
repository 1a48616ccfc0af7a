"""When an engine run under test may be killed in a given stage (the restart tests of both engines)."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from siloflow.engines.markers import parse_markers


def killable(run_dir: Path, stage: str, log_name: str, restart_files: Callable[[Path], list[Path]]) -> bool:
    """Whether a silo-type run has gone far enough into ``stage`` (``fill`` or ``discharge``) to be killed there: two
    restart files (snapshots) written in it. ``log_name`` is the engine's log in ``run_dir``; ``restart_files`` lists
    the engine's restart files of a run, oldest first, named ``<prefix>_<step>.<suffix>``."""
    log = run_dir / log_name
    text = log.read_text(errors="replace") if log.exists() else ""
    steps = [int(path.stem.split("_")[1]) for path in restart_files(run_dir)]
    if stage == "fill":
        return len(steps) >= 2 and "SILOFLOW filled" not in text
    opened = [m for m in parse_markers(text) if m.event == "opened"]
    return bool(opened) and sum(step > opened[0].values["step"] for step in steps) >= 2
