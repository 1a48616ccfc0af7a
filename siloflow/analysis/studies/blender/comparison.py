"""Comparison of blender configurations: the metrics of each, one table, the best one, and whether their
differences exceed their uncertainty.

Pure computation; SI units. See :class:`BlenderMetrics`, :func:`comparison_table`, :func:`best_blender` and
:func:`significance_rows`. Each figure ``<key>`` of the table carries its standard error as ``<key>_error``
(NaN: not known); how each error is obtained is said in :mod:`siloflow.analysis.studies.blender.errors`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from siloflow.analysis.numerics.replicates import REPLICATES_KEY, SEED_STD_SUFFIX
from siloflow.model.checks import number_or_nan, positive_number
from siloflow.analysis.numerics.uncertainty import Significance, combine_independent, difference_significant
from siloflow.analysis.numerics.vrr_noise import CEILING_FACTOR, vrr_near_ceiling

__all__ = ["BlenderMetrics", "comparison_table", "best_blender", "figure_columns", "significance_rows",
           "ERROR_SUFFIX", "CEILING_SUFFIX", "SIGNIFICANCE_COLUMNS"]

#: Suffix of the column that carries the standard error of a figure.
ERROR_SUFFIX = "_error"
#: Suffix of the flag of a VRR within :data:`siloflow.analysis.numerics.vrr_noise.CEILING_FACTOR` of its ceiling.
CEILING_SUFFIX = "_at_ceiling"
#: Columns of :func:`significance_rows`, in order.
SIGNIFICANCE_COLUMNS = ("figure", "configuration_a", "configuration_b", "value_a", "error_a", "value_b", "error_b",
                        "difference", "difference_error", "significance")


@dataclass(frozen=True)
class BlenderMetrics:
    """The numbers that characterise one blender configuration, with their standard errors.

    Attributes
    ----------
    name : str
        Configuration (e.g. ``"diverging"``).
    mass_flow_rate : float
        Steady mass flow rate [kg/s].
    exterior_v_z, interior_v_z, tube_v_z : float
        Mean vertical velocity of the exterior annulus, interior annulus and tube [m/s].
    rtd_mean : float
        Mean residence time ``t_m`` [s].
    rtd_spread : float
        ``sigma / t_m`` [-].
    ts_over_td : float
        ``t_s / t_d`` [-].
    recirculations_to_homogenise : float
        Passes until the outlet stays within the band; NaN if never [-].
    vrr_by_period : mapping
        ``period / t_m`` -> VRR of a sine input [-].
    mass_flow_rate_error, exterior_v_z_error, interior_v_z_error, tube_v_z_error, rtd_mean_error,
    rtd_spread_error, ts_over_td_error, recirculations_to_homogenise_error : float, optional
        Standard errors of the figures of the same name, in their units; NaN (the default) when not known.
    vrr_errors : mapping, optional
        ``period / t_m`` -> standard error of its VRR [-]; a missing period has an unknown error.
    vrr_ceiling : float, optional
        Counting-noise ceiling of the VRRs [-] (the tracers' effective number); NaN when not known.
    """

    name: str
    mass_flow_rate: float
    exterior_v_z: float
    interior_v_z: float
    tube_v_z: float
    rtd_mean: float
    rtd_spread: float
    ts_over_td: float
    recirculations_to_homogenise: float
    vrr_by_period: Mapping
    mass_flow_rate_error: float = math.nan
    exterior_v_z_error: float = math.nan
    interior_v_z_error: float = math.nan
    tube_v_z_error: float = math.nan
    rtd_mean_error: float = math.nan
    rtd_spread_error: float = math.nan
    ts_over_td_error: float = math.nan
    recirculations_to_homogenise_error: float = math.nan
    vrr_errors: Mapping = field(default_factory=dict)
    vrr_ceiling: float = math.nan


#: Table column of each figure with an error (its attribute, its error attribute), in table order.
_FIGURES = (
    ("mass_flow_rate_kg_s", "mass_flow_rate"), ("exterior_v_z_m_s", "exterior_v_z"),
    ("interior_v_z_m_s", "interior_v_z"), ("tube_v_z_m_s", "tube_v_z"), ("rtd_mean_s", "rtd_mean"),
    ("rtd_spread", "rtd_spread"), ("ts_over_td", "ts_over_td"),
    ("recirculations_to_homogenise", "recirculations_to_homogenise"),
)


def _metrics(metrics) -> list[BlenderMetrics]:
    items = list(metrics)
    if not items or not all(isinstance(item, BlenderMetrics) for item in items):
        raise ValueError("metrics must be a non-empty sequence of BlenderMetrics")
    periods = sorted(float(p) for p in items[0].vrr_by_period)
    for item in items:
        if sorted(float(p) for p in item.vrr_by_period) != periods:
            raise ValueError(f"metrics {item.name!r}: VRR periods {sorted(item.vrr_by_period)} differ from {periods}")
    return items


def _vrr_column(period) -> str:
    return f"vrr_at_{float(period):g}_tm"


def _known_ceiling(ceiling) -> bool:
    return math.isfinite(float(ceiling)) and ceiling > 0.0


def comparison_table(metrics: Sequence[BlenderMetrics]) -> list[dict]:
    """One row per run with a stable column order (for :func:`siloflow.analysis.io.tables.write_flow_table`).

    Metrics that share a name are replicates of one configuration (other seeds): each keeps its own row, and
    :func:`siloflow.analysis.numerics.replicates.combine_replicates` on ``["configuration"]`` turns them into one.

    Columns: ``configuration``, then each of ``mass_flow_rate_kg_s, exterior_v_z_m_s, interior_v_z_m_s,
    tube_v_z_m_s, rtd_mean_s, rtd_spread, ts_over_td, recirculations_to_homogenise`` followed by its standard error
    ``<column>_error`` (same unit; NaN when unknown), then ``vrr_at_<f>_tm`` and
    ``vrr_at_<f>_tm_error`` for each period fraction f in increasing order (all configurations must share them).
    When any configuration knows its VRR ceiling, ``vrr_ceiling`` [-] (NaN where unknown) and a flag
    ``vrr_at_<f>_tm_at_ceiling`` per period follow: True where the VRR lies within
    :data:`~siloflow.analysis.numerics.vrr_noise.CEILING_FACTOR` of the ceiling
    (:func:`siloflow.analysis.numerics.vrr_noise.vrr_near_ceiling`; such a VRR is only a lower bound), None where the
    ceiling is unknown.
    """
    items = _metrics(metrics)
    with_ceiling = any(_known_ceiling(item.vrr_ceiling) for item in items)
    rows = []
    for item in items:
        row = {"configuration": item.name}
        for column, attribute in _FIGURES:
            row[column] = float(getattr(item, attribute))
            row[column + ERROR_SUFFIX] = float(getattr(item, attribute + "_error"))
        periods = sorted(item.vrr_by_period)
        for period in periods:
            row[_vrr_column(period)] = float(item.vrr_by_period[period])
            row[_vrr_column(period) + ERROR_SUFFIX] = float(item.vrr_errors.get(period, math.nan))
        if with_ceiling:
            ceiling = float(item.vrr_ceiling)
            known = _known_ceiling(ceiling)
            row["vrr_ceiling"] = ceiling if known else math.nan
            for period in periods:
                row[_vrr_column(period) + CEILING_SUFFIX] = (
                    bool(vrr_near_ceiling(float(item.vrr_by_period[period]), ceiling, CEILING_FACTOR)) if known
                    else None)
        rows.append(row)
    return rows


def best_blender(metrics: Sequence[BlenderMetrics]) -> str:
    """The best blender: fewest recirculations to homogenise, ties broken by the highest VRR at the shortest period.

    Replicates (metrics that share a name) count by their mean over the seeds; a configuration one of whose
    seeds never homogenises (NaN) ranks, like one that never does, after all that do. Remaining ties keep the
    order in which the configurations first appear. Without VRR periods only the recirculations count.
    """
    items = _metrics(metrics)
    # grouped here rather than through combine_replicates: its mean leaves out a seed that never homogenises, which
    # here must rank the whole configuration after those that do
    seeds: dict[str, list[BlenderMetrics]] = {}
    for item in items:
        seeds.setdefault(item.name, []).append(item)

    def key(name: str):
        recirculations = float(np.mean([float(item.recirculations_to_homogenise) for item in seeds[name]]))
        periods = sorted(seeds[name][0].vrr_by_period)
        vrr = float(np.mean([float(item.vrr_by_period[periods[0]]) for item in seeds[name]])) if periods else 0.0
        return (recirculations if math.isfinite(recirculations) else math.inf, -vrr)

    return min(seeds, key=key)


def figure_columns(row: Mapping) -> list[str]:
    """The figures of a :func:`comparison_table` row, in its order: every column but ``configuration``, the errors
    (``*_error``), the ceiling flags (``*_at_ceiling``), ``vrr_ceiling`` and, in a row that combines replicates
    (:func:`siloflow.analysis.numerics.replicates.combine_replicates`), the seed count and the seeds' standard deviations."""
    return [column for column in row if column not in ("configuration", "vrr_ceiling", REPLICATES_KEY)
            and not column.endswith((ERROR_SUFFIX, CEILING_SUFFIX, SEED_STD_SUFFIX))]


def significance_rows(rows: Sequence[Mapping], k: float = 2.0) -> list[dict]:
    """Whether each figure differs between each pair of configurations by more than its uncertainty
    (``comparison/significance.csv``).

    For every figure of :func:`figure_columns` (in table order) and every pair of rows ``a`` before ``b`` (in
    table order), the difference ``value_a - value_b``, its standard error ``sqrt(error_a^2 + error_b^2)`` (the
    runs are independent; :func:`siloflow.analysis.numerics.uncertainty.combine_independent`, NaN when either error is
    unknown) and :func:`siloflow.analysis.numerics.uncertainty.difference_significant` with coverage factor ``k``. The
    outcome is ``"unknown"`` as well where a value is not finite (e.g. a blender without a tube, or one never
    homogenised) and where either VRR is flagged at its counting-noise ceiling (``<figure>_at_ceiling``): such a
    VRR is a lower bound set by the sampling, whose error says nothing about the true difference.

    Parameters
    ----------
    rows : sequence of mapping
        The comparison table (:func:`comparison_table`), at least one row; a figure without an ``_error``
        column has unknown errors.
    k : float, optional
        Coverage factor, > 0 [-]; default 2 (about 95 % for normal errors).

    Returns
    -------
    list of dict
        Rows ``figure``, ``configuration_a``, ``configuration_b``, ``value_a``, ``error_a``, ``value_b``,
        ``error_b``, ``difference`` (``value_a - value_b``), ``difference_error`` (in the figure's unit) and
        ``significance`` (a :class:`~siloflow.analysis.numerics.uncertainty.Significance` value: ``"significant"``,
        ``"not significant"`` or ``"unknown"``); empty for a single configuration.

    Raises
    ------
    ValueError
        On no rows, a row without ``configuration`` or a figure of the first row, or ``k <= 0``.
    """
    k = positive_number("k", k)
    rows = list(rows)
    if not rows:
        raise ValueError("rows must hold at least one comparison row")
    figures = figure_columns(rows[0])
    for i, row in enumerate(rows):
        missing = [column for column in ("configuration", *figures) if column not in row]
        if missing:
            raise ValueError(f"rows[{i}] has no column {missing[0]!r}")
    result = []
    for figure in figures:
        for i, a in enumerate(rows):
            for b in rows[i + 1:]:
                value_a, value_b = number_or_nan(a[figure]), number_or_nan(b[figure])
                error_a = number_or_nan(a.get(figure + ERROR_SUFFIX))
                error_b = number_or_nan(b.get(figure + ERROR_SUFFIX))
                finite = math.isfinite(value_a) and math.isfinite(value_b)
                at_ceiling = bool(a.get(figure + CEILING_SUFFIX)) or bool(b.get(figure + CEILING_SUFFIX))
                outcome = (difference_significant(value_a, error_a, value_b, error_b, k) if finite and not at_ceiling
                           else Significance.UNKNOWN)
                result.append({
                    "figure": figure, "configuration_a": a["configuration"], "configuration_b": b["configuration"],
                    "value_a": value_a, "error_a": error_a, "value_b": value_b, "error_b": error_b,
                    "difference": value_a - value_b, "difference_error": combine_independent([error_a, error_b]),
                    "significance": outcome.value,
                })
    return result
