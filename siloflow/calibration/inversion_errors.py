"""Errors of a particle friction read off a calibration chart: the chart points' own noise through the chart's slope
(:func:`inversion_error`), and the error of reading a bending chart as straight lines (:func:`interpolation_error`).

Pure functions on arrays of chart angles [deg] and particle friction [-]; :mod:`siloflow.calibration.inversion` combines them
(its module docstring gives the formulas' reasoning).
"""

from __future__ import annotations

import math

import numpy as np

from siloflow.analysis.numerics.uncertainty import combine_independent

__all__ = ["inversion_error", "interpolation_error"]


def _segment(angles: np.ndarray, target_angle_deg: float) -> tuple[int, float]:
    """The chart segment ``[theta_i, theta_{i+1}]`` that holds the target (the one to the right of a chart point,
    the last one at the last point) and the target's fraction ``t`` of its angle span [-]; two points at least."""
    i = int(np.clip(np.searchsorted(angles, target_angle_deg, side="right") - 1, 0, angles.size - 2))
    return i, (target_angle_deg - angles[i]) / (angles[i + 1] - angles[i])


def inversion_error(angles, particle, angle_errors, target_angle_deg: float) -> float:
    """Standard error of the particle friction read off a piecewise linear chart at a target angle [-].

    First-order propagation of independent errors of the chart's angles through the local slope (module
    docstring): with the target in the segment ``[theta_i, theta_{i+1}]`` at ``t = (target - theta_i) /
    (theta_{i+1} - theta_i)`` (the segment to the right of a chart point, the last one at the last point),
    ``sqrt(((1 - t) se_i)^2 + (t se_{i+1})^2) / s`` with ``s`` the segment's slope d theta / d p.

    Parameters
    ----------
    angles : array_like, shape (n,)
        Chart angles, strictly increasing [deg].
    particle : array_like, shape (n,)
        Particle friction at those angles, strictly increasing [-].
    angle_errors : array_like, shape (n,), or None
        Standard errors of ``angles`` [deg], NaN where unknown; None: all unknown.
    target_angle_deg : float
        Target angle inside ``[angles[0], angles[-1]]`` [deg].

    Returns
    -------
    float
        The error [-]; NaN when an error with a non-zero weight is unknown or the chart has one point.
    """
    angles = np.asarray(angles, dtype=float)
    particle = np.asarray(particle, dtype=float)
    if angle_errors is None or angles.size < 2:
        return math.nan
    errors = np.asarray(angle_errors, dtype=float)
    i, t = _segment(angles, target_angle_deg)
    slope = (angles[i + 1] - angles[i]) / (particle[i + 1] - particle[i])
    # a point with weight 0 does not enter, even when its error is unknown
    terms = [weight * errors[k] for weight, k in ((1.0 - t, i), (t, i + 1)) if weight != 0.0]
    return combine_independent(terms) / slope


def interpolation_error(angles, particle, target_angle_deg: float) -> float:
    """How far the piecewise linear reading of a chart may be off at a target angle, from the chart's bend [-].

    The straight line through the target's segment ``[theta_i, theta_{i+1}]`` is compared with the parabola through
    those two points and the nearest third chart point (the one beyond the nearer end of the segment; at the chart's
    ends, the only one there is): the difference of the two readings at the target estimates the error of the straight
    line where the curve bends (bulk friction saturates with particle friction). Zero on a straight chart and at a
    chart point.

    Parameters
    ----------
    angles : array_like, shape (n,)
        Chart angles, strictly increasing [deg].
    particle : array_like, shape (n,)
        Particle friction at those angles [-].
    target_angle_deg : float
        Target angle inside ``[angles[0], angles[-1]]`` [deg].

    Returns
    -------
    float
        ``|p_parabola(target) - p_line(target)|`` [-]; NaN for fewer than three points.
    """
    angles = np.asarray(angles, dtype=float)
    particle = np.asarray(particle, dtype=float)
    if angles.size < 3:
        return math.nan
    i, t = _segment(angles, target_angle_deg)
    if i == 0:
        third = 2
    elif i + 1 == angles.size - 1:
        third = i - 1
    else:
        third = i - 1 if t < 0.5 else i + 2
    points = sorted({i, i + 1, third})
    line = particle[i] + t * (particle[i + 1] - particle[i])
    parabola = np.polyval(np.polyfit(angles[points], particle[points], 2), target_angle_deg)
    return float(abs(parabola - line))
