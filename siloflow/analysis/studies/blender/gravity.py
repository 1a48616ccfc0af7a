"""Gravity scaling of blender runs: times and velocities on the clock of 1 g, and which quantities scale.

Times scale with ``sqrt(L / g)`` and velocities and mass flow rates with ``sqrt(g L)``, so a run at
``f g`` reproduces a 1 g run on a clock ``sqrt(f)`` times faster. Pure computation; SI units.

See :func:`gravity_normalised_time`, :func:`gravity_normalised_velocity` and :func:`gravity_scaling`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, positive_number

__all__ = ["GravityScaling", "gravity_normalised_time", "gravity_normalised_velocity", "gravity_scaling"]


def _gravity_factor(value) -> float:
    return positive_number("gravity_factor", value)


def gravity_normalised_time(time, gravity_factor: float):
    """Time of a run at ``gravity_factor`` g on the clock of a 1 g run, ``t sqrt(factor)`` [s].

    Times scale with ``sqrt(L / g)``: a run at ``f g`` does in ``t`` what a 1 g run does in ``t sqrt(f)``.
    """
    return finite_array("time", time, ndim=None) * math.sqrt(_gravity_factor(gravity_factor))


def gravity_normalised_velocity(velocity, gravity_factor: float):
    """Velocity of a run at ``gravity_factor`` g scaled to 1 g, ``v / sqrt(factor)`` [m/s].

    Velocities scale with ``sqrt(g L)``. NaN (no particles) is kept.
    """
    values = np.asarray(velocity, dtype=float)
    if np.any(np.isinf(values)):
        raise ValueError("velocity must not contain infinite values")
    return values / math.sqrt(_gravity_factor(gravity_factor))


@dataclass(frozen=True, eq=False)
class GravityScaling:
    """Which quantities scale with ``sqrt(g)`` across runs at several gravity factors.

    Attributes
    ----------
    rows : list of dict
        One row per quantity and factor, keys ``quantity, gravity_factor, value, ratio_to_1g,
        expected_ratio, relative_deviation, scales`` (for :func:`siloflow.analysis.io.tables.write_flow_table`).
    scales : dict
        Quantity -> True when every factor's ratio to 1 g lies within the tolerance of ``sqrt(factor)``.
    tolerance : float
        Relative tolerance [-].
    """

    rows: list
    scales: dict
    tolerance: float


def gravity_scaling(gravity_factors, quantities: Mapping, tolerance: float = 0.05) -> GravityScaling:
    """Ratios of steady quantities (mass flow rate, mean velocity, ...) to their 1 g value against ``sqrt(factor)``.

    For each quantity ``q`` and factor ``f``: ``ratio = q(f) / q(1)`` and ``expected = sqrt(f)``; the
    quantity scales when ``|ratio / expected - 1| <= tolerance`` at every factor.

    Parameters
    ----------
    gravity_factors : array_like, shape (n,)
        Factors ``g_run / g``, > 0, distinct, one of them 1.
    quantities : mapping name -> array_like, shape (n,)
        Values per factor (e.g. ``"mass_flow_rate_kg_s"``), finite, non-zero at factor 1.
    tolerance : float, optional
        Relative tolerance, > 0; default 0.05.

    Returns
    -------
    GravityScaling
    """
    factors = finite_array("gravity_factors", gravity_factors, ndim=1)
    if factors.size == 0 or np.any(factors <= 0.0) or np.unique(factors).size != factors.size:
        raise ValueError("gravity_factors must be distinct numbers > 0")
    reference = np.flatnonzero(factors == 1.0)
    if reference.size != 1:
        raise ValueError("gravity_factors must include the factor 1 (the reference run)")
    tolerance = positive_number("tolerance", tolerance)
    if not isinstance(quantities, Mapping) or not quantities:
        raise ValueError("quantities must be a non-empty mapping name -> values per factor")
    rows, scales = [], {}
    for name, values in quantities.items():
        values = finite_array(f"quantities[{name!r}]", values, ndim=1)
        if values.shape != factors.shape:
            raise ValueError(
                f"quantities[{name!r}] must hold {factors.size} values (one per factor), got {values.size}"
            )
        base = float(values[reference[0]])
        if base == 0.0:
            raise ValueError(f"quantities[{name!r}] is 0 at factor 1; ratios are undefined")
        within = True
        for factor, value in zip(factors, values):
            ratio, expected = float(value) / base, math.sqrt(float(factor))
            deviation = ratio / expected - 1.0
            ok = abs(deviation) <= tolerance
            within &= ok
            rows.append({"quantity": str(name), "gravity_factor": float(factor), "value": float(value),
                         "ratio_to_1g": ratio, "expected_ratio": expected, "relative_deviation": deviation,
                         "scales": ok})
        scales[str(name)] = within
    return GravityScaling(rows=rows, scales=scales, tolerance=tolerance)
