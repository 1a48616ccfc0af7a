"""LIGGGHTS: rendering decks for siloflow cases, running the engine, reading its log.

Run directory layout (relative paths are what the deck sees, the engine runs inside the run directory)::

    <run>/deck/in.liggghts     the rendered deck
    <run>/deck/meshes/*.stl    wall meshes
    <run>/deck/case.json       derived case quantities (time step, clump count, ...)
    <run>/dumps/               particle dumps (binary legacy VTK)
    <run>/log.liggghts         the engine log
    <run>/engine.out           the engine's screen output
    <run>/run.json             written last, only after every check passed
"""

from __future__ import annotations

import logging
import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.engines.deadline import PartDeadline
from siloflow.engines.interface import EngineNotFound, EngineRunError
from siloflow.engines.run_files import output_bytes, remove_matching, write_run_record
from siloflow.engines.run_files import set_aside_previous_attempt as set_aside
from siloflow.engines.liggghts.dumps import list_dumps
from siloflow.engines.layout import RUN_RECORD, write_text_atomic
from siloflow.engines.liggghts.inputs import DECK_NAME
from siloflow.engines.liggghts.markers import error_lines, log_excerpt
from siloflow.engines.markers import Marker, parse_markers, without_redone
from siloflow.engines.liggghts.thermo import ThermoProgress
from siloflow.engines.progress import run_with_progress
from siloflow.engines.templating import render_deck

LOG_NAME = "log.liggghts"
SCREEN_NAME = "engine.out"
DUMP_PREFIX = "particles"
CONTACT_PREFIX = "contacts"
#: The settled fill's spheres with their wall forces (``dump custom``), one file ``settled_fill_<step>.txt``.
SETTLED_FILL_PREFIX = "settled_fill"
#: Every wall's force on the particles at the settled fill's steps (``fix ave/time``, the wall force file's format).
SETTLED_WALLS_PATH = "dumps/settled_walls.txt"
#: Steps of the run that writes the settled fill's snapshot at its last two steps: the kick of the run's set-up has
#: died away to 1e-3 of the weight after 100 (``settled_fill_snapshot`` in ``siloflow/templates/liggghts/macros.j2``).
SETTLED_SNAPSHOT_STEPS = 200


def settled_fill_context(contacts_prefix: str, contact_columns: int, timestep: float) -> dict:
    """The deck context of the settled fill's snapshot (``settled_fill_snapshot`` in ``siloflow/templates/liggghts/macros.j2``):
    the files of its spheres, pair contacts (``<contacts_prefix>_<step>.txt``, ``contact_columns`` columns of the
    ``pair_contacts`` compute) and walls' forces, and the length of its run; ``timestep`` [s] goes into the walls'
    file title."""
    return {
        "path": f"dumps/{SETTLED_FILL_PREFIX}_*.txt",
        "contacts_path": f"dumps/{contacts_prefix}_*.txt",
        "contact_compute": "pair_contacts",
        "contact_columns": contact_columns,
        "walls_path": SETTLED_WALLS_PATH,
        "steps": SETTLED_SNAPSHOT_STEPS,
        "timestep": timestep,
    }



#: Restart files of a silo-type run, from its pour on: ``restart/state_<step>.restart``, about
#: :data:`~siloflow.engines.run_files.RESTARTS_PER_STAGE` per stage (:func:`~siloflow.engines.run_files.restart_every`).
RESTART_DIR = "restart"
RESTART_PREFIX = "state"
RESTART_PATH = f"{RESTART_DIR}/{RESTART_PREFIX}_*.restart"




# ---------------------------------------------------------------------------------------------- running


def check_programs(executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun") -> None:
    """Refuse (EngineNotFound, naming the config key) a LIGGGHTS executable, or an MPI launcher when ``mpi_ranks``
    > 1, that is not an executable file on PATH or at the path given."""
    if shutil.which(executable) is None:
        raise EngineNotFound(
            f"config key 'engine.liggghts.executable': LIGGGHTS executable '{executable}' is not an executable on "
            "PATH or at that path; install it with `make install` (Debian package liggghts) or give its path"
        )
    if mpi_ranks > 1 and shutil.which(mpirun) is None:
        raise EngineNotFound(f"config key 'engine.mpirun': MPI launcher '{mpirun}' (engine.mpi_ranks is {mpi_ranks}) is "
                             "not an executable on PATH or at that path; install openmpi-bin or give its path")


#: GNU coreutils' line-buffering wrapper of a program's standard output. LIGGGHTS 3.8's ``thermo_modify flush yes``
#: flushes its log file only (``src/thermo.cpp``), not the screen: through a pipe its thermo rows arrive in 4 KB
#: blocks, half an hour apart in a large run, and the progress line (which reads the screen) stalls between them.
LINE_BUFFERED = ("stdbuf", "-oL")


def engine_command(deck: str, executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun",
                   log_name: str = LOG_NAME) -> list[str]:
    """Command line of one engine run, serial or under MPI (no shell involved); its screen line-buffered
    (:data:`LINE_BUFFERED`) where ``stdbuf`` is installed. ``stdbuf`` execs the engine in its own process, so the
    engine receives the signals that stop or interrupt the run."""
    check_programs(executable, mpi_ranks, mpirun)
    command = [executable, "-in", deck, "-log", log_name]
    if shutil.which(LINE_BUFFERED[0]) is not None:
        command = [*LINE_BUFFERED, *command]
    if mpi_ranks > 1:
        command = [mpirun, "-np", str(mpi_ranks), "--oversubscribe", *command]
    return command


def _mpi_environment() -> dict:
    environment = dict(os.environ)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        # Open MPI refuses to run as root unless told; containers and CI run as root.
        environment.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        environment.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return environment


#: The force history of the walls the silo-type decks write (read by :mod:`siloflow.engines.liggghts.forces`).
WALL_FORCES_NAME = "wall_forces.txt"
#: The settled fill of a flat-bottom silo run, which the recirculating silo's runs start from (its restart file, in the
#: run's folder); a run that starts from it reads its copy in ``deck/``.
ASSEMBLY_RESTART = "assembly.restart"
RUN_OUTPUTS = ("dumps", LOG_NAME, SCREEN_NAME, "restart", WALL_FORCES_NAME, ASSEMBLY_RESTART)
#: The restart file LIGGGHTS writes of its own when a signal stops it (SIGTERM at a part's deadline): a resumed run
#: goes on from its periodic restart files instead, so these only serve an inspection of the stopped attempt.
FORCED_RESTARTS = "restart_forced_*.data"


def set_aside_previous_attempt(run_dir: Path, outputs: tuple[str, ...] = RUN_OUTPUTS) -> Path | None:
    """Move the output of an unfinished earlier attempt (``outputs``, and the resumptions' files) into
    ``failed_attempts/<UTC time>/`` (:func:`siloflow.engines.run_files.set_aside_previous_attempt`)."""
    return set_aside(run_dir, outputs, (f"{RESUME_STEM}*", FORCED_RESTARTS))


#: Wall time between progress lines in a run's log (s) and between polls of the engine's output (s).
PROGRESS_LOG_EVERY = 30.0
PROGRESS_POLL_EVERY = 1.0


def run_engine(run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun",
               target_time: float | None = None, deck_name: str = DECK_NAME, log_name: str = LOG_NAME,
               screen_name: str = SCREEN_NAME) -> str:
    """Run the deck ``<run_dir>/deck/<deck_name>`` inside ``run_dir`` and return the log text.

    With ``target_time`` (the simulated time the run reaches, s) progress is reported while it runs: simulated
    time out of the target, clumps and an ETA, every 30 s and at the end, in the log (``logging``) and, when the
    job's stderr is a terminal, as one whole line naming the run there (runs Snakemake starts at once share it).

    Raises
    ------
    EngineRunError
        On a non-zero exit or an ERROR line, quoting the relevant log lines; the run directory is left as is.
    """
    run_dir = Path(run_dir)
    command = engine_command(f"deck/{deck_name}", executable, mpi_ranks, mpirun, log_name)
    (run_dir / "dumps").mkdir(parents=True, exist_ok=True)
    (run_dir / RESTART_DIR).mkdir(exist_ok=True)
    returncode = run_with_progress(command, run_dir, run_dir / screen_name, _mpi_environment(), ThermoProgress(),
                                   target_time, PROGRESS_LOG_EVERY, PROGRESS_POLL_EVERY)
    log_path = run_dir / log_name
    log_text = log_path.read_text(encoding="utf-8", errors="replace") if log_path.exists() else ""
    screen_text = (run_dir / screen_name).read_text(encoding="utf-8", errors="replace")
    problems = error_lines(log_text) or error_lines(screen_text)
    if returncode != 0 or problems:
        raise EngineRunError(
            f"LIGGGHTS run in {run_dir} failed (exit code {returncode}); "
            f"log lines:\n{log_excerpt(log_text or screen_text)}\n"
            f"The run directory is left for inspection: {run_dir}"
        )
    return log_text


@dataclass(frozen=True)
class ResumePoint:
    """Where a stopped silo-type run goes on from a restart file.

    Attributes
    ----------
    stage : str
        The stage the restart file lies in: ``fill`` (the pour), ``settle`` or ``discharge`` (the last stage, after
        the outlet opened).
    final_step : int or None
        In the last stage, the step the uninterrupted run ends at (its outlet's opening step plus the last stage's
        steps); None before.
    settle_checks : int or None
        In the settling, the checks the stopped run had still to make (at least 1); None otherwise.
    """

    stage: str
    final_step: int | None = None
    settle_checks: int | None = None


def resume_point(markers: list[Marker], restart_step: int, last_stage_steps: int,
                 settle_max_checks: int) -> ResumePoint:
    """The stage a restart file written at ``restart_step`` lies in, from the stage markers of the attempts so far.

    The last stage when an ``opened`` marker is at or before it; the settling when a ``filled`` marker is (the checks
    still to make: ``settle_max_checks`` less the ``settle`` markers at or before it, whatever attempt printed them);
    else the pour. ``markers`` are those of the attempts so far without the ones a later attempt made again
    (:func:`siloflow.engines.markers.without_redone`); those after the restart step were printed by an attempt
    that went on past it, and are made again.
    """
    def steps(event: str) -> list[int]:
        return [step for m in markers if m.event == event and (step := int(round(m.values["step"]))) <= restart_step]

    opened = steps("opened")
    if opened:
        return ResumePoint("discharge", final_step=max(opened) + last_stage_steps)
    if steps("filled"):
        return ResumePoint("settle", settle_checks=max(settle_max_checks - len(steps("settle")), 1))
    return ResumePoint("fill")


@dataclass(frozen=True)
class Resume:
    """How a silo-type run resumes: the deck template of its case, its rendering context and the steps of its
    last stage."""

    template: str
    context: dict
    last_stage_steps: int

    def deck(self, restart_file: str, point: ResumePoint) -> str:
        """The resume deck: the case deck from ``restart_file``, in the stage of ``point`` (:func:`resume_point`)."""
        context = dict(self.context)
        context.update(case_template=self.template, resume={"restart_file": restart_file, "stage": point.stage})
        if point.stage == "discharge":
            context.update(
                discharge={**self.context["discharge"], "steps": int(point.final_step), "upto": True},
                # the dumps go on on the steps of the first attempt (multiples of the interval), none at the restart
                dump={**self.context["dump"], "first": False},
            )
        elif point.stage == "settle":
            context["settle"] = {**self.context["settle"], "max_checks": int(point.settle_checks)}
        return render_deck("liggghts/resume.lmp.j2", context)

    def point(self, markers: list[Marker], restart_step: int) -> ResumePoint:
        """:func:`resume_point` of this run's case."""
        return resume_point(markers, restart_step, self.last_stage_steps, self.context["settle"]["max_checks"])


RESUME_STEM = "resume"
RESUME_DECK = "resume.liggghts"
_RESTART_STEP = re.compile(rf"^{RESTART_PREFIX}_(\d+)\.restart$")


def restart_files(run_dir: str | Path) -> list[Path]:
    """Restart files of a run, oldest step first."""
    found = []
    for path in (Path(run_dir) / RESTART_DIR).glob(f"{RESTART_PREFIX}_*.restart"):
        match = _RESTART_STEP.match(path.name)
        if match and path.stat().st_size > 0:
            found.append((int(match.group(1)), path))
    return [path for _, path in sorted(found)]


def attempt_logs(run_dir: str | Path) -> list[Path]:
    """The log of the first attempt and those of its resumptions, in order."""
    run_dir = Path(run_dir)
    resumed = sorted(run_dir.glob(f"{RESUME_STEM}*.{LOG_NAME}"), key=lambda p: int(p.name.split(".")[0][len(RESUME_STEM):]))
    return [path for path in [run_dir / LOG_NAME, *resumed] if path.exists()]


def _logs_text(run_dir: Path) -> str:
    return "\n".join(path.read_text(encoding="utf-8", errors="replace") for path in attempt_logs(run_dir))


#: What a run writes once its fill has settled (snapshot, contacts, walls' forces, the assembly): a run resumed in
#: its fill or settling writes them again, so those of the attempt it resumes are removed first.
SETTLED_OUTPUTS = (f"dumps/{SETTLED_FILL_PREFIX}_*.txt", f"dumps/{CONTACT_PREFIX}_*.txt", SETTLED_WALLS_PATH,
                   ASSEMBLY_RESTART)


def discard_settled_outputs(run_dir: Path) -> list[str]:
    """Remove what a stopped attempt wrote once its fill had settled (:data:`SETTLED_OUTPUTS`), before an attempt that
    resumes in the pour or the settling writes them again; returns the names removed."""
    return remove_matching(run_dir, SETTLED_OUTPUTS)


def _resume_run(run_dir: Path, resume: Resume, markers: list[Marker], engine: dict) -> None:
    """Resume from the newest restart file (the one before it if the newest was cut off by the kill), in the stage
    that file lies in."""
    log = logging.getLogger("siloflow")

    def run_from(restart: Path) -> None:
        relative = f"{RESTART_DIR}/{restart.name}"
        restart_step = int(_RESTART_STEP.match(restart.name).group(1))
        point = resume.point(markers, restart_step)
        if point.stage != "discharge":
            discard_settled_outputs(run_dir)
        write_text_atomic(run_dir / "deck" / RESUME_DECK, resume.deck(relative, point))
        log.info("resuming %s from restart file %s in its %s%s", run_dir.name, relative, point.stage,
                 f" (the last stage ends at step {point.final_step})" if point.final_step is not None else "")
        options = dict(engine)
        if options.get("target_time"):
            # LIGGGHTS restarts the clock at zero: progress counts the simulated time still to go
            final_step = point.final_step or max(int(round(options["target_time"] / resume.context["timestep"])), 1)
            options["target_time"] *= max(final_step - restart_step, 1) / final_step
        attempt = len(attempt_logs(run_dir))
        run_engine(run_dir, **options, deck_name=RESUME_DECK, log_name=f"{RESUME_STEM}{attempt}.{LOG_NAME}",
                   screen_name=f"{RESUME_STEM}{attempt}.{SCREEN_NAME}")

    newest, *older = restart_files(run_dir)[-2:][::-1]
    try:
        run_from(newest)
    except PartDeadline:
        # the part's time ran out while the run went on from its newest file, which was read: the next part
        # resumes from the newest file then; going back one file now would run on past the deadline
        raise
    except EngineRunError as error:
        if not older or "restart" not in str(error).lower():
            raise
        log.warning("restart file %s is unreadable (%s); trying the one before it", newest.name, error)
        run_from(older[0])


def run_checked(run_dir: str | Path, check, engine: dict | None = None, to_record=None,
                resume: Resume | None = None) -> RunRecord:
    """Run the rendered deck of ``run_dir``, check the run and write ``run.json``; returns the record.

    A run that was stopped after its pour began (it left a log and restart files) resumes from its newest restart
    file when ``resume`` is given, in the stage that file lies in; its logs are then the first attempt's
    plus one per resumption, checked together. Otherwise the output of an earlier unfinished attempt is moved to
    ``failed_attempts/`` first, so the dumps of this run are never mixed with older ones. ``check(markers,
    dump_files)`` raises :class:`EngineRunError` or returns what it checked (a dict); ``engine`` holds the
    :func:`run_engine` options and ``to_record(checked)`` turns the checked dict, with ``mpi_ranks``,
    ``resumed_attempts`` and ``output_bytes`` added, into the :class:`RunRecord`. Restart files are deleted once
    the run is complete and checked: they only serve resumption.
    """
    run_dir = Path(run_dir)
    engine = dict(engine or {})
    deck = run_dir / "deck" / DECK_NAME
    if not deck.exists():
        raise FileNotFoundError(f"no deck at {deck}; render it first")
    (run_dir / RUN_RECORD).unlink(missing_ok=True)
    resumed = resume is not None and bool(attempt_logs(run_dir)) and bool(restart_files(run_dir))
    if resumed:
        _resume_run(run_dir, resume, without_redone(parse_markers(_logs_text(run_dir))), engine)
    else:
        set_aside_previous_attempt(run_dir)
        run_engine(run_dir, **engine)
    checked = check(without_redone(parse_markers(_logs_text(run_dir))), list_dumps(run_dir / "dumps", DUMP_PREFIX))
    checked.update({"mpi_ranks": engine.get("mpi_ranks", 1), "resumed_attempts": len(attempt_logs(run_dir)) - 1})
    shutil.rmtree(run_dir / RESTART_DIR, ignore_errors=True)
    for forced in run_dir.glob(FORCED_RESTARTS):
        forced.unlink()
    checked["output_bytes"] = output_bytes(run_dir)
    record = to_record(checked)
    write_run_record(run_dir, record)
    return record
