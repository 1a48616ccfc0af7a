"""Plots of residence time distributions and of the LTI (RTD convolution) model of blending.

Shared by the recirculating silo and the blender (:mod:`siloflow.analysis.studies.blender.plots`). Each writer takes
arrays (or lists of labelled arrays), a path and a title, draws one figure and saves it atomically with
:func:`siloflow.analysis.io.plots.save_figure` (PNG, PDF or SVG, as the path's suffix says); nothing is read from files.
"Concentration" is the blue (tracer) fraction [-]; tolerance bands are relative, ``blue_fraction * (1 +- tolerance)``,
as in :func:`siloflow.analysis.numerics.lti.recirculations_to_homogenise`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from siloflow.model.checks import positive_number
from siloflow.analysis.io.plots import (
    finite_abscissa,
    matching_ordinate,
    non_empty_list,
    positive_finite_points,
    save_figure,
    tuple_entry,
)

__all__ = [
    "BLUE",
    "tolerance_band",
    "plot_rtd_comparison",
    "plot_lti_comparison",
    "plot_vrr_versus_period",
    "plot_recirculation_model",
    "plot_residence_time_comparison",
]

BLUE = "tab:blue"

_LTI_STYLES = {
    "direct": dict(linestyle="-", linewidth=1.8),
    "predicted": dict(linestyle="--", linewidth=1.5),
    "first pass": dict(linestyle=":", linewidth=1.5),
    "input": dict(linestyle="-", linewidth=0.9, color="0.5"),
}
"""Line styles for the style hints of :func:`plot_lti_comparison`; other hints get a thin solid line."""


def tolerance_band(axes, blue_fraction: float, tolerance: float) -> None:
    """Draw the blue fraction (dashed) and the shaded band ``blue_fraction * (1 +- tolerance)``."""
    axes.axhline(blue_fraction, color="black", linestyle="--", linewidth=1.0,
                 label=f"blue fraction {blue_fraction:.3g}")
    axes.axhspan(blue_fraction * (1.0 - tolerance), blue_fraction * (1.0 + tolerance), color="0.5", alpha=0.15,
                 label=f"±{100 * tolerance:g} % band")


def plot_rtd_comparison(curves, path: str | os.PathLike, title: str, dimensionless: bool = True) -> Path:
    """Residence time distributions of several runs or models, drawn as steps over their bins.

    Parameters
    ----------
    curves : list of (str, array_like, array_like, float)
        ``(label, t, E, t_mean)``: bin centres t [s] (finite), RTD E(t) [1/s] (same length) and the
        mean residence time t_m [s] (> 0), which the legend shows.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    dimensionless : bool, optional
        True to draw E(theta) = t_m E against theta = t / t_m; False for E [1/s] against t [s].

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``curves``, mismatched lengths, non-positive ``t_mean``.
    """
    checked = []
    for i, item in enumerate(non_empty_list("curves", curves)):
        label, t, e, t_mean = tuple_entry("curves", i, item, 4)
        t = finite_abscissa(f"curves[{i}] t", t)
        e = matching_ordinate(f"curves[{i}] E", e, t.size, f"curves[{i}] t")
        checked.append((str(label), t, e, positive_number(f"curves[{i}] t_mean", t_mean)))
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        for label, t, e, t_mean in checked:
            x, y = (t / t_mean, t_mean * e) if dimensionless else (t, e)
            axes.plot(x, y, drawstyle="steps-mid", linewidth=1.3, label=f"{label} (t_m = {t_mean:.3g} s)")
        if dimensionless:
            axes.axvline(1.0, color="0.4", linestyle=":", linewidth=0.9)
            axes.set_xlabel("theta = t / t_m [-]")
            axes.set_ylabel("E(theta) = t_m E(t) [-]")
        else:
            axes.set_xlabel("residence time t [s]")
            axes.set_ylabel("E(t) [1/s]")
        axes.set_xlim(left=0.0)
        axes.set_ylim(bottom=0.0)
        axes.set_title(title)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_lti_comparison(time, series, path: str | os.PathLike, title: str, blue_fraction: float | None = None,
                        x_label: str = "t [s]") -> Path:
    """Outlet concentration simulated directly and predicted by the LTI (RTD convolution) model.

    Parameters
    ----------
    time : array_like
        Common abscissa (finite): time [s], or any other axis named by ``x_label`` (e.g. Nr [-]).
    series : list of (str, array_like, str)
        ``(label, concentration, style)``: blue concentration [-] on ``time`` (same length; NaN is
        drawn as a gap) and a style hint: ``"direct"`` (solid), ``"predicted"`` (dashed),
        ``"first pass"`` (dotted), ``"input"`` (thin grey); any other hint gives a thin solid line.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    blue_fraction : float or None, optional
        Blue fraction of the inventory [-] (> 0) drawn as a dashed line; None to omit.
    x_label : str, optional
        Label of the x axis.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``time`` or ``series``, mismatched lengths, non-positive
        ``blue_fraction``.
    """
    time = finite_abscissa("time", time)
    checked = []
    for i, item in enumerate(non_empty_list("series", series)):
        label, concentration, style = tuple_entry("series", i, item, 3)
        checked.append((str(label), matching_ordinate(f"series[{i}] concentration", concentration, time.size, "time"),
                        str(style)))
    if blue_fraction is not None:
        blue_fraction = positive_number("blue_fraction", blue_fraction)
    figure, axes = plt.subplots(figsize=(6.8, 4.2))
    try:
        if blue_fraction is not None:
            axes.axhline(blue_fraction, color="black", linestyle="--", linewidth=0.9,
                         label=f"blue fraction {blue_fraction:.3g}")
        for label, concentration, style in checked:
            line_style = _LTI_STYLES.get(style.strip().lower(), dict(linestyle="-", linewidth=1.0))
            axes.plot(time, concentration, label=f"{label} ({style})", **line_style)
        axes.set_xlabel(x_label)
        axes.set_ylabel("blue concentration at the outlet [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_vrr_versus_period(period_fraction, curves, path: str | os.PathLike, title: str) -> Path:
    """Variance reduction ratio against the period of a periodic input (log-log).

    Points whose VRR is NaN, infinite, zero or negative are skipped.

    Parameters
    ----------
    period_fraction : array_like
        Input period divided by the mean residence time, T / t_m [-] (finite, > 0).
    curves : list of (str, array_like)
        ``(label, VRR)``: variance reduction ratio [-] at each period (same length as
        ``period_fraction``).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty or non-positive ``period_fraction``, empty ``curves``, mismatched
        lengths.
    """
    period_fraction = finite_abscissa("period_fraction", period_fraction)
    if np.any(period_fraction <= 0.0):
        raise ValueError("period_fraction must contain only numbers > 0 (log axis)")
    checked = []
    for i, item in enumerate(non_empty_list("curves", curves)):
        label, vrr = tuple_entry("curves", i, item, 2)
        checked.append((str(label), matching_ordinate(f"curves[{i}] VRR", vrr, period_fraction.size, "period_fraction")))
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        axes.set_xscale("log")
        axes.set_yscale("log")
        axes.axhline(1.0, color="black", linewidth=0.9, label="VRR = 1 (no blending)")
        for label, vrr in checked:
            x, y = positive_finite_points(period_fraction, vrr)
            axes.plot(x, y, "o-", markersize=4, linewidth=1.2, label=label if x.size else f"{label} (no finite VRR)")
        axes.set_xlabel("input period / mean residence time, T / t_m [-]")
        axes.set_ylabel("variance reduction ratio VRR [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3, which="both")
        axes.legend(fontsize=8)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_recirculation_model(time_in_passes, concentration, blue_fraction: float, homogenised_after: float,
                             path: str | os.PathLike, title: str, tolerance: float = 0.10) -> Path:
    """Discontinuous (recirculation) mode of the LTI model: outlet concentration over the passes.

    Parameters
    ----------
    time_in_passes : array_like
        Time in passes, Nr = t / t_m [-] (finite).
    concentration : array_like
        Predicted blue concentration at the outlet [-] (same length; NaN is drawn as a gap).
    blue_fraction : float
        Blue fraction of the inventory [-] (> 0), the centre of the band.
    homogenised_after : float
        Recirculations after which the concentration stays within the band [-], drawn as a vertical
        line; NaN when it is never reached (then the plot says "not within band").
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    tolerance : float, optional
        Relative half-width of the band, ``blue_fraction * (1 +- tolerance)`` [-] (> 0).

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty or mismatched arrays, non-positive ``blue_fraction`` or ``tolerance``,
        infinite ``homogenised_after``.
    """
    passes = finite_abscissa("time_in_passes", time_in_passes)
    concentration = matching_ordinate("concentration", concentration, passes.size, "time_in_passes")
    blue_fraction = positive_number("blue_fraction", blue_fraction)
    tolerance = positive_number("tolerance", tolerance)
    homogenised_after = float(homogenised_after)
    if math.isinf(homogenised_after):
        raise ValueError(f"homogenised_after must be finite or NaN, got {homogenised_after!r}")
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        tolerance_band(axes, blue_fraction, tolerance)
        first, last = math.ceil(passes.min()), math.floor(passes.max())
        if 0 <= last - first <= 50:
            for boundary in range(first, last + 1):
                axes.axvline(boundary, color="0.85", linewidth=0.6, zorder=0)
        axes.plot(passes, concentration, "-", color=BLUE, linewidth=1.4, label="LTI model, recirculated")
        if math.isnan(homogenised_after):
            axes.text(0.98, 0.04, "not within band", transform=axes.transAxes, ha="right", va="bottom",
                      color="tab:red", fontsize=9)
        else:
            axes.axvline(homogenised_after, color="tab:red", linestyle="--", linewidth=1.2,
                         label=f"within band after Nr = {homogenised_after:.3g}")
        axes.set_xlabel("number of passes Nr = t / t_m [-]")
        axes.set_ylabel("blue concentration at the outlet [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3, axis="y")
        axes.legend(fontsize=8)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_residence_time_comparison(samples, path: str | os.PathLike, title: str) -> Path:
    """Residence time samples compared: step histograms on common bins (left), cumulative F(t) (right).

    NaN entries (e.g. clumps that never left) are ignored and counted in the legend; F(t) is the
    empirical distribution of the finite residence times of each sample.

    Parameters
    ----------
    samples : list of (str, array_like)
        ``(label, residence_times)``: 1-D residence times [s]; each sample needs at least one finite
        value (infinite values are not allowed).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``samples``, a sample that is not 1-D, has no finite value or
        holds an infinite value.
    """
    checked = []
    for i, item in enumerate(non_empty_list("samples", samples)):
        label, times = tuple_entry("samples", i, item, 2)
        times = np.asarray(times, dtype=float)
        if times.ndim != 1:
            raise ValueError(f"samples[{i}] residence times must be a 1-D array, got shape {times.shape}")
        if np.any(np.isinf(times)):
            raise ValueError(f"samples[{i}] residence times must be finite or NaN")
        finite = times[np.isfinite(times)]
        if finite.size == 0:
            raise ValueError(f"samples[{i}] residence times must hold at least one finite value")
        checked.append((str(label), np.sort(finite), times.size - finite.size))
    bins = np.histogram_bin_edges(np.concatenate([times for _, times, _ in checked]), bins="auto")
    if bins.size > 81:
        bins = np.linspace(bins[0], bins[-1], 81)
    figure, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.0))
    try:
        for label, times, ignored in checked:
            legend = f"{label} (n = {times.size}" + (f", {ignored} NaN ignored)" if ignored else ")")
            _, _, patches = left.hist(times, bins=bins, density=True, histtype="step", linewidth=1.3, label=legend)
            fraction = np.arange(1, times.size + 1) / times.size
            right.step(np.concatenate([[times[0]], times]), np.concatenate([[0.0], fraction]), where="post",
                       color=patches[0].get_edgecolor(), linewidth=1.3, label=legend)
        left.set_xlabel("residence time t [s]")
        left.set_ylabel("probability density [1/s]")
        left.grid(alpha=0.3)
        left.legend(fontsize=7)
        right.set_xlabel("residence time t [s]")
        right.set_ylabel("cumulative fraction F(t) [-]")
        right.set_ylim(0.0, 1.02)
        right.grid(alpha=0.3)
        figure.suptitle(title)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
