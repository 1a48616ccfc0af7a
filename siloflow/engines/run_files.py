"""What every engine's run leaves in its run directory besides the engine's own files: the run record written last,
the size of everything written, and the moving aside of an unfinished earlier attempt (never deleted)."""

from __future__ import annotations

import logging
import shutil
import time
from pathlib import Path
from typing import Callable

from siloflow.model.record import RunRecord
from siloflow.engines.estimates import format_bytes
from siloflow.engines.layout import RUN_RECORD, write_text_atomic

__all__ = ["FAILED_ATTEMPTS", "RESTARTS_PER_STAGE", "earlier_attempt_logs", "output_bytes", "remove_matching",
           "restart_every", "set_aside_attempts", "set_aside_previous_attempt", "write_run_record"]

#: The folder of a run directory that holds its unfinished earlier attempts, one ``<UTC time>/`` folder each.
FAILED_ATTEMPTS = "failed_attempts"
#: Restart files (LIGGGHTS) or snapshots (YADE) a silo-type run writes per stage, from its pour on.
RESTARTS_PER_STAGE = 20


def restart_every(stage_steps: int) -> int:
    """Steps between restart files of a stage of ``stage_steps`` steps: a stopped run loses at most 1/20 of it."""
    if stage_steps < 1:
        raise ValueError(f"stage_steps must be >= 1, got {stage_steps!r}")
    return max(1, -(-stage_steps // RESTARTS_PER_STAGE))


def remove_matching(run_dir: Path, patterns: tuple[str, ...]) -> list[str]:
    """Remove the files of ``run_dir`` that match ``patterns`` (globs relative to it); returns their relative names, in
    the patterns' order. What a stopped attempt wrote after the restart file a resumed attempt goes on from, which
    that attempt writes again."""
    removed = []
    for pattern in patterns:
        for stale in sorted(Path(run_dir).glob(pattern)):
            stale.unlink()
            removed.append(stale.relative_to(run_dir).as_posix())
    return removed


def set_aside_previous_attempt(run_dir: Path, outputs: tuple[str, ...], patterns: tuple[str, ...] = ()) -> Path | None:
    """Move the output of an unfinished earlier attempt into ``failed_attempts/<UTC time>/``.

    Nothing is deleted: the user may want to inspect a failed run. ``outputs`` names the files and
    folders a run writes, ``patterns`` globs of further ones (the files of resumed attempts). Returns the new
    location, if any.
    """
    run_dir = Path(run_dir)
    leftovers = [run_dir / name for name in outputs if (run_dir / name).exists()]
    leftovers += sorted({path for pattern in patterns for path in run_dir.glob(pattern)})
    if not leftovers:
        return None
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
    target = run_dir / FAILED_ATTEMPTS / stamp
    attempt = 1
    while target.exists():
        attempt += 1
        target = run_dir / FAILED_ATTEMPTS / f"{stamp}-{attempt}"
    target.mkdir(parents=True)
    for path in leftovers:
        shutil.move(str(path), str(target / path.name))
    return target


def set_aside_attempts(run_dir: str | Path) -> list[Path]:
    """The folders of a run's earlier attempts that :func:`set_aside_previous_attempt` moved aside, oldest first."""
    folder = Path(run_dir) / FAILED_ATTEMPTS
    return sorted(path for path in folder.iterdir() if path.is_dir()) if folder.is_dir() else []


def earlier_attempt_logs(run_dir: str | Path, attempt_logs: Callable[[Path], list[Path]]) -> list[Path]:
    """The logs of a run's attempts before its last: those of the attempts set aside (:func:`set_aside_attempts`),
    then those of the run directory but its last (the attempt the run step's benchmark times). ``attempt_logs`` lists
    an engine's logs of one directory, first attempt and resumptions in order."""
    return [*(path for attempt in set_aside_attempts(run_dir) for path in attempt_logs(attempt)),
            *attempt_logs(Path(run_dir))[:-1]]


def write_run_record(run_dir: Path, record: RunRecord) -> Path:
    """Write ``run.json`` last and atomically: its presence means the run is complete and checked."""
    path = Path(run_dir) / RUN_RECORD
    write_text_atomic(path, record.to_json())
    logging.getLogger("siloflow").info("run complete: %s; the run wrote %s", path, format_bytes(record.output_bytes))
    return path


def output_bytes(run_dir: str | Path) -> int:
    """Size of everything a run wrote (dumps, logs, deck, meshes) in bytes; ``run.json`` reports it."""
    return sum(path.stat().st_size for path in Path(run_dir).rglob("*") if path.is_file())
