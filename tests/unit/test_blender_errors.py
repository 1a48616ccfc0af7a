"""Exact answers for the standard errors of the blender's figures, the comparison table's error and ceiling
columns, and the significance of the differences between configurations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.uncertainty import Significance
from siloflow.analysis.studies.blender.comparison import BlenderMetrics, comparison_table, figure_columns, significance_rows
from siloflow.analysis.studies.blender.errors import (
    effective_count,
    homogenisation_error,
    passage_velocity_estimates,
    residence_time_error,
    sine_vrr_error,
    steady_flow_rate_estimate,
    tracer_errors,
)
from siloflow.analysis.numerics.lti import recirculations_to_homogenise
from siloflow.analysis.studies.blender.steady_field import BlenderField

NAN = math.nan
SE_1234 = math.sqrt(5.0 / 3.0) / 2.0  # std([1, 2, 3, 4], ddof=1) / sqrt(4)


# --------------------------------------------------------------------------- mass flow rate


def test_flow_rate_takes_the_batch_slopes_of_the_steady_window_only():
    # samples at t = -2 ... 11 s; the window [0, 11] s holds 12 of them, in 4 batches of 3 with slopes 1, 2, 3, 4 kg/s
    time = np.arange(-2.0, 12.0)
    mass = np.array([500.0, -70.0, 0.0, 1.0, 2.0, 10.0, 12.0, 14.0, 30.0, 33.0, 36.0, 50.0, 54.0, 58.0])
    estimate = steady_flow_rate_estimate(time, mass, (0.0, 11.0), n_batches=4)
    assert (estimate.value, estimate.n, estimate.method) == (2.5, 4, "batch rate")
    assert estimate.std_error == pytest.approx(SE_1234, rel=1e-14)
    # by default as many batches of two as the window allows, at most 10: 12 samples give 6
    assert steady_flow_rate_estimate(time, mass, (0.0, 11.0)).n == 6


def test_flow_rate_of_a_window_too_short_for_two_batches_has_an_unknown_error():
    estimate = steady_flow_rate_estimate([0.0, 1.0, 2.0, 3.0], [9.0, 0.0, 2.0, 4.0], (1.0, 3.0))
    assert estimate.value == pytest.approx(2.0) and math.isnan(estimate.std_error) and estimate.n == 1
    with pytest.raises(ValueError, match="holds 1 sample"):
        steady_flow_rate_estimate([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], (0.5, 1.5))
    with pytest.raises(ValueError, match="no frame"):
        steady_flow_rate_estimate([0.0, 1.0], [0.0, 1.0], (2.0, 3.0))
    with pytest.raises(ValueError, match="shape of time"):
        steady_flow_rate_estimate([0.0, 1.0], [0.0], (0.0, 1.0))
    with pytest.raises(ValueError, match="n_batches"):
        steady_flow_rate_estimate([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 3.0], (0.0, 3.0), n_batches=1)


# --------------------------------------------------------------------------- passage velocities

X = np.array([-0.015, -0.005, 0.005, 0.015])     # bins 10 mm wide, both halves
Z = np.array([0.005, 0.015])
PASSAGES = {"inner": (0.0, 0.01), "outer": (0.01, 0.02), "beyond": (0.02, 0.03)}


def frame(inner, outer):
    """One frame: speed ``inner`` in the bins |x| = 5 mm and ``outer`` in |x| = 15 mm (None: no particle there)."""
    v_z = np.zeros((X.size, Z.size))
    fraction = np.full((X.size, Z.size), 0.5)
    v_z[[1, 2]] = -inner
    if outer is None:
        fraction[[0, 3]] = 0.0
    else:
        v_z[[0, 3]] = -outer
    return BlenderField(x=X, z=Z, v_x=np.zeros_like(v_z), v_z=v_z, solid_fraction=fraction)


def test_passage_velocities_are_batch_means_of_the_per_frame_means_leaving_out_empty_frames():
    # inner: 8 frames, 3 batches of 2 after the 2 oldest: means 2, 3, 4. outer: the first frame has no particle
    # there, so 7 values, 3 batches of 2 after the oldest: again 2, 3, 4.
    speeds = [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0]
    outer = [None, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0]
    estimates = passage_velocity_estimates([frame(a, b) for a, b in zip(speeds, outer)], 0.005, PASSAGES, n_batches=3)
    for name in ("inner", "outer"):
        assert (estimates[name].value, estimates[name].n, estimates[name].method) == (-3.0, 3, "batch means")
        assert estimates[name].std_error == pytest.approx(1.0 / math.sqrt(3.0), rel=1e-14)
    assert estimates["beyond"] is None  # no bin in that interval in any frame


def test_passage_velocity_of_a_single_frame_has_an_unknown_error():
    estimates = passage_velocity_estimates([frame(2.0, 1.0)], 0.005, PASSAGES)
    assert estimates["inner"].value == -2.0 and math.isnan(estimates["inner"].std_error)
    assert estimates["inner"].n == 1
    with pytest.raises(ValueError, match="n_batches"):
        passage_velocity_estimates([frame(2.0, 1.0)], 0.005, PASSAGES, n_batches=1)
    with pytest.raises(ValueError, match="BlenderField"):
        passage_velocity_estimates([None], 0.005, PASSAGES)


# --------------------------------------------------------------------------- tracers


def test_effective_count_of_equal_and_unequal_weights():
    assert effective_count([0.6, 0.6, 0.6, 0.6]) == pytest.approx(4.0, rel=1e-15)
    assert effective_count([1.0, 3.0]) == pytest.approx(16.0 / 10.0, rel=1e-15)
    with pytest.raises(ValueError, match="not all 0"):
        effective_count([0.0, 0.0])
    with pytest.raises(ValueError, match="not all 0"):
        effective_count([1.0, -1.0])


def test_tracer_errors_of_four_equal_tracers():
    # tau = 1, 2, 3, 4 s and a tracer that never left: t_m = 2.5 s, sigma^2 = 1.25 s^2, n = 4
    errors = tracer_errors([1.0, 2.0, NAN, 3.0, 4.0], resolution=0.0)
    assert errors.n_effective == pytest.approx(4.0)
    assert errors.t_mean == pytest.approx(SE_1234, rel=1e-14)  # std(ddof=1) / sqrt(n)
    spread = math.sqrt(1.25) / 2.5
    assert errors.spread == pytest.approx(spread * math.sqrt((0.5 + spread ** 2) / 3.0), rel=1e-14)
    # t_s = 1 s and t_d = 4 s each 1 s from the next exit: sqrt((1/4)^2 + (1 * 1 / 16)^2)
    assert errors.ts_over_td == pytest.approx(math.sqrt(17.0) / 16.0, rel=1e-14)
    # a detection resolution of sqrt(12) s adds 1 s^2 to each end's variance
    assert tracer_errors([1.0, 2.0, 3.0, 4.0], resolution=math.sqrt(12.0)).ts_over_td == pytest.approx(
        math.sqrt(2.0) * math.sqrt(17.0) / 16.0, rel=1e-14)
    # an unknown resolution leaves t_s / t_d without an error, not the others
    unknown = tracer_errors([1.0, 2.0, 3.0, 4.0], resolution=NAN)
    assert math.isnan(unknown.ts_over_td) and unknown.t_mean == pytest.approx(SE_1234, rel=1e-14)


def test_tracer_errors_weight_the_tracers():
    # tau = 1, 3 s with weights 1, 3: t_m = 2.5 s, sigma^2 = (1.5^2 + 3 * 0.5^2) / 4 = 0.75 s^2, n_eff = 1.6
    errors = tracer_errors([1.0, 3.0], weights=[1.0, 3.0])
    assert errors.n_effective == pytest.approx(1.6, rel=1e-15)
    assert errors.t_mean == pytest.approx(math.sqrt(0.75 / 0.6), rel=1e-14)
    # a single exited tracer: n_eff = 1, no spread to take an error from and no second exit
    single = tracer_errors([2.0, NAN])
    assert single.n_effective == 1.0 and math.isnan(single.t_mean) and math.isnan(single.ts_over_td)


def test_residence_time_error_adds_the_flow_rates_relative_error():
    # 3 s from the tracers; 4 % of t_m = 100 s from a flow rate of 0.5 +- 0.02 kg/s: sqrt(3^2 + 4^2)
    assert residence_time_error(100.0, 3.0, 0.5, 0.02) == pytest.approx(5.0, rel=1e-14)
    assert residence_time_error(100.0, 3.0, -0.5, 0.0) == 3.0
    assert math.isnan(residence_time_error(100.0, 3.0, 0.5, NAN))
    assert math.isnan(residence_time_error(100.0, NAN, 0.5, 0.02))
    with pytest.raises(ValueError, match="non-zero"):
        residence_time_error(100.0, 3.0, 0.0, 0.02)
    with pytest.raises(ValueError, match="flow_rate_error"):
        residence_time_error(100.0, 3.0, 0.5, -0.02)


def test_tracer_errors_reject_bad_input():
    with pytest.raises(ValueError, match="no tracer exited"):
        tracer_errors([NAN, NAN])
    with pytest.raises(ValueError, match="weights"):
        tracer_errors([1.0, 2.0], weights=[1.0])
    with pytest.raises(ValueError, match="weights"):
        tracer_errors([1.0, 2.0], weights=[1.0, 0.0])
    with pytest.raises(ValueError, match="residence_time"):
        tracer_errors([1.0, -2.0])
    with pytest.raises(ValueError, match="resolution"):
        tracer_errors([1.0, 2.0], resolution=-0.1)


def test_sine_vrr_error_vanishes_undamped_and_grows_towards_the_ceiling():
    assert sine_vrr_error(1.0, 100.0) == 0.0
    assert sine_vrr_error(51.0, 100.0) == pytest.approx(51.0, rel=1e-15)  # 51 sqrt(2 * 50 / 100)
    assert sine_vrr_error(0.5, 100.0) == 0.0  # below 1 only by round-off: no negative variance
    np.testing.assert_allclose(sine_vrr_error([9.0, NAN, math.inf], 16.0), [9.0, NAN, NAN], rtol=1e-15)
    with pytest.raises(ValueError, match="vrr must be >= 0"):
        sine_vrr_error(-1.0, 10.0)
    with pytest.raises(ValueError, match="n_effective"):
        sine_vrr_error(2.0, 0.0)


@pytest.mark.parametrize("omega", [3.0, 7.0])
def test_sine_vrr_error_matches_the_spread_of_vrrs_from_drawn_tracers(omega):
    # 400 tracers from an exponential RTD of mean 1: phi = 1 / (1 + i omega), true VRR = 1 + omega^2 (10 and 50).
    # The VRR of each draw is 1 / |mean(exp(-i omega tau))|^2; half the central 68 % of 4000 draws is its spread.
    n = 400
    tau = np.random.default_rng(20261125).exponential(1.0, (4000, n))
    vrr = 1.0 / np.abs(np.exp(-1j * omega * tau).mean(axis=1)) ** 2
    low, high = np.percentile(vrr, [15.87, 84.13])
    assert 0.5 * (high - low) == pytest.approx(sine_vrr_error(1.0 + omega ** 2, n), rel=0.1)


# --------------------------------------------------------------------------- comparison table


def test_comparison_table_carries_errors_the_ceiling_and_its_flags():
    known = BlenderMetrics(name="a", mass_flow_rate=0.5, exterior_v_z=-0.01, interior_v_z=-0.02, tube_v_z=NAN,
                           rtd_mean=20.0, rtd_spread=0.3, ts_over_td=0.2, recirculations_to_homogenise=2.0,
                           vrr_by_period={2.0: 10.0, 0.5: 300.0}, mass_flow_rate_error=0.01, rtd_mean_error=1.5,
                           vrr_errors={0.5: 250.0}, vrr_ceiling=500.0)
    unknown = BlenderMetrics(name="b", mass_flow_rate=0.4, exterior_v_z=-0.01, interior_v_z=-0.02, tube_v_z=-0.03,
                             rtd_mean=10.0, rtd_spread=0.4, ts_over_td=0.1, recirculations_to_homogenise=NAN,
                             vrr_by_period={0.5: 20.0, 2.0: 3.0})
    first, second = comparison_table([known, unknown])
    assert list(first)[-9:] == ["recirculations_to_homogenise", "recirculations_to_homogenise_error", "vrr_at_0.5_tm",
                                "vrr_at_0.5_tm_error", "vrr_at_2_tm", "vrr_at_2_tm_error", "vrr_ceiling",
                                "vrr_at_0.5_tm_at_ceiling", "vrr_at_2_tm_at_ceiling"]
    assert (first["mass_flow_rate_kg_s_error"], first["rtd_mean_s_error"], first["vrr_at_0.5_tm_error"]) == (
        0.01, 1.5, 250.0)
    assert math.isnan(first["vrr_at_2_tm_error"]) and math.isnan(first["tube_v_z_m_s_error"])
    # 300 >= 500 / 2 is at the ceiling, 10 is not; b's ceiling is unknown, and so are its flags
    assert (first["vrr_ceiling"], first["vrr_at_0.5_tm_at_ceiling"], first["vrr_at_2_tm_at_ceiling"]) == (
        500.0, True, False)
    assert math.isnan(second["vrr_ceiling"]) and second["vrr_at_0.5_tm_at_ceiling"] is None
    assert figure_columns(first) == [
        "mass_flow_rate_kg_s", "exterior_v_z_m_s", "interior_v_z_m_s", "tube_v_z_m_s", "rtd_mean_s", "rtd_spread",
        "ts_over_td", "recirculations_to_homogenise", "vrr_at_0.5_tm", "vrr_at_2_tm",
    ]


# --------------------------------------------------------------------------- significance

ROWS = [
    {"configuration": "a", "flow": 3.0, "flow_error": 0.3, "recirculations_to_homogenise": 2.0, "vrr_at_1_tm": 10.0,
     "vrr_at_1_tm_error": 1.0, "vrr_ceiling": 150.0, "vrr_at_1_tm_at_ceiling": False},
    {"configuration": "b", "flow": 1.0, "flow_error": 0.4, "recirculations_to_homogenise": 3.0, "vrr_at_1_tm": 12.0,
     "vrr_at_1_tm_error": 2.0, "vrr_ceiling": 150.0, "vrr_at_1_tm_at_ceiling": False},
    {"configuration": "c", "flow": 2.0, "flow_error": NAN, "recirculations_to_homogenise": NAN, "vrr_at_1_tm": 90.0,
     "vrr_at_1_tm_error": 80.0, "vrr_ceiling": 150.0, "vrr_at_1_tm_at_ceiling": True},
]


def test_significance_rows_compare_every_pair_of_every_figure():
    rows = significance_rows(ROWS)
    assert list(rows[0]) == ["figure", "configuration_a", "configuration_b", "value_a", "error_a", "value_b", "error_b",
                             "difference", "difference_error", "significance"]
    expected = [
        # flow: 2 > 2 x 0.5 for a - b; c's error is unknown
        ("flow", "a", "b", 2.0, 0.5, "significant"), ("flow", "a", "c", 1.0, NAN, "unknown"),
        ("flow", "b", "c", -1.0, NAN, "unknown"),
        # no error column: unknown; c never homogenised
        ("recirculations_to_homogenise", "a", "b", -1.0, NAN, "unknown"),
        ("recirculations_to_homogenise", "a", "c", NAN, NAN, "unknown"),
        ("recirculations_to_homogenise", "b", "c", NAN, NAN, "unknown"),
        # 2 < 2 sqrt(5); c's VRR is at its ceiling, a lower bound
        ("vrr_at_1_tm", "a", "b", -2.0, math.sqrt(5.0), "not significant"),
        ("vrr_at_1_tm", "a", "c", -80.0, math.hypot(1.0, 80.0), "unknown"),
        ("vrr_at_1_tm", "b", "c", -78.0, math.hypot(2.0, 80.0), "unknown"),
    ]
    assert len(rows) == len(expected)
    for row, (figure, a, b, difference, error, significance) in zip(rows, expected):
        assert (row["figure"], row["configuration_a"], row["configuration_b"], row["significance"]) == (
            figure, a, b, significance)
        np.testing.assert_allclose([row["difference"], row["difference_error"]], [difference, error], rtol=1e-14)
    assert (rows[0]["value_a"], rows[0]["error_a"], rows[0]["value_b"], rows[0]["error_b"]) == (3.0, 0.3, 1.0, 0.4)
    assert rows[0]["significance"] == Significance.SIGNIFICANT.value


def test_significance_rows_take_the_coverage_factor_and_check_their_input():
    assert significance_rows(ROWS, k=5.0)[0]["significance"] == "not significant"  # 2 < 5 x 0.5
    assert significance_rows(ROWS[:1]) == []
    with pytest.raises(ValueError, match="k must be"):
        significance_rows(ROWS, k=0.0)
    with pytest.raises(ValueError, match="at least one"):
        significance_rows([])
    with pytest.raises(ValueError, match=r"rows\[1\] has no column 'flow'"):
        significance_rows([ROWS[0], {"configuration": "b"}])


def _crossing(concentration):
    """Windows until c stays within 10 % of 1 (one window per recirculation)."""
    return recirculations_to_homogenise(concentration, mean=1.0, tolerance=0.1, per_pass_length=1.0)


def _identity(first_pass):
    return first_pass


def test_without_counting_noise_the_homogenisation_error_is_the_windows_resolution():
    # no noise, or noise where it cannot move the crossing (window 0 is 4 above the band): one window, uniform
    for variance in ([0.0, 0.0, 0.0, 0.0], [1e-4, 0.0, 0.0, 0.0]):
        assert homogenisation_error([5.0, 1.0, 1.0, 1.0], variance, _identity, _crossing, 1.0) == pytest.approx(
            1.0 / math.sqrt(12.0), rel=1e-12)
    # four windows per recirculation: a quarter of that
    assert homogenisation_error([5.0, 1.0, 1.0, 1.0], [0.0] * 4, _identity, _crossing, 4.0) == pytest.approx(
        0.25 / math.sqrt(12.0), rel=1e-12)


def test_noise_that_can_add_an_excursion_moves_the_crossing_by_it():
    # window 2 has unit noise: it leaves the band (|z| > 0.1) with p = 2 (1 - Phi(0.1)) = 0.9203, and the crossing
    # is then 3 instead of 1: a two-point spread of 2 sqrt(p (1 - p)), with the resolution added
    p = math.erfc(0.1 / math.sqrt(2.0))
    expected = math.hypot(2.0 * math.sqrt(p * (1.0 - p)), 1.0 / math.sqrt(12.0))
    error = homogenisation_error([5.0, 1.0, 1.0, 1.0], [0.0, 0.0, 1.0, 0.0], _identity, _crossing, 1.0, draws=4000)
    # 4000 draws: p is known to sqrt(p (1 - p) / 4000) = 0.0043, the spread to about 4 %
    assert error == pytest.approx(expected, rel=0.04)


def test_a_figure_most_draws_never_reach_has_no_error():
    # the last window leaves the band in 92 % of the draws: not homogenised within the record
    assert math.isnan(homogenisation_error([1.0, 1.0, 1.0], [0.0, 0.0, 1.0], _identity, _crossing, 1.0))


@pytest.mark.parametrize("first, variance, windows, draws, message", [
    ([1.0, 1.0], [0.0], 1.0, 10, "shape"),
    ([1.0], [-1.0], 1.0, 10, ">= 0"),
    ([1.0], [0.0], 0.0, 10, "per_pass_length"),
    ([1.0], [0.0], 1.0, 1, "draws"),
    ([1.0], [NAN], 1.0, 10, "first_pass_variance"),
])
def test_homogenisation_error_refuses_bad_input(first, variance, windows, draws, message):
    with pytest.raises(ValueError, match=message):
        homogenisation_error(first, variance, _identity, _crossing, windows, draws=draws)

