"""Plots of the multi-flow blender analysis (the modules of :mod:`siloflow.analysis.studies.blender`).

Each writer takes the results of the blender analysis (or plain arrays), a path and a title, draws one figure
and saves it atomically with :func:`siloflow.analysis.io.plots.save_figure` (PNG, PDF or SVG, as the path's suffix says);
nothing is read from files.
Lengths are given in m and drawn in mm; x = 0 is the silo axis and z = 0 the outlet plane. The RTD and the
discontinuous mode are drawn by the writers of :mod:`siloflow.analysis.studies.silo_recirculation.rtd_plots`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from siloflow.model.checks import finite_array, number_or_nan, positive_number
from siloflow.analysis.io.plot_style import (
    BAND_ALPHA,
    LINE_STYLES,
    PAGE_WIDTH,
    REFERENCE_COLOUR,
    StudyNote,
    StudyValue,
    colour_of,
    draw_study_value,
    journal_style,
    legend_outside,
    note_study,
    study_findings,
)
from siloflow.analysis.io.plots import non_empty_list, positive_finite_points, save_figure, tuple_entry
from siloflow.analysis.numerics.rtd import RTD
from siloflow.analysis.studies.blender.gravity import gravity_normalised_time, gravity_normalised_velocity
from siloflow.analysis.studies.blender.modes import ContinuousMode, DiscontinuousMode
from siloflow.analysis.studies.blender.profiles import ChannelBoundary, PassageVelocities, ProfilesOverTime
from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.tracers import TracerPathlines, VirtualTracerRTD
from siloflow.analysis.studies.silo_recirculation.rtd_plots import plot_recirculation_model, plot_rtd_comparison

__all__ = [
    "plot_profiles_over_time",
    "plot_passage_distributions",
    "plot_channel_boundary",
    "plot_tracer_pathlines",
    "plot_rtd_theta",
    "plot_discontinuous_mode",
    "plot_continuous_mode",
    "plot_gravity_scaling",
    "plot_configuration_comparison",
]

MM = 1.0e3
"""Metres to millimetres."""
_PASSAGES = ("tube", "interior", "exterior")
"""The blender's passages, in the order that gives each its colour of the palette in every figure."""


def _instance(name: str, value, kind):
    if not isinstance(value, kind):
        raise ValueError(f"{name} must be a {kind.__name__}, got {type(value).__name__}")
    return value


def _labelled(name: str, items, kind) -> list[tuple[str, object]]:
    """Checked non-empty mapping label -> instance of ``kind``, as a list of pairs."""
    if not isinstance(items, Mapping):
        raise ValueError(f"{name} must be a mapping label -> {kind.__name__}")
    pairs = non_empty_list(name, items.items())
    return [(str(label), _instance(f"{name}[{label!r}]", value, kind)) for label, value in pairs]


# --------------------------------------------------------------------------- profiles


def plot_profiles_over_time(profiles: ProfilesOverTime, path: str | os.PathLike, title: str) -> Path:
    """Normalised vertical velocity ``v_z / cross-section mean`` across the width, one panel per key height.

    Each panel holds one line per time window (NaN outside the cross-section is a gap) and the
    reference line 1 (plug flow).

    Parameters
    ----------
    profiles : siloflow.analysis.studies.blender.profiles.ProfilesOverTime
        Profiles at key heights for several windows.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    profiles = _instance("profiles", profiles, ProfilesOverTime)
    n_heights = profiles.heights.size
    columns = min(n_heights, 4)
    rows = math.ceil(n_heights / columns)
    figure, axes_grid = plt.subplots(rows, columns, figsize=(3.4 * columns, 3.0 * rows + 0.5), squeeze=False,
                                     sharex=True, sharey=True, layout="constrained")
    try:
        for axes in axes_grid.flat[n_heights:]:
            axes.set_visible(False)
        for h, axes in enumerate(axes_grid.flat[:n_heights]):
            axes.axhline(1.0, color="0.5", linestyle=":", linewidth=0.9)
            for w, time in enumerate(profiles.window_time):
                axes.plot(MM * profiles.x, profiles.normalised[w, h], "-", linewidth=1.2, label=f"t = {time:.3g} s")
            axes.set_title(f"z = {MM * profiles.heights[h]:.0f} mm", fontsize=9)
            axes.grid(alpha=0.3)
        for axes in axes_grid[-1, :]:
            axes.set_xlabel("x [mm]")
        for axes in axes_grid[:, 0]:
            axes.set_ylabel("v_z / cross-section mean [-]")
        axes_grid.flat[0].legend(fontsize=7)
        figure.suptitle(title)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def _passage_findings(findings, outlet: PassageVelocities) -> list:
    """Checked findings of :func:`plot_passage_distributions`: notes, or dimensionless values of outlet passages."""
    checked = study_findings(findings, StudyValue, StudyNote)
    for i, item in enumerate(checked):
        if isinstance(item, StudyValue) and (item.unit not in ("", "-") or item.series not in outlet.passages):
            raise ValueError(f"findings[{i}] ({item.id}) must be a velocity over the cross-section mean (unit '-') "
                             f"of an outlet passage ({', '.join(outlet.passages)}) as its series, got unit "
                             f"{item.unit!r} and series {item.series!r}")
    return checked


def _passage_entry(name: str, panels) -> str:
    """The legend entry of a passage: its mean at the inlet and outlet (n/a where it has none or no bin) [m/s]."""
    means = [result.mean_v_z.get(name, math.nan) for _, result in panels]
    shown = ", ".join(f"{where.split()[-1]} {mean:.3g}" if math.isfinite(mean) else f"{where.split()[-1]} n/a"
                      for (where, _), mean in zip(panels, means))
    return f"{name}: {shown} m/s"


def plot_passage_distributions(inlet: PassageVelocities, outlet: PassageVelocities, path: str | os.PathLike,
                               title: str, findings: Sequence[StudyValue | StudyNote] | None = None) -> Path:
    """Vertical velocity across the width at the insert inlet (left) and outlet (right), passage means marked, in
    the project's style (:func:`siloflow.analysis.io.plot_style.journal_style`).

    The profile is drawn in grey (``gid="profile"``); each passage has one colour of
    :data:`~siloflow.analysis.io.plot_style.PALETTE` in both panels (tube, interior, exterior annulus always the
    same), is shaded on both sides of the axis and its mean velocity drawn as a horizontal segment over it
    (``gid="passage_mean"``; a passage without bins has no segment). One legend for both panels stands right of
    the outlet panel: the profile, each passage with its inlet and outlet means, then the findings.

    Parameters
    ----------
    inlet, outlet : siloflow.analysis.studies.blender.profiles.PassageVelocities
        Profiles and passage means at the two heights.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    findings : sequence of StudyValue or StudyNote, optional
        The study's findings at the insert outlet, drawn on the outlet panel. A
        :class:`~siloflow.analysis.io.plot_style.StudyValue` is a passage's velocity over the outlet's
        cross-section mean (unit ``"-"``, its ``series`` the passage, e.g. M1's ``StudyValue("M1", 0.16,
        series="exterior")``): a dotted segment at that fraction of the mean [m/s] over the passage (its band
        shaded, if given), in the passage's colour, ``gid="finding <id>"``, legend ``study (M1): exterior ~0.16 of
        mean`` (none where the mean is not finite). A :class:`~siloflow.analysis.io.plot_style.StudyNote` is a
        legend entry, e.g. M2's expected order ``study_note(PARTS["M2.outlet_order"])`` (:mod:`siloflow.analysis.studies.validation.figure_findings`). None (the default):
        none.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        For an inlet or outlet that is no PassageVelocities, a finding that is neither a study value nor a note,
        or a study value not dimensionless or of no outlet passage.
    """
    panels = [("insert inlet", _instance("inlet", inlet, PassageVelocities)),
              ("insert outlet", _instance("outlet", outlet, PassageVelocities))]
    checked = _passage_findings(findings, outlet)
    names = list(dict.fromkeys([*inlet.passages, *outlet.passages]))
    # the study's passages first, so that each keeps its colour whichever a configuration has
    colours = colour_of([*_PASSAGES, *names])
    with journal_style():
        figure, axes_pair = plt.subplots(1, 2, figsize=(PAGE_WIDTH, 3.0), sharey=True)
        try:
            # room on the right for the one legend of both panels, so that the figure keeps the page's width
            figure.subplots_adjust(left=0.09, right=0.62, bottom=0.15, top=0.84, wspace=0.08)
            for axes, (where, result) in zip(axes_pair, panels):
                profile = result.profile
                axes.plot(MM * profile.x, profile.v_z, "o-", color=REFERENCE_COLOUR, markersize=2.5, linewidth=1.0,
                          label="v_z", gid="profile")
                for name, (lo, hi) in result.passages.items():
                    for sign in (-1.0, 1.0):
                        axes.axvspan(sign * MM * lo, sign * MM * hi, color=colours[name], alpha=BAND_ALPHA,
                                     linewidth=0.0)
                    mean = result.mean_v_z[name]
                    if math.isfinite(mean):
                        for sign, label in ((1.0, f"{name}: {mean:.3g} m/s"), (-1.0, "_nolegend_")):
                            axes.plot([sign * MM * lo, sign * MM * hi], [mean, mean], "-", color=colours[name],
                                      linewidth=2.5, label=label, gid="passage_mean")
                axes.axhline(0.0, color="black", linewidth=0.6)
                axes.set_title(f"{where}, z = {MM * profile.z:.0f} mm")
                axes.set_xlabel("x [mm]")
                axes.grid(alpha=0.3)
            axes_pair[0].set_ylabel("v_z [m/s]")
            handles = [Line2D([], [], marker="o", markersize=2.5, linewidth=1.0, color=REFERENCE_COLOUR,
                              label="v_z profile")]
            handles += [Line2D([], [], linewidth=2.5, color=colours[name], label=_passage_entry(name, panels))
                        for name in names]
            handles += [_draw_passage_finding(axes_pair[1], item, outlet, colours) for item in checked]
            legend_outside(axes_pair[1], handles=[handle for handle in handles if handle is not None])
            figure.suptitle(title)
            return save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)


def _draw_passage_finding(axes, item, outlet: PassageVelocities, colours: Mapping):
    """Draw one finding of :func:`plot_passage_distributions` on the outlet panel; its legend handle (None: not
    drawn, the outlet's cross-section mean being unknown)."""
    if isinstance(item, StudyNote):
        return note_study(axes, item)
    mean = outlet.profile.cross_section_mean
    if not math.isfinite(mean):
        return None
    lo, hi = outlet.passages[item.series]
    return draw_study_value(axes, item, colour=colours[item.series], convert=lambda ratio: ratio * mean,
                            spans=[(MM * lo, MM * hi), (-MM * hi, -MM * lo)], label=f"{item.label} of mean")[-1]


def plot_channel_boundary(field: BlenderField, boundary: ChannelBoundary, path: str | os.PathLike, title: str) -> Path:
    """Speed ``|v_z|`` over the (x, z) field with the flow channel boundary and the inner wall.

    Parameters
    ----------
    field : siloflow.analysis.studies.blender.steady_field.BlenderField
        The steady field (bins without particles are left blank).
    boundary : siloflow.analysis.studies.blender.profiles.ChannelBoundary
        Boundary per row (:func:`siloflow.analysis.studies.blender.profiles.flow_channel_boundary_over_height` of ``field``).
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
        On wrong types or a boundary whose rows are not those of the field.
    """
    field = _instance("field", field, BlenderField)
    boundary = _instance("boundary", boundary, ChannelBoundary)
    if boundary.z.shape != field.z.shape or np.any(boundary.z != field.z):
        raise ValueError("boundary must have the rows (z) of field")
    speed = np.ma.masked_invalid(np.abs(field.v_z))
    figure, axes = plt.subplots(figsize=(5.5, 6.0))
    try:
        mesh = axes.pcolormesh(MM * field.x, MM * field.z, speed.T, shading="nearest", cmap="viridis")
        figure.colorbar(mesh, ax=axes, label="|v_z| [m/s]")
        axes.plot(MM * boundary.left, MM * boundary.z, "-", color="tab:red", linewidth=1.5,
                  label=f"flow channel boundary ({100 * boundary.fraction:g} %)")
        axes.plot(MM * boundary.right, MM * boundary.z, "-", color="tab:red", linewidth=1.5)
        axes.plot(-MM * boundary.wall_x, MM * boundary.z, "--", color="white", linewidth=1.0, label="inner wall")
        axes.plot(MM * boundary.wall_x, MM * boundary.z, "--", color="white", linewidth=1.0)
        axes.set_aspect("equal")
        axes.set_xlabel("x [mm]")
        axes.set_ylabel("z [mm]")
        axes.set_title(title)
        axes.legend(loc="upper center", fontsize=7)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


# --------------------------------------------------------------------------- tracers and RTD


def plot_tracer_pathlines(pathlines: TracerPathlines, path: str | os.PathLike, title: str) -> Path:
    """Pathlines of the virtual tracers in the x-z plane (left) and their residence time across the width (right).

    Tracers that did not exit are drawn dotted on the left and left out on the right (counted in the
    legend).

    Parameters
    ----------
    pathlines : siloflow.analysis.studies.blender.tracers.TracerPathlines
        Released tracers and their paths.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    pathlines = _instance("pathlines", pathlines, TracerPathlines)
    exited = np.isfinite(pathlines.residence_time)
    figure, (left, right) = plt.subplots(1, 2, figsize=(10.0, 5.0))
    try:
        for points, out in zip(pathlines.paths, exited):
            left.plot(MM * points[:, 0], MM * points[:, 1], "-" if out else ":", color="tab:blue", linewidth=1.0)
        left.axhline(0.0, color="black", linewidth=1.0)
        left.set_aspect("equal")
        left.set_xlabel("x [mm]")
        left.set_ylabel("z [mm]")
        left.set_title(f"released at z = {MM * pathlines.release_z:.0f} mm", fontsize=9)
        label = "residence time" + (f" ({pathlines.n_not_exited} not out)" if pathlines.n_not_exited else "")
        right.plot(MM * pathlines.release_x[exited], pathlines.residence_time[exited], "o-", markersize=4,
                   linewidth=1.2, label=label)
        right.set_xlabel("release x [mm]")
        right.set_ylabel("residence time [s]")
        right.set_ylim(bottom=0.0)
        right.grid(alpha=0.3)
        right.legend(fontsize=8)
        figure.suptitle(title)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


def plot_rtd_theta(rtds: Mapping, path: str | os.PathLike, title: str) -> Path:
    """RTDs of several configurations as ``E(theta)`` against ``theta = t / t_m`` on one axes.

    Drawn by :func:`siloflow.analysis.studies.silo_recirculation.rtd_plots.plot_rtd_comparison`.

    Parameters
    ----------
    rtds : mapping label -> RTD or VirtualTracerRTD
        One RTD per configuration.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    if isinstance(rtds, Mapping):
        rtds = {label: value.rtd if isinstance(value, VirtualTracerRTD) else value for label, value in rtds.items()}
    curves = [(label, rtd.time, rtd.E, rtd.t_mean) for label, rtd in _labelled("rtds", rtds, RTD)]
    return plot_rtd_comparison(curves, path, title, dimensionless=True)


def plot_discontinuous_mode(result: DiscontinuousMode, path: str | os.PathLike, title: str) -> Path:
    """Outlet tracer concentration of the two-layer fill over the passes, with the homogenisation band.

    Drawn by :func:`siloflow.analysis.studies.silo_recirculation.rtd_plots.plot_recirculation_model` (the tracer is the
    "blue" batch).

    Parameters
    ----------
    result : siloflow.analysis.studies.blender.modes.DiscontinuousMode
        The recirculated two-layer fill.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    result = _instance("result", result, DiscontinuousMode)
    return plot_recirculation_model(result.time_in_passes, result.concentration, result.tracer_fraction,
                                    result.homogenised_after, path, title, tolerance=result.tolerance)


def plot_continuous_mode(results: Mapping, path: str | os.PathLike, title: str) -> Path:
    """VRR (left, log-log) and outlet CoV (right, log x) of sine inputs against the period over ``t_m``.

    Non-finite or non-positive VRRs are skipped on the log axes (a fully damped period has VRR inf);
    resonant periods (local minima of the VRR) are ringed.

    Parameters
    ----------
    results : mapping label -> siloflow.analysis.studies.blender.modes.ContinuousMode
        One result per configuration.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    checked = _labelled("results", results, ContinuousMode)
    figure, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.2))
    try:
        left.set_xscale("log")
        left.set_yscale("log")
        right.set_xscale("log")
        left.axhline(1.0, color="black", linewidth=0.9, label="VRR = 1 (no blending)")
        for label, result in checked:
            x, y = positive_finite_points(result.period_over_tm, result.vrr)
            (line,) = left.plot(x, y, "o-", markersize=4, linewidth=1.2, label=label)
            resonant = np.isin(result.period_over_tm, result.resonant_periods_over_tm)
            left.plot(result.period_over_tm[resonant], result.vrr[resonant], "o", markersize=10, fillstyle="none",
                      color=line.get_color())
            keep = np.isfinite(result.cov_out)
            right.plot(result.period_over_tm[keep], result.cov_out[keep], "o-", markersize=4, linewidth=1.2,
                       color=line.get_color(), label=label)
        left.set_xlabel("input period / mean residence time, T / t_m [-]")
        left.set_ylabel("variance reduction ratio VRR [-]")
        left.grid(alpha=0.3, which="both")
        left.legend(fontsize=8)
        right.set_xlabel("input period / mean residence time, T / t_m [-]")
        right.set_ylabel("outlet coefficient of variation [-]")
        right.set_ylim(bottom=0.0)
        right.grid(alpha=0.3, which="both")
        figure.suptitle(title)
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)


# --------------------------------------------------------------------------- gravity and comparison


def plot_gravity_scaling(runs: Sequence, path: str | os.PathLike, title: str,
                         quantity: str = "mean velocity", findings: Sequence[StudyNote] | None = None) -> Path:
    """Runs at several gravity factors on the 1 g scale: ``v / sqrt(f)`` against ``t sqrt(f)``, in the project's
    style (:func:`siloflow.analysis.io.plot_style.journal_style`).

    One colour per configuration (the run's label) and one line style per gravity factor (``gid="run"``); the
    legend stands right of the axes. Where the velocity scales with the square root of gravity, the runs of a
    configuration lie on one curve.

    Parameters
    ----------
    runs : list of (str, float, array_like, array_like)
        ``(label, gravity_factor, time, velocity)``: factor ``g_run / g`` (> 0), times [s] (finite) and a
        velocity [m/s] of the same length (NaN is a gap).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    quantity : str, optional
        What the velocity is, for the axis label.
    findings : sequence of StudyNote, optional
        The study's finding on the scaling, e.g. M4's ``StudyNote("M4", "v scales with sqrt(g)")``: the curve the
        runs of a configuration lie on under that scaling, that of its run of the lowest gravity factor (the first
        of them), is drawn once under the runs as a wide light grey line (``gid="finding <id>"``), one legend entry
        for all configurations, the notes' labels (``study (M4): v scales with sqrt(g)``). None (the default):
        none.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the run: no run, a gravity factor not > 0, non-finite times or a velocity not of their shape; a
        finding that is not a StudyNote; more configurations than the palette's 8 colours.
    """
    checked = []
    for i, item in enumerate(non_empty_list("runs", runs)):
        label, factor, time, velocity = tuple_entry("runs", i, item, 4)
        factor = positive_number(f"runs[{i}] gravity_factor", factor)
        time = finite_array(f"runs[{i}] time", time)
        velocity = np.asarray(velocity, dtype=float)
        if velocity.shape != time.shape:
            raise ValueError(f"runs[{i}] velocity must have the shape of time {time.shape}, got {velocity.shape}")
        checked.append((str(label), factor, gravity_normalised_time(time, factor),
                        gravity_normalised_velocity(velocity, factor)))
    notes = study_findings(findings, StudyNote)
    configurations = list(dict.fromkeys(label for label, _, _, _ in checked))
    colours = colour_of(configurations)
    factors = sorted({factor for _, factor, _, _ in checked})
    styles = {factor: LINE_STYLES[k % len(LINE_STYLES)] for k, factor in enumerate(factors)}
    with journal_style():
        figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 3.4))
        try:
            figure.subplots_adjust(left=0.1, right=0.62, bottom=0.14, top=0.9)
            if notes:
                # drawn first, under the runs, which are read against it: each configuration's lowest factor, the
                # legend entry once
                for k, configuration in enumerate(configurations):
                    _, _, time, velocity = min((run for run in checked if run[0] == configuration),
                                               key=lambda run: run[1])
                    axes.plot(time, velocity, "-", color="0.75", linewidth=5.0, solid_capstyle="round",
                              label="; ".join(note.label for note in notes) if k == 0 else "_nolegend_",
                              gid=f"finding {notes[0].id}")
            for label, factor, time, velocity in checked:
                axes.plot(time, velocity, styles[factor], color=colours[label], label=f"{label} ({factor:g} g)",
                          gid="run")
            axes.set_xlabel("t sqrt(g_run / g) [s]")
            axes.set_ylabel(f"{quantity} / sqrt(g_run / g) [m/s]")
            axes.set_title(title)
            axes.grid(alpha=0.3)
            legend_outside(axes)
            return save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)


def plot_configuration_comparison(rows: Sequence, columns: Sequence, path: str | os.PathLike, title: str,
                                  best: str | None = None) -> Path:
    """Bar charts of chosen metrics, one panel per metric and one bar per configuration.

    Parameters
    ----------
    rows : list of dict
        :func:`siloflow.analysis.studies.blender.comparison.comparison_table` rows (key ``"configuration"`` and the metrics).
    columns : sequence of str
        Metric columns to draw, each a key of every row; NaN values leave the bar out. A column whose rows carry
        ``<column>_error`` gets error bars of one standard error (none where the error is NaN or missing).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    best : str, optional
        Configuration to outline in black (e.g. :func:`siloflow.analysis.studies.blender.comparison.best_blender`); it must be one of
        the rows.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    rows = non_empty_list("rows", rows)
    columns = [str(column) for column in non_empty_list("columns", columns)]
    names = []
    for i, row in enumerate(rows):
        if not isinstance(row, Mapping) or "configuration" not in row:
            raise ValueError(f"rows[{i}] must be a dict with a 'configuration' key")
        missing = [column for column in columns if column not in row]
        if missing:
            raise ValueError(f"rows[{i}] has no column {missing[0]!r}")
        names.append(str(row["configuration"]))
    if best is not None and best not in names:
        raise ValueError(f"best must be one of the configurations {names}, got {best!r}")
    values = np.array([[float(row[column]) for column in columns] for row in rows])
    errors = np.array([[number_or_nan(row.get(f"{column}_error")) for column in columns] for row in rows])
    panels = len(columns)
    figure, axes_row = plt.subplots(1, panels, figsize=(2.6 * panels + 1.0, 3.8), squeeze=False)
    try:
        positions = np.arange(len(names))
        for c, (axes, column) in enumerate(zip(axes_row[0], columns)):
            bars = axes.bar(positions, np.nan_to_num(values[:, c], nan=0.0, posinf=0.0, neginf=0.0),
                            color=[f"C{i}" for i in range(len(names))])
            shown = np.isfinite(values[:, c]) & np.isfinite(errors[:, c])
            if np.any(shown):
                axes.errorbar(positions[shown], values[shown, c], yerr=errors[shown, c], fmt="none", ecolor="black",
                              elinewidth=1.0, capsize=3.0)
            for bar, name, value in zip(bars, names, values[:, c]):
                if not math.isfinite(value):
                    bar.set_visible(False)
                    axes.text(bar.get_x() + 0.5 * bar.get_width(), 0.0, "n/a", ha="center", va="bottom", fontsize=8)
                if name == best:
                    bar.set_edgecolor("black")
                    bar.set_linewidth(2.0)
            axes.set_xticks(positions, names, rotation=30, ha="right", fontsize=8)
            axes.set_title(column, fontsize=8)
            axes.axhline(0.0, color="black", linewidth=0.6)
            axes.grid(alpha=0.3, axis="y")
        figure.suptitle(title if best is None else f"{title} (best: {best})")
        figure.tight_layout()
        return save_figure(figure, path, tight=True)
    finally:
        plt.close(figure)
