"""What every plot writer shares: the figure writer (PNG, PDF or SVG, atomic), the silo outline and argument checks.

The study plots (:mod:`siloflow.analysis.studies.silo_flat.plots`, :mod:`siloflow.analysis.studies.silo_recirculation.plots`,
:mod:`siloflow.analysis.studies.silo_recirculation.rtd_plots`, :mod:`siloflow.analysis.studies.blender.plots`,
:mod:`siloflow.calibration.charts`, :mod:`siloflow.calibration.bayes.plots`) save through :func:`save_figure`, which takes the format
from the file name's suffix (:data:`PLOT_FORMATS`; the workflow names its plots after ``plots.format``). No module
of siloflow chooses a matplotlib backend: importing one leaves a notebook's backend as it was. Each writer draws on a
figure of its own and lets pyplot go of it once saved (or never hands it to pyplot), so it shows no window whatever
the backend; the workflow, its scripts and the tests run with ``MPLBACKEND=Agg`` (set by the Snakefile and by
tests/conftest.py), where matplotlib would otherwise look for a display first. Lengths drawn in the x-z plane follow the project convention: x across the width
with x = 0 on the silo axis, z up with the floor and outlet plane at z = 0.
"""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import numpy as np

from siloflow.model.checks import finite_array
from siloflow.analysis.io.tables import atomic_output

__all__ = [
    "PLOT_FORMATS",
    "PLOT_DPI",
    "plot_format",
    "save_figure",
    "silo_outline",
    "non_empty_list",
    "tuple_entry",
    "finite_abscissa",
    "matching_ordinate",
    "positive_finite_points",
]

#: The formats a plot is written in, by file name suffix: PNG (raster) for the report and the validation record's
#: page, PDF and SVG (vector) for papers. The configuration's ``plots.format`` takes one of them.
PLOT_FORMATS = ("png", "pdf", "svg")
#: Resolution of a PNG (dots per inch): a 6.4 x 4.8 in figure is 960 x 720 px. A PDF or SVG is vector; this is then
#: only the resolution of what is drawn as an image in it (a rasterised field).
PLOT_DPI = 150
#: Settings of a vector file: TrueType fonts embedded in a PDF (matplotlib's default Type 3 fonts are refused by
#: journals' submission checks).
_VECTOR_SETTINGS = {"pdf.fonttype": 42}


def plot_format(path: str | os.PathLike) -> str:
    """The format of a plot file, from its name's suffix (one of :data:`PLOT_FORMATS`).

    Raises
    ------
    ValueError
        When the suffix is none of :data:`PLOT_FORMATS`, naming the path.
    """
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in PLOT_FORMATS:
        raise ValueError(f"{os.fspath(path)}: a plot is written as {', '.join(f'.{f}' for f in PLOT_FORMATS)}; "
                         f"the suffix {Path(path).suffix or '(none)'!r} is none of them")
    return suffix


def save_figure(figure, path: str | os.PathLike, tight: bool = False) -> Path:
    """Save a figure in the format its file name says, atomically: a reader never sees a half-written file.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure, drawn; any backend (a figure saves through the canvas of the file's format).
    path : str or os.PathLike
        Destination; its suffix chooses the format (:func:`plot_format`): ``.png`` at :data:`PLOT_DPI` dpi,
        ``.pdf`` or ``.svg`` vector. The parent folder is created if needed.
    tight : bool, optional
        Crop the page to what is drawn (titles or labels reaching past the figure's edge stay in).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        For a suffix that is none of :data:`PLOT_FORMATS`; nothing is written.
    """
    file_format = plot_format(path)
    with atomic_output(path) as temporary, matplotlib.rc_context(_VECTOR_SETTINGS):
        # The temporary name has no suffix, so give the format explicitly.
        figure.savefig(temporary, dpi=PLOT_DPI, format=file_format, bbox_inches="tight" if tight else None)
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
