"""Validation rows of the flat-bottom silo: filling bulk density, flow rate and Beverloo, Janssen, B(z), the flow
channel and the front-wall friction series with its flow-pattern index.

The scale shows a silo figure when the silo is deep enough in particle diameters that the front and back walls do
not set it, its settled fill carries its weight (the force balance of the physical fill), and the figure's own
error resolves what it is about. Inputs are the run's files as read: ``case.json``, ``flow.json``,
``fields.json``, ``fill_balance.json`` and the rows of ``janssen.csv``, ``kinematic.csv`` and
``flow_channel_boundary.csv``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation.rows import Criteria, plus_minus, precise, ratio, resolved, row, verdict

__all__ = ["SiloRun", "silo_rows", "front_wall_series_rows"]

GROUP = "Flat-bottom silo"
SERIES_GROUP = "Front-wall friction series"


class SiloRun:
    """The figures of one flat-bottom silo run, as read from its files (see the module docstring)."""

    def __init__(self, case: Mapping, flow: Mapping, fields: Mapping, balance: Mapping,
                 janssen: Sequence[Mapping] = (), kinematic: Sequence[Mapping] = (),
                 boundary: Sequence[Mapping] = ()):
        self.case, self.flow, self.fields, self.balance = case, flow, fields, balance
        self.janssen, self.kinematic, self.boundary = list(janssen), list(kinematic), list(boundary)

    @property
    def diameter(self) -> float:
        return float(self.case["equivalent_diameter_m"])

    def depth_check(self, criteria: Criteria) -> tuple[bool, str]:
        depth = float(self.case["depth_m"])
        ratio_ = depth / self.diameter
        return ratio_ >= criteria.min_depth_diameters, (
            f"depth {depth * 1000:.1f} mm = {ratio_:.1f} particle diameters (>= {criteria.min_depth_diameters:g})")

    def balance_check(self) -> tuple[bool, str]:
        problems = list(self.balance.get("problems") or [])
        text = f"the settled fill's walls and floor carry {float(self.balance['support_ratio']):.4f} of its weight"
        return not problems, text + (f" ({'; '.join(problems)})" if problems else "")

    def outlet_check(self, criteria: Criteria) -> tuple[bool, str]:
        outlet = float(self.case["outlet_width_m"])
        ratio_ = outlet / self.diameter
        return ratio_ >= criteria.min_outlet_diameters, (
            f"outlet {outlet * 1000:.0f} mm = {ratio_:.1f} particle diameters (>= {criteria.min_outlet_diameters:g})")


def silo_rows(run: SiloRun, criteria: Criteria) -> list[dict]:
    """The base run's rows: bulk density, flow rate, Beverloo's coefficient, Janssen, B(z) and the flow channel."""
    k = criteria.coverage_factor
    case_name = run.case["run_id"]
    depth_ok, depth_text = run.depth_check(criteria)
    balance_ok, balance_text = run.balance_check()
    outlet_ok, outlet_text = run.outlet_check(criteria)
    flow = run.flow
    rows = []
    density, density_error = flow["filling_bulk_density_kg_m3"], number_or_nan(flow.get("filling_bulk_density_kg_m3_error"))
    rows.append(row(GROUP, "Filling bulk density", case_name, density, density_error, "kg/m3", "667 (40 mm deep)",
                    verdict(depth_ok, balance_ok), f"{depth_text}; {balance_text}"))
    rate, rate_error = flow["mass_flow_rate_kg_s"], number_or_nan(flow.get("mass_flow_rate_kg_s_error"))
    steady, steady_text = precise(rate, rate_error, criteria)
    rows.append(row(GROUP, "Steady mass flow rate", case_name, rate, rate_error, "kg/s", "",
                    verdict(depth_ok, outlet_ok, steady),
                    f"{depth_text}; {outlet_text}; {steady_text}; Beverloo predicts "
                    f"{flow['beverloo_mass_flow_rate_kg_s']:.4g} kg/s"))
    beverloo = flow["beverloo"]
    ratio_value, ratio_error = flow["beverloo_ratio"], number_or_nan(flow.get("beverloo_ratio_error"))
    coefficient = beverloo["discharge_coefficient"]
    rows.append(row(GROUP, f"Beverloo discharge coefficient C (k = {beverloo['shape_coefficient']:g})", case_name,
                    coefficient * ratio_value, coefficient * ratio_error, "-", f"{coefficient:g}",
                    verdict(depth_ok, outlet_ok, steady),
                    f"C that makes Beverloo match the measured rate: flow / Beverloo {plus_minus(ratio_value, ratio_error)};"
                    f" {outlet_text}; flow rate's {steady_text}"))
    rows += _janssen_rows(run, case_name, depth_ok, depth_text, balance_ok, k)
    for entry in run.kinematic:
        b, error = number_or_nan(entry["B_m"]), number_or_nan(entry.get("B_m_error"))
        b_precise, b_text = precise(b, error, criteria)
        rows.append(row(GROUP, f"Kinematic constant B at z = {float(entry['z_m']) * 1000:.0f} mm", case_name,
                        b, error, "m", "", verdict(depth_ok, math.isfinite(b) and b_precise),
                        f"{depth_text}; B = {b / run.diameter:.2f} particle diameters, error from "
                        f"{int(float(entry['batches']))} time batches; {b_text}"))
    rows += _channel_rows(run, case_name, depth_ok, depth_text, k)
    return rows


def _janssen_rows(run: SiloRun, case_name: str, depth_ok: bool, depth_text: str, balance_ok: bool,
                  k: float) -> list[dict]:
    if not run.janssen:
        return []
    deepest = max(run.janssen, key=lambda entry: float(entry["depth_below_surface_m"]))
    depth = float(deepest["depth_below_surface_m"])
    sigma, sigma_error = float(deepest["sigma_v_dem_Pa"]), number_or_nan(deepest.get("sigma_v_dem_Pa_error"))
    hydrostatic = float(deepest["hydrostatic_pa"])
    hydro_ratio = ratio(sigma, sigma_error, hydrostatic, number_or_nan(deepest.get("hydrostatic_pa_error")))
    janssen_ratio = ratio(sigma, sigma_error, float(deepest["sigma_v_janssen_Pa"]), 0.0)
    carried = resolved(1.0 - hydro_ratio[0], hydro_ratio[1], k)
    where = f"{depth * 1000:.0f} mm below the surface"
    return [
        row(GROUP, f"Vertical stress / hydrostatic, {where}", case_name, *hydro_ratio, "-", "< 1 (walls carry weight)",
            verdict(depth_ok, balance_ok, carried),
            f"{depth_text}; DEM {plus_minus(sigma, sigma_error)} Pa against rho g h = {hydrostatic:.4g} Pa: the walls' "
            f"share {'resolved' if carried else 'not resolved'} at {k:g} standard errors"),
        row(GROUP, f"Vertical stress / Janssen, {where}", case_name, *janssen_ratio, "-", "1",
            verdict(depth_ok, balance_ok, carried),
            f"Janssen with the configured friction angles predicts {float(deepest['sigma_v_janssen_Pa']):.4g} Pa"),
    ]


def _channel_rows(run: SiloRun, case_name: str, depth_ok: bool, depth_text: str, k: float) -> list[dict]:
    """Half-width of the flow channel at the largest boundary fraction, per height, against the silo's."""
    if not run.boundary:
        return []
    fraction = max(float(entry["fraction"]) for entry in run.boundary)
    half_silo = 0.5 * float(run.case["width_m"])
    rows = []
    for entry in run.boundary:
        if float(entry["fraction"]) != fraction:
            continue
        left, right = number_or_nan(entry["x_left_m"]), number_or_nan(entry["x_right_m"])
        error = 0.5 * combine_independent([number_or_nan(entry.get("x_left_m_error")),
                                           number_or_nan(entry.get("x_right_m_error"))])
        half = 0.5 * (right - left)
        inside = resolved(half_silo - half, error, k) if math.isfinite(half) else False
        rows.append(row(GROUP, f"Flow channel half-width ({fraction:g} of centreline v_z) at z = "
                               f"{float(entry['z_m']) * 1000:.0f} mm", case_name, half, error, "m",
                        "narrower than the silo (funnel flow)", verdict(depth_ok, inside),
                        f"{depth_text}; the silo's half-width is {half_silo * 1000:.0f} mm"))
    return rows


def _index_at(fields: Mapping, height: float) -> tuple[float, float, float]:
    """The flow-pattern index (and error) at the profile height nearest ``height`` (m), with that height."""
    indices = fields.get("flow_pattern_index") or {}
    if not indices:
        return math.nan, math.nan, math.nan
    nearest = min(indices, key=lambda key: abs(float(key) - height))
    return (number_or_nan(indices[nearest]), number_or_nan((fields.get("flow_pattern_index_error") or {}).get(nearest)),
            float(nearest))


def front_wall_series_rows(series: Sequence[tuple[str, SiloRun]], height: float, criteria: Criteria) -> list[dict]:
    """One row per run of the front-wall friction series (label, run) with its flow-pattern index (wall over
    centreline v_z) at the profile height nearest ``height`` (m), and one row with the index's change across the
    walled runs (highest friction minus lowest; labels ``mu_fw=<value>``)."""
    rows, walled = [], []
    for label, run in series:
        depth_ok, depth_text = run.depth_check(criteria)
        index, error, at = _index_at(run.fields, height)
        rows.append(row(SERIES_GROUP, f"Flow-pattern index (wall / centreline v_z) at z = {at * 1000:.0f} mm", label,
                        index, error, "-", "", verdict(depth_ok, math.isfinite(index) and math.isfinite(error)),
                        f"{depth_text}; run {run.case['run_id']}, flow rate "
                        f"{plus_minus(run.flow['mass_flow_rate_kg_s'], number_or_nan(run.flow.get('mass_flow_rate_kg_s_error')))} kg/s"))
        if label.startswith("mu_fw="):
            walled.append((float(label.split("=", 1)[1]), index, error, depth_ok))
    if len(walled) >= 2:
        walled.sort()
        (low, index_low, error_low, ok_low), (high, index_high, error_high, ok_high) = walled[0], walled[-1]
        change = index_high - index_low
        error = combine_independent([error_low, error_high])
        seen = resolved(change, error, criteria.coverage_factor)
        rows.append(row(SERIES_GROUP, f"Flow-pattern index, front-wall friction {high:g} - {low:g}", "series",
                        change, error, "-", "lower with more front-wall friction (towards funnel flow)",
                        verdict(ok_low and ok_high, seen),
                        f"the change is {'resolved' if seen else 'not resolved' if seen is False else 'unknown'} at "
                        f"{criteria.coverage_factor:g} standard errors"))
    return rows
