"""Comparison of blender configurations: the metrics of each, one table, and the best one.

Pure computation; SI units. See :class:`BlenderMetrics`, :func:`comparison_table` and :func:`best_blender`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

__all__ = ["BlenderMetrics", "comparison_table", "best_blender"]


@dataclass(frozen=True)
class BlenderMetrics:
    """The numbers that characterise one blender configuration.

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


def _metrics(metrics) -> list[BlenderMetrics]:
    items = list(metrics)
    if not items or not all(isinstance(item, BlenderMetrics) for item in items):
        raise ValueError("metrics must be a non-empty sequence of BlenderMetrics")
    names = [item.name for item in items]
    if len(set(names)) != len(names):
        raise ValueError(f"metrics must have distinct names, got {names}")
    periods = sorted(float(p) for p in items[0].vrr_by_period)
    for item in items:
        if sorted(float(p) for p in item.vrr_by_period) != periods:
            raise ValueError(f"metrics {item.name!r}: VRR periods {sorted(item.vrr_by_period)} differ from {periods}")
    return items


def comparison_table(metrics: Sequence[BlenderMetrics]) -> list[dict]:
    """One row per configuration with a stable column order (for :func:`analysis.io.tables.write_flow_table`).

    Columns: ``configuration, mass_flow_rate_kg_s, exterior_v_z_m_s, interior_v_z_m_s, tube_v_z_m_s,
    rtd_mean_s, rtd_spread, ts_over_td, recirculations_to_homogenise``, then ``vrr_at_<f>_tm`` for each
    period fraction f in increasing order (all configurations must share them).
    """
    items = _metrics(metrics)
    rows = []
    for item in items:
        row = {
            "configuration": item.name,
            "mass_flow_rate_kg_s": float(item.mass_flow_rate),
            "exterior_v_z_m_s": float(item.exterior_v_z),
            "interior_v_z_m_s": float(item.interior_v_z),
            "tube_v_z_m_s": float(item.tube_v_z),
            "rtd_mean_s": float(item.rtd_mean),
            "rtd_spread": float(item.rtd_spread),
            "ts_over_td": float(item.ts_over_td),
            "recirculations_to_homogenise": float(item.recirculations_to_homogenise),
        }
        for period in sorted(item.vrr_by_period):
            row[f"vrr_at_{float(period):g}_tm"] = float(item.vrr_by_period[period])
        rows.append(row)
    return rows


def best_blender(metrics: Sequence[BlenderMetrics]) -> str:
    """The best blender: fewest recirculations to homogenise, ties broken by the highest VRR at the shortest period.

    A configuration that never homogenises (NaN) ranks after all that do; remaining ties keep the
    given order. Without VRR periods only the recirculations count.
    """
    items = _metrics(metrics)

    def key(item: BlenderMetrics):
        recirculations = float(item.recirculations_to_homogenise)
        periods = sorted(item.vrr_by_period)
        vrr = float(item.vrr_by_period[periods[0]]) if periods else 0.0
        return (recirculations if math.isfinite(recirculations) else math.inf, -vrr)

    return min(items, key=key).name
