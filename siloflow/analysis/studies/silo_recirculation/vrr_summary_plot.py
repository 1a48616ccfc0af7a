"""The VRR of every flow pattern and batch layout of the blending study in one figure, in the project's journal style
(:mod:`siloflow.analysis.io.plot_style`): one colour per flow pattern, one line style per layout, the seeds of one flow
pattern and layout as their mean with a band of one standard error of the mean, the counting-noise ceiling drawn
once, the legend outside the data; optionally the study's findings beside them. Pure: arrays in, a figure out
(:func:`siloflow.analysis.io.plots.save_figure`).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from siloflow.model.checks import positive_number
from siloflow.analysis.io.plots import finite_abscissa, non_empty_list, save_figure
from siloflow.analysis.io.plot_style import LINE_STYLES, MARKERS, PAGE_WIDTH, colour_of, journal_style, legend_outside

__all__ = ["plot_vrr_summary", "vrr_replicate_curves"]


def _positive_finite_or_nan(values: np.ndarray) -> np.ndarray:
    """``values`` with every entry that is NaN, infinite or <= 0 set to NaN (what a log axis or a mean cannot
    take)."""
    return np.where(np.isfinite(values) & (values > 0.0), values, np.nan)


def vrr_replicate_curves(rows: Sequence[Mapping], curves: Sequence) -> list[dict]:
    """The VRR curves of :func:`siloflow.analysis.studies.silo_recirculation.tables.summary_rows` grouped into
    replicates per flow pattern and layout, for :func:`plot_vrr_summary`.

    Parameters
    ----------
    rows : sequence of mapping
        The rows of ``summary_rows``, one per run and layout, before replicates are combined: each has
        ``flow_pattern`` and ``layout``, and where the run discharged after its recirculations
        ``final_discharge_recirculations`` (its Nr [-]) and ``final_discharge_vrr`` [-] (NaN or absent: none).
    curves : sequence of tuple
        The curves of ``summary_rows``, in the same order as ``rows``: ``(label, Nr, VRR, ceiling, VRR error)``
        with Nr the number of recirculations at mid-window [-], the VRR [-] and the run's counting-noise ceiling
        [-] (None: none); label and errors are not used (the spread of the seeds replaces the errors).

    Returns
    -------
    list of dict
        One per (flow pattern, layout), in the order of first appearance: ``{"flow_pattern", "layout",
        "recirculations", "vrr", "ceiling", "discharge"}`` with ``vrr`` of shape (n_seeds, n_points), one row per run
        (seed) in the order of ``rows``, on the Nr grid of the first run, ``ceiling`` the lowest ceiling of the runs
        (None if none has one) and ``discharge`` the discharge after the recirculations of the seeds that have one,
        ``{"recirculations": array (n,), "vrr": array (n,)}`` (None when no seed has one).

    Raises
    ------
    ValueError
        When ``rows`` and ``curves`` differ in length, or a row lacks ``flow_pattern`` or ``layout``.
    """
    rows, curves = list(rows), list(curves)
    if len(rows) != len(curves):
        raise ValueError(f"rows and curves must be of the same length (one curve per row), got {len(rows)} and "
                         f"{len(curves)}")
    groups: dict[tuple[str, str], dict] = {}
    for i, (row, curve) in enumerate(zip(rows, curves)):
        if "flow_pattern" not in row or "layout" not in row:
            raise ValueError(f"rows[{i}] must have the keys flow_pattern and layout")
        _, recirculations, vrr, ceiling = tuple(curve)[:4]
        recirculations = np.asarray(recirculations, dtype=float)
        vrr = np.asarray(vrr, dtype=float)
        key = (str(row["flow_pattern"]), str(row["layout"]))
        group = groups.setdefault(key, {"flow_pattern": key[0], "layout": key[1], "recirculations": recirculations,
                                        "vrr": [], "ceiling": None, "discharge_nr": [], "discharge_vrr": []})
        discharge_nr = float(row.get("final_discharge_recirculations", math.nan))
        discharge_vrr = float(row.get("final_discharge_vrr", math.nan))
        if math.isfinite(discharge_nr) and math.isfinite(discharge_vrr):
            group["discharge_nr"].append(discharge_nr)
            group["discharge_vrr"].append(discharge_vrr)
        grid = group["recirculations"]
        if recirculations.shape != grid.shape or not np.array_equal(recirculations, grid):
            # Seeds run for different lengths (or with other windows) have other Nr grids: put this seed's VRR on
            # the first seed's grid, interpolating log VRR (the VRR grows about exponentially with Nr, so log VRR is
            # near linear between windows); outside this seed's own Nr range it has no value (NaN), and a VRR that a
            # log cannot take (NaN, inf, <= 0) is left out of the interpolation.
            usable = np.isfinite(recirculations) & np.isfinite(_positive_finite_or_nan(vrr))
            order = np.argsort(recirculations[usable])
            known_nr, known_vrr = recirculations[usable][order], vrr[usable][order]
            vrr = (np.exp(np.interp(grid, known_nr, np.log(known_vrr), left=np.nan, right=np.nan))
                   if known_nr.size else np.full(grid.shape, np.nan))
        group["vrr"].append(vrr)
        if ceiling is not None and math.isfinite(float(ceiling)):
            group["ceiling"] = float(ceiling) if group["ceiling"] is None else min(group["ceiling"], float(ceiling))
    return [{**{key: value for key, value in group.items() if not key.startswith("discharge_")},
             "vrr": np.vstack(group["vrr"]),
             "discharge": {"recirculations": np.array(group["discharge_nr"]), "vrr": np.array(group["discharge_vrr"])}
             if group["discharge_nr"] else None}
            for group in groups.values()]


def _replicate_curves(curves) -> list[dict]:
    """Checked curves of :func:`plot_vrr_summary`: Nr finite, VRR of shape (n_seeds, n_points), ceiling > 0 or None,
    one curve per (flow pattern, layout)."""
    checked, seen = [], set()
    for i, item in enumerate(non_empty_list("curves", curves)):
        if not isinstance(item, Mapping):
            raise ValueError(f"curves[{i}] must be a dict with flow_pattern, layout, recirculations, vrr and ceiling")
        missing = [key for key in ("flow_pattern", "layout", "recirculations", "vrr") if key not in item]
        if missing:
            raise ValueError(f"curves[{i}] lacks {', '.join(missing)}")
        key = (str(item["flow_pattern"]), str(item["layout"]))
        if key in seen:
            raise ValueError(f"curves[{i}]: flow pattern {key[0]!r} with layout {key[1]!r} appears twice; give its "
                             "seeds as rows of one vrr array")
        seen.add(key)
        recirculations = finite_abscissa(f"curves[{i}] recirculations", item["recirculations"])
        vrr = np.asarray(item["vrr"], dtype=float)
        if vrr.ndim != 2 or vrr.shape[0] < 1:
            raise ValueError(f"curves[{i}] vrr must be a 2-D array of shape (n_seeds, n_points), one row per seed, "
                             f"got shape {vrr.shape}")
        if vrr.shape[1] != recirculations.size:
            raise ValueError(f"curves[{i}] vrr must have as many columns as curves[{i}] recirculations has entries "
                             f"({recirculations.size}), got shape {vrr.shape}")
        ceiling = item.get("ceiling")
        if ceiling is not None:
            ceiling = positive_number(f"curves[{i}] ceiling", ceiling)
        discharge = item.get("discharge")
        if discharge is not None:
            nr = finite_abscissa(f"curves[{i}] discharge recirculations", discharge["recirculations"])
            values = np.asarray(discharge["vrr"], dtype=float).reshape(-1)
            if values.shape != nr.shape:
                raise ValueError(f"curves[{i}] discharge vrr must have one value per discharge Nr ({nr.size}), got "
                                 f"{values.size}")
            discharge = {"recirculations": nr, "vrr": values}
        checked.append({"flow_pattern": key[0], "layout": key[1], "recirculations": recirculations, "vrr": vrr,
                        "ceiling": ceiling, "discharge": discharge})
    return checked


def _findings(findings) -> list[dict]:
    """Checked findings of :func:`plot_vrr_summary`: an id, a flow pattern, a finite Nr and 0 < low <= high."""
    checked = []
    for i, item in enumerate(findings or []):
        if not isinstance(item, Mapping):
            raise ValueError(f"findings[{i}] must be a dict with id, flow_pattern, at, low and high")
        missing = [key for key in ("id", "flow_pattern", "at", "low", "high") if key not in item]
        if missing:
            raise ValueError(f"findings[{i}] lacks {', '.join(missing)}")
        at = float(item["at"])
        if not math.isfinite(at):
            raise ValueError(f"findings[{i}] at must be a finite number of recirculations, got {at!r}")
        low = positive_number(f"findings[{i}] low", item["low"])
        high = positive_number(f"findings[{i}] high", item["high"])
        if high < low:
            raise ValueError(f"findings[{i}] high must be >= low, got low {low:g} and high {high:g}")
        checked.append({"id": str(item["id"]), "flow_pattern": str(item["flow_pattern"]), "at": at, "low": low,
                        "high": high})
    return checked


def _replicate_mean(vrr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean over the seeds (rows) at each Nr and its standard error (NaN where fewer than 2 seeds have a value).

    A VRR that is NaN, infinite or <= 0 is left out at its Nr: an infinite VRR (no variance left at the outlet)
    has no mean with the others; a point with no value left is NaN (a gap in the line).
    """
    values = _positive_finite_or_nan(vrr)
    counts = np.sum(np.isfinite(values), axis=0)
    with warnings.catch_warnings():
        # a point no seed has a value at is NaN, by design: numpy's all-NaN warnings say nothing more
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(values, axis=0)
        error = np.where(counts >= 2, np.nanstd(values, axis=0, ddof=1) / np.sqrt(np.maximum(counts, 1)), np.nan)
    return mean, error


def _draw_discharge(axes, discharge: Mapping, colour: str, marker: str) -> None:
    """One curve's discharge after the recirculations: the seeds' mean Nr and mean VRR as an open marker, with a bar
    of one standard error of the mean when 2 or more seeds have a VRR a log axis can take."""
    # the seeds are the rows of one point: their mean and its standard error as the curves' (_replicate_mean)
    mean, error = (float(value[0]) for value in _replicate_mean(discharge["vrr"].reshape(-1, 1)))
    if not math.isfinite(mean):
        return
    usable = np.isfinite(_positive_finite_or_nan(discharge["vrr"]))
    nr, vrr = float(np.mean(discharge["recirculations"][usable])), mean
    axes.plot([nr], [vrr], linestyle="none", marker=marker, markersize=7, markerfacecolor="white", color=colour,
              markeredgewidth=1.5, gid="vrr_discharge", label="_nolegend_", zorder=3)
    if math.isfinite(error):
        bar = axes.errorbar([nr], [vrr], yerr=[[min(error, 0.999 * vrr)], [error]], fmt="none", color=colour,
                            elinewidth=1.0, capsize=2.5, label="_nolegend_")
        for artist in bar.lines[2]:
            artist.set_gid("vrr_discharge_error")


def _display_name(name: str) -> str:
    """A flow pattern's name as a reader reads it: ``internal_flow`` -> ``internal flow``."""
    return name.replace("_", " ")


def plot_vrr_summary(curves, path: str | os.PathLike, title: str, findings=None) -> Path:
    """Variance reduction ratio against the number of recirculations of every flow pattern and layout, replicates
    as their mean and band, beside the study's findings (log y axis), in the project's style
    (:func:`siloflow.analysis.io.plot_style.journal_style`).

    One colour per flow pattern (:func:`siloflow.analysis.io.plot_style.colour_of`, in the order of first
    appearance), one line style and marker per layout (the same layout the same style in every flow pattern).
    The seeds of a curve are drawn as their mean at each Nr (``gid="vrr_mean"``), with a band of +- one standard
    error of the mean across the seeds (``gid="vrr_band"``, alpha 0.2) when there are 2 or more; on the log axis
    a band reaching 0 or below runs to the bottom of the axes. A VRR that is NaN, infinite or <= 0 is left out of
    the mean at its Nr; a Nr with none left is a gap.
    The counting-noise ceiling is drawn once (``gid="ceiling"``), dashed grey with a label at its right end: the
    lowest ceiling of the curves, the VRR above which the runs with that ceiling can no longer be told from a
    perfectly mixed outflow (:func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`).
    A curve's discharge after the recirculations (the study's VRR "at the end of Nr recirculations", §6.4.2) is one
    open marker of its layout at the seeds' mean Nr and mean VRR (``gid="vrr_discharge"``), with a bar of one
    standard error of the mean across the seeds when 2 or more have one (``gid="vrr_discharge_error"``).
    Each finding is a vertical bar from ``low`` to ``high`` at Nr = ``at`` in its flow pattern's colour
    (``gid="finding <id>"``).
    The legend stands to the right of the axes (:func:`siloflow.analysis.io.plot_style.legend_outside`): the flow
    patterns (colours), then the layouts (line styles), then the findings, each once.

    Parameters
    ----------
    curves : list of dict
        ``{"flow_pattern": str, "layout": str, "recirculations": array_like, "vrr": array_like, "ceiling": float or
        None}``: the number of recirculations Nr = t / t_res at which the VRR is taken [-] (finite, n_points), the
        variance reduction ratio sigma_in^2 / sigma_out^2 of each seed [-] (shape (n_seeds, n_points), one row per
        seed) and the counting-noise ceiling of that curve's VRR [-] (> 0; None or absent: none); optionally
        ``"discharge": {"recirculations": array_like, "vrr": array_like}``, the Nr [-] and VRR [-] of the discharge
        after the recirculations of each seed that has one (None or absent: none). One curve per (flow pattern,
        layout); :func:`vrr_replicate_curves` builds them from the summary table's rows and curves.
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    title : str
        Figure title.
    findings : list of dict, optional
        The study's values drawn beside the result: ``{"id": str, "flow_pattern": str, "at": float, "low": float,
        "high": float}``, the finding's id in the study's list (e.g. ``"B4"``), its flow pattern, the Nr it holds at
        [-] and its VRR range [-] (0 < low <= high). A flow pattern with no curve takes the next colour. None: none.

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    ValueError
        Naming the argument: empty ``curves``, a curve that is not a dict or lacks a key, a (flow pattern, layout)
        given twice, non-finite Nr, ``vrr`` not 2-D or not as long as Nr, a non-positive ceiling, a finding that
        lacks a key or has a non-finite ``at``, a non-positive ``low`` or ``high`` or ``high < low``; more than 8
        flow patterns (the palette's colours).
    """
    checked = _replicate_curves(curves)
    checked_findings = _findings(findings)
    # the findings' flow patterns without a curve come after the curves' ones: those keep their colours
    colours = colour_of([curve["flow_pattern"] for curve in checked] +
                        [finding["flow_pattern"] for finding in checked_findings])
    patterns = list(dict.fromkeys(curve["flow_pattern"] for curve in checked))
    layouts = list(dict.fromkeys(curve["layout"] for curve in checked))
    styles = {layout: (LINE_STYLES[k % len(LINE_STYLES)], MARKERS[k % len(MARKERS)])
              for k, layout in enumerate(layouts)}
    ceilings = [curve["ceiling"] for curve in checked if curve["ceiling"] is not None]
    with journal_style():
        figure, axes = plt.subplots(figsize=(PAGE_WIDTH, 3.6))
        try:
            # room on the right for the legend, so that the figure keeps the page's width
            figure.subplots_adjust(left=0.1, right=0.66, bottom=0.13, top=0.91)
            axes.set_yscale("log")
            for curve in checked:
                colour = colours[curve["flow_pattern"]]
                line_style, marker = styles[curve["layout"]]
                mean, error = _replicate_mean(curve["vrr"])
                axes.plot(curve["recirculations"], mean, linestyle=line_style, marker=marker, color=colour,
                          gid="vrr_mean", label="_nolegend_")
                if curve["vrr"].shape[0] >= 2:
                    axes.fill_between(curve["recirculations"], mean - error, mean + error, color=colour, alpha=0.2,
                                      linewidth=0.0, gid="vrr_band", label="_nolegend_")
                if curve["discharge"] is not None:
                    _draw_discharge(axes, curve["discharge"], colour, marker)
            if ceilings:
                ceiling = min(ceilings)
                axes.axhline(ceiling, color="0.5", linestyle="--", linewidth=1.0, gid="ceiling", label="_nolegend_")
                axes.text(0.99, ceiling, "counting-noise ceiling", transform=axes.get_yaxis_transform(),
                          ha="right", va="bottom", color="0.35", gid="ceiling_label")
            for finding in checked_findings:
                middle = math.sqrt(finding["low"] * finding["high"])  # the middle on a log axis
                bar = axes.errorbar([finding["at"]], [middle],
                                    yerr=[[middle - finding["low"]], [finding["high"] - middle]], fmt="none",
                                    color=colours[finding["flow_pattern"]], elinewidth=2.5, capsize=4.0,
                                    capthick=1.3, label="_nolegend_")
                for artist in bar.lines[2]:
                    artist.set_gid(f"finding {finding['id']}")
            # proxy artists: each flow pattern, layout and finding once, however many curves and seeds share it
            handles = [Line2D([], [], color=colours[pattern], linestyle="-", label=_display_name(pattern))
                       for pattern in patterns]
            handles += [Line2D([], [], color="0.3", linestyle=styles[layout][0], marker=styles[layout][1],
                               label=f"layout {layout}") for layout in layouts]
            if any(curve["discharge"] is not None for curve in checked):
                handles.append(Line2D([], [], color="0.3", linestyle="none", marker="o", markerfacecolor="white",
                                      markersize=7, label="discharge after the recirculations"))
            handles += [Line2D([], [], color=colours[finding["flow_pattern"]], linestyle="none", marker="|",
                               markersize=9, markeredgewidth=2.5,
                               label=f"study {finding['id']}: {_display_name(finding['flow_pattern'])} "
                                     f"{finding['low']:g}-{finding['high']:g}")
                        for finding in checked_findings]
            legend_outside(axes, handles=handles)
            axes.set_xlabel("number of recirculations Nr [-]")
            axes.set_ylabel("variance reduction ratio VRR [-]")
            axes.set_title(title)
            axes.grid(alpha=0.3, which="both")
            return save_figure(figure, path, tight=True)
        finally:
            plt.close(figure)
