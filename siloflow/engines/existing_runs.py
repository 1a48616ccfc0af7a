"""Runs siloflow did not make: their folders checked before anything runs, their frames read through their engine.

A user points siloflow at the folder of a run made by their own engine input (``silo_flat.existing_runs``). The
description is checked by :func:`siloflow.engines.config.existing_silo_runs` when the configuration is validated; here the
folder is: :func:`check_existing_runs` asks the run's engine for the dump files (the folder exists, the pattern
matches), reads the one dump at or before the opening (the settled fill: it must hold particles, and a mass or a
density to give one), and wants at least one dump after the opening. Every refusal is a
:class:`~siloflow.engines.config.ConfigError` naming the key and the problem, so that the workflow stops before any step
runs. :func:`read_existing_frames` reads every frame for the analysis (:mod:`siloflow.analysis.studies.silo_flat.existing_run`).

Only the engine (:meth:`siloflow.engines.interface.Engine.dump_files`, :meth:`~siloflow.engines.interface.Engine.read_dump_files`)
knows its file names and formats.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from siloflow.model.existing_run import ExistingRunError, ExistingSiloRun
from siloflow.model.frames import ParticleFrame
from siloflow.engines.config import EXISTING_RUNS_KEY, ConfigError, existing_silo_runs
from siloflow.engines.interface import CaseNotSupported, DumpFile, engine_named

__all__ = ["check_existing_run", "check_existing_runs", "opening_files", "read_existing_frames"]


def _error(run: ExistingSiloRun, key: str, reason: str) -> ConfigError:
    return ConfigError(f"config key '{EXISTING_RUNS_KEY}.{run.name}.{key}': {reason}")


def opening_files(files: Sequence[DumpFile], open_step: int) -> tuple[list[DumpFile], bool]:
    """The files that hold the fill at the opening, and whether any file comes after it, by the steps their names
    give.

    Parameters
    ----------
    files : sequence of DumpFile
        In step order.
    open_step : int
        Step at which the outlet opened (-).

    Returns
    -------
    settled : list of DumpFile
        The last file named at or before ``open_step``; every file whose name gives no step (it holds its own steps,
        so it must be read to tell); empty when every named file comes after the opening.
    later : bool
        Whether a file is named after ``open_step``, or one holds its own steps (it may).
    """
    unnamed = [dump for dump in files if dump.step is None]
    before = [dump for dump in files if dump.step is not None and dump.step <= open_step]
    later = bool(unnamed) or any(dump.step is not None and dump.step > open_step for dump in files)
    return (before[-1:] + unnamed), later


def check_existing_run(run: ExistingSiloRun) -> list[DumpFile]:
    """Check a run's folder and dumps before anything runs.

    Parameters
    ----------
    run : ExistingSiloRun
        The run's description.

    Returns
    -------
    list of DumpFile
        Its dump files, in step order.

    Raises
    ------
    ConfigError
        Naming the key: the folder does not exist; the pattern is refused or matches nothing; a dump it matches is
        no particle dump its engine writes; no dump at or before the opening, or the one there holds no particle;
        the dumps carry no mass and no ``density`` is given (or a density cannot give it); no dump after the
        opening.
    """
    engine = engine_named(run.engine)
    try:
        files = engine.dump_files(run.folder, run.dumps)
    except ExistingRunError as error:
        raise _error(run, error.key, error.reason) from None
    except CaseNotSupported as error:
        raise _error(run, "engine", str(error)) from None
    settled, later = opening_files(files, run.open_step)
    if not settled:
        raise _error(run, "open_step", f"no dump at or before the opening (step {run.open_step}; the first dump is "
                                       f"of step {files[0].step}): the fill at the opening is not in the folder")
    try:
        frames = engine.read_dump_files(settled, run.timestep, density=run.density)
    except ValueError as error:  # DumpFormatError is a ValueError
        if run.density is None and _readable_with_a_density(engine, settled, run.timestep):
            names = ", ".join(str(dump.path) for dump in settled)
            raise _error(run, "density", f"required: the dumps carry no mass ({names}); give the particle density "
                                         "(kg/m3), from which each sphere's mass is density x 4/3 pi r^3") from None
        raise _error(run, "dumps", str(error)) from None
    at_opening = [frame for frame in frames if frame.step <= run.open_step]
    if not at_opening:
        raise _error(run, "open_step", f"no dump at or before the opening (step {run.open_step})")
    if len(at_opening[-1]) == 0:
        raise _error(run, "open_step", f"the dump of step {at_opening[-1].step}, the last at or before the opening "
                                       f"(step {run.open_step}), holds no particle: the silo was not filled yet")
    if not later or (all(dump.step is None for dump in files) and frames[-1].step <= run.open_step):
        raise _error(run, "open_step", f"no dump after the opening (step {run.open_step}): nothing of the discharge "
                                       "is in the folder")
    return files


def _readable_with_a_density(engine, files: Sequence[DumpFile], timestep: float) -> bool:
    """Whether the files read once a density is given: then the missing mass was their only fault."""
    try:
        engine.read_dump_files(files, timestep, density=1.0)
    except ValueError:
        return False
    return True


def check_existing_runs(config: Mapping) -> dict[str, list[DumpFile]]:
    """Check every run of ``silo_flat.existing_runs`` of a validated configuration (:func:`check_existing_run`).

    Returns
    -------
    dict of str to list of DumpFile
        Each run's dump files, by name.

    Raises
    ------
    ConfigError
        Naming the run's key and the problem.
    """
    return {name: check_existing_run(run) for name, run in existing_silo_runs(config).items()}


def read_existing_frames(run: ExistingSiloRun, on_damaged: str = "error") -> list[ParticleFrame]:
    """The particle frames of a run siloflow did not make from the fill at the opening on, in the order of its files
    (the dumps' own coordinates).

    Files named before the last one at or before the opening (the filling) are not read; a file that holds its own
    steps is read whole.

    Parameters
    ----------
    run : ExistingSiloRun
        The run's description.
    on_damaged : {"error", "skip"}
        What a damaged dump does.

    Returns
    -------
    list of ParticleFrame
        The frames; a mass from ``run.density`` where the dumps carry none.
        :func:`siloflow.analysis.studies.silo_flat.existing_run.opening_frames` picks the discharge from them.

    Raises
    ------
    ExistingRunError
        The folder or pattern fails (naming the key).
    ValueError
        A damaged dump under ``on_damaged="error"``, or a dump without mass and no density.
    """
    engine = engine_named(run.engine)
    files = engine.dump_files(run.folder, run.dumps)
    named = [dump.step for dump in opening_files(files, run.open_step)[0] if dump.step is not None]
    first = named[0] if named else None
    wanted = [dump for dump in files if dump.step is None or first is None or dump.step >= first]
    return engine.read_dump_files(wanted, run.timestep, density=run.density, on_damaged=on_damaged)
