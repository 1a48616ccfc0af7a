"""The seam between a case and the engine that runs it: one small interface and a registry of engines by name.

A case (:mod:`siloflow.model.cases`) is engine-neutral data. An engine turns it into input files, runs them and reads the
outputs back into neutral objects (:mod:`model`): particle frames, the force and torque each wall exerts on
the particles, contact forces at saved instants, and the typed run record. Nothing outside an engine's own package
(``engines/<name>/``) and templates (``templates/<name>/``) knows its file names or formats.

Each engine is a subclass of :class:`Engine` in the package ``engines.<name>`` that decorates itself with
:func:`register`; :func:`engine_named` imports that package on first use (the engine kinds are listed in
:data:`ENGINE_KINDS`, as the configuration schema's ``engine.kind`` enumerates them). As in signac-flow, each engine
class names its own base template, and its case templates extend it with blocks.

A run siloflow did not make (a user's own input, ``silo_flat.existing_runs``) is known only from its particle dumps:
an engine that reads those implements :meth:`Engine.dump_files` and :meth:`Engine.read_dump_files`; one that does not
refuses, naming itself.

Adding an engine: create ``engines/<name>/`` with an :class:`Engine` subclass, its templates under
``templates/<name>/``, add the name to :data:`ENGINE_KINDS` and to the schema's ``engine.kind`` enum.
"""

from __future__ import annotations

import importlib
import math
import os
import shutil
import subprocess
from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Mapping

from siloflow.model.cases.kinds import configured_kinds
from siloflow.model.cases.common import engine_kind

if TYPE_CHECKING:  # the neutral types appear in signatures only
    from siloflow.model.contacts import ContactFrame
    from siloflow.model.forces import WallForceHistory
    from siloflow.model.frames import ParticleFrame
    from siloflow.model.record import RunRecord
    from siloflow.model.settled import SettledFill
    from siloflow.model.cost import MeasuredWork

__all__ = [
    "ENGINE_KINDS",
    "CaseNotSupported",
    "DumpFile",
    "Engine",
    "EngineError",
    "EngineNotFound",
    "EngineOptions",
    "EngineRunError",
    "engine_for",
    "engine_named",
    "register",
]

#: Engines siloflow can drive, by registry name (the package ``engines.<name>`` implements each).
ENGINE_KINDS = ("liggghts", "yade")


class EngineError(RuntimeError):
    """Base of the errors an engine raises while running a case."""


class EngineNotFound(EngineError):
    """The engine's executable or launcher is not installed or not on PATH."""


class EngineRunError(EngineError):
    """A run failed; the message quotes the relevant log lines and names the run directory."""


class CaseNotSupported(ValueError):
    """The engine cannot run this case as configured; the message names the config key and the engine's limit."""


@dataclass(frozen=True)
class EngineOptions:
    """How an engine is started (the validated ``engine`` config section).

    Attributes
    ----------
    mpi_ranks : int
        MPI ranks per run; 1 runs serially without a launcher.
    mpirun : str
        MPI launcher used when ``mpi_ranks > 1``.
    settings : dict
        The engine's own settings (``engine.<kind>``, e.g. the LIGGGHTS executable).
    """

    mpi_ranks: int = 1
    mpirun: str = "mpirun"
    settings: Mapping[str, Any] | None = None

    @classmethod
    def from_config(cls, config: Mapping, kind: str) -> "EngineOptions":
        """Options of engine ``kind`` from a validated configuration."""
        section = config["engine"]
        return cls(mpi_ranks=int(section["mpi_ranks"]), mpirun=str(section["mpirun"]),
                   settings=dict(section.get(kind, {})))


@dataclass(frozen=True)
class DumpFile:
    """One particle dump file of a run siloflow did not make (:meth:`Engine.dump_files`).

    Attributes
    ----------
    path : pathlib.Path
        The file.
    step : int or None
        The step its name gives; None for a file that holds its own steps (several snapshots).
    """

    path: Path
    step: int | None


class Engine(ABC):
    """What every DEM engine does for siloflow. Subclasses set :attr:`name` and :attr:`base_template`."""

    #: Registry name (``engine.kind`` in the config).
    name: ClassVar[str]
    #: The engine's base template under ``templates/``; each case template extends it.
    base_template: ClassVar[str]
    #: The Debian package that installs the engine (`make install`), whose version the validation record states.
    debian_package: ClassVar[str]

    def installed_version(self) -> str:
        """The installed version of :attr:`debian_package` (dpkg's), or ``"unknown"`` where dpkg does not know it."""
        try:
            found = subprocess.run(["dpkg-query", "--show", "--showformat=${Version}", self.debian_package],
                                   capture_output=True, text=True, check=False, timeout=30)
        except (OSError, subprocess.TimeoutExpired):
            return "unknown"
        return found.stdout.strip() if found.returncode == 0 and found.stdout.strip() else "unknown"

    @abstractmethod
    def check_installed(self, options: EngineOptions) -> None:
        """Refuse, before anything runs, an engine whose programs (as ``options`` name them) are not installed.

        Raises
        ------
        EngineNotFound
            Naming the config key that names the missing program and how to install it.
        """

    @abstractmethod
    def check_case(self, case) -> None:
        """Refuse a case the engine cannot run as configured, before anything runs.

        Raises
        ------
        CaseNotSupported
            Naming the config key and the engine's limit.
        """

    @abstractmethod
    def write_inputs(self, case, run_dir: str | Path, assembly_dir: str | Path | None = None) -> Path:
        """Render the case into ``<run_dir>/deck/``; the neutral case summary ``deck/case.json`` is written last.

        ``assembly_dir`` is the folder of the run whose settled fill ``case`` starts from (its ``assembly``;
        :meth:`place_assembly`), None for a case that makes its own. Returns the path of ``deck/case.json``.
        """

    #: The file in a flat-bottom silo run's folder that keeps its settled fill (the engine's own restart format); a
    #: run that starts from it reads a copy of the same name in its ``deck/``.
    assembly_file: ClassVar[str]

    def place_assembly(self, case, run_dir: str | Path, assembly_dir: str | Path | None) -> None:
        """Put the settled fill ``case`` starts from (the :attr:`assembly_file` of the run in ``assembly_dir``) into
        ``<run_dir>/deck/``, as a hard link where the file system allows one (else a copy): the deck keeps the fill it
        was rendered for even when that run is made again. Nothing for a case without an ``assembly``.

        Raises
        ------
        ValueError
            When the case starts from an assembly and ``assembly_dir`` is None.
        FileNotFoundError
            When that run's folder holds no settled fill, naming the folder.
        """
        assembly = getattr(case, "assembly", None)
        if assembly is None:
            return
        if assembly_dir is None:
            raise ValueError(f"run {case.run_id} starts from the settled fill of run {assembly.run_id}: give that run's "
                             "folder")
        source = Path(assembly_dir) / self.assembly_file
        if not source.is_file():
            raise FileNotFoundError(
                f"{source}: run {assembly.run_id} has no settled fill, which run {case.run_id} starts from; it failed "
                f"or was made before its runs kept one: move its folder {assembly_dir} aside and make it again")
        target = Path(run_dir) / "deck" / self.assembly_file
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = target.with_name(target.name + ".partial")
        partial.unlink(missing_ok=True)
        try:
            os.link(source, partial)
        except OSError:
            shutil.copyfile(source, partial)
        os.replace(partial, target)

    @abstractmethod
    def run(self, case, run_dir: str | Path, options: EngineOptions) -> RunRecord:
        """Run rendered inputs (serial or MPI, with progress, failure detection and resume), check that the run did
        what the case asked and write ``<run_dir>/run.json`` last.

        Raises
        ------
        EngineNotFound, EngineRunError
        """

    @abstractmethod
    def measured_work(self, run_dir: str | Path) -> MeasuredWork | None:
        """The CPU time a run took on this machine and the sphere-steps it made (the spheres it held, summed over
        its steps), from the engine's own timing of every attempt, or None when the run left no timing (not run, or
        stopped before its first stage ended)."""

    @abstractmethod
    def earlier_attempt_seconds(self, run_dir: str | Path) -> list[float]:
        """Time each of a run's attempts before its last took (s), oldest first, from the engine's own timing in its
        log, up to the last time it logged: those moved aside into ``failed_attempts/`` to start afresh
        (:func:`siloflow.engines.run_files.set_aside_attempts`), then those resumed in place from the run's restart
        files; none for a run made in one go. Snakemake's benchmark of the run step times its last attempt only."""

    def earlier_attempts_seconds(self, run_dir: str | Path) -> float:
        """Time a run's attempts before its last took together (s): :meth:`earlier_attempt_seconds` summed."""
        return math.fsum(self.earlier_attempt_seconds(run_dir))

    def measured_cost(self, run_dir: str | Path) -> float | None:
        """CPU seconds per sphere-step that a run took on this machine (s), from :meth:`measured_work`, or None when
        the run left no timing."""
        work = self.measured_work(run_dir)
        return work.seconds_per_sphere_step if work is not None else None

    @abstractmethod
    def read_frames(self, run_dir: str | Path, record: RunRecord, on_damaged: str = "error") -> list[ParticleFrame]:
        """The particle frames a run saved, oldest first (``on_damaged``: ``error`` or ``skip`` a damaged one)."""

    @abstractmethod
    def wall_forces(self, run_dir: str | Path, record: RunRecord) -> WallForceHistory:
        """The force and torque each wall exerted on the particles, as a time series."""

    @abstractmethod
    def contacts(self, run_dir: str | Path, record: RunRecord, kind: str = "pair") -> list[ContactFrame]:
        """Contact forces at the saved instants, oldest first: ``pair`` (particle-particle) or ``wall``."""

    @abstractmethod
    def settled_fill(self, run_dir: str | Path, record: RunRecord) -> tuple[SettledFill, ...]:
        """The fill at rest after its settle stage, at each step of its snapshot (consecutive steps, oldest first):
        spheres with the walls' force on each, the pair contacts and each wall's force of that step (for the force
        balance of :mod:`siloflow.analysis.numerics.force_balance`, which averages the steps).

        Raises
        ------
        CaseNotSupported
            When the engine saves no settled fill for this case.
        """

    # Runs siloflow did not make (a user's own input): the engine reads their particle dumps and nothing else. Not
    # abstract: an engine that cannot refuses, naming itself.

    def dump_files(self, folder: str | Path, pattern: str) -> list[DumpFile]:
        """The particle dump files a run of the engine's own input left in ``folder``, in step order.

        Parameters
        ----------
        folder : str or path-like
            The run's folder.
        pattern : str
            The dump file names, relative to ``folder``, as the engine's dump command names them.

        Raises
        ------
        siloflow.model.existing_run.ExistingRunError
            Naming ``folder`` (missing) or ``dumps`` (a pattern the engine does not write, or no file).
        CaseNotSupported
            When the engine reads no dumps of runs siloflow did not make.
        """
        raise CaseNotSupported(f"siloflow reads no {self.name} dumps of runs it did not make")

    def read_dump_files(self, files, timestep: float, *, density: float | None = None,
                        on_damaged: str = "error") -> list[ParticleFrame]:
        """The particle frames of :meth:`dump_files`' files, in their order.

        Parameters
        ----------
        files : sequence of DumpFile
            The files.
        timestep : float
            The run's time step (s): a frame's time is its step times it.
        density : float, optional
            Particle density (kg/m^3), for dumps without a mass.
        on_damaged : {"error", "skip"}
            What a damaged dump does.
        """
        raise CaseNotSupported(f"siloflow reads no {self.name} dumps of runs it did not make")


_REGISTERED: dict[str, type[Engine]] = {}


def register(engine_class: type[Engine]) -> type[Engine]:
    """Class decorator: make an :class:`Engine` subclass available under its :attr:`Engine.name`."""
    name = engine_class.name
    if name not in ENGINE_KINDS:
        raise ValueError(f"engine name {name!r} is not one of ENGINE_KINDS {ENGINE_KINDS}")
    _REGISTERED[name] = engine_class
    return engine_class


def engine_named(name: str) -> Engine:
    """The engine registered as ``name`` (its package is imported on first use).

    Raises
    ------
    KeyError
        When siloflow has no engine of that name.
    """
    if name not in ENGINE_KINDS:
        raise KeyError(f"unknown engine {name!r}; siloflow has: {', '.join(ENGINE_KINDS)}")
    if name not in _REGISTERED:
        # the engine's package registers its class when imported
        importlib.import_module(f"{__package__}.{name}")
    return _REGISTERED[name]()


def engine_for(config: Mapping, section: str) -> Engine:
    """The engine that runs the cases of config section ``section``."""
    if section not in configured_kinds():
        raise KeyError(f"unknown case section {section!r}; the cases are {', '.join(configured_kinds())}")
    return engine_named(engine_kind(config, section))
