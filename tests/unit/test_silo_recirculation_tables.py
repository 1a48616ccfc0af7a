"""Unit tests for siloflow.analysis.studies.silo_recirculation.tables: the rows and summaries of a hand-built result.

The result is built by hand from its dataclasses, with numbers chosen so every row follows in closed form:
``t_open = 0``, ``t_res = 2 s``, windows of 1 s (centres 0.5, 1.5, 2.5 s, so Nr = 0.25, 0.75, 1.25), 4, 4 and
0 crossings (the last window empty, NaN). Only the parts the tables read are filled; the events, tracer passes
and kernels the tables never touch are None.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from siloflow.analysis.io.tables import write_flow_table, write_json
from siloflow.analysis.numerics.lti import VRRTable
from siloflow.analysis.numerics.rtd import RTD
from siloflow.analysis.studies.silo_recirculation.concentration import OutletConcentration
from siloflow.analysis.studies.silo_recirculation.study import (
    BlendingResult,
    Layout,
    LayoutResult,
    LoopTiming,
    ParticleRTD,
    VerificationResult,
)
from siloflow.analysis.studies.silo_recirculation.tables import (
    blending_summary,
    clumps_per_window,
    concentration_rows,
    johanson_curve,
    model_rows,
    rtd_rows,
    summary_rows,
    verification_rows,
    verification_summary,
    vrr_period_rows,
    vrr_rows,
)
from siloflow.analysis.numerics.uncertainty import Estimate
from siloflow.analysis.studies.silo_recirculation.tracers import TracerPasses
from siloflow.analysis.studies.silo_recirculation.transit import TransitLittlesLaw
from siloflow.analysis.studies.silo_recirculation.vrr import LittlesLaw, RecirculationVRR

NAN = math.nan
EDGES = np.array([0.0, 1.0, 2.0, 3.0])
CENTRES = np.array([0.5, 1.5, 2.5])
# Errors passed through as they are; a frame interval of sqrt(6) s gives a residence-time resolution of 1 s.
TIMING = LoopTiming(t_open=0.0, t_end=3.0, residence_time=2.0, holdup=20.0, throughput=10.0, recirculations=1.5,
                    residence_time_error=0.125, holdup_error=0.5, throughput_error=0.25, frame_interval=math.sqrt(6.0))
# Particle RTD of 4 tracers, 3 out at 1.25, 2.0 and 2.75 s: bins [1, 2) and [2, 3] hold 1 and 2 of 4. Its mean has
# the standard error sqrt(0.375 / 2); the gaps at both ends are 0.75 s, so with the 1 s resolution t_s and t_d
# have the error sqrt(0.75^2 + 1^2) = 1.25 s.
SILO_RTD = RTD(time=np.array([1.5, 2.5]), edges=np.array([1.0, 2.0, 3.0]), E=np.array([0.25, 0.5]), t_mean=2.0,
               variance=0.375, t_first=1.25, t_last=2.75, n_exited=3, n_total=4)
TRACER = TracerPasses(entry_time=np.array([1.0, 1.5, 2.0, 2.5]), exit_time=np.array([2.25, 3.5, 4.75, NAN]),
                      pass_index=np.arange(4), clump_index=np.arange(4), clump_id=np.arange(4), entry_at="wrap")
# Eulerian RTD of 4 virtual tracers out at 0.5, 1.5, 2.5 and 3.5 s (mean error sqrt(1.25 / 3)).
EULERIAN_RTD = RTD(time=np.array([1.0, 3.0]), edges=np.array([0.0, 2.0, 4.0]), E=np.array([0.25, 0.25]), t_mean=2.0,
                   variance=1.25, t_first=0.5, t_last=3.5, n_exited=4, n_total=4)


def outlet(n_blue, n_total=(4, 4, 0)) -> OutletConcentration:
    n_total, n_blue = np.array(n_total), np.array(n_blue)
    concentration = np.array([b / n if n else NAN for b, n in zip(n_blue, n_total)])
    return OutletConcentration(edges=EDGES, centres=CENTRES, n_total=n_total, n_blue=n_blue,
                               concentration=concentration, window=1.0)


def vrr(values, sigma_out, n_windows, blue_fraction) -> RecirculationVRR:
    return RecirculationVRR(recirculation_number=np.array([0.5, 1.5]), vrr=np.array(values),
                            sigma_out=np.array(sigma_out), n_windows=np.array(n_windows),
                            sigma_in=math.sqrt(blue_fraction * (1 - blue_fraction)), blue_fraction=blue_fraction)


# Layout 1: measured 0.25, 0.75 in recirculation 1 (variance 1/16, VRR 0.25 / (1/16) = 4); predicted 0.5, 0.75
# (variance 1/64, VRR 16); one window in recirculation 2, so NaN there.
HALF = LayoutResult(
    layout=Layout("bottom half", 0.5), colours=None, concentration=outlet([1, 3, 0]), first_pass=outlet([1, 2, 0]),
    predicted=np.array([0.5, 0.75, 0.5]), predicted_johanson=np.array([0.375, 0.625, 0.5]),
    vrr=vrr([4.0, NAN], [0.25, NAN], [2, 0], 0.5), vrr_predicted=vrr([16.0, NAN], [0.125, NAN], [2, 1], 0.5),
    homogenised_after=NAN, model_time_nr=np.array([0.0, 0.5, 1.0]), model_concentration=np.array([1.0, 0.0, 0.5]),
    model_homogenised_after=1.0, recirculation_number=np.array([0.25, 0.75, 1.25]),
)
# Layout 2: measured 0, 0.5 (VRR 0.1875 / 0.0625 = 3); the prediction is constant (VRR inf).
TOP = LayoutResult(
    layout=Layout("top 25 %", 0.25, sublayers=2, blue_at="top"), colours=None, concentration=outlet([0, 2, 0]),
    first_pass=outlet([0, 1, 0]), predicted=np.array([0.25, 0.25, 0.25]),
    predicted_johanson=np.array([0.0, 0.5, 0.25]), vrr=vrr([3.0, NAN], [0.25, NAN], [2, 0], 0.25),
    vrr_predicted=vrr([math.inf, NAN], [0.0, NAN], [2, 1], 0.25), homogenised_after=2.0,
    model_time_nr=np.array([0.0, 0.5]), model_concentration=np.array([0.0, 1.0]), model_homogenised_after=NAN,
    recirculation_number=np.array([0.25, 0.75, 1.25]),
)
PARTICLE_RTD = ParticleRTD(tracer=TRACER, silo=SILO_RTD, loop=None, loop_E_on_windows=None, start_time=0.8, n_tracer=4,
                           johanson_V1=0.5, johanson_P=0.75, steady=None, silo_E_on_windows=None,
                           johanson_loop_E_on_windows=None)
RESULT = BlendingResult(
    timing=TIMING, events=None, window=1.0, rtd=PARTICLE_RTD, layouts=[HALF, TOP],
    vrr_sine=VRRTable(period_over_tm=np.array([0.5, 1.0]), period=np.array([1.0, 2.0]), vrr=np.array([10.0, 2.0]),
                      t_mean=2.0, waveform="sine", n_periods=4),
    vrr_square=VRRTable(period_over_tm=np.array([0.5]), period=np.array([1.0]), vrr=np.array([8.0]), t_mean=2.0,
                        waveform="square", n_periods=4),
)
#: What of the run's case the blending summary holds.
RUN = {"run_id": "recirculation_ab12", "flow_pattern": "mass flow", "estimated_residence_time": 2.5,
       "nominal_residence_time": 1.25}


def assert_rows(rows, columns, expected):
    """Same columns in the same order in every row, and the same values (NaN equal to NaN)."""
    assert [list(row) for row in rows] == [columns] * len(expected)
    np.testing.assert_equal(rows, expected)


def test_concentration_rows_list_every_window_of_every_layout_in_order():
    columns = ["layout", "time_s", "recirculations", "crossings", "concentration", "first_exit_concentration",
               "predicted", "predicted_johanson"]
    assert_rows(concentration_rows(RESULT), columns, [dict(zip(columns, row)) for row in [
        ["bottom half", 0.5, 0.25, 4, 0.25, 0.25, 0.5, 0.375],
        ["bottom half", 1.5, 0.75, 4, 0.75, 0.5, 0.75, 0.625],
        ["bottom half", 2.5, 1.25, 0, NAN, NAN, 0.5, 0.5],
        ["top 25 %", 0.5, 0.25, 4, 0.0, 0.0, 0.25, 0.0],
        ["top 25 %", 1.5, 0.75, 4, 0.5, 0.25, 0.25, 0.5],
        ["top 25 %", 2.5, 1.25, 0, NAN, NAN, 0.25, 0.25],
    ]])
    assert all(type(row["crossings"]) is int for row in concentration_rows(RESULT))


VRR_COLUMNS = ["layout", "recirculation_number", "vrr", "sigma_out", "n_windows", "sigma_in", "blue_fraction",
               "vrr_predicted", "vrr_ceiling", "vrr_at_ceiling", "vrr_kind", "vrr_predicted_over_measured",
               "vrr_error"]
SIGMA_TOP = math.sqrt(0.1875)
# sqrt(2 / (N - 1)) VRR with N = 2 windows: sqrt(2) x 4 and sqrt(2) x 3
HALF_ERROR, TOP_ERROR = math.sqrt(2.0) * 4.0, math.sqrt(2.0) * 3.0


def with_throughput(throughput: float, result: BlendingResult = RESULT) -> BlendingResult:
    """The hand-built result with another throughput: clumps per window (and the VRR ceiling) = throughput x 1 s."""
    return dataclasses.replace(result, timing=dataclasses.replace(TIMING, throughput=throughput))


def test_vrr_rows_put_the_layout_first_then_the_prediction_then_the_ceiling():
    # 10 clumps per window: ceiling 10, flagged from 5 on; VRRs 4 and 3 are values, compared with the prediction
    assert_rows(vrr_rows(RESULT), VRR_COLUMNS, [dict(zip(VRR_COLUMNS, row)) for row in [
        ["bottom half", 0.5, 4.0, 0.25, 2, 0.5, 0.5, 16.0, 10.0, False, "value", 4.0, HALF_ERROR],
        ["bottom half", 1.5, NAN, NAN, 0, 0.5, 0.5, NAN, 10.0, False, "none", NAN, NAN],
        ["top 25 %", 0.5, 3.0, 0.25, 2, SIGMA_TOP, 0.25, math.inf, 10.0, False, "value", math.inf, TOP_ERROR],
        ["top 25 %", 1.5, NAN, NAN, 0, SIGMA_TOP, 0.25, NAN, 10.0, False, "none", NAN, NAN],
    ]])
    assert all(type(row["vrr_at_ceiling"]) is bool for row in vrr_rows(RESULT))


def test_vrr_rows_mark_a_vrr_at_half_the_ceiling_as_a_lower_bound_not_compared():
    # 8 clumps per window: ceiling 8, flagged from 8 / 2 = 4 on, so VRR 4 (bottom half) is at the boundary and
    # flagged; VRR 3 (top 25 %) is not. The lower bound gets no prediction ratio.
    assert_rows(vrr_rows(with_throughput(8.0)), VRR_COLUMNS, [dict(zip(VRR_COLUMNS, row)) for row in [
        ["bottom half", 0.5, 4.0, 0.25, 2, 0.5, 0.5, 16.0, 8.0, True, "lower bound", NAN, HALF_ERROR],
        ["bottom half", 1.5, NAN, NAN, 0, 0.5, 0.5, NAN, 8.0, False, "none", NAN, NAN],
        ["top 25 %", 0.5, 3.0, 0.25, 2, SIGMA_TOP, 0.25, math.inf, 8.0, False, "value", math.inf, TOP_ERROR],
        ["top 25 %", 1.5, NAN, NAN, 0, SIGMA_TOP, 0.25, NAN, 8.0, False, "none", NAN, NAN],
    ]])


@pytest.mark.parametrize("throughput, factor, expected", [
    (8.0001, 2.0, [False, False]),  # 4 < 8.0001 / 2
    (6.0, 2.0, [True, True]),  # 4 and 3 >= 3
    (10.0, 2.5, [True, False]),  # 4 >= 10 / 2.5 > 3
    (10.0, 1.0, [False, False]),  # at the ceiling itself only
])
def test_vrr_rows_flag_from_ceiling_over_factor(throughput, factor, expected):
    rows = vrr_rows(with_throughput(throughput), factor=factor)
    assert [row["vrr_at_ceiling"] for row in rows[::2]] == expected
    assert [row["vrr_kind"] for row in rows[::2]] == ["lower bound" if flag else "value" for flag in expected]


def test_an_infinite_measured_vrr_is_a_lower_bound():
    # no variance left in 2 windows of 10 clumps: possible only through the sampling, so it is at the ceiling
    infinite = dataclasses.replace(HALF, vrr=vrr([math.inf, NAN], [0.0, NAN], [2, 0], 0.5))
    (row, _) = vrr_rows(dataclasses.replace(RESULT, layouts=[infinite]))
    assert (row["vrr"], row["vrr_at_ceiling"], row["vrr_kind"]) == (math.inf, True, "lower bound")
    assert math.isnan(row["vrr_predicted_over_measured"])


def test_model_rows_follow_each_layouts_own_model_axis():
    columns = ["layout", "recirculations", "concentration"]
    assert_rows(model_rows(RESULT), columns, [dict(zip(columns, row)) for row in [
        ["bottom half", 0.0, 1.0], ["bottom half", 0.5, 0.0], ["bottom half", 1.0, 0.5],
        ["top 25 %", 0.0, 0.0], ["top 25 %", 0.5, 1.0],
    ]])


def test_johanson_curve_is_the_triangle_on_the_particle_rtd_bins():
    # tau = 2 s, V1 = 0.5, P = 0.75: the triangle ends at theta = 3 - 0.5 - 0.75 = 1.75, base 1.25. At t = 1.5 and
    # 2.5 s (theta 0.75 and 1.25, both on the falling side) E(theta) = 2 (1.75 - theta) / (1.25 * 1) = 1.6 and 0.8,
    # so E(t) = E(theta) / tau = 0.8 and 0.4 1/s.
    np.testing.assert_allclose(johanson_curve(RESULT), [0.8, 0.4], rtol=1e-15, atol=0)


def test_rtd_rows_stack_particle_ids_eulerian_and_johanson():
    columns = ["method", "time_s", "E_per_s", "t_mean_s"]
    assert_rows(rtd_rows(RESULT, EULERIAN_RTD, np.array([0.8, 0.4])), columns, [dict(zip(columns, row)) for row in [
        ["particle_ids", 1.5, 0.25, 2.0], ["particle_ids", 2.5, 0.5, 2.0],
        ["eulerian", 1.0, 0.25, 2.0], ["eulerian", 3.0, 0.25, 2.0],
        ["johanson", 1.5, 0.8, 2.0], ["johanson", 2.5, 0.4, 2.0],
    ]])


def test_vrr_period_rows_are_the_sine_rows_then_the_square_rows():
    columns = ["period_over_tm", "period_s", "vrr", "t_mean_s", "waveform"]
    assert_rows(vrr_period_rows(RESULT), columns, [dict(zip(columns, row)) for row in [
        [0.5, 1.0, 10.0, 2.0, "sine"], [1.0, 2.0, 2.0, 2.0, "sine"], [0.5, 1.0, 8.0, 2.0, "square"],
    ]])


def test_clumps_per_window_is_throughput_times_window():
    assert clumps_per_window(RESULT) == 10.0  # 10 clumps/s x 1 s


def test_blending_summary_holds_timing_rtds_and_every_layout():
    summary = blending_summary(RESULT, EULERIAN_RTD, 0.005, **RUN)
    half, top = summary.pop("layouts").values()
    # t_s / t_d = 5 / 11 with t_s and t_d both +- 1.25 s: (5 / 11) sqrt((1.25 / 1.25)^2 + (1.25 / 2.75)^2)
    ratio_error = (5.0 / 11.0) * math.sqrt(1.0 + (5.0 / 11.0) ** 2)
    rounded = {"time_resolution_s": 1.0, "t_s_error": 1.25, "t_d_error": 1.25, "t_s_over_t_d_error": ratio_error}
    for key, value in rounded.items():  # through sqrt(6) / sqrt(6): exact to round-off
        assert summary["rtd_particle_ids"].pop(key) == pytest.approx(value, rel=1e-15)
    np.testing.assert_equal(summary, {
        "run_id": "recirculation_ab12", "flow_pattern": "mass flow", "residence_time_s": 2.0,
        "estimated_residence_time_s": 2.5, "nominal_residence_time_s": 1.25, "holdup_clumps": 20.0, "throughput_clumps_per_s": 10.0,
        "recirculations": 1.5, "window_s": 1.0, "clumps_per_window": 10.0, "vrr_sampling_limit": 10.0,
        "vrr_ceiling_factor": 2.0,
        "residence_time_s_error": 0.125, "holdup_clumps_error": 0.5, "throughput_clumps_per_s_error": 0.25,
        "frame_interval_s": math.sqrt(6.0),
        "rtd_particle_ids": {"t_mean_s": 2.0, "variance_s2": 0.375, "t_s": 1.25, "t_d": 2.75,
                             "t_s_over_t_d": 1.25 / 2.75, "n_tracer": 4, "fraction_exited": 0.75,
                             "t_mean_s_error": math.sqrt(0.375 / 2.0), "t_mean_transit_s": NAN,
                             "t_mean_transit_s_error": NAN, "n_transit": None},
        "rtd_eulerian": {"t_mean_s": 2.0, "variance_s2": 1.25, "t_s": 0.5, "t_d": 3.5, "fraction_exited": 1.0,
                         "bin_size_m": 0.005, "t_mean_s_error": math.sqrt(1.25 / 3.0)},
        "johanson": {"V1": 0.5, "P": 0.75},
        # no Little's law on the transit clumps in this result: unknown, not zero
        **NO_TRANSIT,
    })
    assert list(blending_summary(RESULT, EULERIAN_RTD, 0.005, **RUN)["layouts"]) == ["bottom half", "top 25 %"]
    # RMS of (0.5 - 0.25, 0.75 - 0.75) over the two windows with data: sqrt(0.0625 / 2)
    np.testing.assert_equal(half, {
        "blue_fraction": 0.5, "sublayers": 1, "vrr_by_recirculation": [4.0, NAN], "vrr_predicted": [16.0, NAN],
        "vrr_at_ceiling": [False, False], "prediction_rms_error": math.sqrt(0.03125),
        "homogenised_after_recirculations": NAN, "model_homogenised_after_recirculations": 1.0,
        "vrr_by_recirculation_error": [HALF_ERROR, NAN],
    })
    # RMS of (0.25 - 0, 0.25 - 0.5): sqrt(0.0625)
    np.testing.assert_equal(top, {
        "blue_fraction": 0.25, "sublayers": 2, "vrr_by_recirculation": [3.0, NAN], "vrr_predicted": [math.inf, NAN],
        "vrr_at_ceiling": [False, False], "prediction_rms_error": 0.25, "homogenised_after_recirculations": 2.0,
        "model_homogenised_after_recirculations": NAN, "vrr_by_recirculation_error": [TOP_ERROR, NAN],
    })


NO_TRANSIT = {
    "transit_horizon_s": NAN, "transit_holdup_clumps": NAN, "transit_holdup_clumps_error": NAN,
    "transit_throughput_clumps_per_s": NAN, "transit_throughput_clumps_per_s_error": NAN,
    "transit_residence_time_s": NAN, "transit_residence_time_s_error": NAN, "transit_fraction": NAN,
    "transit_fraction_error": NAN, "slow_holdup_clumps": NAN, "slow_holdup_clumps_error": NAN,
    "stagnant_clumps": None, "littles_law_difference_s": NAN, "littles_law_difference_s_error": NAN,
    "littles_law_significance": "unknown", "littles_law_coverage_factor": 2.0,
}
# Little's law on the transit clumps: 12 +- 0.3 in transit at 10 +- 0.4 per second, 1.2 s (relative errors 0.025
# and 0.04); 20 in all at 12.5 per second; the tracer's mean up to the 3 s horizon 1.1 +- 0.05 s over 30 tracers.
TRANSIT = TransitLittlesLaw(
    horizon=3.0, t_from=3.0, t_to=6.0,
    transit=LittlesLaw(holdup=Estimate(12.0, 0.3, 10, "batch means", 9),
                       throughput=Estimate(10.0, 0.4, 10, "batch rate", 9),
                       residence_time=Estimate(1.2, 1.2 * math.hypot(0.025, 0.04), 10, "propagated batch means", 9)),
    whole=LittlesLaw(holdup=Estimate(20.0, 0.5, 10, "batch means", 9),
                     throughput=Estimate(12.5, 0.5, 10, "batch rate", 9),
                     residence_time=Estimate(1.6, 0.1, 10, "propagated batch means", 9)),
    transit_fraction=Estimate(0.8, 0.04, 100, "binomial"), slow_holdup=Estimate(8.0, 0.25, 10, "batch means", 9),
    stagnant_clumps=5,
)
TRACER_TRANSIT_MEAN = Estimate(1.1, 0.05, 30, "tracer sample", 29)


def test_blending_summary_reports_littles_law_on_the_transit_clumps_beside_the_holdup_residence_time():
    result = dataclasses.replace(RESULT, transit=TRANSIT, tracer_transit_mean=TRACER_TRANSIT_MEAN)
    summary = blending_summary(result, EULERIAN_RTD, 0.005, **RUN)
    transit_error = 1.2 * math.hypot(0.025, 0.04)
    expected = {
        "transit_horizon_s": 3.0, "transit_holdup_clumps": 12.0, "transit_holdup_clumps_error": 0.3,
        "transit_throughput_clumps_per_s": 10.0, "transit_throughput_clumps_per_s_error": 0.4,
        "transit_residence_time_s": 1.2, "transit_residence_time_s_error": transit_error,
        "transit_fraction": 0.8, "transit_fraction_error": 0.04, "slow_holdup_clumps": 8.0,
        "slow_holdup_clumps_error": 0.25, "stagnant_clumps": 5,
        "littles_law_difference_s": 1.2 - 1.1, "littles_law_difference_s_error": math.hypot(transit_error, 0.05),
        "littles_law_coverage_factor": 2.0,
    }
    np.testing.assert_equal({key: summary[key] for key in expected}, expected)
    # 0.1 s against 2 x sqrt(0.0566^2 + 0.05^2) = 0.151 s: Little's law holds
    assert summary["littles_law_significance"] == "not significant"
    assert {key: summary["rtd_particle_ids"][key] for key in ("t_mean_transit_s", "t_mean_transit_s_error",
                                                               "n_transit")} == {
        "t_mean_transit_s": 1.1, "t_mean_transit_s_error": 0.05, "n_transit": 30}
    # the holdup residence time (stagnant zones included) stays what it was
    assert summary["residence_time_s"] == 2.0
    # ... but not within one: 0.1 s > 0.0755 s
    tight = blending_summary(result, EULERIAN_RTD, 0.005, **RUN, k=1.0)
    assert (tight["littles_law_significance"], tight["littles_law_coverage_factor"]) == ("significant", 1.0)
    wide_apart = dataclasses.replace(result, tracer_transit_mean=Estimate(0.8, 0.05, 30, "tracer sample", 29))
    assert blending_summary(wide_apart, EULERIAN_RTD, 0.005, **RUN)["littles_law_significance"] == "significant"


def test_blending_summary_flags_vrrs_at_the_ceiling_with_its_factor():
    summary = blending_summary(with_throughput(8.0), EULERIAN_RTD, 0.005, **RUN)
    assert (summary["vrr_sampling_limit"], summary["vrr_ceiling_factor"]) == (8.0, 2.0)
    assert [layout["vrr_at_ceiling"] for layout in summary["layouts"].values()] == [[True, False], [False, False]]
    summary = blending_summary(with_throughput(8.0), EULERIAN_RTD, 0.005, **RUN, factor=8.0 / 3.0)
    assert summary["vrr_ceiling_factor"] == 8.0 / 3.0
    assert [layout["vrr_at_ceiling"] for layout in summary["layouts"].values()] == [[True, False], [True, False]]


def test_blending_summary_and_tables_write_as_json_and_csv(tmp_path):
    loaded = json.loads(write_json(tmp_path / "blending.json",
                                   blending_summary(RESULT, EULERIAN_RTD, 0.005, **RUN)).read_text())
    # arrays become lists, NaN and inf become null
    assert loaded["layouts"]["bottom half"]["vrr_by_recirculation"] == [4.0, None]
    assert loaded["layouts"]["top 25 %"]["vrr_predicted"] == [None, None]
    assert loaded["layouts"]["top 25 %"]["model_homogenised_after_recirculations"] is None
    assert loaded["layouts"]["bottom half"]["vrr_at_ceiling"] == [False, False]
    assert loaded["layouts"]["bottom half"]["vrr_by_recirculation_error"] == [HALF_ERROR, None]
    assert loaded["residence_time_s_error"] == 0.125
    text = write_flow_table(tmp_path / "vrr.csv", vrr_rows(with_throughput(8.0))).read_text()
    # the error column comes last, after the columns older readers know
    assert text.splitlines()[:3] == [
        "layout,recirculation_number,vrr,sigma_out,n_windows,sigma_in,blue_fraction,vrr_predicted,vrr_ceiling,"
        "vrr_at_ceiling,vrr_kind,vrr_predicted_over_measured,vrr_error",
        "bottom half,0.5,4.0,0.25,2,0.5,0.5,16.0,8.0,True,lower bound,,5.656854249492381",
        "bottom half,1.5,,,0,0.5,0.5,,8.0,False,none,,",
    ]
    text = write_flow_table(tmp_path / "concentration.csv", concentration_rows(RESULT)).read_text()
    assert text.splitlines()[:2] == [
        "layout,time_s,recirculations,crossings,concentration,first_exit_concentration,predicted,predicted_johanson",
        "bottom half,0.5,0.25,4,0.25,0.25,0.5,0.375",
    ]
    assert text.splitlines()[3] == "bottom half,2.5,1.25,0,,,0.5,0.5"


VERIFICATION = VerificationResult(
    particle_residence=np.array([1.0, 3.0, NAN]),
    eulerian_residence={0.005: np.array([2.0, 4.0]), 0.01: np.array([NAN])},
    particle_paths=[], pathlines={}, timing=TIMING,
)


def test_verification_rows_list_the_particles_then_each_bin_size():
    columns = ["method", "bin_size_m", "residence_time_s"]
    assert_rows(verification_rows(VERIFICATION), columns, [dict(zip(columns, row)) for row in [
        ["particles", "", 1.0], ["particles", "", 3.0], ["particles", "", NAN],
        ["eulerian", 0.005, 2.0], ["eulerian", 0.005, 4.0], ["eulerian", 0.01, NAN],
    ]])


UNKNOWN_DIFFERENCE = {"mean_difference_s": None, "mean_difference_s_error": NAN,
                      "mean_difference_significance": "unknown", "means_agree": None}


def test_verification_summary_names_bin_sizes_in_millimetres():
    # particles 1 and 3 s: mean 2 s, s = sqrt(2) s, error sqrt(2) / sqrt(2) = 1 s; 5 mm: 2 and 4 s, 3 +- 1 s.
    # The difference 1 s is within 2 x sqrt(1 + 1) s: the means agree.
    summary = verification_summary(VERIFICATION, run_id=RUN["run_id"])
    np.testing.assert_equal(summary, {
        "run_id": "recirculation_ab12", "residence_time_s": 2.0, "residence_time_s_error": 0.125, "n_tracers": 3,
        "coverage_factor": 2.0,
        "particles": {"n": 3, "n_exited": 2, "mean_s": 2.0, "mean_s_error": 1.0, "std_s": 1.0},
        "eulerian": {"5 mm": {"n": 2, "n_exited": 2, "mean_s": 3.0, "mean_s_error": 1.0, "std_s": 1.0,
                              "mean_difference_s": 1.0, "mean_difference_s_error": math.sqrt(2.0),
                              "mean_difference_significance": "not significant", "means_agree": True},
                     "10 mm": {"n": 1, "n_exited": 0, "mean_s": None, "mean_s_error": None, "std_s": None,
                               **UNKNOWN_DIFFERENCE}},
    })
    assert list(summary["eulerian"]) == ["5 mm", "10 mm"]


def test_verification_summary_says_whether_each_bin_size_agrees_with_the_particles():
    verification = dataclasses.replace(VERIFICATION, eulerian_residence={
        0.005: np.array([2.0, 4.0]),  # 3 +- 1 s: 1 s from the particles' 2 +- 1 s, within 2 sqrt(2) s
        0.01: np.array([6.0, 6.0]),  # 6 +- 0 s: 4 s away, more than 2 x 1 s
        0.015: np.array([5.0, NAN]),  # one tracer out: no error, so the agreement is unknown
        0.02: np.array([5.0, 7.0]),  # 6 +- 1 s: 4 s away, more than 2 sqrt(2) s
    })
    eulerian = verification_summary(verification, run_id=RUN["run_id"])["eulerian"]
    assert [(stats["mean_difference_significance"], stats["means_agree"]) for stats in eulerian.values()] == [
        ("not significant", True), ("significant", False), ("unknown", None), ("significant", False)]
    assert eulerian["10 mm"]["mean_difference_s"] == 4.0 and eulerian["10 mm"]["mean_difference_s_error"] == 1.0
    assert eulerian["15 mm"]["mean_difference_s"] == 3.0 and math.isnan(eulerian["15 mm"]["mean_difference_s_error"])
    # with k = 4: 20 mm's 4 s is within 4 sqrt(2) s, and 10 mm's 4 s is not more than 4 x 1 s
    loose = verification_summary(verification, run_id=RUN["run_id"], k=4.0)
    assert loose["coverage_factor"] == 4.0
    assert (loose["eulerian"]["20 mm"]["means_agree"], loose["eulerian"]["10 mm"]["means_agree"]) == (True, True)
    assert loose["eulerian"]["20 mm"]["mean_difference_s_error"] == math.sqrt(2.0)


@pytest.mark.parametrize("function", [concentration_rows, vrr_rows, model_rows])
def test_a_result_without_layouts_gives_no_rows(function):
    empty = BlendingResult(timing=TIMING, events=None, window=1.0, rtd=PARTICLE_RTD)
    assert function(empty) == []


SUMMARY = {"flow_pattern": "semi", "run_id": "r1", "residence_time_s": 2.0, "vrr_sampling_limit": 4.0,
           "rtd_particle_ids": {"t_s_over_t_d": 0.25, "t_mean_s": 1.5}, "rtd_eulerian": {"t_mean_s": 1.6},
           "layouts": {"blue13": {"vrr_by_recirculation": [2.0, None, 1.9], "prediction_rms_error": 0.1,
                                  "homogenised_after_recirculations": 3, "model_homogenised_after_recirculations": 4}}}


def test_summary_rows_one_per_run_and_layout_with_vrr_columns_and_curves():
    rows, curves = summary_rows([SUMMARY])
    assert len(rows) == 1
    assert list(rows[0]) == ["flow_pattern", "layout", "run_id", "residence_time_s", "t_s_over_t_d", "rtd_mean_ids_s",
                             "rtd_mean_eulerian_s", "vrr_nr1", "vrr_nr2", "vrr_nr3", "prediction_rms_error",
                             "homogenised_after_recirculations", "model_homogenised_after_recirculations",
                             "vrr_ceiling", "vrr_at_ceiling_nr1", "vrr_at_ceiling_nr2", "vrr_at_ceiling_nr3",
                             "residence_time_s_error", "t_s_over_t_d_error", "rtd_mean_ids_s_error",
                             "rtd_mean_eulerian_s_error", "vrr_nr1_error", "vrr_nr2_error", "vrr_nr3_error",
                             "transit_residence_time_s", "transit_residence_time_s_error", "rtd_mean_ids_transit_s",
                             "rtd_mean_ids_transit_s_error", "final_discharge_recirculations", "final_discharge_vrr",
                             "final_discharge_vrr_error", "final_discharge_vrr_at_ceiling"]
    np.testing.assert_equal(rows[0], {
        "flow_pattern": "semi", "layout": "blue13", "run_id": "r1", "residence_time_s": 2.0, "t_s_over_t_d": 0.25,
        "rtd_mean_ids_s": 1.5, "rtd_mean_eulerian_s": 1.6, "vrr_nr1": 2.0, "vrr_nr2": NAN, "vrr_nr3": 1.9,
        "prediction_rms_error": 0.1, "homogenised_after_recirculations": 3, "model_homogenised_after_recirculations": 4,
        # ceiling 4: VRR 2 = 4 / 2 is flagged, 1.9 and the missing VRR are not
        "vrr_ceiling": 4.0, "vrr_at_ceiling_nr1": True, "vrr_at_ceiling_nr2": False, "vrr_at_ceiling_nr3": False,
        # a summary written without errors: unknown, not zero
        "residence_time_s_error": NAN, "t_s_over_t_d_error": NAN, "rtd_mean_ids_s_error": NAN,
        "rtd_mean_eulerian_s_error": NAN, "vrr_nr1_error": NAN, "vrr_nr2_error": NAN, "vrr_nr3_error": NAN,
        # nor the transit figures
        "transit_residence_time_s": NAN, "transit_residence_time_s_error": NAN, "rtd_mean_ids_transit_s": NAN,
        "rtd_mean_ids_transit_s_error": NAN,
        # nor a discharge after the recirculations
        "final_discharge_recirculations": NAN, "final_discharge_vrr": NAN, "final_discharge_vrr_error": NAN,
        "final_discharge_vrr_at_ceiling": False,
    })
    ((label, nr, values, ceiling, errors),) = curves
    assert (label, nr, ceiling) == ("semi blue13", [0.5, 1.5, 2.5], 4.0)
    np.testing.assert_equal(values, [2.0, NAN, 1.9])
    np.testing.assert_equal(errors, [NAN, NAN, NAN])


SUMMARY_WITH_ERRORS = {
    **SUMMARY, "residence_time_s_error": 0.05,
    "rtd_particle_ids": {**SUMMARY["rtd_particle_ids"], "t_s_over_t_d_error": 0.02, "t_mean_s_error": 0.1},
    "rtd_eulerian": {**SUMMARY["rtd_eulerian"], "t_mean_s_error": 0.125},
    "layouts": {"blue13": {**SUMMARY["layouts"]["blue13"], "vrr_by_recirculation_error": [1.0, None, 0.5]}},
}


def test_summary_rows_carry_the_errors_the_summary_holds():
    rows, curves = summary_rows([SUMMARY_WITH_ERRORS])
    errors = {key: value for key, value in rows[0].items() if key.endswith("_error") and key != "prediction_rms_error"}
    np.testing.assert_equal(errors, {
        "residence_time_s_error": 0.05, "t_s_over_t_d_error": 0.02, "rtd_mean_ids_s_error": 0.1,
        "rtd_mean_eulerian_s_error": 0.125, "vrr_nr1_error": 1.0, "vrr_nr2_error": NAN, "vrr_nr3_error": 0.5,
        "transit_residence_time_s_error": NAN, "rtd_mean_ids_transit_s_error": NAN,
        "final_discharge_vrr_error": NAN,
    })
    np.testing.assert_equal(curves[0][4], [1.0, NAN, 0.5])


def test_summary_rows_of_a_written_summary_give_the_errors_blending_summary_computed(tmp_path):
    written = json.loads(write_json(tmp_path / "blending.json",
                                    blending_summary(RESULT, EULERIAN_RTD, 0.005, **RUN)).read_text())
    rows, _ = summary_rows([written])
    half = rows[0]
    assert (half["residence_time_s"], half["residence_time_s_error"]) == (2.0, 0.125)
    assert half["t_s_over_t_d_error"] == pytest.approx((5.0 / 11.0) * math.sqrt(1.0 + (5.0 / 11.0) ** 2), rel=1e-15)
    assert half["rtd_mean_ids_s_error"] == math.sqrt(0.375 / 2.0)
    assert half["rtd_mean_eulerian_s_error"] == math.sqrt(1.25 / 3.0)
    assert half["vrr_nr1_error"] == HALF_ERROR and math.isnan(half["vrr_nr2_error"])
    assert math.isnan(half["transit_residence_time_s"]) and math.isnan(half["rtd_mean_ids_transit_s_error"])
    result = dataclasses.replace(RESULT, transit=TRANSIT, tracer_transit_mean=TRACER_TRANSIT_MEAN)
    written = json.loads(write_json(tmp_path / "transit.json",
                                    blending_summary(result, EULERIAN_RTD, 0.005, **RUN)).read_text())
    half = summary_rows([written])[0][0]
    assert (half["transit_residence_time_s"], half["transit_residence_time_s_error"]) == (
        1.2, 1.2 * math.hypot(0.025, 0.04))
    assert (half["rtd_mean_ids_transit_s"], half["rtd_mean_ids_transit_s_error"]) == (1.1, 0.05)
    assert written["stagnant_clumps"] == 5 and written["littles_law_significance"] == "not significant"


def test_summary_rows_take_the_flags_the_summary_holds_and_the_factor_otherwise():
    # an infinite VRR is written as null; the flag written with it still says it is at the ceiling
    layout = {**SUMMARY["layouts"]["blue13"], "vrr_at_ceiling": [False, True, False]}
    stored = {**SUMMARY, "layouts": {"blue13": layout}}
    rows, _ = summary_rows([stored])
    assert [rows[0][f"vrr_at_ceiling_nr{k}"] for k in (1, 2, 3)] == [False, True, False]
    rows, _ = summary_rows([SUMMARY], factor=2.5)  # flagged from 4 / 2.5 = 1.6 on
    assert [rows[0][f"vrr_at_ceiling_nr{k}"] for k in (1, 2, 3)] == [True, False, True]


def test_summary_rows_without_a_ceiling_flag_nothing():
    rows, curves = summary_rows([{key: value for key, value in SUMMARY.items() if key != "vrr_sampling_limit"}])
    assert math.isnan(rows[0]["vrr_ceiling"]) and curves[0][3] is None
    assert [rows[0][f"vrr_at_ceiling_nr{k}"] for k in (1, 2, 3)] == [False, False, False]
