"""What a finished Jenike shear run must show, whatever engine ran it: its force history (one format, written by
every engine's inputs), the stage markers (:mod:`siloflow.engines.markers`) checked against the case, and the run record.

The force history is a whitespace table: comment lines starting with ``#``, then one row per output interval, the
step followed by :data:`FORCE_COLUMNS` (SI units). Each row averages the interval before it; its time is the mean
time of that interval. Forces are those of the particles ON the lid, the shear ring and the base (bottom ring or
plate).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from siloflow.model.forces import WallForceHistory
from siloflow.model.record import RunRecord
from siloflow.model.cases.jenike import JenikeCase
from siloflow.model.file_messages import first_not_read
from siloflow.engines.interface import EngineRunError
from siloflow.engines.markers import Marker

__all__ = [
    "FORCE_COLUMNS", "JENIKE_FLOOR_WALLS", "JENIKE_STAGE_MARKERS", "JENIKE_WALLS", "SETTLED_WALLS", "STAGES",
    "check_jenike_run", "jenike_run_record", "jenike_wall_forces", "read_jenike_force_history",
]

#: Columns of the force history, in file order after the step (SI units: s, N, m, kg).
FORCE_COLUMNS = (
    "time",
    "lid_fx",
    "lid_fy",
    "lid_fz",
    "ring_fx",
    "ring_fy",
    "ring_fz",
    "bottom_fx",
    "bottom_fy",
    "bottom_fz",
    "lid_z",
    "mass_above",
)

#: The stage markers a Jenike run prints, in order.
STAGES = ("filled", "levelled", "lid_placed", "consolidated", "sheared")
#: Stage kinds of the markers that end the stages of the Jenike case (lid_placed starts the consolidation).
JENIKE_STAGE_MARKERS = {"filled": "fill", "levelled": "settle", "consolidated": "consolidate", "sheared": "shear"}
#: The walls of the neutral force history, and those whose force on the settled fill its snapshot records.
JENIKE_WALLS = ("lid", "shear_ring", "base")
SETTLED_WALLS = ("base", "shear_ring", "mould")
#: The walls that make the settled fill's floor: the bottom ring or the plate.
JENIKE_FLOOR_WALLS = ("base",)


def read_jenike_force_history(path: str | Path) -> dict[str, np.ndarray]:
    """Read a Jenike run's force history (module docstring).

    Returns
    -------
    dict of numpy.ndarray
        ``step`` and the :data:`FORCE_COLUMNS`: time (s); forces of the particles on the lid, the shear
        ring and the bottom ring or plate (N); the lid's height (m); the clump mass above the shear plane
        (kg).

    Raises
    ------
    FileNotFoundError
        When there is no file.
    ValueError
        Naming the file, if it is empty, a row has the wrong number of columns or is not numeric (e.g. a
        run cut off while writing), or times do not increase.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no force history at {path}")
    rows = []
    expected = len(FORCE_COLUMNS) + 1
    for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        fields = text.split()
        if len(fields) != expected:
            raise ValueError(
                f"{path}: line {number} has {len(fields)} columns, expected {expected} "
                f"(step {' '.join(FORCE_COLUMNS)}); the file is malformed or truncated"
            )
        try:
            values = [float(field) for field in fields]
        except ValueError:  # its message quotes the field, and the file may be any file: the place is given
            raise ValueError(f"{path}: line {number}, column {first_not_read(fields)} is not a number") from None
        if not all(np.isfinite(values)):
            raise ValueError(f"{path}: line {number}, column {int(np.argmin(np.isfinite(values))) + 1} is not finite")
        rows.append(values)
    if not rows:
        raise ValueError(f"{path}: the force history holds no data rows")
    table = np.array(rows, dtype=float)
    history = {"step": table[:, 0]}
    history.update({name: table[:, i + 1] for i, name in enumerate(FORCE_COLUMNS)})
    if np.any(np.diff(history["time"]) <= 0):
        raise ValueError(f"{path}: times do not increase from row to row")
    return history


def jenike_wall_forces(history: dict[str, np.ndarray]) -> WallForceHistory:
    """A Jenike force history (:func:`read_jenike_force_history`) as a wall force history.

    Returns
    -------
    siloflow.model.forces.WallForceHistory
        Walls ``lid``, ``shear_ring``, ``base`` (the bottom ring or plate) with the forces they exert on the
        particles [N] (the file holds those of the particles on them: negated); torques NaN (not written);
        signals ``lid_z`` (the lid's height) [m] and ``mass_above`` (clump mass above the shear plane) [kg].
        Each sample averages the output interval before it; its time is the mean time of that interval [s].
    """
    columns = {"lid": "lid", "shear_ring": "ring", "base": "bottom"}
    force = {wall: -np.column_stack([history[f"{prefix}_f{axis}"] for axis in "xyz"])
             for wall, prefix in columns.items()}
    n = len(history["time"])
    return WallForceHistory(
        time=history["time"],
        walls=JENIKE_WALLS,
        force=force,
        torque={wall: np.full((n, 3), np.nan) for wall in JENIKE_WALLS},
        signals={"lid_z": history["lid_z"], "mass_above": history["mass_above"]},
    )


def check_jenike_run(case: JenikeCase, markers: list[Marker], run_dir: Path, history_path: Path) -> dict:
    """Check that a finished Jenike run did what the case asked; returns the stage record.

    Raises
    ------
    EngineRunError
        When a stage marker is missing, too few clumps were created, levelling removed nothing (the cell
        was not filled above the ring top), or clumps were lost after levelling.
    ValueError, FileNotFoundError
        When the force history is missing or malformed (:func:`read_jenike_force_history`).
    """
    by_event: dict[str, list] = {}
    for marker in markers:
        by_event.setdefault(marker.event, []).append(marker)
    for event in STAGES:
        if event not in by_event:
            raise EngineRunError(f"{run_dir}: the log has no '{event}' stage marker; the run did not reach its end")
    stages = {event: by_event[event][-1].values for event in STAGES}
    created = int(round(stages["filled"]["clumps"]))
    if created < 0.98 * case.fill.n_clumps:
        raise EngineRunError(
            f"{run_dir}: only {created} of {case.fill.n_clumps} clumps were created or stayed in the cell"
        )
    levelled = int(round(stages["levelled"]["clumps"]))
    if levelled >= created:
        raise EngineRunError(
            f"{run_dir}: levelling removed no clump: the fill (top sphere centre at "
            f"{stages['filled']['top']:.4g} m) did not reach the top of the shear ring "
            f"({case.geometry.ring_top:.4g} m); raise jenike.fill.overfill"
        )
    final = int(round(stages["sheared"]["clumps"]))
    if final != levelled:
        raise EngineRunError(f"{run_dir}: {levelled - final} clumps were lost between levelling and the end of shear")
    history = read_jenike_force_history(history_path)
    return {
        "stages": stages,
        "n_clumps_created": created,
        "n_clumps": levelled,
        "timestep_s": case.timestep,
        "consolidation_start_s": stages["lid_placed"]["time"],
        "shear_start_s": stages["consolidated"]["time"],
        "shear_end_s": stages["sheared"]["time"],
        "force_samples": int(history["time"].size),
        "forces": Path(history_path).name,
    }


def jenike_run_record(engine: str, case: JenikeCase, checked: dict, n_frames: int, mpi_ranks: int,
                      output_bytes: int) -> RunRecord:
    """The run record of a checked Jenike run (``checked`` from :func:`check_jenike_run`)."""
    stages = checked["stages"]
    return RunRecord(
        engine=engine,
        case="jenike",
        run_id=case.run_id,
        timestep_s=case.timestep,
        n_clumps=checked["n_clumps"],
        n_frames=n_frames,
        mpi_ranks=mpi_ranks,
        stages={kind: stages[marker] for marker, kind in JENIKE_STAGE_MARKERS.items()},
        output_bytes=output_bytes,
        labels={key: checked[key] for key in ("consolidation_start_s", "shear_start_s", "shear_end_s",
                                              "n_clumps_created", "force_samples")},
    )
