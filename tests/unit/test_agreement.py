"""The rules that judge a measured figure against a finding of the study: for each kind a case reproduced, one not
reproduced and one not resolved, on constructed numbers whose answers are worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.studies.validation.agreement import (NOT_REPRODUCED, NOT_RESOLVED, REPRODUCED,
                                                            AgreementTolerances, in_order, interval, negligible,
                                                            power_law, power_law_exponent, quantile, ratio_in_band,
                                                            sign_of_change, study_band, value_in_band)
from siloflow.analysis.studies.validation.findings import part
from siloflow.engines.config import validate_config

#: The tolerances the cases are worked out with (the schema's defaults, written out).
TOL = AgreementTolerances(about_relative=0.10, no_band_relative=0.10, negligible_relative=0.05,
                          plateau_relative=0.10, uniform_relative=0.20, exponent_absolute=0.05, max_relative_error=0.25)


def test_schema_defaults_load_into_the_tolerances():
    section = validate_config({})["validation"]
    assert section["agreement"] == {"about_relative": 0.1, "no_band_relative": 0.1, "negligible_relative": 0.05,
                                    "plateau_relative": 0.1, "uniform_relative": 0.2, "exponent_absolute": 0.05}
    assert AgreementTolerances.from_config(section) == TOL == AgreementTolerances()
    changed = validate_config({"validation": {"agreement": {"about_relative": 0.2}, "max_relative_error": 0.3}})
    tolerances = AgreementTolerances.from_config(changed["validation"])
    assert (tolerances.about_relative, tolerances.max_relative_error, tolerances.negligible_relative) == (0.2, 0.3, 0.05)


def test_three_seeds_take_the_t_quantile_and_a_within_run_error_the_normal_one():
    assert quantile(2) == pytest.approx(4.303, abs=5e-4)
    assert quantile(None) == pytest.approx(1.960, abs=5e-4)
    assert interval(10.0, 1.0, 2) == pytest.approx((10.0 - 4.3027, 10.0 + 4.3027), abs=1e-4)
    assert interval(10.0, 1.0, None) == pytest.approx((8.04004, 11.95996), abs=1e-5)
    with pytest.raises(ValueError, match="dof"):
        quantile(0)


# --- value against a band ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("value, error, dof, steady, verdict", [
    (10.0, 0.5, 2, True, REPRODUCED),
    (15.0, 0.3, 2, True, NOT_REPRODUCED),       # 15 - 4.303 * 0.3 = 13.7 > 13
    (13.5, 0.5, None, True, REPRODUCED),       # 12.52 to 14.48 overlaps 8 to 13: consistent at 95 %
    (10.0, 3.0, None, True, NOT_RESOLVED),     # inside, but 30 % relative error
    (60.0, 18.0, None, True, NOT_REPRODUCED),  # 30 % relative error, yet 24.7 to 95.3 misses 8 to 13
    (10.0, 0.5, 2, False, NOT_RESOLVED),       # inside, not steady
    (20.0, 0.5, 2, False, NOT_REPRODUCED),     # unsteadiness does not rescue a figure outside
    (10.0, math.nan, None, True, NOT_RESOLVED),
])
def test_value_against_the_studys_own_band(value, error, dof, steady, verdict):
    assert value_in_band(value, error, dof, part("B4.internal"), TOL, steady=steady).verdict == verdict


def test_about_widens_the_value_and_the_t_quantile_can_reach_it():
    sphere = part("C2.sphere")  # about 0.42: 0.378 to 0.462
    assert study_band(sphere, TOL) == pytest.approx((0.378, 0.462))
    assert value_in_band(0.47, 0.003, None, sphere, TOL).verdict == NOT_REPRODUCED  # 0.4641 to 0.4759
    assert value_in_band(0.47, 0.003, 2, sphere, TOL).verdict == REPRODUCED  # 0.4571 to 0.4829
    assert value_in_band(0.40, 0.002, 2, sphere, TOL).reason.startswith("C2.sphere: 0.4 ± 0.002 (95 %: 0.3914 to ")
    assert study_band(part("B8.internal"), TOL) == pytest.approx((0.351, 0.429))


def test_a_configured_number_is_passed_by_the_caller():
    aluminium = part("C7.aluminium")
    assert value_in_band(9.6, 0.2, 2, aluminium, TOL, configured=(8.5, 10.5)).verdict == REPRODUCED
    assert value_in_band(12.6, 0.2, 2, aluminium, TOL, configured=(8.5, 10.5)).verdict == NOT_REPRODUCED
    with pytest.raises(ValueError, match="calibration.targets_deg.aluminium"):
        value_in_band(9.6, 0.2, 2, aluminium, TOL)


def test_a_rule_refuses_a_part_of_another_kind():
    with pytest.raises(ValueError, match="S5.dem is a sign part"):
        value_in_band(1.0, 0.1, 2, part("S5.dem"), TOL)


# --- ratio ------------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("a, ua, b, ub, verdict", [
    (0.96, 0.0384, 0.4, 0.016, REPRODUCED),  # 2.4 ± 0.136: 2.134 reaches 2.2 only with b's error propagated too
    (1.2, 0.01, 0.4, 0.004, NOT_REPRODUCED),  # 3.0 ± 0.042
    (0.8, 0.2, 0.4, 0.1, NOT_RESOLVED),  # 2.0 ± 0.71: 35 % relative error
    (0.8, 0.01, 0.0, 0.01, NOT_RESOLVED),  # no ratio
])
def test_ratio_with_the_error_propagated_from_both_figures(a, ua, b, ub, verdict):
    doubled = part("C5.friction_0_5")  # about 2: 1.8 to 2.2
    assert ratio_in_band(a, ua, b, ub, None, doubled, TOL).verdict == verdict


def test_ratio_error_propagation_is_first_order_and_independent():
    # 2.4 * sqrt(0.04^2 + 0.04^2) = 0.1358; with a's error alone (0.096) 2.4 - 1.96 * 0.096 = 2.212 misses 2.2
    agreement = ratio_in_band(0.96, 0.0384, 0.4, 0.016, None, part("C5.friction_0_5"), TOL)
    assert "2.4 ± 0.14 (95 %: 2.134 to 2.666" in agreement.reason
    assert value_in_band(2.4, 0.096, None, part("C5.friction_0_5"), TOL).verdict == NOT_REPRODUCED
    assert ratio_in_band(1.02, 0.002, 1.0, 0.002, 2, part("S3.mass_flow"), TOL).verdict == REPRODUCED
    assert ratio_in_band(1.06, 0.002, 1.0, 0.002, 2, part("S3.mass_flow"), TOL).verdict == NOT_REPRODUCED


# --- sign of a change -------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("change, error, dof, verdict", [
    (-0.01, 0.002, None, REPRODUCED),  # B decreases with height, resolved
    (0.01, 0.002, None, NOT_REPRODUCED),  # resolved, the other sign
    (-0.003, 0.002, None, NOT_RESOLVED),  # 0.003 <= 1.96 * 0.002
    (-3.0, 1.0, None, REPRODUCED),  # 3 > 1.960
    (-3.0, 1.0, 2, NOT_RESOLVED),  # 3 <= 4.303 for three seeds
    (-0.01, math.nan, None, NOT_RESOLVED),
])
def test_sign_of_a_change(change, error, dof, verdict):
    assert sign_of_change(change, error, dof, part("S5.dem")).verdict == verdict


# --- order ------------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("values, verdict", [
    ((1.79, 1.49, 0.16), REPRODUCED),
    ((1.49, 1.79, 0.16), NOT_REPRODUCED),  # tube - interior = -0.30, resolved beyond 1.96 * 0.0707 = 0.139
    ((1.50, 1.49, 0.16), NOT_RESOLVED),  # tube - interior = 0.01, not resolved
    ((1.50, 1.49, 1.80), NOT_REPRODUCED),  # one pair unresolved, one resolved the wrong way
])
def test_order_of_adjacent_pairs(values, verdict):
    assert in_order(values, (0.05, 0.05, 0.05), None, part("M2.outlet_order")).verdict == verdict


def test_order_needs_one_figure_per_name():
    with pytest.raises(ValueError, match="one value and one error for each"):
        in_order((1.0, 0.5), (0.1, 0.1), None, part("M2.outlet_order"))


# --- negligible -------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("change, error, dof, verdict", [
    (0.002, 0.005, None, REPRODUCED),  # -0.0078 to 0.0118 inside -+0.025 (5 % of 0.5)
    (0.1, 0.01, None, NOT_REPRODUCED),  # 0.0804 to 0.1196
    (-0.1, 0.01, None, NOT_REPRODUCED),
    (0.02, 0.01, None, NOT_RESOLVED),  # 0.0004 to 0.0396 straddles 0.025
    (0.002, 0.005, 2, REPRODUCED),  # three seeds: -0.0195 to 0.0235, still inside
    (0.002, math.nan, None, NOT_RESOLVED),
])
def test_negligible_change(change, error, dof, verdict):
    assert negligible(change, error, dof, 0.5, part("C4"), TOL).verdict == verdict


def test_negligible_takes_the_parts_tolerance_and_three_seeds_widen_the_interval():
    # uniform_relative 0.2 of a mean 1.0: -+0.2
    assert negligible(0.1, 0.04, None, 1.0, part("M2.inlet_uniform"), TOL).verdict == REPRODUCED  # 0.022 to 0.178
    assert negligible(0.1, 0.04, 2, 1.0, part("M2.inlet_uniform"), TOL).verdict == NOT_RESOLVED  # -0.072 to 0.272


# --- power law --------------------------------------------------------------------------------------------------------

GRAVITY = (1.0, 5.0, 50.0)


def _scaled(exponent, relative_error=0.01):
    values = [2.0 * g ** exponent for g in GRAVITY]
    return values, [relative_error * v for v in values]


def test_exponent_of_a_weighted_log_log_fit():
    values, errors = _scaled(0.5)
    exponent, error = power_law_exponent(GRAVITY, values, errors)
    x = np.log(GRAVITY)
    assert exponent == pytest.approx(0.5, abs=1e-12)
    assert error == pytest.approx(0.01 / math.sqrt(((x - x.mean()) ** 2).sum()), rel=1e-9)  # 0.00360
    # Without errors, from the scatter: ln v = 0.5 ln f + (0, d, 0) at f = 1, 2, 4 has the slope 0.5 exactly,
    # residuals (-d/3, 2d/3, -d/3), s^2 = 2 d^2 / 3 on 1 dof and Sxx = 2 ln(2)^2, so the error is d / (ln(2) sqrt(3)).
    d = 0.03
    exponent, error = power_law_exponent((1.0, 2.0, 4.0), (1.0, math.sqrt(2.0) * math.exp(d), 2.0))
    assert (exponent, error) == pytest.approx((0.5, d / (math.log(2.0) * math.sqrt(3.0))), rel=1e-9)


@pytest.mark.parametrize("exponent, relative_error, steady, verdict", [
    (0.5, 0.01, True, REPRODUCED),
    (0.8, 0.01, True, NOT_REPRODUCED),
    (0.56, 0.5, True, NOT_RESOLVED),  # 0.56 ± 0.18: overlaps 0.45 to 0.55, 32 % relative error
    (0.5, 0.01, False, NOT_RESOLVED),
])
def test_scaling_with_the_square_root_of_gravity(exponent, relative_error, steady, verdict):
    values, errors = _scaled(exponent, relative_error)
    assert power_law(GRAVITY, values, errors, None, part("M4.mass_flow"), TOL, steady=steady).verdict == verdict


@pytest.mark.parametrize("exponent, relative_error, verdict", [
    (0.2, 0.01, REPRODUCED),  # deviates: 0.2 ± 0.0036 outside 0.45 to 0.55
    (0.5, 0.01, NOT_REPRODUCED),  # scales: inside
    (0.4, 0.2, NOT_RESOLVED),  # 0.4 ± 0.072 straddles 0.45
])
def test_deviation_from_the_scaling(exponent, relative_error, verdict):
    values, errors = _scaled(exponent, relative_error)
    assert power_law(GRAVITY, values, errors, None, part("M4.exterior_deviates"), TOL).verdict == verdict


def test_two_factors_without_errors_resolve_nothing():
    agreement = power_law((1.0, 5.0), (1.0, math.sqrt(5.0)), None, None, part("M4.mass_flow"), TOL)
    assert agreement.verdict == NOT_RESOLVED
    with pytest.raises(ValueError, match="positive"):
        power_law_exponent(GRAVITY, (1.0, 0.0, 2.0))
