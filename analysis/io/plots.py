"""What every plot writer shares: the headless backend, atomic PNG output, the silo outline and argument checks.

The study plots (:mod:`analysis.studies.silo_flat.plots`, :mod:`analysis.studies.silo_recirculation.plots`,
:mod:`analysis.studies.silo_recirculation.rtd_plots`, :mod:`analysis.studies.blender.plots`,
:mod:`calibration.charts`) draw with matplotlib's Agg backend (no display needed) and save through
:func:`save_png`. Lengths drawn in the x-z plane follow the project convention: x across the width with
x = 0 on the silo axis, z up with the floor and outlet plane at z = 0.
"""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: runs on clusters and in CI

import numpy as np  # noqa: E402

from model.checks import finite_array  # noqa: E402
from analysis.io.tables import atomic_output  # noqa: E402

__all__ = [
    "save_png",
    "silo_outline",
    "non_empty_list",
    "tuple_entry",
    "finite_abscissa",
    "matching_ordinate",
    "positive_finite_points",
]


def save_png(figure, path: str | os.PathLike, tight: bool = False) -> Path:
    """Save a figure as a 150 dpi PNG, atomically: a reader never sees a half-written file."""
    with atomic_output(path) as temporary:
        # The temporary name has no .png suffix, so give the format explicitly.
        figure.savefig(temporary, dpi=150, format="png", bbox_inches="tight" if tight else None)
    return Path(path)


def silo_outline(axes, width: float, outlet_width: float, top: float) -> None:
    """Draw the walls and floor of a flat-bottom silo with a centred slot outlet, in the units given.

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        Axes in the x-z plane.
    width : float
        Silo width W; the walls stand at x = +-W/2.
    outlet_width : float
        Slot width B0, centred on x = 0 in the floor z = 0.
    top : float
        Height up to which the walls are drawn.
    """
    half, slot = 0.5 * width, 0.5 * outlet_width
    outline = dict(color="black", linewidth=1.5)
    axes.plot([-half, -half, -slot], [top, 0.0, 0.0], **outline)
    axes.plot([half, half, slot], [top, 0.0, 0.0], **outline)


def non_empty_list(name: str, items) -> list:
    """``items`` as a list; a ValueError naming ``name`` when it is empty."""
    items = list(items)
    if not items:
        raise ValueError(f"{name} must not be empty")
    return items


def tuple_entry(name: str, index: int, item, size: int) -> tuple:
    """``item`` (entry ``index`` of the argument ``name``) as a tuple of ``size`` items, else a ValueError."""
    try:
        entry = tuple(item)
    except TypeError:
        entry = ()
    if len(entry) != size:
        raise ValueError(f"{name}[{index}] must be a tuple of {size} items")
    return entry


def finite_abscissa(name: str, values) -> np.ndarray:
    """A non-empty, finite 1-D array (the x values of a curve)."""
    array = finite_array(name, values)
    if array.size == 0:
        raise ValueError(f"{name} must not be empty")
    return array


def matching_ordinate(name: str, values, length: int, reference: str) -> np.ndarray:
    """A 1-D float array of ``length`` entries, the y values over the abscissa ``reference``.

    NaN is allowed (drawn as a gap or skipped).
    """
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or array.size != length:
        raise ValueError(f"{name} must be a 1-D array of the same length as {reference} ({length}), "
                         f"got shape {array.shape}")
    return array


def positive_finite_points(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The points with finite x and y and ``y > 0`` (what a log y axis can show)."""
    keep = np.isfinite(x) & np.isfinite(y) & (y > 0.0)
    return x[keep], y[keep]
