"""Argument checks shared by the recirculation modules (tracks, concentration, VRR, transit).

Each returns the checked value or raises a ValueError that names the argument.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["open_fraction", "event_times"]


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
