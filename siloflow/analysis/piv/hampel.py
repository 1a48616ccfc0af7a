"""Outlier removal of PIV fields: the Hampel filter in space.

A node is an outlier when its value differs from the median of its valid neighbours (a square window of
``2 half_window + 1`` nodes, itself left out) by more than ``threshold`` times their scaled median absolute deviation
(1.4826 MAD, the normal distribution's standard deviation) plus a noise floor: the normalised median test of
Westerweel and Scarano (2005), whose floor keeps a smooth gradient at the edge of the field (where every neighbour
lies on one side and they agree with each other) from being taken for an outlier. Outliers become invalid; every
other node keeps its value bit for bit. Each velocity component is tested; a node fails if either does.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from siloflow.analysis.piv.field import PlanarField

__all__ = ["MAD_SCALE", "hampel_filter", "hampel_outliers"]

#: 1 / Phi^-1(3/4): the MAD of normal data times this is its standard deviation.
MAD_SCALE = 1.4826


def hampel_outliers(values: np.ndarray, valid: np.ndarray, half_window: int = 1, threshold: float = 3.0,
                    noise_floor: float = 0.0, min_neighbours: int = 3) -> np.ndarray:
    """Where a 2-D array has Hampel outliers (bool, same shape): ``|value - median| > threshold (1.4826 MAD +
    noise_floor)`` over the valid neighbours (``noise_floor`` in the values' unit). Invalid nodes are never outliers
    and never neighbours; a node with fewer than ``min_neighbours`` valid neighbours is kept.

    Raises
    ------
    ValueError
        For a window below 1, a threshold not above 0, or arrays of different shapes.
    """
    values, valid = np.asarray(values, dtype=float), np.asarray(valid, dtype=bool)
    if values.shape != valid.shape or values.ndim != 2:
        raise ValueError("values and valid must be 2-D arrays of one shape")
    if int(half_window) < 1 or not threshold > 0 or not noise_floor >= 0:
        raise ValueError(f"half_window must be >= 1, threshold > 0 and noise_floor >= 0, got {half_window!r}, "
                         f"{threshold!r} and {noise_floor!r}")
    h = int(half_window)
    padded = np.pad(np.where(valid, values, np.nan), h, constant_values=np.nan)
    windows = sliding_window_view(padded, (2 * h + 1, 2 * h + 1)).reshape(*values.shape, -1).copy()
    windows[..., (2 * h + 1) ** 2 // 2] = np.nan  # the node itself is not its own neighbour
    count = np.sum(np.isfinite(windows), axis=-1)
    enough = count >= min_neighbours
    with np.errstate(all="ignore"):
        median = np.nanmedian(np.where(enough[..., None], windows, 0.0), axis=-1)
        mad = MAD_SCALE * np.nanmedian(np.abs(np.where(enough[..., None], windows, 0.0) - median[..., None]), axis=-1)
    return valid & enough & (np.abs(values - median) > threshold * (mad + noise_floor))


def hampel_filter(field: PlanarField, half_window: int = 1, threshold: float = 3.0,
                  noise_floor: float = 0.0) -> PlanarField:
    """``field`` with its Hampel outliers (in ``u`` or ``w``; ``noise_floor`` in m/s) made invalid; every other node
    unchanged."""
    outliers = (hampel_outliers(field.u, field.valid, half_window, threshold, noise_floor)
                | hampel_outliers(field.w, field.valid, half_window, threshold, noise_floor))
    return PlanarField(field.x, field.z, field.u, field.w, field.valid & ~outliers, field.time)
