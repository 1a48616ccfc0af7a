"""YADE: running a rendered script headless, with progress, failure detection and resumption, and checking the run.

A script runs as ``<python> deck/run.py`` inside the run directory, with the system Python 3 that Debian's
``libyade`` is built for (``engine.yade.python``), never through YADE's launcher (``yade``, ``yade-batch``), which
always serves a Python console and an XMLRPC server on open ports. ``OMP_NUM_THREADS`` is ``engine.yade.threads``
(one by default: on a busy 2-core machine more threads made YADE 20 times slower).

Run directory layout (the script sees relative paths)::

    <run>/deck/run.py                    the rendered script
    <run>/deck/case.json                 derived case quantities
    <run>/log.yade                       the script's output: stage markers, progress, errors
    <run>/dumps/particles_<step>.npz     particle frames (numpy archives)
    <run>/dumps/settled_fill_<step>.npz  the settled fill's snapshot
    <run>/wall_force_history.txt                every wall's force and torque on the particles, one row per sample
    <run>/restart/state_<step>.yade      O.save snapshots of the last stage (deleted once the run is checked)
    <run>/resume<k>.log.yade, resume_<step>_wall_force_history.txt    the resumed attempts' log and wall forces
    <run>/run.json                       written last, only after every check passed

A killed run whose last stage had begun resumes from its newest snapshot (``O.load``; the one before it if the
newest cannot be read): frames of steps after the snapshot are written again, wall force rows after it are taken
from the resumed attempt.
"""

from __future__ import annotations

import logging
import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from siloflow.model.record import RunRecord
from siloflow.engines.deadline import PartDeadline
from siloflow.engines.interface import EngineNotFound, EngineRunError
from siloflow.engines.markers import Marker, parse_markers, without_redone
from siloflow.engines.progress import run_with_progress
from siloflow.engines.run_files import output_bytes, remove_matching, set_aside_previous_attempt, write_run_record
from siloflow.engines.yade.inputs import DECK_NAME
from siloflow.engines.yade.progress import ScriptProgress

LOG_NAME = "log.yade"
DUMP_PREFIX = "particles"
SETTLED_FILL_PREFIX = "settled_fill"
WALL_FORCES_NAME = "wall_force_history.txt"
RESTART_DIR = "restart"
RESUME_STEM = "resume"
#: The settled fill of a flat-bottom silo run, which the recirculating silo's runs start from (YADE's saved scene, in
#: the run's folder); a run that starts from it loads its copy in ``deck/``.
ASSEMBLY_STATE = "assembly.yade"
RUN_OUTPUTS = ("dumps", LOG_NAME, RESTART_DIR, WALL_FORCES_NAME, ASSEMBLY_STATE)
#: Where Debian's libyade keeps YADE's Python modules (the scripts put it on sys.path).
YADE_PYTHON_PATH = "/usr/lib/x86_64-linux-gnu/yade-double/py"
_RESTART = re.compile(r"^state_(\d+)\.yade$")
#: Wall time between progress lines (s) and between polls of the script's output (s).
PROGRESS_LOG_EVERY = 30.0
PROGRESS_POLL_EVERY = 1.0


@dataclass(frozen=True)
class YadeOptions:
    """How YADE is started (``engine.yade``): the Python 3 that imports it and its OpenMP threads per run."""

    python: str = "/usr/bin/python3"
    threads: int = 1


def restart_files(run_dir: str | Path) -> list[Path]:
    """The snapshots of a run, oldest step first."""
    found = []
    for path in (Path(run_dir) / RESTART_DIR).glob("state_*.yade"):
        match = _RESTART.match(path.name)
        if match and path.stat().st_size > 0:
            found.append((int(match.group(1)), path))
    return [path for _, path in sorted(found)]


def attempt_logs(run_dir: str | Path) -> list[Path]:
    """The log of the first attempt and those of its resumptions, in order."""
    run_dir = Path(run_dir)
    resumed = sorted(run_dir.glob(f"{RESUME_STEM}*.{LOG_NAME}"),
                     key=lambda p: int(p.name.split(".")[0][len(RESUME_STEM):]))
    return [path for path in [run_dir / LOG_NAME, *resumed] if path.exists()]


def _logs_text(run_dir: Path) -> str:
    return "\n".join(path.read_text(encoding="utf-8", errors="replace") for path in attempt_logs(run_dir))


def check_programs(options: YadeOptions) -> None:
    """Refuse (EngineNotFound, naming the config key) a Python for YADE that is not an executable on PATH or at the
    path given, or a machine without YADE's Python modules."""
    if shutil.which(options.python) is None:
        raise EngineNotFound(f"config key 'engine.yade.python': Python 3 '{options.python}' for YADE is not an "
                             "executable on PATH or at that path; give the Python 3 that imports YADE (/usr/bin/python3)")
    if not Path(YADE_PYTHON_PATH, "yade").is_dir():
        raise EngineNotFound(f"YADE's Python modules are not in {YADE_PYTHON_PATH}; install YADE with `make install` "
                             "(Debian package yade, without recommends)")


def script_command(options: YadeOptions, arguments: tuple[str, ...] = ()) -> list[str]:
    """The command line of a run (no shell involved; the arguments are paths and step numbers siloflow made)."""
    check_programs(options)
    return [options.python, f"deck/{DECK_NAME}", *arguments]


def _error_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith(("ERROR", "Traceback")) or "Error:" in line]


def run_script(run_dir: str | Path, options: YadeOptions, target_time: float | None = None,
               arguments: tuple[str, ...] = (), log_name: str = LOG_NAME) -> str:
    """Run ``<run_dir>/deck/run.py`` inside ``run_dir``; returns its output.

    Progress (simulated time out of ``target_time``, clumps, ETA) is logged every 30 s from the script's
    ``SILOFLOW progress`` lines.

    Raises
    ------
    EngineRunError
        On a non-zero exit or an ERROR line, quoting them; the run directory is left as is.
    """
    run_dir = Path(run_dir)
    command = script_command(options, arguments)
    environment = {**os.environ, "OMP_NUM_THREADS": str(options.threads), "PYTHONUNBUFFERED": "1"}
    environment.pop("PYTHONPATH", None)  # the project's environment must not shadow the system Python's modules
    returncode = run_with_progress(command, run_dir, run_dir / log_name, environment, ScriptProgress(), target_time,
                                   PROGRESS_LOG_EVERY, PROGRESS_POLL_EVERY)
    text = (run_dir / log_name).read_text(encoding="utf-8", errors="replace")
    problems = _error_lines(text)
    if returncode != 0 or problems:
        quoted = "\n".join("    " + line for line in (problems or text.rstrip().splitlines())[-15:])
        raise EngineRunError(f"YADE run in {run_dir} failed (exit code {returncode}); log lines:\n{quoted}\n"
                             f"The run directory is left for inspection: {run_dir}")
    return text


def _resume(run_dir: Path, options: YadeOptions, target_time: float, markers: list[Marker]) -> None:
    """Resume from the newest snapshot (the one before it if the newest cannot be read), in the stage the snapshot
    keeps in its tags: the pour, the settling, or the last stage, which ends at the step the ``opened`` marker names
    (``markers``: those of the attempts so far)."""
    log = logging.getLogger("siloflow")
    newest, *older = restart_files(run_dir)[-2:][::-1]
    for attempt_from in (newest, *older):
        step = int(_RESTART.match(attempt_from.name).group(1))
        opened = [m for m in markers if m.event == "opened" and m.values["step"] <= step]
        attempt = len(attempt_logs(run_dir))
        arguments = (f"{RESTART_DIR}/{attempt_from.name}",)
        remaining = target_time
        if opened:
            final_step = int(round(opened[-1].values["final_step"]))
            arguments += (str(final_step),)
            remaining = target_time * max(final_step - step, 1) / final_step
            log.info("resuming %s from snapshot %s in its discharge (the last stage ends at step %d)", run_dir.name,
                     attempt_from.name, final_step)
        else:
            # what the stopped attempt wrote once its fill had settled is written again
            remove_matching(run_dir, (f"dumps/{SETTLED_FILL_PREFIX}_*.npz", ASSEMBLY_STATE))
            # YADE keeps its clock in the snapshot: the progress goes on from the simulated time it holds
            log.info("resuming %s from snapshot %s before its outlet opened", run_dir.name, attempt_from.name)
        try:
            run_script(run_dir, options, remaining, arguments, f"{RESUME_STEM}{attempt}.{LOG_NAME}")
            return
        except PartDeadline:
            # the part's time ran out while the run went on: the next part resumes it; an older snapshot now would
            # run on past the deadline
            raise
        except EngineRunError as error:
            if attempt_from is not newest or not older:
                raise
            log.warning("snapshot %s could not be resumed (%s); trying the one before it", attempt_from.name, error)


def run_script_checked(run_dir: str | Path, options: YadeOptions, target_time: float,
                       check: Callable[[list[Marker], list[Path]], dict],
                       to_record: Callable[[dict], RunRecord], extra_outputs: tuple[str, ...] = ()) -> RunRecord:
    """Run (or resume) the rendered script of ``run_dir``, check the run and write ``run.json``; returns the record.

    ``check(markers, frame_files)`` raises :class:`EngineRunError` or returns what it checked; ``to_record`` turns
    that, with ``mpi_ranks``, ``resumed_attempts`` and ``output_bytes`` added, into the :class:`RunRecord`.
    ``extra_outputs`` names the case's own outputs besides :data:`RUN_OUTPUTS`, set aside with them before a new
    attempt.
    """
    run_dir = Path(run_dir)
    if not (run_dir / "deck" / DECK_NAME).exists():
        raise FileNotFoundError(f"no script at {run_dir / 'deck' / DECK_NAME}; render it first")
    (run_dir / "run.json").unlink(missing_ok=True)
    if attempt_logs(run_dir) and restart_files(run_dir):
        _resume(run_dir, options, target_time, without_redone(parse_markers(_logs_text(run_dir))))
    else:
        set_aside_previous_attempt(run_dir, RUN_OUTPUTS + tuple(extra_outputs), (f"{RESUME_STEM}*",))
        (run_dir / "dumps").mkdir(parents=True, exist_ok=True)
        run_script(run_dir, options, target_time)
    checked = check(without_redone(parse_markers(_logs_text(run_dir))), frame_files(run_dir, DUMP_PREFIX))
    checked.update({"mpi_ranks": 1, "resumed_attempts": len(attempt_logs(run_dir)) - 1})
    shutil.rmtree(run_dir / RESTART_DIR, ignore_errors=True)
    checked["output_bytes"] = output_bytes(run_dir)
    record = to_record(checked)
    write_run_record(run_dir, record)
    return record


_FRAME = re.compile(r"^(\w+?)_(\d+)\.npz$")


def frame_files(run_dir: str | Path, prefix: str) -> list[Path]:
    """``dumps/<prefix>_<step>.npz`` of a run, by step."""
    found = []
    for path in (Path(run_dir) / "dumps").glob(f"{prefix}_*.npz"):
        match = _FRAME.match(path.name)
        if match and match.group(1) == prefix:
            found.append((int(match.group(2)), path))
    return [path for _, path in sorted(found)]
