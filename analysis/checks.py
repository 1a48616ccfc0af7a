"""Argument checks shared by the analysis and calibration functions."""

from __future__ import annotations

import math

import numpy as np


def finite_array(name: str, values, ndim: int | None = 1) -> np.ndarray:
    """``values`` as a float array of ``ndim`` dimensions with only finite entries.

    Raises
    ------
    ValueError
        Naming the argument ``name`` when the shape is wrong or a value is NaN or infinite.
    """
    array = np.asarray(values, dtype=float)
    if ndim is not None and array.ndim != ndim:
        raise ValueError(f"{name} must be a {ndim}-D array, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers")
    return array


def positive_number(name: str, value) -> float:
    """``value`` as a float that is finite and > 0; a ValueError names ``name`` otherwise."""
    value = float(value)
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def non_negative_number(name: str, value) -> float:
    """``value`` as a float that is finite and >= 0; a ValueError names ``name`` otherwise."""
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return value


def per_particle_values(name: str, values, n: int) -> np.ndarray:
    """A scalar or length-n array (masses, radii) broadcast to length n, finite and >= 0."""
    array = np.asarray(values, dtype=float)
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got shape {array.shape}")
    if not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ValueError(f"{name} must contain finite numbers >= 0")
    return array
