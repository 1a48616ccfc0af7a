"""When an engine run under test may be killed in a given stage, and a part's deadline that falls on a resumed run
(the restart tests of both engines)."""

from __future__ import annotations

import os
import signal
import threading
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

from siloflow.engines.deadline import until
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


@contextmanager
def deadline_once(launched: Callable[[], bool], what: str, poll_s: float = 0.05,
                  limit_s: float = 600.0) -> Iterator[None]:
    """Let a validation part's deadline fall on the body the moment ``launched()`` holds (the resumed engine has
    started), whatever the machine's speed; a fixed deadline in seconds may come after a tiny run has finished on a
    fast machine. The deadline is :func:`siloflow.engines.deadline.until`'s own: a SIGALRM to this process, here
    sent by a watcher thread instead of the interval timer. ``limit_s`` (s) bounds the body where ``launched()``
    never holds."""
    done = threading.Event()

    def watch():
        while not done.is_set():
            if launched():
                os.kill(os.getpid(), signal.SIGALRM)
                return
            time.sleep(poll_s)

    watcher = threading.Thread(target=watch, daemon=True)
    with until(time.time() + limit_s, what):
        watcher.start()
        try:
            yield
        finally:
            done.set()
            watcher.join()


def started_log(path: Path) -> Callable[[], bool]:
    """Whether the engine writing its log to ``path`` has started: the log holds something."""
    return lambda: path.exists() and path.stat().st_size > 0
