"""The cross-engine check: the same small silo on two engines, several seeds each. Per run: the filling bulk
density, the steady flow rate (:func:`siloflow.analysis.studies.silo_flat.metrics.silo_flow_metrics`) and the vertical
velocity on the centreline at one height during the steady discharge; across runs: each engine's mean and spread
over its seeds, and the difference between the engines in units of its standard error.
"""

from __future__ import annotations

import math
from typing import Mapping, Sequence

import numpy as np

from siloflow.model.frames import ClumpFrame

__all__ = ["CROSS_ENGINE_QUANTITIES", "centreline_vertical_velocity", "compare_engines"]

#: What is compared: key of a run's metrics -> (label, unit).
CROSS_ENGINE_QUANTITIES = {
    "filling_bulk_density_kg_m3": ("filling bulk density", "kg/m3"),
    "mass_flow_rate_kg_s": ("steady mass flow rate", "kg/s"),
    "centreline_v_z_m_s": ("vertical velocity on the centreline", "m/s"),
}


def centreline_vertical_velocity(frames: Sequence[ClumpFrame], height: float, half_band: float, half_width: float,
                                 start: float, end: float) -> float:
    """Mean vertical velocity [m/s] of the clumps within ``half_width`` of x = 0 and ``half_band`` of z = ``height``
    [m], over the frames with ``start <= time <= end`` [s] (every clump of every such frame counts once).

    Raises
    ------
    ValueError
        When no clump is in the band in that window.
    """
    velocities = []
    for frame in frames:
        if start <= frame.time <= end:
            x, z = frame.position[:, 0], frame.position[:, 2]
            inside = (np.abs(x) <= half_width) & (np.abs(z - height) <= half_band)
            velocities.append(frame.velocity[inside, 2])
    found = np.concatenate(velocities) if velocities else np.empty(0)
    if not found.size:
        raise ValueError(f"no clump within {half_width} m of the centreline at {height} m between {start} and {end} s")
    return float(found.mean())


def compare_engines(values: Mapping[str, Sequence[float]], label: str, unit: str) -> dict:
    """One row of the cross-engine table: per engine (two) the mean and standard deviation over its seeds, the
    difference of the means (first minus second), its standard error ``sqrt(s1^2 / n1 + s2^2 / n2)`` and their
    ratio, and whether the difference is larger than two standard errors.

    Raises
    ------
    ValueError
        Unless there are exactly two engines, each with at least two finite values.
    """
    if len(values) != 2:
        raise ValueError(f"compare two engines, got {list(values)}")
    row: dict = {"quantity": label, "unit": unit}
    stats = []
    for engine, sample in values.items():
        array = np.asarray(sample, dtype=float)
        if array.size < 2 or not np.all(np.isfinite(array)):
            raise ValueError(f"{engine}: need at least two finite values of {label}, got {list(sample)}")
        stats.append((array.mean(), array.std(ddof=1), array.size))
        row[f"{engine}_mean"], row[f"{engine}_std"], row[f"{engine}_seeds"] = stats[-1]
    (m1, s1, n1), (m2, s2, n2) = stats
    difference = m1 - m2
    error = math.sqrt(s1**2 / n1 + s2**2 / n2)
    row.update({"difference": difference, "difference_error": error,
                "difference_in_errors": difference / error if error > 0 else math.inf * np.sign(difference),
                "larger_than_2_errors": bool(abs(difference) > 2.0 * error)})
    return row
