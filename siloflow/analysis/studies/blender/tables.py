"""Table rows and JSON summaries of the blender study: one run, the configuration comparison, gravity scaling.

Pure functions from the results of :mod:`siloflow.analysis.studies.blender.study` (and the run summaries it writes, as read
back from JSON) to plain rows (one dict per row, for :func:`siloflow.analysis.io.tables.write_flow_table`), summary dicts
(for :func:`siloflow.analysis.io.tables.write_json`) and the comparison's Markdown page; no file I/O. The column names and
their order are the file formats the comparison, report and thesis read, so they change only together with their
readers. SI units: times in s, E in 1/s, lengths in m, velocities in m/s, mass flow rates in kg/s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.io.tables import markdown_table
from siloflow.analysis.numerics.rtd import RTD
from siloflow.analysis.numerics.uncertainty import format_estimate
from siloflow.analysis.numerics.vrr_noise import CEILING_FACTOR
from siloflow.analysis.studies.blender.comparison import CEILING_SUFFIX, ERROR_SUFFIX, BlenderMetrics
from siloflow.analysis.studies.blender.gravity import gravity_scaling
from siloflow.analysis.studies.blender.modes import ContinuousMode
from siloflow.analysis.studies.blender.profiles import ProfilesOverTime
from siloflow.analysis.studies.blender.study import BlenderStudy, rtd_summary, study_summary
from siloflow.analysis.studies.blender.tracers import TracerPathlines

__all__ = [
    "blender_summary",
    "profile_rows",
    "residence_rows",
    "rtd_rows",
    "vrr_period_rows",
    "lowest_gravity_runs",
    "rtd_label",
    "comparison_markdown",
    "GRAVITY_QUANTITIES",
    "gravity_rows",
]

#: Steady quantities of a run summary's ``metrics`` tested for ``sqrt(g)`` scaling, in table order.
GRAVITY_QUANTITIES = ("mass_flow_rate_kg_s", "exterior_v_z_m_s", "interior_v_z_m_s")


def blender_summary(flow: Mapping, study: BlenderStudy, metrics: BlenderMetrics, *, run_id: str, configuration: str,
                    gravity_factor: float, geometry: Mapping, mode: str, n_clumps: int,
                    steady_window: Sequence[float], vertical_section: Mapping | None = None,
                    wall_layer: Mapping | None = None) -> dict:
    """The summary of one blender run (``blender.json``).

    Parameters
    ----------
    flow : mapping
        The run's flow record: ``mass_flow_rate_standard_error_kg_s`` [kg/s] and the history
        ``time_since_open_s`` [s], ``discharged_mass_kg`` [kg], ``mean_v_z_m_s`` [m/s].
    study : BlenderStudy
        The study of the run (:func:`siloflow.analysis.studies.blender.study.analyse_blender`).
    metrics : BlenderMetrics
        Its figures of merit (:func:`siloflow.analysis.studies.blender.study.study_metrics`).
    run_id : str
        The run's id.
    configuration : str
        Its insert configuration.
    gravity_factor : float
        Its gravity multiple [-].
    geometry : mapping
        The insert summary (:func:`siloflow.model.cases.blender_passages.geometry_summary`) [m, degrees].
    mode : str
        ``"continuous"`` or ``"batch"``.
    n_clumps : int
        Clumps of the fill [-].
    steady_window : sequence of float
        (start, end) of the steady window after opening [s].
    vertical_section : mapping, optional
        The depth-averaged field's uniformity across the vertical section
        (:func:`siloflow.analysis.studies.blender.sections.section_uniformity`); None when not computed.
    wall_layer : mapping, optional
        The wall layer's figures (:func:`siloflow.analysis.studies.blender.sections.wall_layer_summary`); None when
        not computed.

    Returns
    -------
    dict
        ``run_id``, ``configuration``, ``gravity_factor``, ``geometry``, ``mode``, ``n_clumps``,
        ``steady_window_s`` (a list), ``mass_flow_rate_standard_error_kg_s``, the keys of
        :func:`~siloflow.analysis.studies.blender.study.study_summary`, ``vertical_section`` and ``wall_layer`` (null
        when not given), ``rtd_curve`` (the RTD as
        :func:`~siloflow.analysis.studies.blender.study.rtd_summary`, which
        :func:`~siloflow.analysis.studies.blender.study.rtd_from_summary` reads back) and ``flow_history``.
    """
    return {
        "run_id": run_id, "configuration": configuration, "gravity_factor": gravity_factor,
        "geometry": geometry, "mode": mode, "n_clumps": n_clumps,
        "steady_window_s": list(steady_window), "mass_flow_rate_standard_error_kg_s":
            flow["mass_flow_rate_standard_error_kg_s"],
        **study_summary(study, metrics),
        "vertical_section": None if vertical_section is None else dict(vertical_section),
        "wall_layer": None if wall_layer is None else dict(wall_layer),
        "rtd_curve": rtd_summary(study.rtd.rtd),
        "flow_history": {"time_since_open_s": flow["time_since_open_s"],
                         "discharged_mass_kg": flow["discharged_mass_kg"], "mean_v_z_m_s": flow["mean_v_z_m_s"]},
    }


def profile_rows(profiles: ProfilesOverTime) -> list[dict]:
    """The vertical velocity profiles at the key heights over time, one row per bin (``profiles.csv``).

    Parameters
    ----------
    profiles : ProfilesOverTime
        Profiles per window and height (:func:`siloflow.analysis.studies.blender.profiles.profiles_over_time`).

    Returns
    -------
    list of dict
        Rows ``window_time_s`` [s], ``height_m`` [m], ``x_m`` (bin centre [m]), ``v_z_m_s`` [m/s] and
        ``normalised`` (``v_z`` over the cross-section mean [-]), window-major, then height, then x.
    """
    return [
        {"window_time_s": float(t), "height_m": float(h), "x_m": float(x), "v_z_m_s": float(v), "normalised": float(n)}
        for w, t in enumerate(profiles.window_time) for k, h in enumerate(profiles.heights)
        for x, v, n in zip(profiles.x, profiles.v_z[w, k], profiles.normalised[w, k])
    ]


def residence_rows(pathlines: TracerPathlines) -> list[dict]:
    """Residence time of the pathlines released across the width (``residence_across_width.csv``).

    Parameters
    ----------
    pathlines : TracerPathlines
        Virtual tracers released at one height (:func:`siloflow.analysis.studies.blender.tracers.tracer_pathlines`).

    Returns
    -------
    list of dict
        Rows ``release_x_m`` [m] and ``residence_time_s`` [s] (NaN: not out within the time followed).
    """
    return [
        {"release_x_m": float(x), "residence_time_s": float(t)}
        for x, t in zip(pathlines.release_x, pathlines.residence_time)
    ]


def rtd_rows(rtd: RTD) -> list[dict]:
    """An RTD in dimensional and dimensionless form, one row per bin (``rtd.csv``).

    Parameters
    ----------
    rtd : siloflow.analysis.numerics.rtd.RTD
        The RTD of the run (``study.rtd.rtd``).

    Returns
    -------
    list of dict
        Rows ``time_s`` (bin centre [s]), ``E_per_s`` [1/s], ``theta`` (``t / t_m`` [-]) and ``E_theta``
        (``t_m E`` [-]).
    """
    return [
        {"time_s": float(t), "E_per_s": float(e), "theta": float(th), "E_theta": float(et)}
        for t, e, th, et in zip(rtd.time, rtd.E, rtd.theta, rtd.E_theta)
    ]


def vrr_period_rows(continuous: ContinuousMode) -> list[dict]:
    """VRR and outlet CoV of sine inputs against their period (``vrr_period.csv``).

    Parameters
    ----------
    continuous : ContinuousMode
        The continuous mode of the run (:func:`siloflow.analysis.studies.blender.modes.continuous_mode`).

    Returns
    -------
    list of dict
        Rows ``period_over_tm`` [-], ``vrr`` [-] and ``cov_out`` [-].
    """
    return [
        {"period_over_tm": float(p), "vrr": float(v), "cov_out": float(c)}
        for p, v, c in zip(continuous.period_over_tm, continuous.vrr, continuous.cov_out)
    ]


def lowest_gravity_runs(summaries: Sequence[Mapping]) -> tuple[float, list[Mapping]]:
    """The runs at the lowest gravity factor, the ones the configuration comparison compares.

    Parameters
    ----------
    summaries : sequence of mapping
        Run summaries (:func:`blender_summary`, as read from JSON), each with its ``gravity_factor`` [-].

    Returns
    -------
    tuple of (float, list of mapping)
        The lowest gravity factor [-] and the summaries run at it, in the given order.
    """
    lowest = min(summary["gravity_factor"] for summary in summaries)
    return lowest, [summary for summary in summaries if summary["gravity_factor"] == lowest]


def rtd_label(summary: Mapping, summaries: Sequence[Mapping]) -> str:
    """The legend label of a run's RTD among ``summaries``: its configuration, and its run id where another run
    of the same configuration (a replicate with another seed) is among them."""
    configuration = summary["configuration"]
    repeated = sum(other["configuration"] == configuration for other in summaries) > 1
    return f"{configuration} ({summary['run_id']})" if repeated else configuration


def _estimate_cell(row: Mapping, column: str) -> str | float:
    """A figure's cell: ``"value ± error"`` when the row has its error, marked when the VRR is at its ceiling."""
    value = row.get(column, "")
    if column + ERROR_SUFFIX not in row:
        return value
    value = number_or_nan(value)
    cell = format_estimate(value, number_or_nan(row[column + ERROR_SUFFIX])) if math.isfinite(value) else "n/a"
    return f"{cell} (at ceiling)" if row.get(column + CEILING_SUFFIX) else cell


def comparison_markdown(gravity_factor: float, rows: Sequence[Mapping], best: str, tolerance: float) -> str:
    """The configuration comparison as a Markdown page (``configurations.md``).

    A figure with a standard error prints as ``"value ± error"``
    (:func:`siloflow.analysis.numerics.uncertainty.format_estimate`: the error to 2 significant digits, the value to the
    same place; ``"± unknown"`` for an unknown error, ``"n/a"`` for no value), a VRR within
    :data:`~siloflow.analysis.numerics.vrr_noise.CEILING_FACTOR` of its counting-noise ceiling with ``"(at ceiling)"``;
    the error and flag columns themselves are not shown.

    Parameters
    ----------
    gravity_factor : float
        Gravity factor the configurations were compared at [-].
    rows : sequence of mapping
        The comparison table (:func:`siloflow.analysis.studies.blender.comparison.comparison_table`).
    best : str
        The best configuration (:func:`siloflow.analysis.studies.blender.comparison.best_blender`).
    tolerance : float
        Homogenisation band the ranking used, relative to the mean [-].

    Returns
    -------
    str
        A heading, the table and a sentence naming the best blender and the ranking rule; with errors, a sentence
        on how to read them.
    """
    rows = list(rows)
    columns = [column for column in rows[0] if not column.endswith(ERROR_SUFFIX) and not column.endswith(CEILING_SUFFIX)]
    shown = [{column: _estimate_cell(row, column) for column in columns} for row in rows]
    page = (f"# Insert configurations at {gravity_factor:g} g\n\n{markdown_table(shown)}\n"
            f"Best blender: **{best}** (fewest recirculations to homogenise within +-{tolerance:.0%}, ties broken "
            "by the highest VRR at the shortest period).\n")
    if any(column + ERROR_SUFFIX in rows[0] for column in columns):
        page += ("\nFigures are value ± standard error. A VRR marked (at ceiling) lies within a factor "
                 f"{CEILING_FACTOR:g} of its counting-noise ceiling, so it is only a lower bound. Whether the "
                 "differences between configurations exceed their uncertainty: significance.csv.\n")
    return page


def gravity_rows(summaries: Sequence[Mapping], tolerance: float = 0.1) -> tuple[list[dict], list[tuple], list[tuple]]:
    """Gravity scaling of every configuration run at 1 g and at least one other factor (``scaling.csv``).

    For each configuration (in sorted order), its runs sorted by gravity factor give the quantities of
    :data:`GRAVITY_QUANTITIES` per factor (the mean of its seeds where a factor runs several, whose first seed gives
    the curve); those finite at every factor (JSON's null, a NaN written out, counts
    as not finite) go to :func:`siloflow.analysis.studies.blender.gravity.gravity_scaling`.

    Parameters
    ----------
    summaries : sequence of mapping
        Run summaries (:func:`blender_summary`, as read from JSON): ``configuration``, ``gravity_factor`` [-],
        ``metrics`` and ``flow_history``.
    tolerance : float, optional
        Relative tolerance of the scaling test [-]; default 0.1.

    Returns
    -------
    rows : list of dict
        ``configuration``, then the columns of :attr:`siloflow.analysis.studies.blender.gravity.GravityScaling.rows`
        (``quantity``, ``gravity_factor`` [-], ``value``, ``ratio_to_1g`` [-], ``expected_ratio`` [-],
        ``relative_deviation`` [-], ``scales``); empty when no configuration can be scaled.
    curves : list of tuple
        ``(configuration, gravity_factor [-], time_since_open_s [s], mean_v_z_m_s [m/s])`` of each scaled run,
        for :func:`siloflow.analysis.studies.blender.plots.plot_gravity_scaling`.
    skipped : list of tuple
        ``(configuration, gravity_factors)`` of the configurations left out: without a 1 g run or another
        factor.
    """
    rows, curves, skipped = [], [], []
    for configuration in sorted({s["configuration"] for s in summaries}):
        by_factor: dict[float, list] = {}
        for s in summaries:
            if s["configuration"] == configuration:
                by_factor.setdefault(float(s["gravity_factor"]), []).append(s)
        factors = sorted(by_factor)
        if 1.0 not in factors or len(factors) < 2:
            skipped.append((configuration, factors))
            continue
        # the seeds of one factor (a replicated reference) count as their mean
        quantities = {key: [float(np.mean([number_or_nan(s["metrics"][key]) for s in by_factor[f]])) for f in factors]
                      for key in GRAVITY_QUANTITIES}
        quantities = {k: v for k, v in quantities.items() if np.all(np.isfinite(v))}
        scaling = gravity_scaling(factors, quantities, tolerance=tolerance)
        rows += [{"configuration": configuration, **row} for row in scaling.rows]
        curves += [(configuration, f, by_factor[f][0]["flow_history"]["time_since_open_s"],
                    by_factor[f][0]["flow_history"]["mean_v_z_m_s"]) for f in factors]
    return rows, curves, skipped
