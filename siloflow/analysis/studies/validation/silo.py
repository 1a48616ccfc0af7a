"""Validation rows of the flat-bottom silo (thesis ch. 5): each judged against a finding part S1-S6 where the study
states one, else a measurement with no finding (the flow rate, Beverloo's C, the flow channel).

Rows (see :mod:`siloflow.analysis.studies.validation.rows`):

- S2: the filling bulk density; S1: the stress gradient near the free surface over the unit weight, the change of
  the gradient from the top to the bottom of the fill, the stress at the base over Janssen's; S5.dem: the change of
  the kinematic constant B from the lowest to the highest fitted height;
- the front-wall friction series: S6.hydrostatic (the stress at the base over the hydrostatic one with frictionless
  front and back walls) and S6.towards_internal_flow (the change of the flow-pattern index, near-wall over
  centreline vertical velocity, from front/back friction 0 to the highest run).

A settled fill that does not carry its weight (the force balance of the physical fill) is not steady: its stress
and density rows can then be "not resolved" at most. The rows of the time-averaged fields (B, the flow channel, the
flow-pattern index) say in ``differs`` when their averaging window is not the study's 0.5-0.7 s after the outlet
opened (:func:`window_clause`, §5.4.3.4, §5.5.2) and when B's heights are not the study's profile heights
(:func:`heights_clause`, §5.4.3.4). Inputs are the run's files as read: ``case.json``,
``flow.json``, ``fields.json``, ``fill_balance.json`` and the rows of ``janssen.csv``, ``kinematic.csv`` and
``flow_channel_boundary.csv``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent, line_slope
from siloflow.analysis.studies.silo_flat.field_clock import WINDOW_CONFIGURED, WINDOW_STEADY
from siloflow.analysis.studies.validation import agreement as rules
from siloflow.analysis.studies.validation.agreement import AgreementTolerances, ratio
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.analysis.studies.validation.rows import joined, plus_minus, precise, resolution, row

__all__ = ["SiloRun", "silo_rows", "front_wall_series_rows", "stress_gradient", "window_clause", "heights_clause",
           "STUDY_WINDOW", "STUDY_HEIGHTS", "MADE", "UNMADE"]

GROUP = "Flat-bottom silo"
SERIES_GROUP = "Front-wall friction series"
#: The finding parts these rows make.
MADE = ("S1.linear_near_surface", "S1.saturates", "S1.janssen", "S2", "S5.dem", "S6.hydrostatic",
        "S6.towards_internal_flow")
#: The parts of ch. 5 these rows cannot make, and what would make them.
UNMADE = MappingProxyType({
    "S3.mass_flow": "needs the experiment's mass flow rate, which no configuration key holds (the study's table in "
                    "§5.4.2 is not legible); the rows quote the measured rate with no finding",
    "S3.volumetric_flow": "needs the experiment's volumetric flow rate, as S3.mass_flow",
    "S4.faster_start": "needs the experiment's PIV profiles (silo_flat.piv.measured_profiles, null in "
                       "config/validation.yaml) and the instantaneous profiles at t = 0.1 s",
    "S4.steady_profiles": "needs the experiment's PIV profiles (silo_flat.piv.measured_profiles)",
    "S5.experiment": "a finding of the experiment's PIV: needs silo_flat.piv.measured_profiles",
    "S6.uniform_velocity": "needs the velocity across the width at Z = 120 mm of the frictionless front/back run; "
                           "the series keeps no field of its runs and the tier's fill ends below 120 mm",
})
#: The study's averaging window of the steady profiles, B and the flow channel, after the outlet opened (s; §5.4.3.4,
#: and §5.5.2 for the front-wall friction series).
STUDY_WINDOW = (0.5, 0.7)
#: The study's heights of the steady velocity profiles above the outlet (m; §5.4.3.4).
STUDY_HEIGHTS = (0.02, 0.04, 0.08, 0.12)
#: Two times or heights closer than this are the same (s or m): config values and their JSON round trip.
_SAME = 1e-9
#: The share of the Janssen profile's points, from either end, over which a stress gradient is fitted: the study
#: says "near the surface" and "saturates" with no depths, so the shallowest and deepest thirds are taken.
GRADIENT_SHARE = 1.0 / 3.0


class SiloRun:
    """The figures of one flat-bottom silo run, as read from its files (see the module docstring)."""

    def __init__(self, case: Mapping, flow: Mapping, fields: Mapping, balance: Mapping,
                 janssen: Sequence[Mapping] = (), kinematic: Sequence[Mapping] = (),
                 boundary: Sequence[Mapping] = ()):
        self.case, self.flow, self.fields, self.balance = case, flow, fields, balance
        self.janssen, self.kinematic, self.boundary = list(janssen), list(kinematic), list(boundary)

    @property
    def diameter(self) -> float:
        """The particle's volume-equivalent diameter (m)."""
        return float(self.case["equivalent_diameter_m"])

    def settled(self) -> tuple[bool, str]:
        """Whether the settled fill carries its weight (no problem in the force balance), and the evidence."""
        problems = list(self.balance.get("problems") or [])
        text = f"the settled fill's walls and floor carry {float(self.balance['support_ratio']):.4f} of its weight"
        return not problems, text + (f" ({'; '.join(problems)})" if problems else "")


def _millimetres(heights: Sequence[float]) -> str:
    return ", ".join(f"{height * 1000:.0f}" for height in heights)


def window_clause(fields: Mapping, flow: Mapping, what: str = "profiles", section: str = "§5.4.3.4") -> str:
    """The ``differs`` clause of a figure of the run's time-averaged fields: "" when they were averaged over the
    study's 0.5-0.7 s after the outlet opened (:data:`STUDY_WINDOW`, §5.4.3.4), else how they were.

    Parameters
    ----------
    fields : mapping
        The run's ``fields.json``: ``average_window_s`` ([start, end], s after opening) and ``average_window_source``
        (:data:`~siloflow.analysis.studies.silo_flat.field_clock.WINDOW_CONFIGURED` or ``WINDOW_STEADY``); a summary
        written before the source was recorded is taken for the steady window where its times are the flow's.
    flow : mapping
        The run's ``flow.json``: ``steady_window`` (the discharged-mass fractions) and ``steady_window_start_s``,
        ``steady_window_end_s`` (their times, s).
    what : str
        What was averaged, the clause's subject.
    section : str
        The thesis section that states the study's window for this figure.

    Returns
    -------
    str
        E.g. ``"profiles averaged over the discharged-mass window 0.2-0.8 (t = 0.31-1.2 s), not the study's 0.5-0.7 s
        (§5.4.3.4)"``; a summary without ``average_window_s`` says that the window is not recorded.
    """
    study = f"not the study's {STUDY_WINDOW[0]:g}-{STUDY_WINDOW[1]:g} s ({section})"
    window = fields.get("average_window_s")
    if not window or len(window) != 2:
        return f"{what} averaged over a window fields.json does not record, {study}"
    start, end = float(window[0]), float(window[1])
    if abs(start - STUDY_WINDOW[0]) <= _SAME and abs(end - STUDY_WINDOW[1]) <= _SAME:
        return ""
    source = fields.get("average_window_source")
    if source is None:
        steady = (number_or_nan(flow.get("steady_window_start_s")), number_or_nan(flow.get("steady_window_end_s")))
        same = abs(start - steady[0]) <= _SAME and abs(end - steady[1]) <= _SAME
        source = WINDOW_STEADY if same else WINDOW_CONFIGURED
    fractions = flow.get("steady_window")
    if source == WINDOW_STEADY and fractions and len(fractions) == 2:
        return (f"{what} averaged over the discharged-mass window {float(fractions[0]):g}-{float(fractions[1]):g} "
                f"(t = {start:.3g}-{end:.3g} s), {study}")
    return f"{what} averaged over t = {start:.3g}-{end:.3g} s after opening, {study}"


def heights_clause(heights: Sequence[float], what: str = "at") -> str:
    """The ``differs`` clause of a figure taken at ``heights`` above the outlet (m): "" when they are the study's
    profile heights 20, 40, 80 and 120 mm (:data:`STUDY_HEIGHTS`, §5.4.3.4), else e.g. ``"at 20, 40, 60 mm, not the
    study's 20, 40, 80, 120 mm (§5.4.3.4)"`` (``what`` opens it)."""
    ordered = sorted(float(height) for height in heights)
    if len(ordered) == len(STUDY_HEIGHTS) and all(abs(a - b) <= _SAME for a, b in zip(ordered, STUDY_HEIGHTS)):
        return ""
    return f"{what} {_millimetres(ordered)} mm, not the study's {_millimetres(STUDY_HEIGHTS)} mm (§5.4.3.4)"


def _column(entries: Sequence[Mapping], key: str) -> np.ndarray:
    return np.array([number_or_nan(entry.get(key)) for entry in entries], dtype=float)


def stress_gradient(depth, stress, error) -> tuple[float, float]:
    """The slope of the vertical stress against the depth below the surface and its standard error (Pa/m).

    A straight-line fit weighted by the stresses' standard errors as known errors; unweighted with the scatter's
    error when an error is unknown or zero (NaN error for two points):
    :func:`siloflow.analysis.numerics.uncertainty.line_slope`.

    Parameters
    ----------
    depth : array_like
        Depths below the free surface (m), at least two distinct.
    stress, error : array_like
        Vertical stress and its standard error at each depth (Pa).
    """
    x, y, e = (np.asarray(a, dtype=float) for a in (depth, stress, error))
    if x.ndim != 1 or x.shape != y.shape or x.shape != e.shape or np.unique(x).size < 2:
        raise ValueError("depth, stress and error must be equal 1-D arrays with two distinct depths at least")
    known = bool(np.all(np.isfinite(e)) and np.all(e > 0))
    return line_slope(x, y, e if known else None)


def _ends(entries: Sequence[Mapping]) -> tuple[list, list]:
    """The shallowest and the deepest :data:`GRADIENT_SHARE` of a Janssen profile's points (at least two each)."""
    ordered = sorted(entries, key=lambda entry: float(entry["depth_below_surface_m"]))
    n = max(2, int(round(GRADIENT_SHARE * len(ordered))))
    return ordered[:n], ordered[-n:]


def _gradient(entries: Sequence[Mapping], key: str, error_key: str) -> tuple[float, float]:
    return stress_gradient(_column(entries, "depth_below_surface_m"), _column(entries, key), _column(entries, error_key))


def _span(entries: Sequence[Mapping]) -> str:
    depths = [float(entry["depth_below_surface_m"]) * 1000 for entry in entries]
    return f"{min(depths):.0f}-{max(depths):.0f} mm below the surface ({len(depths)} points)"


def silo_rows(run: SiloRun, tolerances: AgreementTolerances, dof: float | None, note: str = "") -> list[dict]:
    """The base run's rows: S2, S1 and S5.dem, with the flow rate, Beverloo's C and the flow channel as
    measurements.

    Parameters
    ----------
    run : SiloRun
    tolerances : AgreementTolerances
    dof : float or None
        Degrees of freedom of the run's errors (seeds - 1), None for within-run errors.
    note : str
        Evidence about the seeds, appended to every row's.
    """
    case_name = run.case["run_id"]
    settled, settled_text = run.settled()
    tail = f"; {note}" if note else ""
    flow = run.flow
    rows = []
    density, density_error = flow["filling_bulk_density_kg_m3"], number_or_nan(flow.get("filling_bulk_density_kg_m3_error"))
    rows.append(row(GROUP, "Filling bulk density", case_name, density, density_error, "kg/m3",
                    f"{settled_text}; total particle mass over the filled volume{tail}", dof=dof, finding="S2",
                    agreement=rules.value_in_band(density, density_error, dof, PARTS["S2"], tolerances,
                                                  steady=settled)))
    rate, rate_error = flow["mass_flow_rate_kg_s"], number_or_nan(flow.get("mass_flow_rate_kg_s_error"))
    rows.append(row(GROUP, "Steady mass flow rate", case_name, rate, rate_error, "kg/s",
                    f"{precise(rate, rate_error, tolerances)[1]}; Beverloo predicts "
                    f"{flow['beverloo_mass_flow_rate_kg_s']:.4g} kg/s{tail}", dof=dof,
                    study="the experiment's rate (S3; not in the configuration)"))
    beverloo = flow["beverloo"]
    ratio_value, ratio_error = flow["beverloo_ratio"], number_or_nan(flow.get("beverloo_ratio_error"))
    coefficient = beverloo["discharge_coefficient"]
    rows.append(row(GROUP, f"Beverloo discharge coefficient C (k = {beverloo['shape_coefficient']:g})", case_name,
                    coefficient * ratio_value, coefficient * ratio_error, "-",
                    f"C that makes Beverloo match the measured rate: flow / Beverloo {plus_minus(ratio_value, ratio_error)}"
                    f"{tail}", dof=dof, study=f"{coefficient:g} (the configured C, silo_flat.beverloo)"))
    rows += _janssen_rows(run, case_name, settled, settled_text, tolerances, dof, tail)
    rows += _b_rows(run, case_name, tolerances, dof, tail)
    rows += _channel_rows(run, case_name, dof, tail)
    return rows


def _janssen_rows(run: SiloRun, case_name: str, settled: bool, settled_text: str, tolerances: AgreementTolerances,
                  dof: float | None, tail: str) -> list[dict]:
    if len(run.janssen) < 4:
        return []
    top, bottom = _ends(run.janssen)
    dem_top = _gradient(top, "sigma_v_dem_Pa", "sigma_v_dem_Pa_error")
    deepest = bottom[-1]
    # rho g h is linear in the depth: its slope is rho g, with the bulk density's relative error
    depth = float(deepest["depth_below_surface_m"])
    unit_weight = (float(deepest["hydrostatic_pa"]) / depth, number_or_nan(deepest.get("hydrostatic_pa_error")) / depth)
    dem_bottom = _gradient(bottom, "sigma_v_dem_Pa", "sigma_v_dem_Pa_error")
    change = dem_bottom[0] - dem_top[0], combine_independent([dem_bottom[1], dem_top[1]])
    sigma, sigma_error = float(deepest["sigma_v_dem_Pa"]), number_or_nan(deepest.get("sigma_v_dem_Pa_error"))
    janssen = float(deepest["sigma_v_janssen_Pa"])
    hydrostatic = float(deepest["hydrostatic_pa"]), number_or_nan(deepest.get("hydrostatic_pa_error"))
    where = f"{float(deepest['depth_below_surface_m']) * 1000:.0f} mm below the surface"
    gradient_note = "the shallowest and deepest thirds of the profile: the study names no depths"
    # Janssen's curve is not straight over the window either: its own slope there shows how far "linear, at rho g"
    # can hold for a fill in good agreement with Janssen (the row's verdict stays the comparison with rho g)
    janssen_top = stress_gradient(_column(top, "depth_below_surface_m"), _column(top, "sigma_v_janssen_Pa"),
                                  [math.nan] * len(top))[0]
    return [
        row(GROUP, "Stress gradient near the surface / unit weight", case_name,
            *ratio(*dem_top, *unit_weight), "-",
            f"{settled_text}; fitted over {_span(top)}: DEM {plus_minus(*dem_top)} Pa/m, rho g "
            f"{plus_minus(*unit_weight)} Pa/m ({gradient_note}); Janssen's curve over the same depths: "
            f"{janssen_top:.4g} Pa/m ({janssen_top / unit_weight[0]:.3f} of rho g; the DEM's gradient "
            f"{dem_top[0] / janssen_top:.3f} of it){tail}", dof=dof, finding="S1.linear_near_surface",
            agreement=rules.ratio_in_band(*dem_top, *unit_weight, dof, PARTS["S1.linear_near_surface"], tolerances,
                                          steady=settled)),
        row(GROUP, "Change of the stress gradient, bottom - top of the fill", case_name, *change, "Pa/m",
            f"{settled_text}; top {_span(top)}: {plus_minus(*dem_top)} Pa/m; bottom {_span(bottom)}: "
            f"{plus_minus(*dem_bottom)} Pa/m{tail}", dof=dof, finding="S1.saturates",
            agreement=rules.sign_of_change(*change, dof, PARTS["S1.saturates"], steady=settled)),
        row(GROUP, f"Vertical stress / Janssen, {where}", case_name, *ratio(sigma, sigma_error, janssen, 0.0), "-",
            f"{settled_text}; DEM {plus_minus(sigma, sigma_error)} Pa; Janssen with the configured friction angles "
            f"predicts {janssen:.4g} Pa{tail}", dof=dof, finding="S1.janssen",
            agreement=rules.ratio_in_band(sigma, sigma_error, janssen, 0.0, dof, PARTS["S1.janssen"], tolerances,
                                          steady=settled)),
        row(GROUP, f"Vertical stress / hydrostatic, {where}", case_name, *ratio(sigma, sigma_error, *hydrostatic), "-",
            f"{settled_text}; DEM {plus_minus(sigma, sigma_error)} Pa against rho g h = {hydrostatic[0]:.4g} Pa: the "
            f"walls' share {resolution(hydrostatic[0] - sigma, combine_independent([sigma_error, hydrostatic[1]]), dof)}"
            f"{tail}", dof=dof, study="< 1: the walls carry part of the weight (§5.4.1)"),
    ]


def _b_rows(run: SiloRun, case_name: str, tolerances: AgreementTolerances, dof: float | None, tail: str) -> list[dict]:
    """S5.dem: B at the highest fitted height minus B at the lowest (§5.4.3.4: each B fitted to the steady profile
    averaged over 0.5-0.7 s)."""
    fitted = sorted((entry for entry in run.kinematic if math.isfinite(number_or_nan(entry["B_m"]))),
                    key=lambda entry: float(entry["z_m"]))
    if len(fitted) < 2:
        return []
    low, high = fitted[0], fitted[-1]
    change = (float(high["B_m"]) - float(low["B_m"]),
              combine_independent([number_or_nan(high.get("B_m_error")), number_or_nan(low.get("B_m_error"))]))
    listing = "; ".join(f"z {float(entry['z_m']) * 1000:.0f} mm: B {plus_minus(float(entry['B_m']) * 1000, number_or_nan(entry.get('B_m_error')) * 1000)} mm "
                        f"({int(float(entry['batches']))} time batches)" for entry in fitted)
    differs = joined((window_clause(run.fields, run.flow),
                      heights_clause([float(entry["z_m"]) for entry in fitted], "B fitted at")))
    return [row(GROUP, f"Change of the kinematic constant B, z = {float(high['z_m']) * 1000:.0f} - "
                       f"{float(low['z_m']) * 1000:.0f} mm", case_name, *change, "m",
                f"{listing}; particle diameter {run.diameter * 1000:.2f} mm{tail}", dof=dof, finding="S5.dem",
                agreement=rules.sign_of_change(*change, dof, PARTS["S5.dem"]), differs=differs)]


def _channel_rows(run: SiloRun, case_name: str, dof: float | None, tail: str) -> list[dict]:
    """Half-width of the flow channel at the largest boundary fraction, per height: a measurement (§5.4.3.5, of the
    velocities time-averaged as the profiles are)."""
    if not run.boundary:
        return []
    fraction = max(float(entry["fraction"]) for entry in run.boundary)
    half_silo = 0.5 * float(run.case["width_m"])
    differs = window_clause(run.fields, run.flow, "velocities")
    rows = []
    for entry in run.boundary:
        if float(entry["fraction"]) != fraction:
            continue
        left, right = number_or_nan(entry["x_left_m"]), number_or_nan(entry["x_right_m"])
        error = 0.5 * combine_independent([number_or_nan(entry.get("x_left_m_error")),
                                           number_or_nan(entry.get("x_right_m_error"))])
        half = 0.5 * (right - left)
        rows.append(row(GROUP, f"Flow channel half-width ({fraction:g} of centreline v_z) at z = "
                               f"{float(entry['z_m']) * 1000:.0f} mm", case_name, half, error, "m",
                        f"the silo's half-width is {half_silo * 1000:.0f} mm: narrower "
                        f"{resolution(half_silo - half, error, dof)}{tail}", dof=dof,
                        study="funnel flow: narrower than the silo (§5.4.3.5)", differs=differs))
    return rows


def _index_at(fields: Mapping, height: float) -> tuple[float, float, float]:
    """The flow-pattern index (and error) at the profile height nearest ``height`` (m), with that height."""
    indices = fields.get("flow_pattern_index") or {}
    if not indices:
        return math.nan, math.nan, math.nan
    nearest = min(indices, key=lambda key: abs(float(key) - height))
    return (number_or_nan(indices[nearest]), number_or_nan((fields.get("flow_pattern_index_error") or {}).get(nearest)),
            float(nearest))


#: The height of S6's velocities (m, §5.5).
S6_HEIGHT = 0.12


def front_wall_series_rows(series: Sequence[tuple[str, SiloRun, str]], height: float,
                           tolerances: AgreementTolerances, dof: float | None) -> list[dict]:
    """The front-wall friction series: per run (label, run, seed note) its flow-pattern index (wall over centreline
    v_z) at the profile height nearest ``height`` (m), a measurement; S6.towards_internal_flow, the index's change
    from front/back friction 0 to the highest (labels ``mu_fw=<value>``); S6.hydrostatic of the frictionless run.

    ``dof`` is that of the runs' errors (seeds - 1 of the spread they carry; None for within-run errors).
    """
    rows, walled = [], []
    for label, run, note in series:
        index, error, at = _index_at(run.fields, height)
        rows.append(row(SERIES_GROUP, f"Flow-pattern index (wall / centreline v_z) at z = {at * 1000:.0f} mm", label,
                        index, error, "-",
                        f"run {run.case['run_id']}, flow rate "
                        f"{plus_minus(run.flow['mass_flow_rate_kg_s'], number_or_nan(run.flow.get('mass_flow_rate_kg_s_error')))}"
                        f" kg/s; {note}", dof=dof, study="-",
                        differs=window_clause(run.fields, run.flow, "velocities", "§5.5.2")))
        if label.startswith("mu_fw="):
            walled.append((float(label.split("=", 1)[1]), index, error, at, run, note))
    walled.sort(key=lambda entry: entry[0])
    if len(walled) >= 2:
        (low, index_low, error_low, at, _, note_low), (high, index_high, error_high, _, _, note_high) = walled[0], walled[-1]
        change = index_high - index_low, combine_independent([error_low, error_high])
        differs = [f"at z = {at * 1000:.0f} mm, not {S6_HEIGHT * 1000:.0f} mm"] if abs(at - S6_HEIGHT) > 1e-9 else []
        if (low, high) != (0.0, 1.0):
            differs.append(f"front/back friction {low:g} to {high:g}, not 0 to 1")
        # the study's profiles of the series are averaged over 0.5-0.7 s too (§5.5.2); each run says its own window
        differs += list(dict.fromkeys(filter(None, (window_clause(run.fields, run.flow, "velocities", "§5.5.2")
                                                    for run in (walled[0][4], walled[-1][4])))))
        rows.append(row(SERIES_GROUP, f"Change of the flow-pattern index, front-wall friction {high:g} - {low:g}",
                        "series", *change, "-", f"{low:g}: {note_low}; {high:g}: {note_high}", dof=dof,
                        finding="S6.towards_internal_flow", differs="; ".join(differs),
                        agreement=rules.sign_of_change(*change, dof, PARTS["S6.towards_internal_flow"])))
    if walled and walled[0][0] == 0.0 and walled[0][4].janssen:
        run, note = walled[0][4], walled[0][5]
        settled, settled_text = run.settled()
        deepest = max(run.janssen, key=lambda entry: float(entry["depth_below_surface_m"]))
        sigma = float(deepest["sigma_v_dem_Pa"]), number_or_nan(deepest.get("sigma_v_dem_Pa_error"))
        hydrostatic = float(deepest["hydrostatic_pa"]), number_or_nan(deepest.get("hydrostatic_pa_error"))
        rows.append(row(SERIES_GROUP, f"Vertical stress / hydrostatic, "
                                      f"{float(deepest['depth_below_surface_m']) * 1000:.0f} mm below the surface, "
                                      "front/back friction 0", "mu_fw=0", *ratio(*sigma, *hydrostatic), "-",
                        f"{settled_text}; DEM {plus_minus(*sigma)} Pa against rho g h {hydrostatic[0]:.4g} Pa; {note}",
                        dof=dof, finding="S6.hydrostatic",
                        agreement=rules.ratio_in_band(*sigma, *hydrostatic, dof, PARTS["S6.hydrostatic"], tolerances,
                                                      steady=settled)))
    return rows
