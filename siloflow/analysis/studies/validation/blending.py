"""Validation rows of the blending studies: the recirculating silo (VRR, RTD, flowing bulk density) and the
multi-flow blender (passage velocities, mass flow of the insert, gravity series).

Inputs are files as read: per recirculation run its ``case.json``, ``blending.json`` and the rows of its
``rtd.csv``; per blender run its ``blender.json``. A VRR is shown when it lies below the counting-noise ceiling
of the outlet windows (their clump count); a blender insert is in mass flow when its exterior annulus moves at
least ``mass_flow_velocity_ratio`` of the tube's velocity.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation.rows import Criteria, plus_minus, precise, ratio, resolved, row, verdict

__all__ = ["rtd_peak", "recirculation_rows", "blender_rows", "gravity_rows"]

RECIRCULATION_GROUP = "Recirculating silo (blending)"
BLENDER_GROUP = "Multi-flow blender"
GRAVITY_GROUP = "Blender gravity series"
#: The passages of the blender (metric key: name in the geometry's clear widths), outermost first.
PASSAGES = {"exterior": "exterior annulus", "interior": "interior annulus", "tube": "tube"}
#: Figures whose scaling with sqrt(g) the gravity rows test.
GRAVITY_FIGURES = {"mass_flow_rate_kg_s": "mass flow rate", "tube_v_z_m_s": "tube velocity",
                   "exterior_v_z_m_s": "exterior annulus velocity"}


def rtd_peak(times, density, t_mean: float, t_mean_error: float) -> tuple[float, float]:
    """The RTD's peak in normalised time, theta = t_peak / t_mean, and its standard error (-).

    The peak is the bin of largest E(t) (the first of equal ones); its time is known to a bin, so its error is
    the bin width over sqrt(12), combined with the relative error of the mean.

    Parameters
    ----------
    times : array_like, shape (n,)
        Bin centres, equally spaced (s).
    density : array_like, shape (n,)
        E(t) at each bin (1/s).
    t_mean, t_mean_error : float
        The RTD's mean residence time and its standard error (s).
    """
    t = np.asarray(times, dtype=float)
    e = np.asarray(density, dtype=float)
    if t.ndim != 1 or t.shape != e.shape or t.size < 2:
        raise ValueError("times and density must be equal 1-D arrays of at least two bins")
    peak = float(t[int(np.argmax(e))])
    width = float(t[1] - t[0])
    return ratio(peak, width / math.sqrt(12.0), t_mean, t_mean_error)


def _depth_check(case: Mapping, criteria: Criteria) -> tuple[bool, str]:
    depth, diameter = float(case["depth_m"]), float(case["equivalent_diameter_m"])
    return depth / diameter >= criteria.min_depth_diameters, (
        f"depth {depth * 1000:.1f} mm = {depth / diameter:.1f} particle diameters (>= {criteria.min_depth_diameters:g})")


def recirculation_rows(case: Mapping, summary: Mapping, rtd: Sequence[Mapping], criteria: Criteria) -> list[dict]:
    """Rows of one recirculating-silo run: VRR after the second recirculation per batch layout, the RTD's peak
    and t_s/t_d, and the drop of bulk density while it flows."""
    depth_ok, depth_text = _depth_check(case, criteria)
    pattern = summary["flow_pattern"]
    window = float(summary["clumps_per_window"])
    rows = []
    for name, layout in summary["layouts"].items():
        values, errors = layout["vrr_by_recirculation"], layout["vrr_by_recirculation_error"]
        ceiling = layout["vrr_at_ceiling"]
        nr = min(2, len(values))
        listing = "; ".join(f"Nr {i + 1}: {plus_minus(v, number_or_nan(e))}{' (ceiling)' if c else ''}"
                            for i, (v, e, c) in enumerate(zip(values, errors, ceiling)))
        below = not ceiling[nr - 1]
        rows.append(row(RECIRCULATION_GROUP, f"VRR after recirculation {nr} ({name}: blue {layout['blue_fraction']:g}, "
                                             f"{layout['sublayers']} layer(s))", pattern, values[nr - 1],
                        number_or_nan(errors[nr - 1]), "-", "", verdict(depth_ok, below),
                        f"{depth_text}; outlet windows of {window:.0f} clumps resolve a VRR up to the ceiling "
                        f"{float(summary['vrr_sampling_limit']):.0f}; {listing}"))
    ids = summary["rtd_particle_ids"]
    chosen = [entry for entry in rtd if entry["method"] == "particle_ids"]
    if chosen:
        theta, theta_error = rtd_peak([float(e["time_s"]) for e in chosen], [float(e["E_per_s"]) for e in chosen],
                                      float(ids["t_mean_s"]), number_or_nan(ids.get("t_mean_s_error")))
        theta_precise, theta_text = precise(theta, theta_error, criteria)
        rows.append(row(RECIRCULATION_GROUP, "RTD peak theta = t_peak / t_mean", pattern, theta, theta_error, "-", "",
                        verdict(depth_ok, theta_precise),
                        f"{depth_text}; {int(ids['n_tracer'])} tracer clumps, {len(chosen)} bins; {theta_text}"))
    first, first_error = ids["t_s_over_t_d"], number_or_nan(ids.get("t_s_over_t_d_error"))
    first_precise, first_text = precise(first, first_error, criteria)
    rows.append(row(RECIRCULATION_GROUP, "First appearance / discharge time t_s/t_d", pattern, first, first_error, "-",
                    "", verdict(depth_ok, first_precise),
                    f"{depth_text}; {int(ids['n_tracer'])} tracer clumps; {first_text}"))
    if "bulk_density_drop" in summary:
        drop, error = summary["bulk_density_drop"], number_or_nan(summary.get("bulk_density_drop_error"))
        seen = resolved(drop, error, criteria.coverage_factor)
        low, high = summary["bulk_density_slab_m"]
        rows.append(row(RECIRCULATION_GROUP, "Flowing bulk density drop, 1 - rho_flowing / rho_settled", pattern,
                        drop, error, "-", "the fill dilates while it flows", verdict(depth_ok, seen),
                        f"{depth_text}; slab {low * 1000:.0f}-{high * 1000:.0f} mm: settled "
                        f"{summary['settled_bulk_density_kg_m3']:.1f}, flowing "
                        f"{plus_minus(summary['flowing_bulk_density_kg_m3'], number_or_nan(summary.get('flowing_bulk_density_kg_m3_error')), 4)} kg/m3"))
    return rows


def _metric(metrics: Mapping, key: str) -> tuple[float, float]:
    return number_or_nan(metrics.get(key)), number_or_nan(metrics.get(f"{key}_error"))


def _passages(widths: Mapping) -> dict[str, tuple[str, int]]:
    """The passages a planar cross-section crosses, ``{key: (name, count)}``: the annuli twice (left and right)
    except the interior one of an insert without a tube, which spans both plates; the tube once."""
    present = {key: name for key, name in PASSAGES.items() if name in widths}
    return {key: (name, 1 if key == "tube" or (key == "interior" and "tube" not in present) else 2)
            for key, name in present.items()}


def _cross_section_mean(metrics: Mapping, widths: Mapping) -> tuple[float, float]:
    """Width-weighted mean v_z over the passages a planar cross-section crosses, and its error (m/s)."""
    total, weighted, errors = 0.0, 0.0, []
    for key, (passage, count) in _passages(widths).items():
        value, error = _metric(metrics, f"{key}_v_z_m_s")
        weight = count * float(widths[passage])
        total += weight
        weighted += weight * value
        errors.append(weight * error)
    return weighted / total, combine_independent(errors) / total


def _in_mass_flow(metrics: Mapping, widths: Mapping, criteria: Criteria) -> tuple[tuple[float, float], bool]:
    """Exterior annulus over innermost passage velocity (the tube, else the interior annulus), and whether it
    reaches the mass-flow ratio."""
    inner = "tube" if "tube" in widths else "interior"
    exterior_over_inner = ratio(*_metric(metrics, "exterior_v_z_m_s"), *_metric(metrics, f"{inner}_v_z_m_s"))
    return exterior_over_inner, exterior_over_inner[0] >= criteria.mass_flow_velocity_ratio


def blender_rows(summaries: Sequence[Mapping], cases: Sequence[Mapping], criteria: Criteria) -> list[dict]:
    """Per configuration at the lowest gravity factor: each passage's velocity over the cross-section mean, whether
    the insert is in mass flow (exterior over tube velocity), its mean residence time and recirculations to
    homogenise. The blender's scale shows them when the configuration designed for mass flow
    (``criteria.mass_flow_configuration``) is in mass flow; ``cases`` are the runs' ``case.json``, in order."""
    lowest = min(float(s["gravity_factor"]) for s in summaries)
    chosen = sorted(((s, c) for s, c in zip(summaries, cases) if float(s["gravity_factor"]) == lowest),
                    key=lambda pair: pair[0]["configuration"])
    reference = [s for s, _ in chosen if s["configuration"] == criteria.mass_flow_configuration]
    scale_ok = (_in_mass_flow(reference[0]["metrics"], reference[0]["geometry"]["clear_widths"], criteria)[1]
                if reference else None)
    scale_text = (f"{criteria.mass_flow_configuration} insert "
                  f"{'in mass flow' if scale_ok else 'not in mass flow' if scale_ok is False else 'not run'}")
    rows = []
    for summary, case in chosen:
        metrics, name = summary["metrics"], summary["configuration"]
        depth = (f"depth {float(case['depth_m']) * 1000:.1f} mm = "
                 f"{float(case['depth_m']) / float(case['equivalent_diameter_m']):.1f} particle diameters")
        widths = summary["geometry"]["clear_widths"]
        mean, mean_error = _cross_section_mean(metrics, widths)
        for key, (passage, _) in _passages(widths).items():
            value = ratio(*_metric(metrics, f"{key}_v_z_m_s"), mean, mean_error)
            value_precise, value_text = precise(*value, criteria)
            rows.append(row(BLENDER_GROUP, f"{passage.capitalize()} v_z / cross-section mean", name, *value, "-", "",
                            verdict(scale_ok, value_precise),
                            f"{scale_text}; cross-section mean {plus_minus(mean, mean_error)} m/s (passages weighted by "
                            f"their clear widths); {depth}; {value_text}"))
        exterior_over_tube, in_mass_flow = _in_mass_flow(metrics, widths, criteria)
        inner = "tube" if "tube" in widths else "interior annulus"
        rows.append(row(BLENDER_GROUP, f"Exterior annulus / {inner} v_z (mass flow of the insert)", name,
                        *exterior_over_tube, "-",
                        "mass flow" if name == criteria.mass_flow_configuration else "",
                        verdict(scale_ok),
                        f"{'in' if in_mass_flow else 'not in'} mass flow: the exterior annulus moves at "
                        f"{exterior_over_tube[0]:.2f} of the {inner}'s velocity (mass flow from "
                        f"{criteria.mass_flow_velocity_ratio:g}); {depth}, {summary['n_clumps']} clumps"))
        for key, label in (("rtd_mean_s", "Mean residence time"),
                           ("recirculations_to_homogenise", "Recirculations to homogenise")):
            value = _metric(metrics, key)
            value_precise, value_text = precise(*value, criteria)
            rows.append(row(BLENDER_GROUP, label, name, *value, "s" if key.endswith("_s") else "-", "",
                            verdict(scale_ok, value_precise),
                            f"{scale_text}; error from the run's tracer counts; {value_text}"))
    return rows


def gravity_rows(summaries: Sequence[Mapping], criteria: Criteria) -> list[dict]:
    """Per configuration run at 1 g and other factors f: (q_f / q_1g) / sqrt(f) for the flow rate and passage
    velocities; 1 where q scales with sqrt(g)."""
    rows = []
    k = criteria.coverage_factor
    for name in sorted({s["configuration"] for s in summaries}):
        runs = {float(s["gravity_factor"]): s["metrics"] for s in summaries if s["configuration"] == name}
        if 1.0 not in runs or len(runs) < 2:
            continue
        for factor in sorted(f for f in runs if f != 1.0):
            for key, label in GRAVITY_FIGURES.items():
                value, error = ratio(*_metric(runs[factor], key), *_metric(runs[1.0], key))
                scaled, scaled_error = value / math.sqrt(factor), error / math.sqrt(factor)
                off = resolved(scaled - 1.0, scaled_error, k)
                scaled_precise, scaled_text = precise(scaled, scaled_error, criteria)
                rows.append(row(GRAVITY_GROUP, f"{label.capitalize()} at {factor:g} g / (1 g value x sqrt({factor:g}))",
                                name, scaled, scaled_error, "-", "flow rate and mean velocity scale with sqrt(g)",
                                verdict(scaled_precise),
                                f"{'does not scale' if off else 'scales' if off is False else 'unknown'} with sqrt(g) "
                                f"at {k:g} standard errors; {scaled_text}"))
    return rows
