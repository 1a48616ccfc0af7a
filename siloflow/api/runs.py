"""Opening a finished run folder, of either engine and any case kind: its case summary, its run record, and what
its engine saved (particle frames, wall forces, contacts), read back through that engine.

A run folder is finished when it holds its run record (``run.json``, written last, only when the run passed every
check); its case summary (``deck/case.json``) is the engine-neutral description of the case. Which engine made the
run is in the record, so the same calls read a LIGGGHTS and a YADE run.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

from siloflow.model.contacts import ContactFrame
from siloflow.model.forces import WallForceHistory
from siloflow.model.frames import ClumpFrame, ParticleFrame, clumps_from_frame
from siloflow.model.record import RunRecord, read_run_record
from siloflow.engines.interface import Engine, engine_named
from siloflow.engines.layout import CASE_SUMMARY, RUN_RECORD

__all__ = ["Run", "open_run"]


@dataclass(frozen=True, eq=False)
class Run:
    """A finished run: where it lives, what it was and what it saved.

    Attributes
    ----------
    path : pathlib.Path
        The run folder.
    record : siloflow.model.record.RunRecord
        Its run record (``run.json``): the engine and case kind, the time step [s], the clump count, the stages with
        their times [s], the outlet opening (step, time [s]), the outlet height and periodic domain [m].
    case : dict
        Its case summary (``deck/case.json``): the case's numbers in SI units, named with their unit
        (``width_m``, ``clump_mass_kg``, ``timestep_s``, ...).

    Notes
    -----
    :meth:`frames`, :meth:`clumps`, :meth:`wall_forces` and :meth:`contacts` read the engine's own files each time
    they are called; keep what they return rather than calling them again.
    """

    path: Path
    record: RunRecord
    case: dict

    @property
    def kind(self) -> str:
        """The case kind: ``jenike``, ``silo_flat``, ``silo_recirculation``, ``blender`` or ``verification``."""
        return self.record.case

    @property
    def run_id(self) -> str:
        """The run's id: a label and the hash of every parameter that defines the run."""
        return self.record.run_id

    @property
    def engine(self) -> Engine:
        """The engine that made the run (``engine.name`` is its registry name)."""
        return engine_named(self.record.engine)

    @property
    def record_path(self) -> Path:
        """The run record, ``<path>/run.json``."""
        return self.path / RUN_RECORD

    @property
    def case_path(self) -> Path:
        """The case summary, ``<path>/deck/case.json``."""
        return self.path / CASE_SUMMARY

    @property
    def deck(self) -> Path:
        """The folder of the engine's inputs, ``<path>/deck``."""
        return self.case_path.parent

    def frames(self, since_opening: bool = False, on_damaged: str = "error") -> list[ParticleFrame]:
        """The particle frames the run saved, oldest first: per sphere, positions [m], velocities [m/s], radii [m],
        masses [kg] (the clump's on each of its spheres) and clump ids; each frame's time [s] is simulated time
        since the start of the run.

        Parameters
        ----------
        since_opening : bool, optional
            Only the frames from the outlet's opening on (the record's ``open_step``); default all of them.
        on_damaged : {"error", "skip"}, optional
            What a damaged frame file does: stop with an error naming it (default), or leave it out.

        Raises
        ------
        ValueError
            With ``since_opening`` for a run without an outlet (a Jenike cell).
        """
        frames = self.engine.read_frames(self.path, self.record, on_damaged=on_damaged)
        if not since_opening:
            return frames
        if self.record.open_step is None:
            raise ValueError(f"run {self.run_id} ({self.kind}) has no outlet opening; call frames() without "
                             "since_opening")
        return [frame for frame in frames if frame.step >= self.record.open_step]

    def clumps(self, since_opening: bool = False, on_damaged: str = "error") -> list[ClumpFrame]:
        """The saved frames as clumps (one row per clump: centre [m], velocity [m/s], mass [kg]), oldest first.

        In a domain periodic in z (the record's ``domain_z``), a clump that straddles the boundary is put back
        together and its centre wrapped into the domain (:func:`siloflow.model.frames.clumps_from_frame`).

        Parameters
        ----------
        since_opening, on_damaged
            As for :meth:`frames`.
        """
        periodic = None if self.record.domain_z is None else [None, None, tuple(self.record.domain_z)]
        return [clumps_from_frame(frame, periodic_bounds=periodic)
                for frame in self.frames(since_opening=since_opening, on_damaged=on_damaged)]

    def wall_forces(self) -> WallForceHistory:
        """The force [N] and torque [N m] each wall exerted on the particles, against time [s] (a Jenike cell's
        history also has the lid's height [m] and the mass above the shear plane [kg] as signals)."""
        return self.engine.wall_forces(self.path, self.record)

    def contacts(self, kind: str = "pair") -> list[ContactFrame]:
        """The contact forces the run saved, oldest first: ``pair`` (particle-particle: the centres of the two
        spheres [m] and the force on the first [N]) or ``wall`` (the Jenike cell's particle-wall contacts).

        The silo-type runs save the pair contacts of their settled fill, just before the outlet opens.
        """
        return self.engine.contacts(self.path, self.record, kind)


def open_run(path: str | os.PathLike) -> Run:
    """Open a finished run folder of either engine and any case kind.

    Parameters
    ----------
    path : str or path-like
        The run folder, ``results/<case>/<run id>/`` (or any folder holding ``run.json`` and ``deck/case.json``).

    Returns
    -------
    Run

    Raises
    ------
    FileNotFoundError
        When the folder does not exist, or holds no run record (the run has not finished, or failed a check: its
        ``logs/`` say why) or no case summary.
    siloflow.model.record.RunRecordError
        When the run record is not one this siloflow reads.

    Examples
    --------
    A run folder holds its record and its case summary (the engine's own files, which :meth:`Run.frames` reads,
    are left out here):

    >>> import json, tempfile
    >>> from pathlib import Path
    >>> from siloflow.model.record import RunRecord
    >>> folder = Path(tempfile.mkdtemp()) / "sphere2-0123456789"
    >>> (folder / "deck").mkdir(parents=True)
    >>> record = RunRecord(engine="yade", case="silo_flat", run_id=folder.name, timestep_s=2e-5, n_clumps=1200,
    ...                    n_frames=60, mpi_ranks=1, stages={"open": {"step": 5000, "time": 0.1}},
    ...                    open_step=5000, open_time_s=0.1, outlet_z=0.0)
    >>> _ = (folder / "run.json").write_text(record.to_json())
    >>> _ = (folder / "deck" / "case.json").write_text(json.dumps({"case": "silo_flat", "width_m": 0.15}))
    >>> run = open_run(folder)
    >>> run.kind, run.engine.name, run.record.open_time_s, run.case["width_m"]
    ('silo_flat', 'yade', 0.1, 0.15)
    >>> open_run(folder.parent / "missing")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    FileNotFoundError: no run folder at .../missing
    """
    folder = Path(path)
    if not folder.is_dir():
        raise FileNotFoundError(f"no run folder at {folder}")
    record_path = folder / RUN_RECORD
    if not record_path.is_file():
        raise FileNotFoundError(f"{folder} holds no {RUN_RECORD}: the run has not finished or failed a check "
                                f"(its logs/ say which)")
    case_path = folder / CASE_SUMMARY
    if not case_path.is_file():
        raise FileNotFoundError(f"{folder} holds no case summary {CASE_SUMMARY}")
    return Run(path=folder, record=read_run_record(record_path), case=json.loads(case_path.read_text(encoding="utf-8")))
