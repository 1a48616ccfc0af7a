"""Plots of the flat-bottom silo flow in the study's style: discharge, velocity profiles and fields, stresses.

Each writer takes arrays or dataclasses and a path, draws one figure and saves it atomically in the format of the
path's suffix, PNG, PDF or SVG (:func:`siloflow.analysis.io.plots.save_figure`). It returns that figure, already closed (let go
by pyplot, so a caller that ignores it leaks nothing): its artists still hold the plotted data, which is what the
tests check."""

from __future__ import annotations

import os
from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from siloflow.analysis.io.plot_style import (
    BAND_ALPHA,
    PAGE_WIDTH,
    PALETTE,
    REFERENCE_COLOUR,
    StudyNote,
    colour_of,
    journal_style,
    legend_outside,
    note_study,
    study_findings,
)
from siloflow.analysis.io.plots import save_figure, silo_outline
from siloflow.analysis.numerics.flow import DischargeHistory, FlowRateFit
from siloflow.analysis.studies.silo_flat.field_comparisons import SeedKinematic, SeedProfiles

#: Colour of a velocity profile or fitted kinematic constant: the palette's blue.
_PROFILE_COLOUR = PALETTE[5]
#: Colour of the flow channel boundary: the palette's vermillion, apart from the profiles' blue in any colour vision.
_BOUNDARY_COLOUR = PALETTE[6]


def plot_discharge(
    history: DischargeHistory,
    fit: FlowRateFit,
    beverloo_rate: float | None,
    path: str | os.PathLike,
    title: str,
    rate_error: float | None = None,
) -> Figure:
    """Plot discharged mass against time with the fitted and Beverloo flow rates.

    Draws the discharged mass, the least-squares line over the steady window
    (shaded), and, for comparison, a line of the Beverloo slope through the
    fitted line at the window midpoint (so only the slopes are compared).

    Parameters
    ----------
    history : siloflow.analysis.numerics.flow.DischargeHistory
        Time since opening [s] and discharged mass [kg].
    fit : siloflow.analysis.numerics.flow.FlowRateFit
        Steady flow rate fit [kg/s] and its window [s].
    beverloo_rate : float or None
        Beverloo mass flow rate [kg/s]; None to omit the line.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    rate_error : float, optional
        Standard error of the flow rate [kg/s] for the legend (batch means of the rate); None: the
        least-squares error of the fit, ``fit.standard_error``.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn, already closed (see the module docstring).
    """
    time = np.asarray(history.time, dtype=float)
    error = fit.standard_error if rate_error is None else rate_error
    mass = np.asarray(history.discharged_mass, dtype=float)

    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    try:
        axes.plot(time, mass, ".", markersize=3, color="0.35", label="DEM discharged mass")
        axes.axvspan(fit.t_start, fit.t_end, color="tab:blue", alpha=0.08, label="steady window")

        window_time = np.array([fit.t_start, fit.t_end])
        axes.plot(
            window_time,
            fit.intercept + fit.mass_flow_rate * window_time,
            "-",
            color="tab:blue",
            linewidth=2,
            label=f"fit: {fit.mass_flow_rate:.4g} ± {error:.2g} kg/s",
        )
        if beverloo_rate is not None:
            midpoint_time = 0.5 * (fit.t_start + fit.t_end)
            midpoint_mass = fit.intercept + fit.mass_flow_rate * midpoint_time
            axes.plot(
                window_time,
                midpoint_mass + beverloo_rate * (window_time - midpoint_time),
                "--",
                color="tab:red",
                linewidth=1.5,
                label=f"Beverloo: {beverloo_rate:.4g} kg/s",
            )

        axes.set_xlabel("time since opening [s]")
        axes.set_ylabel("discharged mass [kg]")
        axes.set_title(title)
        axes.grid(True, alpha=0.3)
        axes.legend(loc="upper left", fontsize="small")
        figure.tight_layout()
        save_figure(figure, path)
    finally:
        plt.close(figure)
    return figure


def plot_profiles_over_silo(profiles, width: float, outlet_width: float, top: float, path, title: str,
                            fcb_fraction_index: int = -1, uncertainty=None) -> Figure:
    """Vertical velocity profiles drawn as lines over the silo outline, flow channel boundary marked, in the
    project's style (:func:`siloflow.analysis.io.plot_style.journal_style`).

    Each profile is drawn at its height z as z + s v_z(x) (``gid="profile"``, blue), with the scale s chosen so
    that the fastest profile spans 80 % of the spacing between heights, over a light grey guide at z; the
    vermillion dots mark the flow channel boundary at the chosen fraction of the centreline velocity
    (``gid="fcb"``). With ``uncertainty`` (a :class:`~siloflow.analysis.studies.silo_flat.fields.ProfileUncertainty`)
    each dot gets a horizontal error bar of one standard error (mm), one errorbar container per height (NaN errors
    draw nothing). The legend (the boundary, and the profile with its velocity scale) stands right of the silo.
    Lengths in mm.
    """
    heights = profiles.heights
    spacing = np.min(np.diff(heights)) if heights.size > 1 else 0.02
    peak = np.nanmax(np.abs(profiles.v_z)) or 1.0
    scale = 0.8 * spacing / peak
    x_mm = 1e3 * profiles.x
    with journal_style():
        figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 4.4))
        try:
            # room on the right for the legend, so that the figure keeps the page's width
            figure.subplots_adjust(left=0.1, right=0.62, bottom=0.11, top=0.93)
            silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * top)
            for i, z in enumerate(heights):
                axes.axhline(1e3 * z, color="0.85", linewidth=0.6)
                axes.plot(x_mm, 1e3 * (z + scale * profiles.v_z[i]), color=_PROFILE_COLOUR, gid="profile")
                boundary_mm = 1e3 * np.array([profiles.fcb_left[i, fcb_fraction_index],
                                              profiles.fcb_right[i, fcb_fraction_index]])
                axes.plot(boundary_mm, [1e3 * z, 1e3 * z], "o", color=_BOUNDARY_COLOUR, gid="fcb")
                if uncertainty is not None:
                    errors = [uncertainty.fcb_left_error[i, fcb_fraction_index],
                              uncertainty.fcb_right_error[i, fcb_fraction_index]]
                    axes.errorbar(boundary_mm, [1e3 * z, 1e3 * z], xerr=1e3 * np.array(errors),
                                  fmt="none", ecolor=_BOUNDARY_COLOUR, elinewidth=1.0, capsize=3)
            fraction = profiles.fcb_fractions[fcb_fraction_index]
            # proxies: each kind once in the legend, however many heights
            axes.plot([], [], "o", color=_BOUNDARY_COLOUR, label=f"FCB at {100 * fraction:g} % of centreline v_z")
            axes.plot([], [], color=_PROFILE_COLOUR, label=f"v_z (1 mm = {1e-3 / scale:.3g} m/s)")
            axes.set_aspect("equal")
            axes.set_xlabel("x [mm]")
            axes.set_ylabel("z [mm]")
            axes.set_title(title)
            legend_outside(axes)
            save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)
    return figure


def plot_velocity_contour(x, z, v_z, width: float, outlet_width: float, path, title: str) -> Figure:
    """Contours of the depth-averaged vertical velocity v_z(x, z) (m/s); ``v_z`` has shape (nx, nz)."""
    figure, axes = plt.subplots(figsize=(5.0, 6.0))
    try:
        levels = np.linspace(np.min(v_z), 0.0, 21) if np.min(v_z) < 0 else 21
        filled = axes.contourf(1e3 * np.asarray(x), 1e3 * np.asarray(z), np.asarray(v_z).T, levels=levels,
                               cmap="viridis")
        figure.colorbar(filled, ax=axes, label="v_z [m/s]")
        silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * np.max(z))
        axes.set_aspect("equal")
        axes.set_xlabel("x [mm]")
        axes.set_ylabel("z [mm]")
        axes.set_title(title)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure


def plot_kinematic_constant(heights, B, path, title: str, B_error=None,
                            findings: Sequence[StudyNote] | None = None) -> Figure:
    """Kinematic constant B [mm] against height above the outlet z [mm], in the project's style
    (:func:`siloflow.analysis.io.plot_style.journal_style`).

    B is drawn as one line with markers (``gid="kinematic_B"``), with horizontal error bars of one standard error
    ``B_error`` (NaN draws none) when given. Each finding is an entry of the legend, which stands right of the axes.

    Parameters
    ----------
    heights : array_like
        Heights above the outlet z [m].
    B : array_like
        Kinematic constant B at each height [m].
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix
        (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    B_error : array_like, optional
        Standard error of B at each height [m]; None: no error bars.
    findings : sequence of StudyNote, optional
        The study's expected trend to show beside B (a legend entry labelled with its id), e.g. S5:
        ``StudyNote("S5", "B decreases with height")``. None (the default): none.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn, already closed (see the module docstring).

    Raises
    ------
    ValueError
        For a finding that is not a StudyNote.
    """
    notes = study_findings(findings, StudyNote)
    with journal_style():
        figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 3.4))
        try:
            figure.subplots_adjust(left=0.1, right=0.6, bottom=0.14, top=0.9)
            # the legend lists the data (B, its errors), then the findings they are read against
            handles = axes.plot(1e3 * np.asarray(B), 1e3 * np.asarray(heights), "o-", color=_PROFILE_COLOUR,
                                label="DEM kinematic constant B", gid="kinematic_B")
            if B_error is not None:
                handles.append(axes.errorbar(1e3 * np.asarray(B), 1e3 * np.asarray(heights),
                                             xerr=1e3 * np.asarray(B_error), fmt="none", ecolor=_PROFILE_COLOUR,
                                             capsize=3, label="± standard error"))
            handles += [note_study(axes, note) for note in notes]
            axes.set_xlabel("B [mm]")
            axes.set_ylabel("z [mm]")
            axes.set_title(title)
            axes.grid(alpha=0.3)
            legend_outside(axes, handles=handles)
            save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)
    return figure


def plot_seed_profiles(profiles: SeedProfiles, kinematic: SeedKinematic, path, title: str,
                       findings: Sequence[StudyNote] | None = None) -> Figure:
    """The steady v_z profiles and the kinematic constant B of one configuration's seeds, in the project's style
    (:func:`siloflow.analysis.io.plot_style.journal_style`): the figure the record shows beside the silo's rows.

    Left, v_z [m/s] against x [mm]: one line per height (one colour each, ``gid="v_z z=<mm>"``), the seeds' mean,
    with a band of one standard error of that mean (``gid="v_z band z=<mm>"``) where two or more seeds give one.
    Right, B [mm] against z [mm] (on a log axis when B spans more than a factor 10): the seeds' mean with horizontal
    error bars of its error (``gid="kinematic_B"``; an error bar reaching below zero is cut at the axis), and each
    finding as an entry of the one legend, which stands right of the right axes.

    Parameters
    ----------
    profiles : siloflow.analysis.studies.silo_flat.field_comparisons.SeedProfiles
        The seeds' profiles (m, m/s).
    kinematic : siloflow.analysis.studies.silo_flat.field_comparisons.SeedKinematic
        The seeds' B at each height (m).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix
        (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    findings : sequence of StudyNote, optional
        The study's trend of B (S5), a legend entry labelled with its id. None (the default): none.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn, already closed (see the module docstring).

    Raises
    ------
    ValueError
        For a finding that is not a StudyNote.
    """
    notes = study_findings(findings, StudyNote)
    labels = [f"z = {1e3 * z:g} mm" for z in profiles.heights]
    colours = colour_of(labels)
    x_mm = 1e3 * np.asarray(profiles.x)
    with journal_style():
        figure, (left, right) = plt.subplots(1, 2, figsize=(PAGE_WIDTH, 3.4), gridspec_kw={"width_ratios": [3, 2]})
        try:
            figure.subplots_adjust(left=0.09, right=0.66, bottom=0.14, top=0.88, wspace=0.38)
            handles = []
            for label, z, v_z, error in zip(labels, profiles.heights, profiles.v_z, profiles.v_z_error):
                gid = f"{1e3 * z:g}"
                handles += left.plot(x_mm, v_z, color=colours[label], label=label, gid=f"v_z z={gid}")
                if np.any(np.isfinite(error)):
                    left.fill_between(x_mm, v_z - error, v_z + error, color=colours[label], alpha=2 * BAND_ALPHA,
                                      linewidth=0.0, label="_nolegend_", gid=f"v_z band z={gid}")
            if profiles.seeds > 1:
                handles.append(Patch(color=REFERENCE_COLOUR, alpha=2 * BAND_ALPHA,
                                     label=f"± standard error of {profiles.seeds} seeds' mean"))
            left.set_xlabel("x [mm]")
            left.set_ylabel("v_z [m/s]")
            left.grid(alpha=0.3)
            B_mm, error_mm, z_mm = 1e3 * kinematic.B, 1e3 * kinematic.B_error, 1e3 * kinematic.heights
            error_mm = np.where(np.isfinite(error_mm), error_mm, 0.0)
            # a log axis cannot show a bar that reaches zero: the lower bar stops just short of it
            lower = np.where(np.isfinite(B_mm), np.minimum(error_mm, 0.999 * np.abs(B_mm)), 0.0)
            bars = right.errorbar(B_mm, z_mm, xerr=[lower, error_mm], fmt="o-",
                                  color=_PROFILE_COLOUR, capsize=3, label="B, seeds' mean ± error")
            bars.lines[0].set_gid("kinematic_B")
            handles.append(bars)
            handles += [note_study(right, note) for note in notes]
            finite = B_mm[np.isfinite(B_mm)]
            # B grows by orders of magnitude where the flow turns to plug flow: a log axis keeps the low heights
            # apart
            if finite.size and np.all(finite > 0.0) and finite.max() > 10.0 * finite.min():
                right.set_xscale("log")
            right.set_xlabel("B [mm]")
            right.set_ylabel("z [mm]")
            right.grid(alpha=0.3)
            figure.suptitle(title)
            legend_outside(right, handles=handles)
            save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)
    return figure


def plot_janssen(comparison, path, title: str, findings: Sequence[StudyNote] | None = None) -> Figure:
    """Mean vertical stress against depth below the surface, in the project's style
    (:func:`siloflow.analysis.io.plot_style.journal_style`): the DEM contact stress with horizontal error bars of
    one standard error (one errorbar container, its points ``gid="dem_stress"``), Janssen's formula (``gid="janssen"``) and the hydrostatic
    ``rho_b g h`` (``gid="hydrostatic"``, dotted grey). Stresses in Pa, depth in mm (growing downwards); the legend
    stands right of the axes.

    Parameters
    ----------
    comparison : siloflow.analysis.studies.silo_flat.fields.JanssenComparison
        The stresses to draw.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix
        (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    findings : sequence of StudyNote, optional
        The study's finding on Janssen's curve, which then names it in the legend: with S1,
        ``StudyNote("S1", "DEM in good agreement")``, the Janssen entry reads ``Janssen, study (S1): DEM in good
        agreement``. None (the default): ``Janssen``.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn, already closed (see the module docstring).

    Raises
    ------
    ValueError
        For a finding that is not a StudyNote.
    """
    notes = study_findings(findings, StudyNote)
    janssen_label = ", ".join(["Janssen"] + [note.label for note in notes])
    with journal_style():
        figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 3.4))
        try:
            figure.subplots_adjust(left=0.1, right=0.6, bottom=0.14, top=0.9)
            depth_mm = 1e3 * comparison.depth_below_surface
            # the points and their error bars are one series: one artist, one legend entry
            dem = axes.errorbar(comparison.simulated, depth_mm, xerr=comparison.simulated_error, fmt="o",
                                color=PALETTE[0], capsize=2, label="DEM (contact stress) ± standard error")
            dem.lines[0].set_gid("dem_stress")
            (janssen,) = axes.plot(comparison.janssen, depth_mm, "-", color=_PROFILE_COLOUR, label=janssen_label,
                                   gid="janssen")
            (hydrostatic,) = axes.plot(comparison.hydrostatic, depth_mm, ":", color=REFERENCE_COLOUR,
                                       label="hydrostatic rho_b g h", gid="hydrostatic")
            axes.invert_yaxis()
            axes.set_xlabel("vertical stress [Pa]")
            axes.set_ylabel("depth below surface [mm]")
            axes.set_title(title)
            axes.grid(alpha=0.3)
            legend_outside(axes, handles=[dem, janssen, hydrostatic])
            save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)
    return figure


def plot_centreline_velocity(times, heights, velocities, path, title: str) -> Figure:
    """Centreline vertical velocity against time since opening, one line per height."""
    figure, axes = plt.subplots(figsize=(6.0, 4.0))
    try:
        for j, z in enumerate(heights):
            axes.plot(times, velocities[:, j], label=f"z = {1e3 * z:g} mm")
        axes.set_xlabel("time since opening [s]")
        axes.set_ylabel("v_z on the axis [m/s]")
        axes.set_title(title)
        axes.legend(fontsize=8)
        axes.grid(alpha=0.3)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure


def plot_force_chains(segments, width: float, outlet_width: float, top: float, path, title: str) -> Figure:
    """Branch vectors of contacts in a slice, coloured by normal force (capped)."""
    figure, axes = plt.subplots(figsize=(5.0, 6.0))
    try:
        lines = np.stack([1e3 * segments.start[:, [0, 2]], 1e3 * segments.end[:, [0, 2]]], axis=1)
        collection = LineCollection(lines, array=segments.normal_force, cmap="inferno_r", linewidths=1.2)
        collection.set_clim(0.0, segments.cap)
        axes.add_collection(collection)
        figure.colorbar(collection, ax=axes, shrink=0.6, label=f"normal force [N] (capped at {segments.cap:.3g} N)")
        silo_outline(axes, 1e3 * width, 1e3 * outlet_width, 1e3 * top)
        axes.set_xlim(-0.55e3 * width, 0.55e3 * width)
        axes.set_ylim(-2.0, 1e3 * top)
        axes.set_aspect("equal")
        axes.set_xlabel("x [mm]")
        axes.set_ylabel("z [mm]")
        axes.set_title(title)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure


def plot_measured_comparison(comparisons, path, title: str) -> Figure:
    """Simulated against measured v_z(x), one panel row per measured profile, with the error metrics."""
    rows = max(1, len(comparisons))
    figure, axes_list = plt.subplots(rows, 1, figsize=(6.0, 2.6 * rows), squeeze=False)
    try:
        for axes, comparison in zip(axes_list[:, 0], comparisons):
            measured = comparison.measured
            x_mm = 1e3 * measured.x
            if measured.uncertainty is not None:
                axes.errorbar(x_mm, measured.v_z, yerr=measured.uncertainty, fmt="o", markersize=3, label="measured")
            else:
                axes.plot(x_mm, measured.v_z, "o", markersize=3, label="measured")
            axes.plot(x_mm, comparison.simulated_v_z, "-", label="DEM")
            errors = comparison.errors
            axes.set_title(f"z = {1e3 * measured.z:g} mm, {measured.window}: mean error {errors.mean_error_percent:.1f} %, "
                           f"RMS {errors.rms_error:.3g} m/s", fontsize=9)
            axes.set_ylabel("v_z [m/s]")
            axes.grid(alpha=0.3)
        axes_list[-1, 0].set_xlabel("x [mm]")
        axes_list[0, 0].legend(fontsize=8)
        figure.suptitle(title)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure


def plot_parametric_study(x, profiles, labels, flow_rates, height: float, path, title: str) -> Figure:
    """v_z profiles at one height (left) and the steady mass flow rate (right) for each run of a study."""
    figure, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.0), gridspec_kw={"width_ratios": [3, 2]})
    try:
        for profile, label in zip(profiles, labels):
            left.plot(1e3 * np.asarray(x), profile, label=label)
        left.set_xlabel("x [mm]")
        left.set_ylabel(f"v_z at z = {1e3 * height:g} mm [m/s]")
        left.grid(alpha=0.3)
        left.legend(fontsize=7)
        positions = np.arange(len(labels))
        right.bar(positions, flow_rates, color="tab:blue")
        right.set_xticks(positions, labels, rotation=45, ha="right", fontsize=7)
        right.set_ylabel("steady mass flow rate [kg/s]")
        right.grid(alpha=0.3, axis="y")
        figure.suptitle(title)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure


def plot_kinematic_horizontal_velocity(profiles, path, title: str) -> Figure:
    """Horizontal velocity from the DEM (v_x) against the kinematic model's u = -B dv_z/dx at each height."""
    rows = len(profiles.heights)
    figure, axes_list = plt.subplots(rows, 1, figsize=(6.0, 2.2 * rows), squeeze=False, sharex=True)
    try:
        x_mm = 1e3 * profiles.x
        for i, axes in enumerate(axes_list[:, 0]):
            axes.plot(x_mm, profiles.v_x[i], "o", markersize=3, label="DEM v_x")
            axes.plot(x_mm, profiles.kinematic_u[i], "-", label="kinematic u = -B dv_z/dx")
            axes.set_ylabel(f"z = {1e3 * profiles.heights[i]:g} mm\n[m/s]", fontsize=8)
            axes.grid(alpha=0.3)
        axes_list[0, 0].legend(fontsize=8)
        axes_list[-1, 0].set_xlabel("x [mm]")
        figure.suptitle(title)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure


def plot_posterior_draws(rows, spread, path, title: str) -> Figure:
    """Each figure of the silo at the posterior mean and at each posterior draw, with each run's standard error and
    the calibration's error bar (``spread``: :func:`siloflow.analysis.studies.silo_flat.posterior_draws.calibration_spread`) as
    a band about the posterior mean's value."""
    figure, axes = plt.subplots(1, len(spread), figsize=(4.5 * len(spread), 3.8), squeeze=False)
    try:
        positions = np.arange(len(rows))
        labels = [row["label"] for row in rows]
        for axis, summary in zip(axes[0], spread):
            name = summary["figure"]
            axis.errorbar(positions, [row[name] for row in rows], yerr=[row[f"{name}_error"] for row in rows],
                          fmt="o", capsize=3, color="tab:blue", label="run ± its standard error")
            centre, band = summary["posterior_mean"], summary["calibration_sd"]
            if np.isfinite(centre) and np.isfinite(band):
                axis.axhspan(centre - band, centre + band, color="tab:orange", alpha=0.25,
                             label="posterior mean ± calibration sd")
            axis.set_xticks(positions, labels, rotation=30, ha="right", fontsize=8)
            axis.set_ylabel(f"{name.replace('_', ' ')} [{summary['unit']}]")
            axis.grid(alpha=0.3, axis="y")
            axis.legend(fontsize=7)
        figure.suptitle(title)
        save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
    return figure
