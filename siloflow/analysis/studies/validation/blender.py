"""Validation rows of the multi-flow blender (thesis ch. 7): each judged against a finding part M1-M3 where the study
states one, else a measurement with no finding; and the gravity series: M4 at fixed moduli, a similarity check of the
code at scaled ones.

Rows, from the runs at 1 g (see :mod:`siloflow.analysis.studies.validation.rows`):

- M1: the diverging insert's steady velocity of each passage at the insert outlet over the cross-section mean;
- M2: the converging insert's order tube > interior > exterior annulus at the insert outlet (downward speeds), the
  interior minus the exterior annulus velocity at the insert inlet over the cross-section mean there, and per height
  in the vertical section above the internals the largest deviation of a bin's velocity across the width from their
  mean, relative to it, the bins within one tube width of the tube left out (:func:`_vertical_rows`);
- M3: the VRR of the continuous mode at one input period (``metrics.vrr_by_period["1"]``, LTI of the RTD),
  converging over straight and over diverging;
- the other inserts' passage velocities over the cross-section mean, and every insert's mean residence time and
  recirculations to homogenise, with no finding.

The cross-section mean at a height is the mean over the bins of all its passages (each passage's mean weighted by
its bins there: equal bins, so by its width at that height), as the study normalised its profiles by the mean
across the section (§7.4, §7.5).

M1 and M2 are the study's PIV, which sees the front wall (§7.2; its DEM gave both the front wall and the depth
average, §7.7, §7.8.2.1). Where ``blender.json`` has the wall layer (``wall_layer``: the clumps within a particle
diameter of the front and back walls, :func:`siloflow.analysis.studies.blender.window_fields.wall_layer_positions`)
their rows judge its figures and quote the depth average's beside them; a summary without it gives the depth
average's, and ``differs`` says that it is not the PIV's plane (:data:`DEPTH_AVERAGED`).

Gravity series (:func:`gravity_rows`), by the rule ``blender.gravity_moduli`` the runs were made with:

- at fixed moduli, the study's series (§7.9, the same material at every factor): M4, each figure's exponent
  against the gravity factor (a weighted fit of its logarithm, :func:`~siloflow.analysis.studies.validation.agreement.
  power_law`), the mass flow rate and the cross-section mean velocity judged as scaling with ``sqrt(g)``, the
  annuli's velocities at the insert outlet as deviating from it, and the change of the annuli's velocity
  differential at the insert inlet over ``sqrt(g / g0)``, from 1 g to the largest factor, as decreasing. The study
  ran the diverging insert (its "Inward", inferred): another insert's rows state no finding.
- at scaled moduli, every Young's modulus times ``f`` and every time over ``sqrt(f)``
  (:mod:`siloflow.model.cases.blender`): the flow is similar to the 1 g run's and every rate scales with ``sqrt(g)``
  by construction, so the rows check the code's similarity and state no finding.

A run's moduli are scaled when its ``case.json`` parameters hold ``youngs_modulus_factor``.

Inputs are per-run mappings ``{"case": case.json, "summary": blender.json, "note": str, "dof": float | None}``:
``note`` is the evidence about the run's seeds, appended to the evidence of every row that draws on the run;
``dof`` the degrees of freedom of its errors (seeds - 1; None for within-run errors).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.numerics.vrr_noise import vrr_near_ceiling
from siloflow.analysis.studies.validation import agreement as rules
from siloflow.analysis.studies.validation.agreement import AgreementTolerances, capped, ratio
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.analysis.studies.validation.rows import (joined, plus_minus, precise, resolution, resolved, row,
                                                      smallest_dof)

__all__ = ["BLENDER_GROUP", "GRAVITY_GROUP", "FIXED_GRAVITY_GROUP", "MADE", "UNMADE", "DEPTH_AVERAGED", "smallest_dof",
           "capped",           "section_mean", "blender_rows", "gravity_rows"]

BLENDER_GROUP = "Multi-flow blender"
GRAVITY_GROUP = "Blender gravity series: similarity check of the code (scaled moduli)"
FIXED_GRAVITY_GROUP = "Blender gravity series at fixed moduli"
#: The insert of the study's gravity series (§7.9: its table's "Inward", the text's diverging insert).
STUDY_GRAVITY_INSERT = "diverging"
#: The study's gravity factors (§7.9).
STUDY_GRAVITY_FACTORS = (1.0, 5.0, 50.0)
#: The passages at the insert outlet (metric key: name), innermost first, and their names in the geometry's clear
#: widths.
PASSAGES = {"tube": "tube", "interior": "interior annulus", "exterior": "exterior annulus"}
#: The input period over t_m of M3's VRR (the key of ``metrics.vrr_by_period``).
M3_PERIOD = "1"
#: Figures whose sqrt(g) scaling the gravity rows check: metric key, name, unit.
GRAVITY_FIGURES = (("mass_flow_rate_kg_s", "mass flow rate", "kg/s"), ("tube_v_z_m_s", "tube velocity", "m/s"),
                   ("exterior_v_z_m_s", "exterior annulus velocity", "m/s"))
GRAVITY_STUDY = ("identity: with every modulus scaled by g and every time by 1/sqrt(g) the flow is similar, so it "
                 "scales with sqrt(g) by construction; a check of the code's similarity, not the study's M4 (fixed "
                 "material, §7.9)")
#: The finding parts of ch. 7 these rows make (given the runs each needs).
MADE = ("M1.exterior", "M1.interior", "M1.tube", "M2.outlet_order", "M2.inlet_uniform", "M2.vertical_uniform",
        "M3.over_straight", "M3.over_diverging", "M4.mass_flow", "M4.mean_velocity", "M4.exterior_deviates",
        "M4.interior_deviates", "M4.inlet_differential_decreases")
#: The ``differs`` clause of a PIV figure (M1, M2) taken from the depth average: the summary has no wall layer.
DEPTH_AVERAGED = ("averaged over the depth, not in the layer at the front wall the study's PIV sees (§7.2, §7.5; "
                  "its DEM gave both, §7.8.2.1)")
#: The parts of ch. 7 these rows cannot make: none (M4 needs blender.gravity_moduli fixed).
UNMADE: Mapping[str, str] = MappingProxyType({})


def _metric(metrics: Mapping, key: str) -> tuple[float, float]:
    return number_or_nan(metrics.get(key)), number_or_nan(metrics.get(f"{key}_error"))


def _continuous(summary: Mapping) -> str:
    """The ``differs`` clause of a run not in the study's continuous (constant-head) discharge."""
    mode = summary.get("mode", "continuous")
    return "" if mode == "continuous" else (
        f"{mode} discharge: the study's figure is of the continuous (constant-head) discharge (§7.5)")


def section_mean(velocities: Mapping[str, tuple[float, float]], weights: Mapping[str, float]) -> tuple[float, float]:
    """Weighted mean of passage velocities over a cross-section and its error (m/s), the passages independent.

    Parameters
    ----------
    velocities : mapping name -> (float, float)
        Each passage's mean v_z and its standard error (m/s).
    weights : mapping name -> float
        Each passage's weight (its bins or width at that height), > 0, for every name of ``velocities`` (-).
    """
    total = sum(float(weights[key]) for key in velocities)
    if not total > 0:
        raise ValueError("the passages' weights must add up to more than 0")
    mean = sum(float(weights[key]) * v for key, (v, _) in velocities.items()) / total
    return mean, combine_independent([float(weights[key]) * e for key, (_, e) in velocities.items()]) / total


def _outlet(summary: Mapping) -> tuple[dict, tuple[float, float], str, str]:
    """The passages' depth-averaged (v_z, error) at the insert outlet (m/s), their cross-section mean, the evidence of
    its weights and the ``differs`` clause when they are not the passages' widths at the insert outlet."""
    metrics = summary["metrics"]
    velocities = {key: _metric(metrics, f"{key}_v_z_m_s") for key in PASSAGES}
    velocities = {key: value for key, value in velocities.items() if math.isfinite(value[0])}
    bins = ((summary.get("passages_at_insert_outlet") or {}).get("n_bins")) or {}
    if all(bins.get(key) for key in velocities):
        weights = {key: float(bins[key]) for key in velocities}
        return velocities, section_mean(velocities, weights), _weighting(weights, "outlet"), ""
    # An older summary has no bins: the narrowest clear widths stand in, each annulus crossed twice by a planar
    # section, the tube (and an interior passage without a tube, spanning both plates) once.
    widths = summary["geometry"]["clear_widths"]
    once = {"tube", "interior"} if "tube" not in velocities else {"tube"}
    weights = {key: (1 if key in once else 2) * float(widths[PASSAGES[key]]) for key in velocities}
    return velocities, section_mean(velocities, weights), "passages weighted by their narrowest clear widths", (
        "cross-section mean weighted by the passages' narrowest clear widths, not their widths at the insert outlet")


def _weighting(bins: Mapping[str, float], level: str) -> str:
    return (f"passages weighted by their bins at the insert {level} ("
            + ", ".join(f"{key} {int(w)}" for key, w in bins.items()) + ")")


def _wall_layer(summary: Mapping, level: str) -> tuple[dict, dict, str] | None:
    """The wall layer's passages at the insert ``level`` (``"outlet"`` or ``"inlet"``): name -> (v_z, error) (m/s) of
    those with a velocity and bins, name -> bins, and the evidence of the layer; None when the summary has none."""
    layer = summary.get("wall_layer") or {}
    passages = layer.get(f"passages_at_insert_{level}") or {}
    means, errors, bins = (passages.get(key) or {} for key in ("mean_v_z_m_s", "mean_v_z_m_s_error", "n_bins"))
    velocities = {key: (number_or_nan(means.get(key)), number_or_nan(errors.get(key))) for key in PASSAGES
                  if key in means and bins.get(key)}
    velocities = {key: value for key, value in velocities.items() if math.isfinite(value[0])}
    if not velocities:
        return None
    return velocities, {key: float(bins[key]) for key in velocities}, _wall_layer_label(summary)


def _wall_layer_label(summary: Mapping) -> str:
    """The evidence's name of the wall layer: its depth and walls, and that it is the PIV's plane."""
    layer = summary.get("wall_layer") or {}
    depth = number_or_nan(layer.get("depth_m")) * 1000
    return f"wall layer ({depth:.3g} mm from the {layer.get('walls') or 'front wall'}), the plane the study's PIV sees"


def _steady(summary: Mapping) -> str:
    """The evidence's discharge mode and averaging window of a run, beside the study's: its PIV findings (M1, M2) are
    of the continuous discharge averaged over 2 s (§7.5), its DEM discharged in batch and averaged over 3-4 s (§7.7)."""
    low, high = summary.get("steady_window_s") or (math.nan, math.nan)
    return (f"{summary.get('mode', 'continuous')} discharge averaged over its steady window {float(low):g}-{float(high):g} "
            "s after opening (the study's PIV: continuous discharge, 2 s averages, §7.5; its DEM: batch discharge, "
            "3-4 s, §7.7)")


def _passage_rows(summary: Mapping, note: str, dof, tolerances: AgreementTolerances) -> list[dict]:
    """Each passage's v_z over the cross-section mean at the insert outlet: M1 for the diverging insert, of the wall
    layer where the summary has it (the depth average's quoted beside), else of the depth average."""
    name = summary["configuration"]
    velocities, (mean, mean_error), weighting, depth_differs = _outlet(summary)
    if not {"interior", "exterior"} <= velocities.keys():
        return []
    wall_velocities, wall_bins, plane = _wall_layer(summary, "outlet") or ({}, {}, "")
    wall_mean = section_mean(wall_velocities, wall_bins) if wall_velocities else (math.nan, math.nan)
    depth_clause = joined((depth_differs, DEPTH_AVERAGED, _continuous(summary)))
    rows = []
    for key, (value, error) in velocities.items():
        depth_share = ratio(value, error, mean, mean_error)
        depth_text = (f"{PASSAGES[key]} {plus_minus(value, error)} m/s, cross-section mean "
                      f"{plus_minus(mean, mean_error)} m/s ({weighting})")
        if key in wall_velocities:
            share, row_differs = ratio(*wall_velocities[key], *wall_mean), _continuous(summary)
            evidence = (f"{plane}: {PASSAGES[key]} {plus_minus(*wall_velocities[key])} m/s, cross-section mean "
                        f"{plus_minus(*wall_mean)} m/s ({_weighting(wall_bins, 'outlet')}); depth-averaged "
                        f"{plus_minus(*depth_share)}: {depth_text}")
        else:
            share, row_differs, evidence = depth_share, depth_clause, f"depth-averaged: {depth_text}"
        evidence += f"; {_steady(summary)}; {precise(*share, tolerances)[1]}; {note}"
        figure = f"{PASSAGES[key].capitalize()} v_z / cross-section mean at the insert outlet"
        if name == "diverging":
            part = PARTS[f"M1.{key}"]
            rows.append(row(BLENDER_GROUP, figure, name, *share, "-", evidence, dof=dof, finding=part.id,
                            agreement=rules.value_in_band(*share, dof, part, tolerances), differs=row_differs))
        else:
            rows.append(row(BLENDER_GROUP, figure, name, *share, "-", evidence, dof=dof, study="-",
                            differs=row_differs))
    return rows


def _converging_rows(summary: Mapping, note: str, dof, tolerances: AgreementTolerances) -> list[dict]:
    """M2.outlet_order (downward speeds, tube first), M2.inlet_uniform and M2.vertical_uniform of the converging
    insert, of the wall layer where the summary has it."""
    name, rows = summary["configuration"], []
    depth_velocities, _, _, _ = _outlet(summary)
    wall = _wall_layer(summary, "outlet")
    velocities, plane, differs = ((wall[0], wall[2], _continuous(summary)) if wall is not None else
                                  (depth_velocities, "depth-averaged",
                                   joined((DEPTH_AVERAGED, _continuous(summary)))))
    if {"tube", "interior", "exterior"} <= velocities.keys():
        # Downward speeds, so that "fastest" is the largest, as the study's order reads.
        speeds = [(-velocities[key][0], velocities[key][1]) for key in ("tube", "interior", "exterior")]
        values, errors = [s[0] for s in speeds], [s[1] for s in speeds]
        rows.append(row(BLENDER_GROUP, "Downward speed at the insert outlet, tube > interior > exterior annulus",
                        name, values[0], errors[0], "m/s",
                        f"{plane}: " + "; ".join(f"{PASSAGES[key]} {plus_minus(v, e)} m/s" for key, v, e in
                                                  zip(("tube", "interior", "exterior"), values, errors))
                        + f" (value column: tube); {_steady(summary)}; {note}", dof=dof, finding="M2.outlet_order",
                        agreement=rules.in_order(values, errors, dof, PARTS["M2.outlet_order"]), differs=differs))
    rows += _inlet_rows(summary, note, dof, tolerances)
    rows += _vertical_rows(summary, note, dof, tolerances)
    return rows


def _inlet_rows(summary: Mapping, note: str, dof, tolerances: AgreementTolerances) -> list[dict]:
    """M2.inlet_uniform: the interior minus the exterior annulus velocity at the insert inlet over the cross-section
    mean there."""
    wall = _wall_layer(summary, "inlet")
    if wall is not None:
        passages, bins, plane = wall
        measured, differs = "", _continuous(summary)
    else:
        passages, bins = _inlet_passages(summary)
        if not {"interior", "exterior"} <= passages.keys():
            return []
        # The depth average's inlet means have no batch means behind them: an error only where one is written.
        written = (summary.get("passages_at_insert_inlet") or {}).get("mean_v_z_m_s_error")
        plane = "depth-averaged"
        measured = "" if written else "; its error is not measured (blender.json has no error of the inlet's passages)"
        differs = joined((DEPTH_AVERAGED, _continuous(summary)))
    if not {"interior", "exterior"} <= passages.keys():
        return []
    mean, mean_error = section_mean(passages, bins)
    (interior, e_i), (exterior, e_e) = passages["interior"], passages["exterior"]
    change, change_error = ratio(interior - exterior, combine_independent([e_i, e_e]), mean, mean_error)
    return [row(BLENDER_GROUP, "Interior minus exterior annulus v_z at the insert inlet / cross-section mean",
                summary["configuration"], change, change_error, "-",
                f"{plane}: interior {plus_minus(interior, e_i)} m/s, exterior {plus_minus(exterior, e_e)} m/s, mean "
                f"{plus_minus(mean, mean_error)} m/s over {sum(int(b) for b in bins.values())} bins"
                f"{measured}; {_steady(summary)}; {note}", dof=dof, finding="M2.inlet_uniform",
                agreement=rules.negligible(change, change_error, dof, 1.0, PARTS["M2.inlet_uniform"], tolerances),
                differs=differs)]


def _pair(entry: Mapping, key: str) -> tuple[float, float]:
    """A figure of a summary entry and its error (NaN where absent)."""
    return number_or_nan(entry.get(key)), number_or_nan(entry.get(f"{key}_error"))


def _uniformity_text(entry: Mapping) -> str:
    """Evidence of one height's uniformity figure (an entry of ``vertical_section``)."""
    value = _pair(entry, "largest_deviation")
    mean = _pair(entry, "mean_v_z_m_s")
    excluded = (f", {int(entry['excluded_bins'])} bins within {number_or_nan(entry.get('exclusion_m')) * 1000:.3g} mm "
                "of the tube left out" if entry.get("excluded_bins") else "")
    at = number_or_nan(entry.get("deviation_x_m")) * 1000
    return (f"largest deviation {plus_minus(*value)} at x = {at:.0f} mm from the mean v_z {plus_minus(*mean)} m/s of "
            f"{int(entry.get('n_bins') or 0)} bins across the width{excluded} ({int(entry.get('batches') or 0)} "
            "batches of frames)")


def _vertical_rows(summary: Mapping, note: str, dof, tolerances: AgreementTolerances) -> list[dict]:
    """M2.vertical_uniform: per height of the vertical section, the largest deviation of a bin's v_z across the width
    from the mean of the bins kept (those within one tube width of the tube left out), relative to the mean; of the
    wall layer where the summary has it, the depth average's quoted beside. No row from a summary without
    ``vertical_section`` (written before it was computed) or with no height above the internals."""
    layer = (summary.get("wall_layer") or {}).get("vertical_section") or {}
    depth = summary.get("vertical_section") or {}
    chosen = layer or depth
    if layer:
        plane = _wall_layer_label(summary)
        differs = _continuous(summary)
    else:
        plane = "depth-averaged"
        differs = joined((DEPTH_AVERAGED, _continuous(summary)))
    rows = []
    for key in sorted(chosen, key=float):
        entry = chosen[key]
        value, error = _pair(entry, "largest_deviation")
        evidence = f"{plane}: {_uniformity_text(entry)}"
        if layer and key in depth:
            evidence += f"; depth-averaged: {_uniformity_text(depth[key])}"
        height = number_or_nan(entry.get("height_m")) * 1000
        rows.append(row(BLENDER_GROUP, f"Largest deviation of v_z across the vertical section / its mean, z = "
                                       f"{height:.0f} mm ({entry.get('name') or 'vertical section'})",
                        summary["configuration"], value, error, "-", f"{evidence}; {_steady(summary)}; {note}",
                        dof=dof, finding="M2.vertical_uniform",
                        agreement=rules.negligible(value, error, dof, 1.0, PARTS["M2.vertical_uniform"], tolerances),
                        differs=differs))
    return rows


def _vrr(summary: Mapping) -> tuple[float, float, str]:
    """M3's VRR of a run, its error and why it is only a bound ("" when a measurement)."""
    metrics = summary["metrics"]
    value = number_or_nan((metrics.get("vrr_by_period") or {}).get(M3_PERIOD))
    error = number_or_nan((metrics.get("vrr_by_period_error") or {}).get(M3_PERIOD))
    ceiling = number_or_nan(metrics.get("vrr_ceiling"))
    if math.isfinite(value) and math.isfinite(ceiling) and ceiling > 0 and vrr_near_ceiling(value, ceiling):
        return value, error, (f"{summary['configuration']}'s VRR is near the counting-noise ceiling {ceiling:.0f} of "
                              "its tracers (a lower bound)")
    return value, error, ""


def _m3_rows(at_1g: Mapping[str, Mapping]) -> list[dict]:
    """M3: the converging insert's VRR of the continuous mode against the straight's and the diverging's."""
    rows = []
    if "converging" not in at_1g:
        return rows
    best = at_1g["converging"]
    for other in ("straight", "diverging"):
        if other not in at_1g:
            continue
        runs = (best, at_1g[other])
        taken = [_vrr(run["summary"]) for run in runs]
        values, errors = [t[0] for t in taken], [t[1] for t in taken]
        why, dof = "; ".join(t[2] for t in taken if t[2]), smallest_dof(*(run.get("dof") for run in runs))
        verdict = capped(rules.in_order(values, errors, dof, PARTS[f"M3.over_{other}"]), why)
        rows.append(row(BLENDER_GROUP, f"VRR of the continuous mode at period t_m, converging > {other}",
                        f"converging vs {other}", values[0], errors[0], "-",
                        "; ".join(f"{run['summary']['configuration']} {plus_minus(v, e)} ({run.get('note') or 'no note'})"
                                  for run, v, e in zip(runs, values, errors))
                        + " (value column: converging); sine input, LTI of the RTD of the steady field", dof=dof,
                        finding=f"M3.over_{other}", agreement=verdict,
                        differs=joined((_continuous(run["summary"]) for run in runs))))
    return rows


def blender_rows(runs: Sequence[Mapping], tolerances: AgreementTolerances) -> list[dict]:
    """The rows of the blender's runs at 1 g: per insert its passage velocities over the cross-section mean (M1 for
    the diverging insert), M2 for the converging one, its mean residence time and recirculations to homogenise
    (no finding); then M3 across inserts.

    Parameters
    ----------
    runs : sequence of mapping
        ``{"case", "summary", "note", "dof"}`` per run (see the module docstring); those at other gravity factors
        are left to :func:`gravity_rows`.
    tolerances : AgreementTolerances

    Returns
    -------
    list of dict
        Rows of :func:`~siloflow.analysis.studies.validation.rows.row`, insert by insert (alphabetical), then M3.
    """
    at_1g = {}
    for run in runs:
        if float(run["summary"]["gravity_factor"]) == 1.0:
            name = run["summary"]["configuration"]
            if name in at_1g:
                raise ValueError(f"two runs of {name} at 1 g: pass one run per configuration (its seeds combined)")
            at_1g[name] = run
    rows = []
    for name in sorted(at_1g):
        run = at_1g[name]
        summary, note, dof = run["summary"], run.get("note") or "", run.get("dof")
        rows += _passage_rows(summary, note, dof, tolerances)
        if name == "converging":
            rows += _converging_rows(summary, note, dof, tolerances)
        metrics = summary["metrics"]
        for key, figure, unit, study in (
                ("rtd_mean_s", "Mean residence time of the RTD", "s", "-"),
                ("recirculations_to_homogenise", "Recirculations to homogenise (discontinuous mode)", "-",
                 "- (M3 is judged on the VRR of the continuous mode)")):
            value, error = _metric(metrics, key)
            if math.isfinite(value):
                rows.append(row(BLENDER_GROUP, figure, name, value, error, unit,
                                f"{precise(value, error, tolerances)[1]}; {note}", dof=dof, study=study,
                                differs=_continuous(summary)))
    return rows + _m3_rows(at_1g)


def moduli_scaled(case: Mapping) -> bool:
    """Whether a run's Young's moduli were scaled with its gravity factor (its ``case.json`` parameters hold
    ``youngs_modulus_factor``, :func:`siloflow.model.cases.blender.build_blender_case`)."""
    return "youngs_modulus_factor" in (case.get("parameters") or {})


def gravity_rows(runs: Sequence[Mapping], tolerances: AgreementTolerances) -> list[dict]:
    """The gravity series of every configuration run at 1 g and at other factors: M4 where its runs are at fixed
    moduli (:func:`_fixed_moduli_rows`), a similarity check of the code where they are scaled
    (:func:`_similarity_rows`); see the module docstring.

    Parameters
    ----------
    runs : sequence of mapping
        ``{"case", "summary", "note", "dof"}`` per run; each row's evidence quotes the notes of its runs.
    tolerances : AgreementTolerances

    Returns
    -------
    list of dict
        Configuration by configuration (alphabetical), the rows of its series; none for a configuration without a
        1 g run or another factor.

    Raises
    ------
    ValueError
        Two runs of one configuration and factor, or a series whose runs beyond 1 g mix fixed and scaled moduli.
    """
    series: dict[str, dict[float, Mapping]] = {}
    for run in runs:
        summary = run["summary"]
        factors = series.setdefault(summary["configuration"], {})
        if float(summary["gravity_factor"]) in factors:
            raise ValueError(f"two runs of {summary['configuration']} at {float(summary['gravity_factor']):g} g: pass "
                             "one run per configuration and factor (its seeds combined)")
        factors[float(summary["gravity_factor"])] = run
    rows = []
    for name in sorted(series):
        by_factor = series[name]
        if 1.0 not in by_factor or len(by_factor) < 2:
            continue
        rules_used = {moduli_scaled(run.get("case") or {}) for factor, run in by_factor.items() if factor != 1.0}
        if len(rules_used) > 1:
            raise ValueError(f"the gravity series of {name} mixes runs at fixed and at scaled moduli "
                             "(blender.gravity_moduli): record one rule at a time")
        rows += (_similarity_rows if rules_used == {True} else _fixed_moduli_rows)(name, by_factor, tolerances)
    return rows


def _similarity_rows(name: str, by_factor: Mapping[float, Mapping], tolerances: AgreementTolerances) -> list[dict]:
    """At scaled moduli: per factor f other than 1, ``(q_f / q_1g) / sqrt(f)`` of the mass flow rate and the tube's
    and exterior annulus's velocities (1 where q scales with sqrt(g)), with no finding."""
    rows = []
    base = by_factor[1.0]
    for factor in sorted(f for f in by_factor if f != 1.0):
        run = by_factor[factor]
        dof = smallest_dof(base.get("dof"), run.get("dof"))
        for key, label, unit in GRAVITY_FIGURES:
            q1, qf = _metric(base["summary"]["metrics"], key), _metric(run["summary"]["metrics"], key)
            if not (math.isfinite(q1[0]) and math.isfinite(qf[0])):
                continue
            value, error = ratio(*qf, *q1)
            root = math.sqrt(factor)
            scaled, scaled_error = value / root, error / root
            off = resolved(scaled - 1.0, scaled_error, dof)
            verdict = "unknown whether it scales" if off is None else "does not scale" if off else "scales"
            rows.append(row(
                GRAVITY_GROUP, f"{label.capitalize()} at {factor:g} g / (1 g value × sqrt({factor:g}))", name,
                scaled, scaled_error, "-",
                f"{verdict} with sqrt(g): its departure from 1 is {resolution(scaled - 1.0, scaled_error, dof)}; "
                f"1 g: {plus_minus(*q1)} {unit} ({base.get('note') or 'no note'}); {factor:g} g: "
                f"{plus_minus(*qf)} {unit} ({run.get('note') or 'no note'}); "
                f"{precise(scaled, scaled_error, tolerances)[1]}",
                dof=dof, study=GRAVITY_STUDY))
    return rows


def _downward(pair: tuple[float, float]) -> tuple[float, float]:
    """A v_z and its error (m/s) as a downward speed and its error."""
    return -pair[0], pair[1]


def _inlet_passages(summary: Mapping) -> tuple[dict, dict]:
    """The depth-averaged passages at the insert inlet: name -> (v_z, error) (m/s; the error NaN where the summary
    writes none) and name -> bins; empty when the summary has no inlet."""
    inlet = summary.get("passages_at_insert_inlet") or {}
    means, bins, errors = inlet.get("mean_v_z_m_s") or {}, inlet.get("n_bins") or {}, inlet.get(
        "mean_v_z_m_s_error") or {}
    if not all(bins.get(key) for key in means):
        return {}, {}
    return ({key: (float(v), number_or_nan(errors.get(key))) for key, v in means.items()},
            {key: float(bins[key]) for key in means})


def _series_figures(summary: Mapping) -> dict[str, tuple[float, float]]:
    """The figures of one run that M4 scales (downward speeds, m/s; the mass flow rate, kg/s), each with its error;
    those the summary lacks are left out."""
    metrics = summary["metrics"]
    figures = {"mass_flow": _metric(metrics, "mass_flow_rate_kg_s")}
    for key in ("exterior", "interior"):
        figures[key] = _downward(_metric(metrics, f"{key}_v_z_m_s"))
    velocities, (mean, mean_error), _, _ = _outlet(summary)
    if velocities:
        figures["mean_outlet"] = _downward((mean, mean_error))
    passages, bins = _inlet_passages(summary)
    if passages:
        figures["mean_inlet"] = _downward(section_mean(passages, bins))
        if {"interior", "exterior"} <= passages.keys():
            (interior, e_i), (exterior, e_e) = passages["interior"], passages["exterior"]
            figures["inlet_differential"] = (abs(interior - exterior), combine_independent([e_i, e_e]))
    return {key: value for key, value in figures.items() if math.isfinite(value[0])}


#: M4's power-law figures: key of :func:`_series_figures`, the figure's name, its part.
_M4_POWER = (("mass_flow", "mass flow rate", "M4.mass_flow"),
             ("mean_outlet", "cross-section mean downward speed at the insert outlet", "M4.mean_velocity"),
             ("mean_inlet", "cross-section mean downward speed at the insert inlet", "M4.mean_velocity"),
             ("exterior", "exterior annulus downward speed at the insert outlet", "M4.exterior_deviates"),
             ("interior", "interior annulus downward speed at the insert outlet", "M4.interior_deviates"))


def _batch(summary: Mapping) -> str:
    """The ``differs`` clause of a gravity run not in the study's batch discharge (its DEM, §7.7)."""
    mode = summary.get("mode", "continuous")
    return "" if mode == "batch" else f"{mode} discharge: the study's gravity series discharged in batch (§7.7)"


def _fixed_moduli_rows(name: str, by_factor: Mapping[float, Mapping], tolerances: AgreementTolerances) -> list[dict]:
    """At fixed moduli: M4 for the study's insert (:data:`STUDY_GRAVITY_INSERT`), the same figures with no finding
    for another. Each power law is the exponent of a figure against the gravity factor over every factor run (the
    errors as known sigmas); the inlet differential's change is ``d_max / sqrt(f_max) - d_1g`` (m/s), ``d`` the
    absolute difference of the annuli's downward speeds at the insert inlet."""
    factors = sorted(by_factor)
    runs = [by_factor[f] for f in factors]
    figures = [_series_figures(run["summary"]) for run in runs]
    dof = smallest_dof(*(run.get("dof") for run in runs))
    notes = "; ".join(f"{f:g} g: {run.get('note') or 'no note'}" for f, run in zip(factors, runs))
    factors_text = ", ".join(f"{f:g}" for f in factors)
    differs = joined((
        "" if tuple(factors) == STUDY_GRAVITY_FACTORS else
        f"gravity factors {factors_text} (the study's {', '.join(f'{f:g}' for f in STUDY_GRAVITY_FACTORS)})",
        *(_batch(run["summary"]) for run in runs)))
    study = name == STUDY_GRAVITY_INSERT
    rows = []
    for key, label, part_id in _M4_POWER:
        if not all(key in entry for entry in figures) or not all(entry[key][0] > 0 for entry in figures):
            continue
        values, errors = [entry[key][0] for entry in figures], [entry[key][1] for entry in figures]
        exponent, error = rules.power_law_exponent(factors, values, errors)
        unit = "kg/s" if key == "mass_flow" else "m/s"
        evidence = (f"{label} at {factors_text} g: "
                    + ", ".join(f"{plus_minus(v, e)}" for v, e in zip(values, errors)) + f" {unit}; {notes}")
        judged = (dict(finding=part_id, agreement=rules.power_law(factors, values, errors, dof, PARTS[part_id],
                                                                   tolerances)) if study else dict(study="-"))
        rows.append(row(FIXED_GRAVITY_GROUP, f"Exponent of the {label} against the gravity factor", name, exponent,
                        error, "-", evidence, dof=dof, differs=differs, **judged))
    if all("inlet_differential" in entry for entry in figures):
        (first, first_error), (last, last_error) = figures[0]["inlet_differential"], figures[-1]["inlet_differential"]
        root = math.sqrt(factors[-1])
        change, change_error = last / root - first, combine_independent([last_error / root, first_error])
        evidence = (f"|interior - exterior| downward speed at the insert inlet, 1 g: {plus_minus(first, first_error)} "
                    f"m/s; {factors[-1]:g} g: {plus_minus(last, last_error)} m/s, over sqrt({factors[-1]:g}); {notes}")
        figure = (f"Change of the annuli's velocity differential at the insert inlet over sqrt(g / g0), 1 to "
                  f"{factors[-1]:g} g")
        part = PARTS["M4.inlet_differential_decreases"]
        judged = (dict(finding=part.id, agreement=rules.sign_of_change(change, change_error, dof, part)) if study
                  else dict(study="-"))
        rows.append(row(FIXED_GRAVITY_GROUP, figure, name, change, change_error, "m/s", evidence, dof=dof,
                        differs=differs, **judged))
    return rows
