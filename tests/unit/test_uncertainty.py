"""Unit tests for siloflow.analysis.numerics.uncertainty on synthetic input with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.uncertainty import (
    line_slope,
    Estimate,
    SeedSpread,
    Significance,
    batch_means,
    batch_rate,
    combine_independent,
    counting_error,
    difference_significant,
    format_estimate,
    proportion_error,
    proportion_interval,
    seed_spread,
)
from siloflow.analysis.numerics.vrr_noise import (
    CEILING_FACTOR,
    vrr_ceiling,
    vrr_near_ceiling,
    window_clumps_for_precision,
    window_duration_for_precision,
)

NAN = math.nan
SE_1234 = math.sqrt(5.0 / 3.0) / 2.0  # std([1, 2, 3, 4], ddof=1) / sqrt(4)


# --------------------------------------------------------------------------- formatting


@pytest.mark.parametrize("value, error, digits, expected", [
    (0.11682, 0.00213, 2, "0.1168 ± 0.0021"),
    (0.1168, 0.0021, 2, "0.1168 ± 0.0021"),
    (0.11682, 0.00213, 1, "0.117 ± 0.002"),
    (0.5, 0.0996, 2, "0.50 ± 0.10"),  # the error rounds up into the next decade: still 2 significant digits
    (9.96, 0.996, 2, "10.0 ± 1.0"),
    (12345.0, 123.0, 2, "12340 ± 120"),  # value rounded to the error's tens
    (-1.2345, 0.05, 2, "-1.234 ± 0.050"),  # -1.2345 is stored as -1.23449999...
    (-0.001, 0.3, 2, "0.00 ± 0.30"),  # no "-0.00"
    (3.2e-7, 1.1e-8, 2, "(3.20 ± 0.11)e-07"),  # small: one shared power of ten
    (1.234e7, 1.5e5, 2, "(1.234 ± 0.015)e+07"),  # large
    (0.1168, NAN, 2, "0.1168 ± unknown"),
    (2.0, 0.0, 2, "2 ± 0"),
])
def test_format_estimate_rounds_the_error_and_the_value_to_the_same_place(value, error, digits, expected):
    assert format_estimate(value, error, digits) == expected


def test_format_estimate_rejects_bad_input():
    with pytest.raises(ValueError, match="error must be a finite number >= 0 or NaN"):
        format_estimate(1.0, -0.1)
    with pytest.raises(ValueError, match="error must be a finite number >= 0 or NaN"):
        format_estimate(1.0, math.inf)
    with pytest.raises(ValueError, match="digits must be an integer >= 1"):
        format_estimate(1.0, 0.1, 0)
    with pytest.raises(ValueError, match="digits must be an integer >= 1"):
        format_estimate(1.0, 0.1, 1.5)


# --------------------------------------------------------------------------- Estimate


def test_estimate_formats_and_gives_t_and_normal_intervals():
    estimate = Estimate(value=0.11682, std_error=0.00213, n=10, method="batch means", dof=9)
    assert estimate.format() == "0.1168 ± 0.0021"
    assert estimate.format(1) == "0.117 ± 0.002"
    # Student t with 2 degrees of freedom: q(0.975) = 4.302652729...
    low, high = Estimate(value=2.0, std_error=0.5, n=3, method="seeds", dof=2).interval(0.95)
    assert (2.0 - low, high - 2.0) == pytest.approx((0.5 * 4.3026527297, 0.5 * 4.3026527297), rel=1e-9)
    # a model error (dof inf): the normal quantile 1.959963985
    low, high = Estimate(value=100.0, std_error=10.0, n=100, method="counting").interval(0.95)
    assert (low, high) == pytest.approx((100.0 - 19.59963985, 100.0 + 19.59963985), rel=1e-9)
    assert all(math.isnan(x) for x in Estimate(1.0, NAN, 1, "seeds").interval())


def test_estimate_rejects_bad_fields():
    with pytest.raises(ValueError, match="std_error must be a finite number >= 0 or NaN"):
        Estimate(1.0, -0.1, 3, "seeds")
    with pytest.raises(ValueError, match="value must be a finite number"):
        Estimate(NAN, 0.1, 3, "seeds")
    with pytest.raises(ValueError, match="n must be an integer >= 1"):
        Estimate(1.0, 0.1, 0, "seeds")
    with pytest.raises(ValueError, match="method must be a non-empty label"):
        Estimate(1.0, 0.1, 3, " ")
    with pytest.raises(ValueError, match="dof must be > 0"):
        Estimate(1.0, 0.1, 3, "seeds", dof=0)
    with pytest.raises(ValueError, match=r"confidence must be a number in \(0, 1\)"):
        Estimate(1.0, 0.1, 3, "seeds").interval(1.0)


# --------------------------------------------------------------------------- batch means


def test_batch_means_of_batches_with_known_means():
    # four batches of three samples with means 1, 2, 3, 4 (not constant inside the last two)
    series = [1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 3.0, 4.0, 3.0, 4.0, 5.0]
    estimate = batch_means(series, n_batches=4)
    assert (estimate.value, estimate.n, estimate.method, estimate.dof) == (2.5, 4, "batch means", 3.0)
    assert estimate.std_error == pytest.approx(SE_1234, rel=1e-15)


def test_batch_means_leaves_out_the_oldest_remainder():
    # 13 samples in 4 batches of 3: the first sample (a start-up spike) is not used
    estimate = batch_means([100.0] + [1.0] * 3 + [2.0] * 3 + [3.0] * 3 + [4.0] * 3, n_batches=4)
    assert estimate.value == 2.5
    assert estimate.std_error == pytest.approx(SE_1234, rel=1e-15)


def test_batch_means_of_a_constant_series_has_no_error():
    estimate = batch_means(np.full(20, 0.25), n_batches=10)
    assert (estimate.value, estimate.std_error) == (0.25, 0.0)


def test_batch_means_rejects_bad_input():
    with pytest.raises(ValueError, match="series has 3 samples, too few for 4 batches"):
        batch_means([1.0, 2.0, 3.0], n_batches=4)
    with pytest.raises(ValueError, match="n_batches must be an integer >= 2"):
        batch_means([1.0, 2.0, 3.0], n_batches=1)
    with pytest.raises(ValueError, match="n_batches must be an integer >= 2"):
        batch_means([1.0, 2.0, 3.0], n_batches=2.0)
    with pytest.raises(ValueError, match="n_batches must be an integer >= 2"):
        batch_means([1.0, 2.0, 3.0], n_batches=True)
    with pytest.raises(ValueError, match="series must contain only finite numbers"):
        batch_means([1.0, NAN, 3.0, 4.0], n_batches=2)
    with pytest.raises(ValueError, match="series must be a 1-D array"):
        batch_means(np.ones((4, 2)), n_batches=2)


# --------------------------------------------------------------------------- batch rate


def test_batch_rate_of_a_piecewise_line_with_known_batch_slopes():
    # discharged mass [kg] over 12 s sampled each second; slopes 1, 2, 3, 4 kg/s in the four 3-sample batches
    time = np.arange(12.0)
    mass = np.array([0.0, 1.0, 2.0, 10.0, 12.0, 14.0, 30.0, 33.0, 36.0, 50.0, 54.0, 58.0])
    estimate = batch_rate(time, mass, n_batches=4)
    assert (estimate.value, estimate.n, estimate.method, estimate.dof) == (2.5, 4, "batch rate", 3.0)
    assert estimate.std_error == pytest.approx(SE_1234, rel=1e-15)


def test_batch_rate_of_an_exact_line_on_uneven_times_is_its_slope():
    time = np.cumsum(np.r_[0.0, np.tile([0.1, 0.3, 0.2], 7)])  # 22 samples, uneven steps
    estimate = batch_rate(time, 1.5 - 3.0 * time, n_batches=5)  # 2 oldest samples left out
    assert estimate.value == pytest.approx(-3.0, rel=1e-13)
    assert estimate.std_error == pytest.approx(0.0, abs=1e-12)


def test_batch_rate_rejects_bad_input():
    time = np.arange(8.0)
    with pytest.raises(ValueError, match="time has 8 samples, too few for 5 batches"):
        batch_rate(time, time, n_batches=5)
    with pytest.raises(ValueError, match=r"cumulative must have the shape of time \(8,\)"):
        batch_rate(time, time[:-1], n_batches=2)
    with pytest.raises(ValueError, match="time must be strictly increasing"):
        batch_rate(np.r_[0.0, 1.0, 1.0, 2.0], np.arange(4.0), n_batches=2)
    with pytest.raises(ValueError, match="cumulative must contain only finite numbers"):
        batch_rate(time, np.r_[time[:-1], NAN], n_batches=2)
    with pytest.raises(ValueError, match="n_batches must be an integer >= 2"):
        batch_rate(time, time, n_batches=1)


# --------------------------------------------------------------------------- counting


def test_counting_error_is_the_square_root_of_the_count():
    assert counting_error(16) == 4.0 and counting_error(0) == 0.0
    np.testing.assert_array_equal(counting_error([0, 4, 9, 2.25]), [0.0, 2.0, 3.0, 1.5])
    with pytest.raises(ValueError, match="count must be >= 0"):
        counting_error(-1)
    with pytest.raises(ValueError, match="count must contain only finite numbers"):
        counting_error(NAN)


def test_proportion_error_is_binomial():
    assert proportion_error(25, 100) == math.sqrt(0.25 * 0.75 / 100)
    assert proportion_error(25, 100) == pytest.approx(0.0433012701892219, rel=1e-15)
    np.testing.assert_allclose(proportion_error([0, 50, 100], 100), [0.0, 0.05, 0.0], rtol=1e-15, atol=0)
    with pytest.raises(ValueError, match=r"k must be in \[0, n\]"):
        proportion_error(11, 10)
    with pytest.raises(ValueError, match="n must be an integer >= 1"):
        proportion_error(0, 0)
    with pytest.raises(ValueError, match="k must be an integer"):
        proportion_error(2.5, 10)
    with pytest.raises(ValueError, match="k and n must broadcast together"):
        proportion_error([1, 2], [3, 4, 5])


def test_proportion_interval_is_wilsons():
    z2 = 1.959963984540054 ** 2
    low, high = proportion_interval(0, 10)  # Wilson for k = 0: [0, z^2 / (n + z^2)]
    assert low == 0.0 and high == pytest.approx(z2 / (10 + z2), rel=1e-12)
    low, high = proportion_interval(5, 10)
    assert low + high == pytest.approx(1.0, rel=1e-14) and 0.0 < low < 0.5
    with pytest.raises(ValueError, match="k and n must be single numbers"):
        proportion_interval([1, 2], 10)
    with pytest.raises(ValueError, match=r"confidence must be a number in \(0, 1\)"):
        proportion_interval(1, 10, confidence=0.0)


# --------------------------------------------------------------------------- seeds


def test_seed_spread_of_three_seeds():
    spread = seed_spread([1.0, 2.0, 3.0])
    assert (spread.mean, spread.std, spread.n) == (2.0, 1.0, 3)
    assert spread.std_error == pytest.approx(1.0 / math.sqrt(3.0), rel=1e-15)
    estimate = spread.estimate()
    assert (estimate.value, estimate.std_error, estimate.n, estimate.method, estimate.dof) == (
        2.0, spread.std_error, 3, "seeds", 2.0)


def test_seed_spread_of_one_seed_is_unknown_not_zero():
    spread = seed_spread([0.7])
    assert isinstance(spread, SeedSpread) and (spread.mean, spread.n) == (0.7, 1)
    assert math.isnan(spread.std) and math.isnan(spread.std_error)
    assert spread.estimate().format() == "0.7 ± unknown"


def test_seed_spread_rejects_bad_input():
    with pytest.raises(ValueError, match="values must hold the figure of at least one seed"):
        seed_spread([])
    with pytest.raises(ValueError, match="values must contain only finite numbers"):
        seed_spread([1.0, NAN])


# --------------------------------------------------------------------------- combining and comparing


def test_combine_independent_adds_in_quadrature():
    assert combine_independent([3.0, 4.0]) == 5.0
    assert combine_independent([2.0]) == 2.0
    assert math.isnan(combine_independent([3.0, NAN]))
    with pytest.raises(ValueError, match="errors must be a non-empty 1-D list"):
        combine_independent([])
    with pytest.raises(ValueError, match="errors must be finite numbers >= 0 or NaN"):
        combine_independent([3.0, -4.0])


@pytest.mark.parametrize("a, b, k, expected", [
    (10.0, 0.0, 2.0, Significance.NOT_SIGNIFICANT),  # |a - b| = 2 x 5: at the threshold, not beyond it
    (10.000001, 0.0, 2.0, Significance.SIGNIFICANT),
    (0.0, 10.000001, 2.0, Significance.SIGNIFICANT),
    (-5.0, 5.0, 1.9, Significance.SIGNIFICANT),  # 10 > 9.5
    (12.0, 0.0, 3.0, Significance.NOT_SIGNIFICANT),  # 12 < 15
])
def test_difference_significant_on_both_sides_of_the_threshold(a, b, k, expected):
    assert difference_significant(a, 3.0, b, 4.0, k=k) is expected


def test_difference_significant_is_unknown_without_an_error_and_has_no_truth_value():
    result = difference_significant(1.0, NAN, 100.0, 1.0)
    assert result is Significance.UNKNOWN and result.value == "unknown"
    assert Significance.SIGNIFICANT.value == "significant"
    with pytest.raises(TypeError, match="compare it with Significance.SIGNIFICANT"):
        bool(result)


def test_difference_significant_rejects_bad_input():
    with pytest.raises(ValueError, match="a must be a finite number"):
        difference_significant(NAN, 1.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="ub must be a finite number >= 0 or NaN"):
        difference_significant(1.0, 1.0, 0.0, -1.0)
    with pytest.raises(ValueError, match="k must be a finite number > 0"):
        difference_significant(1.0, 1.0, 0.0, 1.0, k=0.0)


# --------------------------------------------------------------------------- VRR counting-noise ceiling


def test_vrr_ceiling_of_a_batch_input_is_the_clumps_per_window():
    for p in (0.3, 0.5, 0.25, 1.0 / 3.0):
        assert vrr_ceiling(40, p * (1.0 - p), p) == 40.0
    # an input of variance 0.01 around p = 0.5 sampled in windows of 50: 0.01 / (0.25 / 50) = 2
    assert vrr_ceiling(50, 0.01, 0.5) == pytest.approx(2.0, rel=1e-15)


def test_vrr_ceiling_is_what_binomial_windows_of_a_perfect_mix_measure():
    # 20000 windows of 40 clumps drawn from a perfectly mixed outflow with p = 0.3 give VRR = 40 within 2 %
    rng = np.random.default_rng(7)
    concentration = rng.binomial(40, 0.3, size=20000) / 40
    assert 0.21 / concentration.var() == pytest.approx(vrr_ceiling(40, 0.21, 0.3), rel=0.02)


def test_vrr_ceiling_rejects_bad_input():
    with pytest.raises(ValueError, match="clumps_per_window must be a finite number > 0"):
        vrr_ceiling(0, 0.25, 0.5)
    with pytest.raises(ValueError, match="input_variance must be a finite number >= 0"):
        vrr_ceiling(10, -0.1, 0.5)
    with pytest.raises(ValueError, match=r"mean_fraction must be a number in \(0, 1\)"):
        vrr_ceiling(10, 0.25, 1.0)


def test_vrr_near_ceiling_flags_from_ceiling_over_factor():
    assert CEILING_FACTOR == 2.0
    assert vrr_near_ceiling(50.0, 100.0) is True  # the boundary, ceiling / 2, is flagged
    assert vrr_near_ceiling(49.999, 100.0) is False
    assert vrr_near_ceiling(NAN, 100.0) is False  # no VRR
    assert vrr_near_ceiling(math.inf, 100.0) is True  # no variance left: only the sampling can do that
    assert vrr_near_ceiling(99.0, 100.0, factor=1.0) is False
    np.testing.assert_array_equal(vrr_near_ceiling([10.0, 25.0, 60.0, 120.0], [100.0, 100.0, 100.0, 200.0]),
                                  [False, False, True, True])
    np.testing.assert_array_equal(vrr_near_ceiling([10.0, 25.0, 60.0], 100.0, factor=4.0), [False, True, True])


def test_vrr_near_ceiling_rejects_bad_input():
    with pytest.raises(ValueError, match="vrr must be >= 0"):
        vrr_near_ceiling(-1.0, 100.0)
    with pytest.raises(ValueError, match="ceiling must be a finite number > 0"):
        vrr_near_ceiling(1.0, 0.0)
    with pytest.raises(ValueError, match="ceiling must be a finite number > 0"):
        vrr_near_ceiling(1.0, NAN)
    with pytest.raises(ValueError, match="factor must be a finite number >= 1"):
        vrr_near_ceiling(1.0, 100.0, factor=0.5)
    with pytest.raises(ValueError, match="vrr and ceiling must broadcast together"):
        vrr_near_ceiling([1.0, 2.0], [10.0, 20.0, 30.0])


def test_windows_sized_for_a_target_vrr():
    # VRR 60 must stay below ceiling / 2: n > 120, and 120 itself would flag VRR 60 (at the boundary)
    assert window_clumps_for_precision(60) == 121
    assert vrr_near_ceiling(60.0, 120.0) and not vrr_near_ceiling(60.0, window_clumps_for_precision(60))
    assert window_clumps_for_precision(60, factor=1.5) == 91
    assert window_clumps_for_precision(30.2) == 61  # the next whole clump above 60.4
    assert window_duration_for_precision(19.5, throughput=40.0) == 1.0  # 40 > 39 clumps at 40 clumps/s
    with pytest.raises(ValueError, match="target_vrr must be a finite number > 0"):
        window_clumps_for_precision(0.0)
    with pytest.raises(ValueError, match="factor must be a finite number >= 1"):
        window_clumps_for_precision(60, factor=0.9)
    with pytest.raises(ValueError, match="throughput must be a finite number > 0"):
        window_duration_for_precision(60, throughput=0.0)


def test_line_slope_weighted_unweighted_and_two_points():
    # weighted: y = 1 + 10 x with sigma 0.1 at x = 0, 0.1, 0.2: slope error sigma / sqrt(sum (x - mean)^2)
    slope, error = line_slope([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], [0.1, 0.1, 0.1])
    assert slope == pytest.approx(10.0, rel=1e-12) and error == pytest.approx(0.1 / math.sqrt(0.02), rel=1e-12)
    # unweighted: residuals -1/6, +1/3, -1/6 about the line y = 1/6 + x give s^2 = (1/6) / 1, error s / sqrt(2)
    slope, error = line_slope([0.0, 1.0, 2.0], [0.0, 1.5, 2.0])
    assert slope == pytest.approx(1.0, rel=1e-12) and error == pytest.approx(math.sqrt(1.0 / 6.0 / 2.0), rel=1e-12)
    two = line_slope([0.0, 0.5], [1.0, 2.0])
    assert two[0] == 2.0 and math.isnan(two[1])
    with pytest.raises(ValueError, match="two distinct x"):
        line_slope([1.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="finite standard error"):
        line_slope([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
