"""The calibration's validation rows, each judged against a finding part C1-C7: exact answers on hand-built sweeps."""

import math

import pytest

from siloflow.analysis.studies.validation.agreement import (NOT_REPRODUCED, NOT_RESOLVED, REPRODUCED,
                                                            AgreementTolerances)
from siloflow.analysis.studies.validation.calibration import MADE, SECTIONS, UNMADE, calibration_rows
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.analysis.studies.validation.rows import AT_SCALE, NO_FINDING, NOT_AT_SCALE

TOLERANCES = AgreementTolerances()
T2 = 4.302652729911275  # Student t, 95 % two-sided, 2 degrees of freedom (3 seeds)
TARGETS = {"internal": (29.0, 31.0), "aluminium": (8.5, 10.5), "perspex": (10.0, 12.0)}


def _bulk(shape, mu, bulk, error=0.01, test="internal", rolling=0.0, restitution=0.1, blocked=False, lid="rigid",
          speed=0.03, window="steady", pour="configured"):
    """A row of calibration/bulk_friction.csv as read back: strings, a wall test named by its material."""
    return {"shape": shape, "test": "internal" if test == "internal" else "wall",
            "wall_material": "" if test == "internal" else test, "lid": lid, "rolling_friction": str(rolling),
            "restitution": str(restitution), "rotation_blocked": str(blocked), "shear_velocity": str(speed),
            "particle_friction": str(mu), "bulk_friction": str(bulk), "bulk_friction_error": str(error),
            "window_method": window, "pour": pour}


def _curve(shape, points, **kwargs):
    return [_bulk(shape, mu, bulk, **kwargs) for mu, bulk in points]


#: The validation tier's sweep of the two-sphere clump (0.1, 0.3, 0.5, 0.8), rolling 0 and 0.1, internal and wall.
INTERNAL_0 = ((0.1, 0.40), (0.3, 0.50), (0.5, 0.54), (0.8, 0.56))
INTERNAL_1 = ((0.1, 0.41), (0.3, 0.55), (0.5, 0.648), (0.8, 0.66))
WALL_0 = ((0.1, 0.1), (0.3, 0.3), (0.5, 0.34), (0.8, 0.35))
WALL_1 = ((0.1, 0.1), (0.3, 0.15), (0.5, 0.2), (0.8, 0.22))
SWEEP = (_curve("sphere2", INTERNAL_0) + _curve("sphere2", INTERNAL_1, rolling=0.1)
         + _curve("sphere2", WALL_0, test="aluminium", error=0.005)
         + _curve("sphere2", WALL_1, test="aluminium", rolling=0.1, error=0.005))
PARAMETERS = {"shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0,
              "targets_deg": {"internal": 30.0, "aluminium": 9.5},
              "particle_particle": {"sliding_friction": 0.33, "sliding_friction_error": 0.01, "lower": 0.31,
                                    "upper": 0.35, "band_clipped": False}}


def _rows(bulk_rows, parameters=PARAMETERS, dof=2.0, sections=SECTIONS, targets=TARGETS):
    return calibration_rows(bulk_rows, parameters, 0.1, "rigid", 0.03, targets, TOLERANCES, dof, sections=sections)


def _by_finding(rows):
    found = {}
    for entry in rows:
        found.setdefault(entry["finding"], []).append(entry)
    return found


def _one(rows, finding):
    (entry,) = _by_finding(rows)[finding]
    return entry


# ------------------------------------------------------------------------------------------------ what is made


def test_every_calibration_part_is_made_or_says_what_configuration_would_make_it():
    calibration_parts = {part for part in PARTS if part[:2] in {f"C{i}" for i in range(1, 8)}}
    assert set(MADE) | set(UNMADE) == calibration_parts and not set(MADE) & set(UNMADE)
    assert sorted(UNMADE) == ["C1.finite_at_zero", "C3.sphere", "C3.sphere4", "C7.perspex"]
    assert "jenike.sweep.sliding_friction" in UNMADE["C1.finite_at_zero"]
    assert "jenike.sweep.wall_test_shapes" in UNMADE["C3.sphere"] and "jenike.sweep.tests" in UNMADE["C7.perspex"]


def test_the_validation_sweep_makes_the_parts_not_listed_as_unmade():
    checks = (SWEEP + [_bulk("sphere2", 0.1, 0.405, blocked=True), _bulk("sphere2", 0.5, 1.08, blocked=True),
                       _bulk("sphere2", 0.5, 0.545, restitution=0.6)])
    shapes = _curve("sphere", ((0.1, 0.3), (0.3, 0.38), (0.5, 0.42), (0.8, 0.43))) + _curve(
        "sphere4", ((0.1, 0.4), (0.3, 0.5), (0.5, 0.54), (0.8, 0.55)))
    # the checks group reads both groups' charts: it compares the two clumps
    made = {r["finding"] for r in _rows(checks) + _rows(shapes, None, sections=("curves",))
            + _rows(checks + shapes, None, sections=("comparisons",))} - {NO_FINDING}
    assert made == set(MADE)


# ------------------------------------------------------------------------------------------------------ curves


def test_the_curves_of_a_constructed_sweep_give_exact_figures():
    rows = _rows(SWEEP, sections=("curves",))
    assert [r["finding"] for r in rows] == [
        "C3.mobilised", "C3.levels_off", "C3.sphere2", "C1.above_particle_friction", "C2.rises", "C2.levels_off",
        "C2.sphere2", "C6.friction_0_1", "C6.friction_0_5"]
    e = math.hypot(0.01, 0.01)
    above = _one(rows, "C1.above_particle_friction")
    assert above["value"] == pytest.approx(0.3, abs=1e-15) and above["value_error"] == 0.01
    assert above["agreement"] == REPRODUCED and above["differs"] == "" and above["dof"] == 2.0
    rises = _one(rows, "C2.rises")
    assert rises["value"] == pytest.approx(0.14, abs=1e-15) and rises["value_error"] == pytest.approx(e, rel=1e-15)
    assert rises["agreement"] == REPRODUCED and rises["study"] == "increases"
    # 0.02 +- 4.303 x 0.01414 = -0.041 to 0.081 against +- 0.1 x 0.54 = 0.054: partly outside
    level = _one(rows, "C2.levels_off")
    assert level["value"] == pytest.approx(0.02, abs=1e-15) and level["agreement"] == NOT_RESOLVED
    assert "negligible within ± 0.054 (plateau_relative 0.1 of 0.54): partly outside" in level["agreement_reason"]
    plateau = _one(rows, "C2.sphere2")
    assert plateau["value"] == pytest.approx(0.55, abs=1e-15)
    assert plateau["value_error"] == pytest.approx(e / 2, rel=1e-15) and plateau["agreement"] == REPRODUCED
    assert plateau["evidence"].endswith(
        "mean of particle friction -> bulk friction 0.5: 0.54 ± 0.01; 0.8: 0.56 ± 0.01")
    mobilised = _one(rows, "C3.mobilised")
    assert mobilised["value"] == pytest.approx(1.0, abs=1e-15) and mobilised["value_error"] == pytest.approx(0.05)
    wall = _one(rows, "C3.sphere2")
    assert wall["value"] == pytest.approx(0.345, abs=1e-15) and wall["case"] == "sphere2, aluminium, rolling 0"
    ratio = _one(rows, "C6.friction_0_5")
    assert ratio["value"] == pytest.approx(1.2, rel=1e-14) and ratio["case"] == "sphere2, internal, rolling 0 and 0.1"
    assert ratio["value_error"] == pytest.approx(1.2 * math.hypot(0.01 / 0.648, 0.01 / 0.54), rel=1e-12)
    # no row decides scale: the record adds it from the configuration
    assert all(r["scale"] == NO_FINDING and r["scale_reason"] == "" for r in rows)


def test_a_value_that_disagrees_with_its_finding_reads_not_reproduced_and_never_a_scale_word():
    rows = _rows(_curve("sphere", ((0.1, 0.7), (0.3, 0.75), (0.5, 0.80), (0.8, 0.80))), None, sections=("curves",))
    sphere = _one(rows, "C2.sphere")
    # 0.80 +- 4.303 x 0.00707 lies above 0.42 +- 10 %
    assert sphere["agreement"] == NOT_REPRODUCED and sphere["value"] == pytest.approx(0.8)
    assert "lies outside 0.378 to 0.462" in sphere["agreement_reason"]
    for entry in rows:
        assert entry["agreement"] in (REPRODUCED, NOT_REPRODUCED, NOT_RESOLVED)
        text = " ".join(str(entry[key]) for key in ("agreement", "agreement_reason", "evidence", "differs"))
        assert AT_SCALE not in text and NOT_AT_SCALE not in text


@pytest.mark.parametrize("bulk, verdict", [(0.40, REPRODUCED), (0.05, NOT_REPRODUCED), (0.11, NOT_RESOLVED)])
def test_the_sign_rule_resolved_right_resolved_wrong_and_unresolved(bulk, verdict):
    """C1: bulk - particle friction at 0.1 is +0.3 (resolved above), -0.05 (resolved below) or +0.01, within
    4.303 x 0.01."""
    rows = _rows(_curve("sphere4", ((0.1, bulk), (0.5, 0.54))), None, sections=("curves",))
    above = _one(rows, "C1.above_particle_friction")
    assert above["agreement"] == verdict and above["value"] == pytest.approx(bulk - 0.1, abs=1e-15)


@pytest.mark.parametrize("blocked, error, verdict", [(0.401, 0.001, REPRODUCED), (0.5, 0.001, NOT_REPRODUCED),
                                                     (0.41, 0.01, NOT_RESOLVED)])
def test_the_negligible_rule_inside_outside_and_partly(blocked, error, verdict):
    """C5.friction_0_1 against +- 0.05 x 0.4 = 0.02: 0.001 +- 0.006 inside, 0.1 +- 0.006 outside, 0.01 +- 0.061
    partly."""
    rows = [_bulk("sphere2", 0.1, 0.4, error), _bulk("sphere2", 0.1, blocked, error, blocked=True)]
    # the one common point, 0.1, is C5.friction_0_1's: C5.friction_0_5 (at 0.5) is not judged there
    (entry,) = _rows(rows, None, sections=("comparisons",))
    assert entry["finding"] == "C5.friction_0_1" and entry["agreement"] == verdict
    assert entry["value"] == pytest.approx(blocked - 0.4, abs=1e-15)
    assert entry["value_error"] == pytest.approx(math.hypot(error, error), rel=1e-15)
    assert "negligible within ± 0.02 (negligible_relative 0.05 of 0.4)" in entry["agreement_reason"]


def test_a_curve_that_is_not_steady_gives_at_most_not_resolved():
    steady = _curve("sphere2", INTERNAL_0)
    transient = [{**entry, "window_method": "second half"} for entry in steady]
    unsaid = [{**entry, "window_method": ""} for entry in steady]
    assert {r["agreement"] for r in _rows(steady, None, sections=("curves",))} == {REPRODUCED, NOT_RESOLVED}
    for rows in (transient, unsaid):
        judged = _rows(rows, None, sections=("curves",))
        assert {r["agreement"] for r in judged} == {NOT_RESOLVED}
        assert _one(judged, "C1.above_particle_friction")["agreement_reason"].endswith("; but not steady")
        assert "not steady" in _one(judged, "C2.sphere2")["agreement_reason"]
    assert "steady shear window in 0 of 2 shear tests (the others a transient)" in _one(
        _rows(transient, None, sections=("curves",)), "C2.rises")["evidence"]
    assert "(the others do not say)" in _one(_rows(unsaid, None, sections=("curves",)), "C2.rises")["evidence"]
    # a transient that disagrees still disagrees: steadiness never makes a verdict better
    off = [{**entry, "window_method": "second half"} for entry in _curve("sphere", ((0.5, 0.8), (0.8, 0.8)))]
    assert _one(_rows(off, None, sections=("curves",)), "C2.sphere")["agreement"] == NOT_REPRODUCED
    # one transient point: only the rows resting on it
    mixed = [*steady[:3], {**steady[3], "window_method": "second half"}]
    judged = _rows(mixed, None, sections=("curves",))
    assert _one(judged, "C2.rises")["agreement"] == REPRODUCED
    assert "steady shear window in 1 of 2 shear tests" in _one(judged, "C2.sphere2")["evidence"]


def test_a_row_says_which_swept_points_it_uses_in_place_of_the_study_s():
    rows = _rows(_curve("sphere2", INTERNAL_0), None, sections=("curves",))
    # 0.3 and 0.5 are as near 0.4: the knee goes to the plateau's side, where the plateau value starts
    assert _one(rows, "C2.rises")["differs"] == ("the swept particle friction 0.1 instead of the study's 0, 0.5 "
                                                 "instead of the study's 0.4")
    assert _one(rows, "C2.levels_off")["differs"] == ("the swept particle friction 0.5 instead of the study's 0.4, "
                                                      "0.8 instead of the study's 1")
    assert _one(rows, "C2.sphere2")["differs"] == ("the mean of the swept particle friction 0.5, 0.8, not of the "
                                                   "study's 0.4 to 1 in steps of 0.1")
    study = _curve("sphere2", [(round(0.1 * k, 1), 0.3 + 0.06 * min(k, 4)) for k in range(11)])
    judged = _rows(study, None, sections=("curves",))
    assert all(r["differs"] == "" for r in judged)
    # a sweep with particle friction 0 gives C1's second part, 0.3 above 0 here
    zero = _one(judged, "C1.finite_at_zero")
    assert zero["value"] == 0.3 and zero["agreement"] == REPRODUCED
    assert zero["figure"] == "Bulk friction at particle friction 0"
    assert "C1.finite_at_zero" not in _by_finding(rows)


def test_the_clumps_are_compared_by_the_checks_only_when_both_curves_are_given():
    four = _curve("sphere4", ((0.1, 0.4), (0.5, 0.55), (0.8, 0.55)))
    alike = _one(_rows(_curve("sphere2", INTERNAL_0) + four, None, sections=("comparisons",)), "C2.clumps_alike")
    assert alike["value"] == pytest.approx(1.0, abs=1e-15) and alike["agreement"] == REPRODUCED
    assert alike["case"] == "sphere4 / sphere2, internal, rolling 0"
    assert "C2.clumps_alike" not in _by_finding(_rows(_curve("sphere2", INTERNAL_0) + four, None, sections=("curves",)))
    assert "C2.clumps_alike" not in _by_finding(_rows(four, None, sections=("comparisons",)))


# ------------------------------------------------------------------------------------------------- comparisons


def test_the_checks_judge_c4_and_c5_and_quote_the_other_lid_and_speed_with_no_finding():
    rows = (_curve("sphere2", INTERNAL_0)
            + [_bulk("sphere2", 0.1, 0.402, blocked=True), _bulk("sphere2", 0.5, 1.08, blocked=True),
               _bulk("sphere2", 0.5, 0.545, restitution=0.6), _bulk("sphere2", 0.5, 0.60, lid="servo"),
               _bulk("sphere2", 0.5, 0.55, speed=0.015)])
    checks = _rows(rows, None, sections=("comparisons",))
    assert [r["finding"] for r in checks] == ["C5.friction_0_1", "C5.friction_0_5", "C4", NO_FINDING, NO_FINDING]
    doubled = _one(checks, "C5.friction_0_5")
    assert doubled["value"] == pytest.approx(2.0, rel=1e-15) and doubled["agreement"] == REPRODUCED
    restitution = _one(checks, "C4")
    assert restitution["value"] == pytest.approx(0.005, abs=1e-15) and restitution["agreement"] == NOT_RESOLVED
    assert restitution["differs"] == ("restitution 0.6 against 0.1 at particle friction 0.5, not the study's 1e-4 "
                                      "against 1")
    lid, speed = checks[3:]
    assert lid["figure"] == "Bulk friction, servo lid - rigid lid" and lid["value"] == pytest.approx(0.06)
    assert lid["agreement"] == NO_FINDING and lid["study"].startswith("the study ran no servo lid")
    # 0.06 against 4.303 x 0.0141 = 0.061: not resolved with 3 seeds, resolved with a normal quantile
    assert lid["evidence"].endswith("mean 0.06 ± 0.014: not resolved at 95 % (q 4.303, t 2 dof)")
    assert _rows(rows, None, dof=None, sections=("comparisons",))[3]["evidence"].endswith(
        "resolved at 95 % (q 1.96, normal)")
    assert speed["figure"] == "Bulk friction, shear velocity 0.015 - 0.03 m/s"
    assert speed["study"] == "the study sheared at 3 mm/s only (§4.3.1.3)"


def test_the_pour_variant_is_quoted_against_the_configured_pour_with_no_finding():
    """Poured at their own friction 0.3 and 0.5, the samples' bulk friction is 0.02 and 0.04 below the chart's
    (0.50, 0.54): mean -0.03 +- sqrt(2 x 2 x 0.01^2) / 2 = 0.01414; the chart itself is unchanged by the variant."""
    own = [_bulk("sphere2", 0.3, 0.48, pour="own_friction"), _bulk("sphere2", 0.5, 0.50, pour="own_friction")]
    checks = _rows(_curve("sphere2", INTERNAL_0) + own, None, sections=("comparisons",))
    (variant,) = checks
    assert variant["figure"] == "Bulk friction, poured at its own friction - as configured"
    assert variant["value"] == pytest.approx(-0.03, abs=1e-15)
    assert variant["value_error"] == pytest.approx(math.sqrt(4 * 0.01 ** 2) / 2, rel=1e-12)
    assert variant["finding"] == NO_FINDING and "§4.3.1.2-§4.3.1.3" in variant["study"]
    assert "0.3: poured at its own friction 0.48 ± 0.01, as configured 0.5 ± 0.01" in variant["evidence"]
    curves = _rows(_curve("sphere2", INTERNAL_0) + own, None, sections=("curves",))
    assert curves == _rows(_curve("sphere2", INTERNAL_0), None, sections=("curves",))


def test_errors_with_two_degrees_of_freedom_use_t_4_303():
    """C1 at 0.1: 0.04 above the particle friction with error 0.01 is resolved by the normal 1.96, not by t 4.303."""
    rows = _curve("sphere", ((0.1, 0.14), (0.5, 0.42)))
    with_seeds = _one(_rows(rows, None, dof=2.0, sections=("curves",)), "C1.above_particle_friction")
    within_run = _one(_rows(rows, None, dof=None, sections=("curves",)), "C1.above_particle_friction")
    assert with_seeds["agreement"] == NOT_RESOLVED and within_run["agreement"] == REPRODUCED
    low, high = 0.04 - T2 * 0.01, 0.04 + T2 * 0.01
    assert f"(95 %: {low:.4g} to {high:.4g}, q 4.303, t 2 dof)" in with_seeds["agreement_reason"]
    assert with_seeds["dof"] == 2.0 and within_run["dof"] == ""


# -------------------------------------------------------------------------------------------------- calibrated


def test_the_study_s_chosen_inputs_are_read_off_the_charts_interpolated_between_swept_points():
    rows = _rows(SWEEP, sections=("calibrated",))
    internal = _one(rows, "C7.internal")
    # rolling 0.1 at 0.35: a quarter of the way from 0.55 (0.3) to 0.648 (0.5)
    bulk, error = 0.55 + 0.25 * 0.098, math.hypot(0.75 * 0.01, 0.25 * 0.01)
    assert internal["value"] == pytest.approx(math.degrees(math.atan(bulk)), rel=1e-14) and internal["unit"] == "deg"
    assert internal["value_error"] == pytest.approx(math.degrees(error / (1 + bulk ** 2)), rel=1e-12)
    assert internal["agreement"] == REPRODUCED and internal["case"] == "sphere2, internal, rolling 0.1"
    assert internal["differs"] == ("interpolated linearly between the swept particle friction 0.3 and 0.5 (0.35 is "
                                   "not swept)")
    aluminium = _one(rows, "C7.aluminium")
    # 0.1 + 0.35 x 0.05 = 0.1175: 6.70 deg, +- 4.303 x 0.209 deg, below the configured 8.5 to 10.5 deg
    assert aluminium["value"] == pytest.approx(math.degrees(math.atan(0.1175)), rel=1e-14)
    assert aluminium["agreement"] == NOT_REPRODUCED and "the study's 8.5 to 10.5" in aluminium["agreement_reason"]
    assert aluminium["figure"] == "Bulk wall friction angle on aluminium at particle-wall friction 0.17"
    assert "C7.perspex" not in _by_finding(rows)  # no Perspex chart
    assert "C7.aluminium" not in _by_finding(_rows(SWEEP, sections=("calibrated",), targets={}))
    (chosen,) = [r for r in rows if r["finding"] == NO_FINDING]
    assert chosen["figure"] == "Calibrated particle sliding friction (particle-particle)" and chosen["value"] == 0.33
    assert chosen["study"] == "the study's chosen 0.35 (§4.6)" and chosen["agreement"] == NO_FINDING
    # the band 0.31 to 0.35 rests on the points at 0.3 and 0.5
    assert chosen["evidence"].startswith("steady shear window in 2 of 2 shear tests; reproduces the measured 30 deg")


def test_an_unreachable_target_gives_the_chart_s_nearest_angle_and_whether_the_gap_is_resolved():
    internal = _curve("sphere2", ((0.1, 0.44), (0.3, 0.52), (0.5, 0.55), (0.8, 0.56)), rolling=0.1, error=0.005)
    parameters = {"shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0, "targets_deg": {"internal": 30.0},
                  "unreachable": {"internal": "internal 30.0 deg is unreachable"}}
    rows = _rows(internal, parameters, sections=("calibrated",))
    assert [r["finding"] for r in rows] == ["C7.internal", NO_FINDING]
    top = rows[1]
    angle, error = math.degrees(math.atan(0.56)), math.degrees(0.005 / (1.0 + 0.56 ** 2))
    assert top["value"] == pytest.approx(angle, rel=1e-15) and top["value_error"] == pytest.approx(error, rel=1e-15)
    # 30 - 29.249 = 0.751 deg against 4.303 x 0.218 = 0.94 deg: not resolved with 3 seeds
    assert top["evidence"].endswith("at particle friction 0.8, lies 0.751 ± 0.22 deg below the measured 30 deg: "
                                    "not resolved at 95 % (q 4.303, t 2 dof)")
    assert top["study"] == "the study's chosen 0.35 (§4.6)"


# ---------------------------------------------------------------------------------------------------- sections


def test_each_section_may_be_asked_for_alone():
    rows = SWEEP + [_bulk("sphere2", 0.5, 1.08, blocked=True)]
    curves = _rows(rows, None, sections=("curves",))
    checks = _rows(rows, None, sections=("comparisons",))
    chosen = _rows(rows, sections=("calibrated",))
    assert {r["finding"].split(".")[0] for r in curves} == {"C1", "C2", "C3", "C6"}
    # one blocked point, at 0.5: nearer C5's 0.5 than its 0.1, it makes that part only
    assert [r["finding"] for r in checks] == ["C5.friction_0_5"]
    assert [r["finding"] for r in chosen] == ["C7.internal", "C7.aluminium", NO_FINDING]
    assert _rows(rows) == curves + checks + chosen
    with pytest.raises(ValueError, match="need the calibration's parameters"):
        _rows(rows, None)
    with pytest.raises(ValueError, match="unknown calibration row sections chart"):
        _rows(rows, None, sections=("chart",))
