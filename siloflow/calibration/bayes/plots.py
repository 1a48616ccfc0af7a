"""Figures of a Bayesian calibration: the posterior's corner plot and the posterior predictive check (PNG, PDF or SVG).

Each writer draws on its own :class:`matplotlib.figure.Figure` (no pyplot figure manager, no global state, no
backend chosen at import: a Figure saves through the canvas of its file's format whatever the backend), saves it
atomically with :func:`siloflow.analysis.io.plots.save_figure`, cropped to what is drawn (a corner plot's titles may reach past
its edge), in the format of the path's suffix (a reader never sees a half-written plot; a failed write leaves no
temporary file), and returns it: its artists still hold the plotted data, which is what the tests check.
"""

from __future__ import annotations

import os
from typing import Mapping, Sequence

import corner
import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from siloflow.analysis.io.plots import save_figure

__all__ = ["plot_corner", "plot_predictive"]

CHART_COLOR = "tab:red"
TRUTH_COLOR = "#4682b4"
#: The quantiles drawn on each marginal and given in its title (-): the 90 % equal-tailed interval and the median.
QUANTILES = [0.05, 0.5, 0.95]


def _by_name(values, names: Sequence[str], what: str) -> list[float | None]:
    """One value or None per name, from a mapping by name (names it lacks get None) or a sequence in names' order."""
    if values is None:
        return [None] * len(names)
    if isinstance(values, Mapping):
        unknown = sorted(set(values) - set(names))
        if unknown:
            raise ValueError(f"{what} names unknown parameters {unknown} (the parameters are {list(names)})")
        found = [values.get(name) for name in names]
    else:
        found = list(values)
        if len(found) != len(names):
            raise ValueError(f"{what} has {len(found)} values for the {len(names)} parameters {list(names)}")
    return [None if value is None or not np.isfinite(float(value)) else float(value) for value in found]


def plot_corner(samples, names: Sequence[str], path: str | os.PathLike, truths=None, chart=None) -> Figure:
    """Corner plot of posterior samples: each parameter's marginal histogram (with its 5, 50 and 95 % quantiles)
    and each pair's joint density, by :func:`corner.corner`.

    Parameters
    ----------
    samples : array_like, shape (n, d)
        Posterior samples (friction coefficients, -), one column per name.
    names : sequence of str, length d
        The parameters, used as the axes' labels ("[-]" appended); each marginal's title gives its median and the
        distances to its 5 and 95 % quantiles (a wall parameter named by its material alone).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).
    truths : Mapping of str to float, or sequence of float, optional
        Known true values (-) to mark (squares and lines, steel blue), e.g. of a synthetic twin calibration; None
        (or NaN) for a parameter leaves it unmarked.
    chart : Mapping of str to float, or sequence of float, optional
        The chart inversion's values (-) to mark (dashed red lines and dots); a parameter the chart does not give is
        left unmarked.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn.
    """
    names = list(names)
    values = np.asarray(samples, dtype=float)
    values = values[:, np.newaxis] if values.ndim == 1 else values
    if values.ndim != 2 or values.shape[1] != len(names) or len(values) < 2:
        raise ValueError(f"samples must have shape (n >= 2, {len(names)}) for {names}, got {np.shape(samples)}")
    marked_truths = _by_name(truths, names, "truths")
    marked_chart = _by_name(chart, names, "chart")
    size = max(4.0, 2.2 * len(names))
    figure = Figure(figsize=(size, size))
    # the marginals' titles short (a wall parameter by its material), so that they fit above their panel
    titles = [name.split(".", 1)[1] if "." in name else name for name in names]
    corner.corner(values, fig=figure, labels=[f"{name} [-]" for name in names], label_kwargs={"fontsize": 8},
                  quantiles=QUANTILES, title_quantiles=QUANTILES, titles=titles, show_titles=True, title_fmt=".3f",
                  title_kwargs={"fontsize": 8}, truths=None if truths is None else marked_truths,
                  truth_color=TRUTH_COLOR)
    if chart is not None and any(value is not None for value in marked_chart):
        corner.overplot_lines(figure, marked_chart, color=CHART_COLOR, linestyle="--", linewidth=1.0)
        pairs = [[np.nan if value is None else value for value in marked_chart]]
        corner.overplot_points(figure, pairs, color=CHART_COLOR, marker="o", markersize=4)
        figure.text(0.98, 0.98, "dashed red: the chart's values", ha="right", va="top", fontsize=9, color=CHART_COLOR)
    save_figure(figure, path, tight=True)
    return figure


def plot_predictive(rows: Sequence[Mapping], path: str | os.PathLike) -> Figure:
    """The posterior predictive check: per test, each run's bulk friction angle at a posterior draw, with its
    standard error, against the band its target allows.

    One panel per test (in the rows' order). At each run the target's band is drawn as ``target +- allowed``
    (dark) and ``+- 2 allowed`` (light), ``allowed`` the run's allowed uncertainty (the target's, the seed noise and
    the run's error in quadrature, deg); the run is a dot with its standard error, blue when within two allowed
    standard deviations, red when not. The panel's title counts those within.

    Without rows (no predictive draws) the figure says so.

    Parameters
    ----------
    rows : sequence of Mapping
        Rows of :func:`siloflow.calibration.bayes.report.predictive_rows` (``test``, ``set``, ``target_deg``,
        ``allowed_sd_deg``, ``angle_deg``, ``angle_error_deg``, ``within``; deg).
    path : str or os.PathLike
        Destination plot file, written atomically in the format of its suffix (:func:`siloflow.analysis.io.plots.save_figure`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn.
    """
    rows = list(rows)
    if not rows:
        figure = Figure(figsize=(4.2, 2.0))
        figure.text(0.5, 0.5, "no predictive runs\n(calibration.bayesian.predictive_draws = 0)", ha="center",
                    va="center")
        save_figure(figure, path, tight=True)
        return figure
    tests = list(dict.fromkeys(row["test"] for row in rows))
    figure = Figure(figsize=(4.2 * len(tests), 4.0), layout="constrained")
    axes_list = figure.subplots(1, len(tests), squeeze=False)[0]
    for axes, test in zip(axes_list, tests):
        chosen = [row for row in rows if row["test"] == test]
        x = np.array([row["set"] for row in chosen], dtype=float)
        target = np.array([row["target_deg"] for row in chosen], dtype=float)
        allowed = np.array([row["allowed_sd_deg"] for row in chosen], dtype=float)
        angle = np.array([row["angle_deg"] for row in chosen], dtype=float)
        error = np.array([np.nan if row["angle_error_deg"] is None else row["angle_error_deg"] for row in chosen],
                         dtype=float)
        within = np.array([bool(row["within"]) for row in chosen])
        axes.bar(x, 4.0 * allowed, bottom=target - 2.0 * allowed, width=0.8, color="0.5", alpha=0.15,
                 label="target +- 2 allowed sd")
        axes.bar(x, 2.0 * allowed, bottom=target - allowed, width=0.8, color="0.5", alpha=0.3,
                 label="target +- allowed sd")
        axes.plot(x, target, linestyle="none", marker="_", markersize=14, color="0.2", label="target")
        for mask, color, label in ((within, "tab:blue", "run: within"), (~within, "tab:red", "run: outside")):
            if mask.any():
                axes.errorbar(x[mask], angle[mask], yerr=error[mask], linestyle="none", marker="o", markersize=4,
                              capsize=2, color=color, label=label)
        axes.set_title(f"{test}: {int(within.sum())} of {len(chosen)} within 2 sd", fontsize=10)
        axes.xaxis.set_major_locator(MaxNLocator(integer=True))
        axes.set_xlabel("predictive parameter set")
        axes.set_ylabel("bulk friction angle [deg]")
        axes.grid(alpha=0.3)
        axes.legend(fontsize=7, loc="best")
    save_figure(figure, path, tight=True)
    return figure
