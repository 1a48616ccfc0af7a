"""Calibration charts and polar diagnostics (PNG, PDF or SVG; no display needed).

Every writer draws a figure and saves it atomically in the format of its file name (via
:func:`siloflow.analysis.io.plots.save_figure`): a reader never sees a half-written plot
and a failed write leaves no temporary file behind. It returns that figure,
already closed (let go by pyplot, so a caller that ignores it leaks nothing):
its artists still hold the plotted data, which is what the tests check.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import matplotlib.pyplot as plt
from matplotlib.figure import Figure
import numpy as np

from siloflow.analysis.io.plot_style import (
    LINE_STYLES,
    MARKERS,
    PAGE_WIDTH,
    REFERENCE_COLOUR,
    StudyNote,
    StudyValue,
    colour_of,
    draw_reference_band,
    draw_reference_value,
    draw_study_value,
    journal_style,
    legend_outside,
    note_study,
    study_findings,
)
from siloflow.analysis.io.plots import save_figure
from siloflow.calibration.inversion import CalibrationCurve

__all__ = ["plot_calibration_chart", "plot_polar_histogram"]

_X_LABELS = {
    "internal": "particle-particle sliding friction coefficient [-]",
    "wall": "particle-wall sliding friction coefficient [-]",
}
#: The study's particle shapes, in the order that gives each its colour of the palette: a shape keeps its colour in
#: every chart, whichever shapes a chart holds.
_SHAPES = ("sphere", "sphere2", "sphere4")
#: The units a finding drawn on the chart may be stated in: a bulk friction coefficient (drawn at its angle) or a
#: bulk friction angle.
_FINDING_UNITS = ("-", "deg")


def _curve_label(curve: CalibrationCurve, several_shapes: bool, several_materials: bool) -> str:
    parts = []
    if several_shapes:
        parts.append(curve.shape)
    if several_materials and curve.wall_material:
        parts.append(curve.wall_material)
    parts.append(f"mu_r = {curve.rolling_friction:g}")
    return ", ".join(parts)


def _friction_angle_deg(coefficient: float) -> float:
    """The bulk friction angle atan(mu) [deg] of a bulk friction coefficient mu [-]."""
    return math.degrees(math.atan(coefficient))


def _chart_findings(findings) -> list:
    """Checked findings of :func:`plot_calibration_chart`: study values in a unit the chart draws, or notes."""
    checked = study_findings(findings, StudyValue, StudyNote)
    for i, item in enumerate(checked):
        if isinstance(item, StudyValue) and item.unit not in _FINDING_UNITS:
            raise ValueError(f"findings[{i}] ({item.id}) must be a bulk friction coefficient (unit '-') or angle "
                             f"(unit 'deg'), got unit {item.unit!r}")
    return checked


def plot_calibration_chart(
    curves: list[CalibrationCurve],
    path: str | os.PathLike,
    title: str,
    target_angle_deg: float | None = None,
    tolerance_deg: float | None = None,
    findings: Sequence[StudyValue | StudyNote] | None = None,
) -> Figure:
    """Plot a calibration chart: bulk friction against particle sliding friction, in the project's style
    (:func:`siloflow.analysis.io.plot_style.journal_style`).

    One line with markers per curve (normally one per rolling friction, legend
    "mu_r = 0.1"; the shape and wall material are added to the label when the
    curves differ in them): one colour per shape (sphere, two-sphere and four-sphere
    clump always in the same colours of :data:`~siloflow.analysis.io.plot_style.PALETTE`),
    one line style and marker per rolling friction and wall material. The left axis is
    the bulk friction angle ``atan(mu_bulk)`` [deg]; the right axis shows the same scale
    as the bulk friction coefficient ``tan(angle)`` [-]. Error bars show
    ``bulk_standard_error`` converted to degrees (``se / (1 + mu^2)`` rad) where
    it is given. A measured target is drawn once as a dashed grey line (``gid="target"``)
    with a shaded band ``target +- tolerance``. Each finding is drawn beside the curves,
    labelled with its id; the legend stands right of the right axis, outside the data.

    Parameters
    ----------
    curves : list of siloflow.calibration.inversion.CalibrationCurve
        Curves to draw (at least one).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    target_angle_deg : float, optional
        Measured bulk friction angle [deg]; None to omit it.
    tolerance_deg : float, optional
        Its uncertainty [deg]; None (or 0) draws the line without a band.
    findings : sequence of StudyValue or StudyNote, optional
        The study's findings to draw beside the curves (the caller picks those of the chart's test and shapes).
        A :class:`~siloflow.analysis.io.plot_style.StudyValue` is a bulk friction coefficient (unit ``"-"``, e.g.
        the plateau of C2, ``StudyValue("C2", 0.54, series="sphere2")``, or C3) or angle (unit ``"deg"``, e.g. C7's
        measured ~30 deg), drawn as a dotted line across the chart at its angle [deg] with its band (if given)
        shaded, in the colour of its ``series`` (a shape) or grey, with ``gid="finding <id>"`` and the legend
        entry ``study (C2): sphere2 ~0.54``. A :class:`~siloflow.analysis.io.plot_style.StudyNote` is a legend
        entry. None (the default): none.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn, already closed (see the module docstring).

    Raises
    ------
    ValueError
        For no curve, a non-finite target, a negative or non-finite tolerance, a finding that is neither a study
        value nor a note, or a study value in another unit than ``"-"`` or ``"deg"``.
    """
    curves = list(curves)
    if not curves:
        raise ValueError("curves must contain at least one CalibrationCurve")
    if target_angle_deg is not None and not math.isfinite(float(target_angle_deg)):
        raise ValueError(f"target_angle_deg must be finite, got {target_angle_deg!r}")
    if tolerance_deg is not None and not (math.isfinite(float(tolerance_deg)) and float(tolerance_deg) >= 0.0):
        raise ValueError(f"tolerance_deg must be a finite number >= 0, got {tolerance_deg!r}")
    checked_findings = _chart_findings(findings)

    ordered = sorted(curves, key=lambda c: (c.shape, c.wall_material or "", c.rolling_friction))
    several_shapes = len({c.shape for c in ordered}) > 1
    several_materials = len({c.wall_material for c in ordered}) > 1
    tests = {c.test for c in ordered}
    colours = colour_of(list(_SHAPES) + [c.shape for c in ordered] +
                        [item.series for item in checked_findings if getattr(item, "series", None)])
    variants = list(dict.fromkeys((c.wall_material or "", c.rolling_friction) for c in ordered))
    styles = {variant: (LINE_STYLES[k % len(LINE_STYLES)], MARKERS[k % len(MARKERS)])
              for k, variant in enumerate(variants)}

    with journal_style():
        figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 3.6))
        try:
            # room on the right for the coefficient axis and the legend, so that the figure keeps the page's width
            figure.subplots_adjust(left=0.1, right=0.58, bottom=0.13, top=0.91)
            # the legend lists the curves first, then the target and the findings they are read against
            handles = []
            for curve in ordered:
                line_style, marker = styles[(curve.wall_material or "", curve.rolling_friction)]
                handles.append(axes.errorbar(
                    curve.particle_friction,
                    curve.bulk_angle_deg,
                    yerr=curve.bulk_angle_standard_error_deg,
                    color=colours[curve.shape],
                    linestyle=line_style,
                    marker=marker,
                    capsize=2,
                    label=_curve_label(curve, several_shapes, several_materials),
                ))
            if target_angle_deg is not None:
                target = float(target_angle_deg)
                if tolerance_deg:
                    tolerance = float(tolerance_deg)
                    handles.append(draw_reference_band(axes, target - tolerance, target + tolerance,
                                                       f"target {target:g} ± {tolerance:g} deg", gid="target"))
                    draw_reference_value(axes, target, linestyle="--", gid="target")
                else:
                    handles.append(draw_reference_value(axes, target, f"target {target:g} deg", linestyle="--",
                                                        gid="target"))
            for item in checked_findings:
                if isinstance(item, StudyNote):
                    handles.append(note_study(axes, item))
                else:
                    # the line carries the legend entry; a band drawn with it is named by it
                    handles.append(draw_study_value(axes, item, colour=colours.get(item.series, REFERENCE_COLOUR),
                                                    convert=_friction_angle_deg if item.unit == "-" else float)[-1])

            axes.set_xlabel(_X_LABELS[tests.pop()] if len(tests) == 1 else "particle sliding friction coefficient [-]")
            axes.set_ylabel("bulk friction angle [deg]")
            secondary = axes.secondary_yaxis(
                "right",
                functions=(
                    lambda degrees: np.tan(np.radians(np.clip(degrees, -89.0, 89.0))),
                    lambda coefficient: np.degrees(np.arctan(coefficient)),
                ),
            )
            secondary.set_ylabel("bulk friction coefficient [-]")
            axes.set_title(title)
            axes.grid(True, alpha=0.3)
            legend_outside(axes, clear_of=[secondary], handles=handles)
            save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)
    return figure


def plot_polar_histogram(edges_rad, counts, path: str | os.PathLike, title: str) -> Figure:
    """Plot an angular histogram as a polar bar chart (a rose diagram).

    Parameters
    ----------
    edges_rad : array_like, shape (m + 1,)
        Sector edges [rad], increasing, e.g. from
        :func:`siloflow.calibration.friction.angular_histogram` (0 is drawn to the
        right, angles increase counter-clockwise).
    counts : array_like, shape (m,)
        Count (or weight) per sector, >= 0.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn, already closed (see the module docstring).
    """
    edges = np.asarray(edges_rad, dtype=float)
    counts = np.asarray(counts, dtype=float)
    if edges.ndim != 1 or edges.size < 2 or not np.all(np.isfinite(edges)) or np.any(np.diff(edges) <= 0.0):
        raise ValueError("edges_rad must be a 1-D array of at least 2 strictly increasing finite angles")
    if counts.shape != (edges.size - 1,):
        raise ValueError(f"counts must have shape ({edges.size - 1},) (one per sector), got {counts.shape}")
    if not np.all(np.isfinite(counts)) or np.any(counts < 0.0):
        raise ValueError("counts must be finite and >= 0")

    figure = plt.figure(figsize=(5.2, 5.2))
    try:
        axes = figure.add_subplot(projection="polar")
        axes.bar(
            edges[:-1],
            counts,
            width=np.diff(edges),
            align="edge",
            color="tab:blue",
            edgecolor="white",
            linewidth=0.5,
            alpha=0.85,
        )
        axes.set_title(title)
        figure.tight_layout()
        save_figure(figure, path)
    finally:
        plt.close(figure)
    return figure


def plot_force_history(signals, friction, path: str | os.PathLike, title: str) -> Figure:
    """Shear force histories of one shear test with the averaging window and the bulk friction.

    Parameters
    ----------
    signals : siloflow.calibration.shear.ShearSignals or any object with ``time``, ``lid_force``, ``ring_force``,
        ``bottom_force``, ``normal_force``, ``weight_above``
        Force histories of the shear stage (s, N).
    friction : siloflow.calibration.friction.BulkFriction
        The bulk friction and its window.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    """
    time = np.asarray(signals.time, dtype=float)
    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    try:
        axes.plot(time, signals.lid_force + signals.ring_force, label="lid + shear ring", color="tab:blue")
        axes.plot(time, signals.bottom_force, label="bottom ring / plate", color="tab:orange", alpha=0.8)
        axes.plot(time, np.broadcast_to(signals.normal_force + signals.weight_above, time.shape),
                  label="normal force + weight above", color="0.4", linestyle="--")
        window = friction.window
        axes.axvspan(window.t_start, window.t_end, color="tab:blue", alpha=0.08, label="averaging window")
        axes.set_xlabel("time [s]")
        axes.set_ylabel("force [N]")
        axes.set_title(title)
        axes.text(0.02, 0.97,
                  f"mu_bulk = {friction.coefficient:.3f} +- {friction.standard_error:.3f} "
                  f"({friction.angle_deg:.1f} deg)\nbottom side: {friction.bottom_coefficient:.3f}",
                  transform=axes.transAxes, va="top", fontsize=9)
        axes.legend(loc="lower right", fontsize=8)
        axes.grid(alpha=0.3)
        save_figure(figure, path)
    finally:
        plt.close(figure)
    return figure


def plot_lid_comparison(rows: list[dict], path: str | os.PathLike, title: str) -> Figure:
    """Bulk friction against particle friction with the rigid and the servo lid (rows of
    :func:`siloflow.calibration.sweep.lid_comparison`)."""
    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    try:
        groups: dict[tuple, list[dict]] = {}
        for row in rows:
            groups.setdefault((row["shape"], row["rolling_friction"]), []).append(row)
        for (shape, rolling), group in sorted(groups.items()):
            particle = [row["particle_friction"] for row in group]
            axes.plot(particle, [row["bulk_friction_rigid_lid"] for row in group], "o-",
                      label=f"{shape}, mu_r = {rolling:g}: rigid lid")
            axes.plot(particle, [row["bulk_friction_servo_lid"] for row in group], "s--",
                      label=f"{shape}, mu_r = {rolling:g}: servo lid")
        axes.set_xlabel("particle-particle sliding friction coefficient [-]")
        axes.set_ylabel("bulk friction coefficient [-]")
        axes.set_title(title)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        save_figure(figure, path)
    finally:
        plt.close(figure)
    return figure
