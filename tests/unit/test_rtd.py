"""Unit tests for siloflow.analysis.numerics.rtd on samples and curves with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.rtd import (
    RTD,
    RTDMoments,
    johanson_rtd,
    perfect_mixer_rtd,
    plug_flow_rtd,
    rtd_from_exit_times,
    rtd_moments,
)
from siloflow.analysis.numerics.residence_statistics import (
    appearance_times,
    cohort_means_within,
    mean_residence_time,
    mean_residence_time_within,
    residence_time_resolution,
)


def exponential_quantiles(n: int, tau: float) -> np.ndarray:
    """Deterministic perfect-mixer sample: the mid-quantiles of an exponential of mean tau."""
    return -tau * np.log(1.0 - (np.arange(n) + 0.5) / n)


# --------------------------------------------------------------------------- from exit times


def test_discrete_sample_moments_match_closed_forms():
    n = 400
    t_entry = 3.25
    exits = t_entry + np.arange(1, n + 1, dtype=float)  # residence times 1, 2, ..., n
    rtd = rtd_from_exit_times(exits[::-1], t_entry=t_entry, bins=n)
    assert isinstance(rtd, RTD)
    assert rtd.t_mean == pytest.approx((n + 1) / 2, rel=1e-15)
    assert rtd.variance == pytest.approx((n * n - 1) / 12, rel=1e-13)
    assert rtd.t_first == 1.0 and rtd.t_last == float(n)
    assert rtd.ts_over_td == pytest.approx(1.0 / n, rel=1e-15)
    assert rtd.sigma_theta2 == pytest.approx(((n * n - 1) / 12) / ((n + 1) / 2) ** 2, rel=1e-13)
    assert rtd.n_exited == n and rtd.n_total == n and rtd.fraction_exited == 1.0
    assert float(np.sum(rtd.E * rtd.widths)) == pytest.approx(1.0, rel=1e-14)
    assert rtd.edges[0] == 0.0 and rtd.edges[-1] == n
    np.testing.assert_allclose(rtd.time, 0.5 * (rtd.edges[1:] + rtd.edges[:-1]))


def test_two_point_sample():
    rtd = rtd_from_exit_times([2.0, 6.0], bins=[0.0, 4.0, 8.0])
    assert rtd.t_mean == 4.0 and rtd.variance == 4.0
    np.testing.assert_array_equal(rtd.E, [0.125, 0.125])  # one of two tracers per 4 s bin
    assert rtd.ts_over_td == pytest.approx(1.0 / 3.0)


def test_exponential_sample_theta_form_integrates_to_one():
    tau = 2.0
    n = 20_000
    rtd = rtd_from_exit_times(10.0 + exponential_quantiles(n, tau), t_entry=10.0)
    dtheta = np.diff(rtd.edges) / rtd.t_mean
    assert float(np.sum(rtd.E_theta * dtheta)) == pytest.approx(1.0, rel=1e-13)
    np.testing.assert_allclose(rtd.theta, rtd.time / rtd.t_mean)
    # the mid-quantile sample has mean and variance close to tau and tau^2
    assert rtd.t_mean == pytest.approx(tau, rel=1e-3)
    assert rtd.variance == pytest.approx(tau**2, rel=2e-2)
    assert rtd.sigma_theta2 == pytest.approx(1.0, rel=2e-2)


def test_exponential_sample_histogram_matches_bin_averaged_exponential():
    tau = 1.5
    n = 50_000
    rtd = rtd_from_exit_times(exponential_quantiles(n, tau), bins=np.arange(0.0, 25.0, 0.25))
    a, b = rtd.edges[:-1], rtd.edges[1:]
    exact = (np.exp(-a / tau) - np.exp(-b / tau)) / (b - a)
    expected_counts = n * exact * (b - a)
    big = expected_counts >= 1000
    assert big.sum() >= 5
    # deterministic quantiles: each bin holds its expected count to within one tracer
    np.testing.assert_allclose(rtd.E[big], exact[big], rtol=1.0 / 1000 + 1e-12)
    # and the bin averages approach the curve at the bin centres
    np.testing.assert_allclose(rtd.E[big], perfect_mixer_rtd(rtd.time[big], tau), rtol=5e-3)


def test_tracers_that_did_not_leave_reduce_the_area():
    exits = np.array([1.0, 2.0, np.nan, 3.0])
    rtd = rtd_from_exit_times(exits, bins=3)
    assert rtd.n_exited == 3 and rtd.n_total == 4
    assert float(np.sum(rtd.E * rtd.widths)) == pytest.approx(0.75)
    assert rtd.t_mean == 2.0
    rtd = rtd_from_exit_times([1.0, 2.0, 3.0], n_total=10, bins=3)
    assert rtd.fraction_exited == 0.3
    assert float(np.sum(rtd.E * rtd.widths)) == pytest.approx(0.3)


def test_per_tracer_entry_times():
    entries = np.array([0.0, 1.0, 2.0])
    exits = entries + np.array([5.0, 6.0, 7.0])
    rtd = rtd_from_exit_times(exits, t_entry=entries, bins=7)
    assert rtd.t_mean == 6.0 and rtd.t_first == 5.0 and rtd.t_last == 7.0


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(exit_times=[1.0, -1.0]), "t_entry"),
        (dict(exit_times=[1.0, np.inf]), "exit_times"),
        (dict(exit_times=[np.nan, np.nan]), "exit_times"),
        (dict(exit_times=[]), "exit_times"),
        (dict(exit_times=[[1.0]]), "exit_times"),
        (dict(exit_times=[1.0, 2.0], t_entry=[0.0]), "t_entry"),
        (dict(exit_times=[1.0, 2.0], bins=0), "bins"),
        (dict(exit_times=[1.0, 2.0], bins="auto"), "bins"),
        (dict(exit_times=[1.0, 2.0], bins=[0.0, 1.5]), "bins"),
        (dict(exit_times=[1.0, 2.0], bins=[0.0, 3.0, 2.0]), "bins"),
        (dict(exit_times=[1.0, 2.0], n_total=1), "n_total"),
        (dict(exit_times=[1.0, 2.0], n_total=2.5), "n_total"),
        (dict(exit_times=[0.0, 0.0]), "bins"),
    ],
)
def test_rtd_from_exit_times_rejects_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        rtd_from_exit_times(**kwargs)


# --------------------------------------------------------------------------- moments of curves


def test_rtd_moments_trapezoid_by_hand():
    moments = rtd_moments([0.0, 1.0, 2.0], [0.0, 2.0, 0.0])
    assert isinstance(moments, RTDMoments)
    # area 2; mean (0 + 2 + 0) / 2 = 1; variance trapz((t-1)^2 E) / area = (0 + 0 + 0) / 2
    assert moments.area == 2.0 and moments.mean == 1.0 and moments.variance == 0.0


def test_rtd_moments_of_a_finely_sampled_perfect_mixer():
    tau = 0.7
    t = np.linspace(0.0, 40 * tau, 400_001)
    moments = rtd_moments(t, perfect_mixer_rtd(t, tau))
    assert moments.area == pytest.approx(1.0, rel=1e-8)
    assert moments.mean == pytest.approx(tau, rel=1e-8)
    assert moments.variance == pytest.approx(tau**2, rel=1e-7)
    assert moments.sigma_theta2 == pytest.approx(1.0, rel=1e-7)


def test_rtd_moments_rejects_bad_input():
    with pytest.raises(ValueError, match="E"):
        rtd_moments([0.0, 1.0], [1.0])
    with pytest.raises(ValueError, match="time"):
        rtd_moments([1.0, 0.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="E"):
        rtd_moments([0.0, 1.0], [0.0, 0.0])
    with pytest.raises(ValueError, match="time"):
        rtd_moments([0.0, np.nan], [1.0, 1.0])


# --------------------------------------------------------------------------- models


def test_perfect_mixer_values():
    t = np.array([-1.0, 0.0, 2.0])
    np.testing.assert_allclose(perfect_mixer_rtd(t, 2.0), [0.0, 0.5, 0.5 * math.exp(-1.0)], rtol=1e-15)
    with pytest.raises(ValueError, match="tau"):
        perfect_mixer_rtd(t, 0.0)


def test_plug_flow_pulse_is_normalised_and_centred():
    dt = 0.01
    t = np.arange(0, 1001) * dt
    pulse = plug_flow_rtd(t, tau=4.0)  # width = dt
    assert float(np.sum(pulse) * dt) == pytest.approx(1.0, abs=1e-8)
    assert float(np.sum(t * pulse) * dt) == pytest.approx(4.0, rel=1e-8)
    assert float(np.argmax(pulse)) == 400
    wide = plug_flow_rtd(t, tau=4.0, width=0.05)
    assert float(np.sum(wide) * dt) == pytest.approx(1.0, abs=1e-12)
    assert rtd_moments(t, wide).variance == pytest.approx(0.05**2, rel=1e-6)
    with pytest.raises(ValueError, match="width"):
        plug_flow_rtd(t, 4.0, width=-1.0)
    with pytest.raises(ValueError, match="width"):
        plug_flow_rtd([1.0], 4.0)


@pytest.mark.parametrize("v1, p", [(0.5, 1.0), (0.2, 0.6), (0.0, 0.0), (0.4, 1.3), (0.9, 0.95)])
def test_johanson_triangle_has_unit_area_mean_tau_and_triangle_variance(v1, p):
    tau = 2.75
    t = np.linspace(0.0, 4.0 * tau, 440_001)
    e = johanson_rtd(t, tau, v1, p)
    end = 3.0 - v1 - p
    moments = rtd_moments(t, e)
    # (the trapezoid rule smears a jump at P = V1 or P = end over one step)
    assert moments.area == pytest.approx(1.0, rel=5e-5)
    assert moments.mean == pytest.approx(tau, rel=5e-5)
    a, b, c = v1, end, p
    variance = tau**2 * (a * a + b * b + c * c - a * b - a * c - b * c) / 18.0
    assert moments.variance == pytest.approx(variance, rel=2e-4)
    assert np.all(e[t < v1 * tau] == 0.0) and np.all(e[t > end * tau] == 0.0)
    # peak at P: the largest sample sits at theta = P
    assert t[np.argmax(e)] / tau == pytest.approx(p, abs=1e-4)


def test_johanson_symmetric_case_by_hand():
    # V1 = 0.5, P = 1: triangle from 0.5 to 1.5 with peak 2 at theta = 1 (tau = 1)
    e = johanson_rtd([0.5, 0.75, 1.0, 1.25, 1.5], 1.0, 0.5, 1.0)
    np.testing.assert_allclose(e, [0.0, 1.0, 2.0, 1.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("v1, p, match", [(1.0, 1.0, "V1"), (-0.1, 0.5, "V1"), (0.5, 0.4, "P"), (0.2, 1.5, "P")])
def test_johanson_rejects_bad_parameters(v1, p, match):
    with pytest.raises(ValueError, match=match):
        johanson_rtd([0.0, 1.0], 1.0, v1, p)


# --------------------------------------------------------------------------- uncertainty

# Eight tracers with mean 5 s and population standard deviation 2 s: the sample variance is 32 / 7 s^2, so the
# mean has the standard error sqrt(32 / 7 / 8) = sqrt(4 / 7) s. One more tracer never left (NaN).
KNOWN_SAMPLE = np.array([2.0, 4.0, 4.0, 4.0, 5.0, np.nan, 5.0, 7.0, 9.0])


def test_mean_residence_time_is_the_sample_mean_with_its_standard_error():
    mean = mean_residence_time(KNOWN_SAMPLE)
    assert (mean.value, mean.n, mean.dof, mean.method) == (5.0, 8, 7.0, "tracer sample")
    assert mean.std_error == pytest.approx(math.sqrt(4.0 / 7.0), rel=1e-15)
    one = mean_residence_time([np.nan, 3.0])  # a single tracer says nothing about the spread
    assert (one.value, one.n) == (3.0, 1) and math.isnan(one.std_error)


def test_rtd_t_mean_error_equals_that_of_the_sample():
    rtd = rtd_from_exit_times(KNOWN_SAMPLE + 1.0, t_entry=1.0, bins=4)
    assert (rtd.t_mean, rtd.variance) == (5.0, 4.0)
    assert rtd.t_mean_error == pytest.approx(math.sqrt(4.0 / 7.0), rel=1e-15)
    assert math.isnan(rtd_from_exit_times([2.0, np.nan], bins=1).t_mean_error)


@pytest.mark.parametrize("sample, message", [
    ([np.nan, np.nan], "no tracer left"),
    ([], "no tracer left"),
    ([1.0, np.inf], "infinite"),
    ([[1.0, 2.0]], "1-D"),
])
def test_mean_residence_time_rejects_bad_samples(sample, message):
    with pytest.raises(ValueError, match=message):
        mean_residence_time(sample)


def test_mean_residence_time_within_a_horizon_leaves_the_slower_and_unexited_out():
    # KNOWN_SAMPLE up to 5 s: 2, 4, 4, 4, 5, 5 (mean 4, squared deviations 4 + 0 + 0 + 0 + 1 + 1 = 6, so
    # s^2 = 6 / 5 and the error sqrt(6 / 5 / 6) = sqrt(1 / 5)); 7, 9 and the NaN are out
    within = mean_residence_time_within(KNOWN_SAMPLE, 5.0)
    assert (within.value, within.n, within.method) == (4.0, 6, "tracer sample")
    assert within.std_error == pytest.approx(math.sqrt(0.2), rel=1e-15)
    # a horizon beyond the longest residence time gives the plain mean
    whole = mean_residence_time_within(KNOWN_SAMPLE, 100.0)
    assert (whole.value, whole.std_error) == (mean_residence_time(KNOWN_SAMPLE).value,
                                              mean_residence_time(KNOWN_SAMPLE).std_error)


@pytest.mark.parametrize("sample, horizon, message", [
    ([3.0, np.nan], 2.0, "no tracer left within"),
    ([1.0, 2.0], 0.0, "horizon"),
    ([1.0, np.inf], 2.0, "infinite"),
    ([[1.0, 2.0]], 2.0, "1-D"),
])
def test_mean_residence_time_within_rejects_bad_input(sample, horizon, message):
    with pytest.raises(ValueError, match=message):
        mean_residence_time_within(sample, horizon)


def test_cohort_means_cut_the_passes_in_entry_order_and_average_those_within_the_horizon():
    # entries out of order; in entry order the residence times are 1, 3, | 2, 9 (over h = 5), | NaN, 4, | 6 (partial)
    entry = [0.4, 0.1, 0.0, 0.3, 0.2, 0.5, 0.6]
    residence = [np.nan, 3.0, 1.0, 9.0, 2.0, 4.0, 6.0]
    np.testing.assert_array_equal(cohort_means_within(entry, residence, 5.0, 2), [2.0, 2.0, 4.0])
    # a cohort with none within the horizon is dropped
    np.testing.assert_array_equal(cohort_means_within([0.0, 1.0], [7.0, 8.0], 5.0, 1), [])


@pytest.mark.parametrize("entry, residence, horizon, size, message", [
    ([0.0, 1.0], [1.0], 5.0, 1, "shape"),
    ([0.0, np.nan], [1.0, 2.0], 5.0, 1, "entry_time must be finite"),
    ([0.0, 1.0], [1.0, -2.0], 5.0, 1, ">= 0"),
    ([0.0, 1.0], [1.0, 2.0], 0.0, 1, "horizon"),
    ([0.0, 1.0], [1.0, 2.0], 5.0, 0, "cohort_size"),
    ([0.0, 1.0], [1.0, 2.0], 5.0, 1.5, "cohort_size"),
])
def test_cohort_means_reject_bad_input(entry, residence, horizon, size, message):
    with pytest.raises(ValueError, match=message):
        cohort_means_within(entry, residence, horizon, size)


def test_one_cohorts_error_is_the_spread_of_the_other_cohorts_means():
    # cohort means 3, 5, 7: sample standard deviation 2; the tracer's own mean is kept
    within = mean_residence_time_within(KNOWN_SAMPLE, 5.0, [3.0, 5.0, 7.0])
    assert (within.value, within.std_error, within.n, within.method, within.dof) == (4.0, 2.0, 3, "cohort spread", 2)
    # fewer than two cohorts: the error within the tracer
    assert mean_residence_time_within(KNOWN_SAMPLE, 5.0, [3.0]) == mean_residence_time_within(KNOWN_SAMPLE, 5.0)
    with pytest.raises(ValueError, match="cohort_means must"):
        mean_residence_time_within(KNOWN_SAMPLE, 5.0, [3.0, np.nan])


def test_residence_time_resolution_is_the_frame_interval_over_sqrt_6():
    # two events, each uniform over its frame interval: variance 2 x 0.03^2 / 12 = 0.03^2 / 6
    assert residence_time_resolution(0.03) == 0.03 / math.sqrt(6.0)
    assert residence_time_resolution(math.sqrt(6.0)) == pytest.approx(1.0, rel=1e-15)
    assert residence_time_resolution(0.0) == 0.0
    assert math.isnan(residence_time_resolution(math.nan))  # unknown stays unknown
    for bad in (-0.01, math.inf):
        with pytest.raises(ValueError, match="frame_interval must be a finite number >= 0"):
            residence_time_resolution(bad)


def test_appearance_times_combine_the_end_gaps_with_the_resolution():
    # sorted 10, 13, 20, 27, 30 s (one tracer still inside): gaps 3 s at both ends; with a resolution of 4 s
    # t_s = 10 +- 5 s and t_d = 30 +- 5 s, and t_s / t_d = 1/3 +- (1/3) sqrt((5/10)^2 + (5/30)^2) = sqrt(10) / 18
    times = appearance_times([27.0, 10.0, np.nan, 30.0, 13.0, 20.0], resolution=4.0)
    assert (times.t_first.value, times.t_first.std_error) == (10.0, 5.0)
    assert (times.t_last.value, times.t_last.std_error) == (30.0, 5.0)
    assert times.ts_over_td.value == 1.0 / 3.0
    assert times.ts_over_td.std_error == pytest.approx(math.sqrt(10.0) / 18.0, rel=1e-15)
    assert {estimate.n for estimate in (times.t_first, times.t_last, times.ts_over_td)} == {5}
    assert times.t_first.method == "order-statistic gap"
    # the same values as the RTD itself
    rtd = rtd_from_exit_times([27.0, 10.0, np.nan, 30.0, 13.0, 20.0], bins=3)
    assert (rtd.t_first, rtd.t_last, rtd.ts_over_td) == (10.0, 30.0, times.ts_over_td.value)


def test_appearance_times_without_resolution_and_at_the_edges():
    gaps_only = appearance_times([10.0, 13.0, 20.0, 27.0, 30.0])
    assert (gaps_only.t_first.std_error, gaps_only.t_last.std_error) == (3.0, 3.0)
    # t_s = 0 (a tracer out at once): the ratio is 0 with the absolute error of t_s over t_d, 1 / 2
    at_zero = appearance_times([0.0, 1.0, 2.0])
    assert (at_zero.ts_over_td.value, at_zero.ts_over_td.std_error) == (0.0, 0.5)
    # plug flow: no gaps, the resolution alone
    plug = appearance_times([7.5, 7.5, 7.5], resolution=0.1)
    assert (plug.t_first.std_error, plug.t_last.std_error) == (0.1, 0.1)
    assert plug.ts_over_td.std_error == pytest.approx(math.sqrt(2.0) * 0.1 / 7.5, rel=1e-15)
    # one tracer out, or an unknown resolution: the errors are unknown, not zero
    for times in (appearance_times([5.0, np.nan]), appearance_times([1.0, 2.0], resolution=math.nan)):
        assert all(math.isnan(e.std_error) for e in (times.t_first, times.t_last, times.ts_over_td))


@pytest.mark.parametrize("sample, resolution, message", [
    ([np.nan], 0.0, "no tracer left"),
    ([-1.0, 2.0], 0.0, "must be >= 0"),
    ([0.0, 0.0], 0.0, "the longest is 0"),
    ([1.0, 2.0], -0.1, "resolution must be"),
    ([1.0, 2.0], math.inf, "resolution must be"),
])
def test_appearance_times_rejects_bad_input(sample, resolution, message):
    with pytest.raises(ValueError, match=message):
        appearance_times(sample, resolution)
