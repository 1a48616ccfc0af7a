"""Plots of blending in the recirculating planar silo in the study's style.

Each writer takes arrays (or lists of labelled arrays), a path and a title, draws one figure and saves
it atomically as a 150 dpi PNG with :func:`analysis.io.plots.save_png`; nothing is read from files.

Geometry (as in :mod:`analysis.studies.silo_flat.plots`): width W along x with walls at x = +-W/2, floor and outlet
plane at z = 0, a slot outlet of width B0 centred on x = 0, and below it a channel of the same width
down to z = -L_channel; clumps leaving the channel re-enter at the top. Lengths are given in m and drawn
in mm. Batches are coloured blue and white; "concentration" is the blue fraction [-]. The number of
recirculations is Nr = t / t_res (t_res: mean residence time of one pass).

Tolerance bands follow :func:`analysis.numerics.lti.recirculations_to_homogenise`: relative, i.e. the band is
``blue_fraction * (1 +- tolerance)``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis.checks import finite_array, positive_number  # noqa: E402
from analysis.io.plots import save_png  # noqa: E402
from analysis.studies.silo_flat.plots import _silo_outline  # noqa: E402

__all__ = [
    "plot_outlet_concentration",
    "plot_vrr_versus_recirculations",
    "plot_coloured_snapshots",
    "plot_rtd_comparison",
    "plot_lti_comparison",
    "plot_vrr_versus_period",
    "plot_recirculation_model",
    "plot_paths_comparison",
    "plot_residence_time_comparison",
]

BLUE = "tab:blue"
WHITE = "0.78"  # light grey stands in for the white batch on a white background

_LTI_STYLES = {
    "direct": dict(linestyle="-", linewidth=1.8),
    "predicted": dict(linestyle="--", linewidth=1.5),
    "first pass": dict(linestyle=":", linewidth=1.5),
    "input": dict(linestyle="-", linewidth=0.9, color="0.5"),
}
"""Line styles for the style hints of :func:`plot_lti_comparison`; other hints get a thin solid line."""


# --------------------------------------------------------------------------------------------------
# argument checks
# --------------------------------------------------------------------------------------------------


def _non_empty(name: str, items) -> list:
    items = list(items)
    if not items:
        raise ValueError(f"{name} must not be empty")
    return items


def _entry(name: str, index: int, item, size: int) -> tuple:
    try:
        entry = tuple(item)
    except TypeError:
        entry = ()
    if len(entry) != size:
        raise ValueError(f"{name}[{index}] must be a tuple of {size} items")
    return entry


def _abscissa(name: str, values) -> np.ndarray:
    """A non-empty, finite 1-D array (the x values of a curve)."""
    array = finite_array(name, values)
    if array.size == 0:
        raise ValueError(f"{name} must not be empty")
    return array


def _ordinate(name: str, values, length: int, reference: str) -> np.ndarray:
    """A 1-D float array of ``length`` entries (NaN allowed: drawn as gaps or skipped)."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or array.size != length:
        raise ValueError(f"{name} must be a 1-D array of the same length as {reference} ({length}), "
                         f"got shape {array.shape}")
    return array


def _xy_curves(name: str, curves) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Checked (label, x, y) curves: x finite, y of the same length."""
    checked = []
    for i, item in enumerate(_non_empty(name, curves)):
        label, x, y = _entry(name, i, item, 3)
        x = _abscissa(f"{name}[{i}] x", x)
        checked.append((str(label), x, _ordinate(f"{name}[{i}] y", y, x.size, f"{name}[{i}] x")))
    return checked


def _tolerance_band(axes, blue_fraction: float, tolerance: float) -> None:
    axes.axhline(blue_fraction, color="black", linestyle="--", linewidth=1.0,
                 label=f"blue fraction {blue_fraction:.3g}")
    axes.axhspan(blue_fraction * (1.0 - tolerance), blue_fraction * (1.0 + tolerance), color="0.5", alpha=0.15,
                 label=f"±{100 * tolerance:g} % band")


def _channel_outline(axes, outlet_width: float, channel_length: float) -> None:
    slot = 0.5 * outlet_width
    outline = dict(color="black", linewidth=1.5)
    axes.plot([-slot, -slot], [0.0, -channel_length], **outline)
    axes.plot([slot, slot], [0.0, -channel_length], **outline)
    axes.plot([-slot, slot], [-channel_length, -channel_length], ":", color="black", linewidth=0.8)


def _positive_finite(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keep = np.isfinite(x) & np.isfinite(y) & (y > 0.0)
    return x[keep], y[keep]


# --------------------------------------------------------------------------------------------------
# plots
# --------------------------------------------------------------------------------------------------


def plot_outlet_concentration(curves, blue_fraction: float, path: str | os.PathLike, title: str,
                              tolerance: float = 0.10) -> Path:
    """Blue concentration at the outlet against the number of recirculations, with the tolerance band.

    Parameters
    ----------
    curves : list of (str, array_like, array_like)
        ``(label, Nr, concentration)``: number of recirculations Nr = t / t_res [-] (finite) and the
        blue fraction of the clumps leaving the outlet [-] (same length; NaN is drawn as a gap).
    blue_fraction : float
        Blue fraction of the whole inventory [-] (> 0): the homogeneous value, drawn dashed.
    path : str or os.PathLike
        Destination PNG file (written atomically, 150 dpi).
    title : str
        Figure title.
    tolerance : float, optional
        Relative half-width of the shaded band, ``blue_fraction * (1 +- tolerance)`` [-] (> 0).

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``curves``, mismatched lengths, non-positive ``blue_fraction`` or
        ``tolerance``.
    """
    checked = _xy_curves("curves", curves)
    blue_fraction = positive_number("blue_fraction", blue_fraction)
    tolerance = positive_number("tolerance", tolerance)
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        _tolerance_band(axes, blue_fraction, tolerance)
        for label, recirculations, concentration in checked:
            axes.plot(recirculations, concentration, "-", linewidth=1.3, label=label)
        axes.set_ylim(-0.02, 1.02)
        axes.set_xlabel("number of recirculations Nr = t / t_res [-]")
        axes.set_ylabel("blue concentration at the outlet [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        return save_png(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_vrr_versus_recirculations(curves, path: str | os.PathLike, title: str,
                                   noise_limit: float | None = None) -> Path:
    """Variance reduction ratio against the number of recirculations (log y axis).

    Points whose VRR is NaN, zero or negative are skipped; a VRR of +inf (no variance left at the
    outlet) is marked by an upward triangle at the top of the axes.

    Parameters
    ----------
    curves : list of (str, array_like, array_like)
        ``(label, Nr, VRR)``: number of recirculations [-] (finite) and the variance reduction ratio
        sigma_in^2 / sigma_out^2 [-] (same length).
    path : str or os.PathLike
        Destination PNG file (written atomically, 150 dpi).
    title : str
        Figure title.
    noise_limit : float or None, optional
        VRR of a perfectly mixed sample of the same size (sampling-noise limit) [-] (> 0), drawn as a
        dashed line; None to omit.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``curves``, mismatched lengths, non-positive ``noise_limit``.
    """
    checked = _xy_curves("curves", curves)
    if noise_limit is not None:
        noise_limit = positive_number("noise_limit", noise_limit)
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        axes.set_yscale("log")
        axes.axhline(1.0, color="black", linewidth=0.9, label="VRR = 1 (no blending)")
        if noise_limit is not None:
            axes.axhline(noise_limit, color="tab:red", linestyle="--", linewidth=1.0,
                         label=f"sampling-noise limit {noise_limit:.3g}")
        for label, recirculations, vrr in checked:
            x, y = _positive_finite(recirculations, vrr)
            (line,) = axes.plot(x, y, "o-", markersize=4, linewidth=1.2,
                                label=label if x.size else f"{label} (no finite VRR)")
            infinite = recirculations[np.isposinf(vrr)]
            if infinite.size:
                axes.plot(infinite, np.full(infinite.size, 0.97), "^", color=line.get_color(), markersize=6,
                          transform=axes.get_xaxis_transform(), clip_on=False)
        axes.set_xlabel("number of recirculations Nr = t / t_res [-]")
        axes.set_ylabel("variance reduction ratio VRR [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3, which="both")
        axes.legend(fontsize=8)
        return save_png(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_coloured_snapshots(snapshots, width: float, outlet_width: float, top: float, channel_length: float,
                            path: str | os.PathLike, title: str) -> Path:
    """Clump centres coloured by batch (blue / white) in the x-z plane, one panel per snapshot.

    Up to four panels sit in one row; more are laid out in rows of four.

    Parameters
    ----------
    snapshots : list of (float, array_like, array_like, array_like)
        ``(Nr, x, z, is_blue)``: number of recirculations at the snapshot [-], clump centre coordinates
        x and z [m] and a boolean array, True for a blue clump (all three of the same length).
    width : float
        Silo width W [m]; walls at x = +-W/2.
    outlet_width : float
        Slot outlet (and channel) width B0 [m].
    top : float
        Height up to which the walls are drawn [m].
    channel_length : float
        Length of the channel below the outlet [m]; it ends at z = -channel_length.
    path : str or os.PathLike
        Destination PNG file (written atomically, 150 dpi).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``snapshots``, mismatched lengths, non-positive dimensions.
    """
    width = positive_number("width", width)
    outlet_width = positive_number("outlet_width", outlet_width)
    top = positive_number("top", top)
    channel_length = positive_number("channel_length", channel_length)
    checked = []
    for i, item in enumerate(_non_empty("snapshots", snapshots)):
        recirculations, x, z, is_blue = _entry("snapshots", i, item, 4)
        x = finite_array(f"snapshots[{i}] x", x)
        z = finite_array(f"snapshots[{i}] z", z)
        blue = np.asarray(is_blue)
        if z.size != x.size or blue.shape != x.shape:
            raise ValueError(f"snapshots[{i}]: x, z and is_blue must be 1-D arrays of the same length, got shapes "
                             f"{x.shape}, {z.shape} and {blue.shape}")
        checked.append((float(recirculations), 1e3 * x, 1e3 * z, blue.astype(bool)))

    columns = min(len(checked), 4)
    rows = math.ceil(len(checked) / columns)
    panel_height = 2.1 * (top + channel_length + 0.01) / (1.1 * width) + 0.5  # equal aspect, room for titles
    figure, axes_grid = plt.subplots(rows, columns, figsize=(2.6 * columns, panel_height * rows + 0.4),
                                     squeeze=False, sharex=True, sharey=True, layout="constrained")
    try:
        marker = max(0.5, min(4.0, 2000.0 / max(1, max(x.size for _, x, _, _ in checked))))
        for axes in axes_grid.flat[len(checked):]:
            axes.set_visible(False)
        for axes, (recirculations, x, z, blue) in zip(axes_grid.flat, checked):
            axes.scatter(x[~blue], z[~blue], s=marker, color=WHITE, linewidths=0, rasterized=True)
            axes.scatter(x[blue], z[blue], s=marker, color=BLUE, linewidths=0, rasterized=True)
            _silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * top)
            _channel_outline(axes, 1e3 * outlet_width, 1e3 * channel_length)
            axes.set_xlim(-0.55e3 * width, 0.55e3 * width)
            axes.set_ylim(-1e3 * channel_length - 5.0, 1e3 * top + 5.0)
            axes.set_aspect("equal")
            axes.set_title(f"Nr = {recirculations:g}", fontsize=9)
        for axes in axes_grid[-1, :]:
            axes.set_xlabel("x [mm]")
        for axes in axes_grid[:, 0]:
            axes.set_ylabel("z [mm]")
        figure.suptitle(title)
        return save_png(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_rtd_comparison(curves, path: str | os.PathLike, title: str, dimensionless: bool = True) -> Path:
    """Residence time distributions of several runs or models, drawn as steps over their bins.

    Parameters
    ----------
    curves : list of (str, array_like, array_like, float)
        ``(label, t, E, t_mean)``: bin centres t [s] (finite), RTD E(t) [1/s] (same length) and the
        mean residence time t_m [s] (> 0), which the legend shows.
    path : str or os.PathLike
        Destination PNG file (written atomically, 150 dpi).
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
    for i, item in enumerate(_non_empty("curves", curves)):
        label, t, e, t_mean = _entry("curves", i, item, 4)
        t = _abscissa(f"curves[{i}] t", t)
        e = _ordinate(f"curves[{i}] E", e, t.size, f"curves[{i}] t")
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
        return save_png(figure, path, tight=True)
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
        Destination PNG file (written atomically, 150 dpi).
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
    time = _abscissa("time", time)
    checked = []
    for i, item in enumerate(_non_empty("series", series)):
        label, concentration, style = _entry("series", i, item, 3)
        checked.append((str(label), _ordinate(f"series[{i}] concentration", concentration, time.size, "time"),
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
        return save_png(figure, path, tight=True)
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
        Destination PNG file (written atomically, 150 dpi).
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
    period_fraction = _abscissa("period_fraction", period_fraction)
    if np.any(period_fraction <= 0.0):
        raise ValueError("period_fraction must contain only numbers > 0 (log axis)")
    checked = []
    for i, item in enumerate(_non_empty("curves", curves)):
        label, vrr = _entry("curves", i, item, 2)
        checked.append((str(label), _ordinate(f"curves[{i}] VRR", vrr, period_fraction.size, "period_fraction")))
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        axes.set_xscale("log")
        axes.set_yscale("log")
        axes.axhline(1.0, color="black", linewidth=0.9, label="VRR = 1 (no blending)")
        for label, vrr in checked:
            x, y = _positive_finite(period_fraction, vrr)
            axes.plot(x, y, "o-", markersize=4, linewidth=1.2, label=label if x.size else f"{label} (no finite VRR)")
        axes.set_xlabel("input period / mean residence time, T / t_m [-]")
        axes.set_ylabel("variance reduction ratio VRR [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3, which="both")
        axes.legend(fontsize=8)
        return save_png(figure, path, tight=True)
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
        Destination PNG file (written atomically, 150 dpi).
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
    passes = _abscissa("time_in_passes", time_in_passes)
    concentration = _ordinate("concentration", concentration, passes.size, "time_in_passes")
    blue_fraction = positive_number("blue_fraction", blue_fraction)
    tolerance = positive_number("tolerance", tolerance)
    homogenised_after = float(homogenised_after)
    if math.isinf(homogenised_after):
        raise ValueError(f"homogenised_after must be finite or NaN, got {homogenised_after!r}")
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        _tolerance_band(axes, blue_fraction, tolerance)
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
        return save_png(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_paths_comparison(particle_paths, pathlines, width: float, outlet_width: float, top: float,
                          path: str | os.PathLike, title: str) -> Path:
    """DEM particle tracks (solid) against pathlines of the mean velocity field (dashed) in the x-z plane.

    Parameters
    ----------
    particle_paths : list of array_like
        Tracked clump centres, each of shape (n_i, 2) holding (x, z) [m]; rows of NaN break a track
        (e.g. at re-entry).
    pathlines : list of array_like
        Integrated pathlines, each of shape (n_i, 2) holding (x, z) [m]; NaN rows allowed as above.
    width : float
        Silo width W [m]; walls at x = +-W/2.
    outlet_width : float
        Slot outlet width B0 [m].
    top : float
        Height up to which the walls are drawn [m].
    path : str or os.PathLike
        Destination PNG file (written atomically, 150 dpi).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: both lists empty, an entry not of shape (n, 2), non-positive dimensions.
    """
    width = positive_number("width", width)
    outlet_width = positive_number("outlet_width", outlet_width)
    top = positive_number("top", top)

    def points(name: str, items) -> list[np.ndarray]:
        checked = []
        for i, item in enumerate(items):
            array = np.asarray(item, dtype=float)
            if array.ndim != 2 or array.shape[1] != 2:
                raise ValueError(f"{name}[{i}] must have shape (n, 2) of (x, z), got shape {array.shape}")
            checked.append(1e3 * array)
        return checked

    tracks = points("particle_paths", particle_paths)
    lines = points("pathlines", pathlines)
    if not tracks and not lines:
        raise ValueError("particle_paths and pathlines must not both be empty")
    figure, axes = plt.subplots(figsize=(5.0, 6.0))
    try:
        for track in tracks:
            axes.plot(track[:, 0], track[:, 1], "-", color=BLUE, linewidth=1.0, alpha=0.8)
        for line in lines:
            axes.plot(line[:, 0], line[:, 1], "--", color="tab:orange", linewidth=1.2)
        axes.plot([], [], "-", color=BLUE, label=f"DEM particle tracks ({len(tracks)})")
        axes.plot([], [], "--", color="tab:orange", label=f"pathlines ({len(lines)})")
        _silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * top)
        axes.set_xlim(-0.55e3 * width, 0.55e3 * width)
        axes.set_aspect("equal")
        axes.set_xlabel("x [mm]")
        axes.set_ylabel("z [mm]")
        axes.set_title(title)
        axes.legend(loc="upper center", fontsize=8)
        return save_png(figure, path, tight=True)
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
        Destination PNG file (written atomically, 150 dpi).
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
    for i, item in enumerate(_non_empty("samples", samples)):
        label, times = _entry("samples", i, item, 2)
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
        return save_png(figure, path, tight=True)
    finally:
        plt.close(figure)
