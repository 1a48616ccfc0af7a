"""Plots of blending in the recirculating planar silo in the study's style: what the run shows.

Each writer takes arrays (or lists of labelled arrays), a path and a title, draws one figure and saves
it atomically with :func:`siloflow.analysis.io.plots.save_figure` (PNG, PDF or SVG, as the path's suffix says); nothing is
read from files.
The RTD and LTI model curves are drawn by :mod:`siloflow.analysis.studies.silo_recirculation.rtd_plots`, the VRR of every
flow pattern and layout with its seeds by :mod:`siloflow.analysis.studies.silo_recirculation.vrr_summary_plot`.

Geometry (as in :mod:`siloflow.analysis.studies.silo_flat.plots`): width W along x with walls at x = +-W/2, floor and outlet
plane at z = 0, a slot outlet of width B0 centred on x = 0, and below it a channel of the same width
down to z = -L_channel; clumps leaving the channel re-enter at the top. Lengths are given in m and drawn
in mm. Batches are coloured blue and white; "concentration" is the blue fraction [-]. The number of
recirculations is Nr = t / t_res (t_res: the holdup residence time, holdup over throughput).

Tolerance bands follow :func:`siloflow.analysis.numerics.lti.recirculations_to_homogenise`: relative, i.e. the band is
``blue_fraction * (1 +- tolerance)``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from siloflow.model.checks import finite_array, positive_number
from siloflow.analysis.io.plots import (
    finite_abscissa,
    matching_ordinate,
    non_empty_list,
    save_figure,
    silo_outline,
    tuple_entry,
)
from siloflow.analysis.numerics.vrr_noise import CEILING_FACTOR, vrr_near_ceiling
from siloflow.analysis.studies.silo_recirculation.rtd_plots import BLUE, tolerance_band

__all__ = [
    "plot_outlet_concentration",
    "plot_vrr_versus_recirculations",
    "plot_coloured_snapshots",
    "plot_paths_comparison",
]

WHITE = "0.78"  # light grey stands in for the white batch on a white background


def _xy_curves(name: str, curves) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Checked (label, x, y) curves: x finite, y of the same length."""
    checked = []
    for i, item in enumerate(non_empty_list(name, curves)):
        label, x, y = tuple_entry(name, i, item, 3)
        x = finite_abscissa(f"{name}[{i}] x", x)
        checked.append((str(label), x, matching_ordinate(f"{name}[{i}] y", y, x.size, f"{name}[{i}] x")))
    return checked


def _channel_outline(axes, outlet_width: float, channel_length: float) -> None:
    slot = 0.5 * outlet_width
    outline = dict(color="black", linewidth=1.5)
    axes.plot([-slot, -slot], [0.0, -channel_length], **outline)
    axes.plot([slot, slot], [0.0, -channel_length], **outline)
    axes.plot([-slot, slot], [-channel_length, -channel_length], ":", color="black", linewidth=0.8)


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
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
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
        tolerance_band(axes, blue_fraction, tolerance)
        for label, recirculations, concentration in checked:
            axes.plot(recirculations, concentration, "-", linewidth=1.3, label=label)
        axes.set_ylim(-0.02, 1.02)
        axes.set_xlabel("number of recirculations Nr = t / t_res [-]")
        axes.set_ylabel("blue concentration at the outlet [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def _vrr_curves(curves, noise_limit: float | None) -> list[tuple[str, np.ndarray, np.ndarray, float | None,
                                                                   np.ndarray]]:
    """Checked (label, Nr, VRR, ceiling, VRR error) curves; a curve without its own ceiling takes ``noise_limit``,
    one without errors gets NaN errors (no bars)."""
    checked = []
    for i, item in enumerate(non_empty_list("curves", curves)):
        entry = tuple(item) if isinstance(item, (tuple, list)) else ()
        if len(entry) not in (3, 4, 5):
            raise ValueError(f"curves[{i}] must be a tuple of 3 items (label, Nr, VRR), 4 (with the ceiling) or 5 "
                             "(with the ceiling and the VRR errors)")
        label, x, y = entry[:3]
        ceiling = entry[3] if len(entry) >= 4 else None
        error = entry[4] if len(entry) == 5 else None
        x = finite_abscissa(f"curves[{i}] x", x)
        y = matching_ordinate(f"curves[{i}] y", y, x.size, f"curves[{i}] x")
        ceiling = noise_limit if ceiling is None else positive_number(f"curves[{i}] ceiling", ceiling)
        if error is None:
            error = np.full(x.size, np.nan)
        else:
            error = matching_ordinate(f"curves[{i}] error", error, x.size, f"curves[{i}] x")
            if np.any(error < 0.0) or np.any(np.isinf(error)):
                raise ValueError(f"curves[{i}] error must hold standard errors >= 0 (NaN: none)")
        checked.append((str(label), x, y, ceiling, error))
    return checked


def plot_vrr_versus_recirculations(curves, path: str | os.PathLike, title: str, noise_limit: float | None = None,
                                   factor: float = CEILING_FACTOR) -> Path:
    """Variance reduction ratio against the number of recirculations (log y axis), with the counting-noise
    ceiling and the VRRs' standard errors.

    Points whose VRR is NaN, zero or negative are skipped; a VRR of +inf (no variance left at the
    outlet) is marked by an upward triangle at the top of the axes. Each ceiling is drawn as a dashed
    horizontal line; finite VRRs within ``factor`` of their curve's ceiling
    (:func:`siloflow.analysis.numerics.vrr_noise.vrr_near_ceiling`) get an open marker: they are lower bounds,
    set by the sampling noise, not measurements. The points drawn that have a finite error get a bar of
    +- one standard error (``gid="vrr_error"``); on the log axis a bar reaching 0 or below runs to the
    bottom of the axes.

    Parameters
    ----------
    curves : list of tuple
        ``(label, Nr, VRR)``, ``(label, Nr, VRR, ceiling)`` or ``(label, Nr, VRR, ceiling, error)``: number of
        recirculations [-] (finite), the variance reduction ratio sigma_in^2 / sigma_out^2 [-] (same length),
        the counting-noise ceiling of that curve's VRR [-] (> 0; None or absent: ``noise_limit``) and the
        standard error of each VRR [-] (same length, >= 0; NaN: no bar; None or absent: no bars).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    noise_limit : float or None, optional
        Counting-noise ceiling (VRR of a perfectly mixed outflow sampled in windows of the same size,
        :func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`) of the curves without their own [-] (> 0);
        None: those curves have none.
    factor : float, optional
        VRRs at or above ``ceiling / factor`` are drawn open, >= 1 [-].

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``curves``, a curve not of 3, 4 or 5 items, mismatched lengths,
        non-positive ``noise_limit`` or ceiling, a negative or infinite error, ``factor < 1``.
    """
    if noise_limit is not None:
        noise_limit = positive_number("noise_limit", noise_limit)
    factor = float(factor)
    if not (math.isfinite(factor) and factor >= 1.0):
        raise ValueError(f"factor must be a finite number >= 1, got {factor!r}")
    checked = _vrr_curves(curves, noise_limit)
    # One line per distinct ceiling: the layouts of one run share theirs.
    ceilings = sorted({ceiling for *_, ceiling, _ in checked if ceiling is not None})
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    try:
        axes.set_yscale("log")
        axes.axhline(1.0, color="black", linewidth=0.9, label="VRR = 1 (no blending)")
        for ceiling in ceilings:
            axes.axhline(ceiling, color="tab:red", linestyle="--", linewidth=1.0, gid="ceiling",
                         label=f"counting-noise ceiling {ceiling:.3g}")
        any_at_ceiling = False
        for label, recirculations, vrr, ceiling, error in checked:
            # the points a log axis can show (positive_finite_points; the Nr are finite), with their errors
            drawn = np.isfinite(vrr) & (vrr > 0.0)
            x, y, y_error = recirculations[drawn], vrr[drawn], error[drawn]
            (line,) = axes.plot(x, y, "o-", markersize=4, linewidth=1.2,
                                label=label if x.size else f"{label} (no finite VRR)")
            with_bar = np.isfinite(y_error)
            if with_bar.any():
                bars = axes.errorbar(x[with_bar], y[with_bar], yerr=y_error[with_bar], fmt="none",
                                     color=line.get_color(), elinewidth=1.0, capsize=2.5, label="_nolegend_")
                for artist in bars.lines[2]:
                    artist.set_gid("vrr_error")
            at_ceiling = (np.zeros(0, dtype=bool) if ceiling is None else
                          np.asarray(vrr_near_ceiling(y, ceiling, factor), dtype=bool))
            if at_ceiling.any():
                any_at_ceiling = True
                axes.plot(x[at_ceiling], y[at_ceiling], "o", color=line.get_color(), markersize=7,
                          markerfacecolor="white", markeredgewidth=1.3, gid="at_ceiling", label="_nolegend_")
            infinite = recirculations[np.isposinf(vrr)]
            if infinite.size:
                axes.plot(infinite, np.full(infinite.size, 0.97), "^", color=line.get_color(), markersize=6,
                          transform=axes.get_xaxis_transform(), clip_on=False, gid="infinite")
        if any_at_ceiling:
            axes.plot([], [], "o", color="0.3", markersize=7, markerfacecolor="white",
                      label=f"within x{factor:g} of the ceiling: lower bound")
        axes.set_xlabel("number of recirculations Nr = t / t_res [-]")
        axes.set_ylabel("variance reduction ratio VRR [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3, which="both")
        axes.legend(fontsize=8)
        return save_figure(figure, path, tight=True)
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
        Naming the argument: empty ``snapshots``, mismatched lengths, non-positive dimensions.
    """
    width = positive_number("width", width)
    outlet_width = positive_number("outlet_width", outlet_width)
    top = positive_number("top", top)
    channel_length = positive_number("channel_length", channel_length)
    checked = []
    for i, item in enumerate(non_empty_list("snapshots", snapshots)):
        recirculations, x, z, is_blue = tuple_entry("snapshots", i, item, 4)
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
            silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * top)
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
        return save_figure(figure, path, tight=True)
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
        silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * top)
        axes.set_xlim(-0.55e3 * width, 0.55e3 * width)
        axes.set_aspect("equal")
        axes.set_xlabel("x [mm]")
        axes.set_ylabel("z [mm]")
        axes.set_title(title)
        axes.legend(loc="upper center", fontsize=8)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
