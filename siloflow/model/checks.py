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


def finite_number(name: str, value) -> float:
    """``value`` as a finite float; a ValueError names ``name`` otherwise."""
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return value


def increasing_times(name: str, values) -> np.ndarray:
    """A finite, strictly increasing 1-D float array of times (frame times); it may be empty."""
    times = finite_array(name, values, ndim=1)
    if np.any(np.diff(times) <= 0.0):
        raise ValueError(f"{name} must be strictly increasing")
    return times


def uniform_step(name: str, time: np.ndarray, tolerance: float = 1.0e-6) -> float:
    """The step of a uniform, increasing time axis (steps equal to ``tolerance`` relative)."""
    if time.size < 2:
        raise ValueError(f"{name} must have at least 2 samples, got {time.size}")
    dt = (time[-1] - time[0]) / (time.size - 1)
    if not dt > 0.0 or np.max(np.abs(np.diff(time) - dt)) > tolerance * dt:
        raise ValueError(f"{name} must be uniformly spaced and increasing")
    return float(dt)


def points3(name: str, values) -> np.ndarray:
    """``values`` as a C-contiguous float array of shape (n, 3) with finite entries (an empty list gives (0, 3))."""
    array = np.asarray(values, dtype=float)
    if array.ndim == 1 and array.size == 0:
        array = array.reshape(0, 3)
    array = finite_array(name, array, ndim=2)
    if array.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {array.shape}")
    return np.ascontiguousarray(array)


def vector3(name: str, values, positive: bool, scalar_to_all: bool = False) -> np.ndarray:
    """``values`` as a finite float array of 3 components (x, y, z), > 0 in each when ``positive``; a scalar is
    repeated on the three axes when ``scalar_to_all``."""
    array = np.asarray(values, dtype=float)
    if scalar_to_all and array.ndim == 0:
        array = np.full(3, float(array))
    if array.shape != (3,):
        raise ValueError(f"{name} must have 3 components (x, y, z), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers, got {array.tolist()}")
    if positive and np.any(array <= 0.0):
        raise ValueError(f"{name} must be > 0 in every component, got {array.tolist()}")
    return array


def compute_backend(backend: str, have_numba: bool) -> str:
    """The backend to run: ``"numba"`` or ``"numpy"`` for a requested ``"auto"``, ``"numba"`` or ``"numpy"``."""
    if backend not in ("auto", "numba", "numpy"):
        raise ValueError(f"backend must be 'auto', 'numba' or 'numpy', got {backend!r}")
    if backend == "numba" and not have_numba:
        raise ValueError("backend='numba' requested but numba is not installed")
    if backend == "auto":
        return "numba" if have_numba else "numpy"
    return backend


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


def number_or_nan(value) -> float:
    """A number read back from JSON or a table, where null or an empty cell (a NaN when written, or a figure not
    known) is NaN."""
    return math.nan if value is None else float(value)


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
