"""Argument checks shared by the recirculation modules (tracks, concentration, VRR, tracers).

Each returns the checked value or raises a ValueError that names the argument.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["integer_at_least", "open_fraction", "event_times"]


def integer_at_least(name: str, value, minimum: int) -> int:
    """``value`` as an int when it is a whole number (not a bool) >= ``minimum``."""
    if (
        isinstance(value, (bool, np.bool_))
        or not isinstance(value, (int, np.integer, float, np.floating))
        or not math.isfinite(float(value))
        or int(value) != value
        or int(value) < minimum
    ):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def open_fraction(name: str, value) -> float:
    """A number strictly between 0 and 1."""
    value = float(value)
    if not math.isfinite(value) or not 0.0 < value < 1.0:
        raise ValueError(f"{name} must be a number in (0, 1), got {value!r}")
    return value


def event_times(name: str, values) -> np.ndarray:
    """A 1-D float array of times; NaN allowed (no crossing), infinities not."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {array.shape}")
    if np.any(np.isinf(array)):
        raise ValueError(f"{name} must not contain infinite values (use NaN for no crossing)")
    return array
