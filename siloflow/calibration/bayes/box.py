"""The prior box: parameter bounds, and the map of a parameter vector to the unit cube and back.

Every module of :mod:`siloflow.calibration.bayes` works on the same box: the design scales its unit-cube points to it, the
surrogate normalises its inputs by it (so that its length scales are fractions of the prior range, comparable
between a friction of range 0.5 and one of range 0.05), and the sampler starts its walkers inside it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["as_box", "to_unit", "from_unit", "as_points"]


def as_box(lower, upper) -> tuple[np.ndarray, np.ndarray]:
    """Checked bounds of a box.

    Parameters
    ----------
    lower, upper : array_like, shape (d,)
        Lower and upper bound of each parameter, in the parameter's units (friction coefficients [-]).

    Returns
    -------
    lower, upper : ndarray, shape (d,)
        The bounds as float arrays.

    Raises
    ------
    ValueError
        If the bounds are not one-dimensional of one length, not finite, or not ``lower < upper``.
    """
    lower = np.atleast_1d(np.asarray(lower, dtype=float))
    upper = np.atleast_1d(np.asarray(upper, dtype=float))
    if lower.ndim != 1 or lower.shape != upper.shape or lower.size == 0:
        raise ValueError(f"bounds must be two vectors of one length, got shapes {lower.shape} and {upper.shape}")
    if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))):
        raise ValueError(f"bounds must be finite, got lower={lower}, upper={upper}")
    if np.any(lower >= upper):
        raise ValueError(f"every lower bound must be below its upper bound, got lower={lower}, upper={upper}")
    return lower, upper


def as_points(points, d: int, name: str = "points") -> np.ndarray:
    """Points as an ``(n, d)`` float array (a single point of shape ``(d,)`` becomes one row).

    Parameters
    ----------
    points : array_like, shape (n, d) or (d,)
        Parameter vectors, in the parameters' units.
    d : int
        Number of parameters.
    name : str
        What the points are, for the error message.

    Returns
    -------
    ndarray, shape (n, d)
        The points as floats.

    Raises
    ------
    ValueError
        If the points do not have ``d`` columns or are not finite.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim == 1:
        points = points[np.newaxis, :]
    if points.ndim != 2 or points.shape[1] != d:
        raise ValueError(f"{name} must have shape (n, {d}), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"{name} must be finite")
    return points


def to_unit(points, lower, upper) -> np.ndarray:
    """Points of the box mapped to the unit cube, ``(x - lower) / (upper - lower)`` (outside points map outside)."""
    lower, upper = as_box(lower, upper)
    return (np.asarray(points, dtype=float) - lower) / (upper - lower)


def from_unit(points, lower, upper) -> np.ndarray:
    """Points of the unit cube mapped to the box, ``lower + u (upper - lower)``."""
    lower, upper = as_box(lower, upper)
    return lower + np.asarray(points, dtype=float) * (upper - lower)
