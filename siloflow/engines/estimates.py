"""How the runs' estimates are shown and checked before they start: the disk they need against the disk free, and
the table of estimates ``make estimate`` prints.

The estimates themselves come from each case kind's cost model (:mod:`siloflow.model.cost`, named by the kind's registry entry
in :mod:`siloflow.model.cases.kinds`); :func:`estimate_case` asks the registry.
"""

from __future__ import annotations

import math
from typing import Iterable

from siloflow.model.cases.kinds import kind_of_case
from siloflow.model.cost import CostModel, RunEstimate, is_finite


# ---------------------------------------------------------------------------------------------- disk and output


class InsufficientDiskSpace(RuntimeError):
    """The runs would need more disk space than is free."""


def check_disk_space(required_bytes: float, free_bytes: float, where: str, what: str) -> float:
    """Refuse runs whose dumps would not fit on the disk.

    Parameters
    ----------
    required_bytes : float
        Estimated disk space of the runs (bytes, >= 0).
    free_bytes : float
        Free space on the disk that holds the results (bytes, >= 0).
    where : str
        The disk or folder, for the message.
    what : str
        Which runs, for the message (e.g. ``"of the blender study"``).

    Returns
    -------
    float
        The margin, ``free_bytes - required_bytes`` (bytes, >= 0).

    Raises
    ------
    InsufficientDiskSpace
        When ``required_bytes > free_bytes``; the message names both sizes.
    """
    for name, value in (("required_bytes", required_bytes), ("free_bytes", free_bytes)):
        if not is_finite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    if required_bytes > free_bytes:
        raise InsufficientDiskSpace(
            f"the runs {what} need about {format_bytes(required_bytes)} for dumps but only "
            f"{format_bytes(free_bytes)} are free on {where}; free space, move results/ to a larger disk, "
            "or raise dump intervals"
        )
    return free_bytes - required_bytes


def _scaled(value: float, units: tuple[tuple[str, float], ...], digits: int) -> str:
    """``value`` in the largest unit it reaches, ``digits`` significant digits; a value that rounds up to the
    next unit's size is written in that unit."""
    index = 0
    while index + 1 < len(units) and value >= units[index + 1][1]:
        index += 1
    while True:
        name, size = units[index]
        scaled = value / size
        text = f"{scaled:.{digits}g}"
        if "e+" in text:  # a value of 10**digits or more: all its integer digits
            text = f"{float(text):.0f}"
        if index + 1 < len(units) and float(text) * size >= units[index + 1][1]:
            index += 1
            continue
        return f"{text} {name}"


_BYTE_UNITS = (("B", 1.0), ("kB", 1e3), ("MB", 1e6), ("GB", 1e9), ("TB", 1e12))
_TIME_UNITS = (("s", 1.0), ("min", 60.0), ("h", 3600.0), ("d", 86400.0))


def format_bytes(size: float, digits: int = 3) -> str:
    """A size in B, kB, MB, GB or TB (powers of 1000) with ``digits`` significant digits: ``12.3 GB``."""
    if not is_finite(size) or size < 0:
        raise ValueError(f"size must be a finite number >= 0 bytes, got {size!r}")
    if size < 1000:
        return f"{size:.0f} B"
    return _scaled(float(size), _BYTE_UNITS, digits)


def format_duration(seconds: float, digits: int = 2) -> str:
    """A duration in s, min, h or d with ``digits`` significant digits: ``5.6 min``."""
    if not is_finite(seconds) or seconds < 0:
        raise ValueError(f"duration must be a finite number >= 0 s, got {seconds!r}")
    return _scaled(float(seconds), _TIME_UNITS, digits)


#: Columns of :func:`estimate_rows`, in order.
ESTIMATE_COLUMNS = (
    "run", "kind", "mpi_ranks", "clumps", "spheres", "steps", "sphere_steps", "simulated_s", "wall_time", "core_time",
    "dump_frames", "disk",
)


def estimate_rows(estimates: Iterable[RunEstimate]) -> list[dict]:
    """Rows of the table ``make estimate`` prints: one per run, then a totals row.

    Columns (:data:`ESTIMATE_COLUMNS`): run, kind, mpi_ranks, clumps, spheres (the most the run holds), steps,
    sphere_steps (the work, sphere-steps), simulated_s (s), wall_time (formatted), core_time (wall time times MPI
    ranks, formatted: what a cluster account is charged), dump_frames, disk (formatted dumps). The totals row sums
    sphere-steps, wall time (the runs one after another), core time, dump frames and disk; its other cells are
    empty.
    """
    estimates = list(estimates)
    rows = [
        {
            "run": estimate.run_id,
            "kind": estimate.kind,
            "mpi_ranks": estimate.mpi_ranks,
            "clumps": estimate.clumps,
            "spheres": estimate.spheres,
            "steps": estimate.steps,
            "sphere_steps": estimate.sphere_steps,
            "simulated_s": estimate.simulated_time_s,
            "wall_time": format_duration(estimate.wall_time_s),
            "core_time": format_duration(estimate.core_seconds),
            "dump_frames": estimate.dump_frames,
            "disk": format_bytes(estimate.dump_bytes),
        }
        for estimate in estimates
    ]
    totals = dict.fromkeys(ESTIMATE_COLUMNS, "")
    totals.update(
        run=f"total ({len(estimates)} run{'s' if len(estimates) != 1 else ''})",
        sphere_steps=math.fsum(e.sphere_steps for e in estimates),
        wall_time=format_duration(sum(e.wall_time_s for e in estimates)),
        core_time=format_duration(sum(e.core_seconds for e in estimates)),
        dump_frames=sum(e.dump_frames for e in estimates),
        disk=format_bytes(sum(e.dump_bytes for e in estimates)),
    )
    rows.append(totals)
    return rows


def total_dump_bytes(estimates: Iterable[RunEstimate]) -> int:
    """Disk space of all the runs' dumps (bytes), for :func:`check_disk_space`."""
    return sum(estimate.dump_bytes for estimate in estimates)


def estimate_case(case, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a run of any case kind, with the cost model its registry entry names."""
    return kind_of_case(case).estimate(case, mpi_ranks, model)
