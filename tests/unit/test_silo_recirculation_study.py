"""Unit tests for siloflow.analysis.studies.silo_recirculation.study (the composed blending analysis) on exact cases.

Most tests use the "conveyor" of ``test_silo_recirculation_blending.py`` (helpers copied here): 100 clumps evenly spaced
along z, all moving down at 0.1 m/s through a domain periodic in z, so every crossing, re-entry, pass,
window concentration and residence time is known in closed form. Here the clumps are also spread over
four columns in x (``x = -0.075, -0.025, 0.025, 0.075`` m by ``index mod 4``), so that every Eulerian bin
of a 0.2 m wide silo holds clumps at every instant and the bin velocity field is uniform.

Closed forms (clump i, z0_i = -0.245 + 0.01 i):

- outlet crossings at ``0.1 i - 2.45 + 10 j`` s (one every 0.1 s, at 0.05 s past each tenth);
- re-entries at ``0.1 i + 0.05 + 10 j`` s; a pass (top to outlet) takes 0.75 / 0.1 = 7.5 s, a loop
  (outlet to outlet, channel included) 1 / 0.1 = 10 s;
- 75 clumps above the outlet at every frame, 10 crossings per second, so t_res = 75 / 10 = 7.5 s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.studies.silo_recirculation.tracks import RecirculationEvents, recirculation_events
from siloflow.analysis.studies.silo_recirculation.study import (
    residence_summary,
    BlendingResult,
    Layout,
    LoopTiming,
    analyse_blending,
    analyse_layout,
    continuous_mode,
    loop_timing,
    main_run_eulerian_rtd,
    particle_rtd,
    snapshot_frames,
    verify_eulerian_rtd,
)
from siloflow.analysis.numerics.rtd import johanson_rtd

# --------------------------------------------------------------------------- the conveyor

BOTTOM, OUTLET, TOP = -0.25, 0.0, 0.75  # domain height L = 1 m
HEIGHT = TOP - BOTTOM
SPEED = 0.1  # m/s downwards
PASS_TIME = (TOP - OUTLET) / SPEED  # 7.5 s: re-entry at the top to the outlet
LOOP_TIME = HEIGHT / SPEED  # 10 s: outlet to outlet
N_CLUMPS = 100
FRAME_STEP = 0.02
TIMES = np.arange(1501) * FRAME_STEP  # 0 ... 30 s
IDS = 3 * np.arange(N_CLUMPS) - 150  # ascending with the index, negative ones included
INDEX = np.arange(N_CLUMPS)
Z0 = BOTTOM + (INDEX + 0.5) / N_CLUMPS * HEIGHT  # -0.245 ... 0.745
X0 = -0.075 + 0.05 * (INDEX % 4)  # four columns: any 4 clumps adjacent in z cover all of them
# Clumps in the order they cross the outlet within one loop: 25 ... 99 (in the silo at t = 0), then 0 ... 24.
CROSSING_ORDER = np.r_[np.arange(25, 100), np.arange(25)]

# Analysis parameters. The concentration window is t_res / 15 = 0.5 s (5 crossings, edges 0.05 s from the
# nearest crossing), so a loop is 20 windows and a pass 15: windows and pass times are commensurate. The
# factor (1 - 1e-9) puts the edges 20 w and 15 w a hair (~1e-8 s) *below* the loop and pass times, which
# in exact arithmetic fall on them: the measured loop times (10 s, +-1e-15 from the interpolated crossing
# times) then land in bin 20 and the pass times in bin 15 whatever the round-off, while the window edges
# move by < 1e-7 s, far from any crossing.
WINDOW_FRACTION = (1.0 - 1.0e-9) / 15.0
WINDOW = WINDOW_FRACTION * PASS_TIME
TRACER_FRACTION = 0.21  # round(0.21 * 75) = round(15.75) = 16 tracer passes
TRACER_START = 0.4  # marked from t = 0.4 * 7.5 = 3 s (no entry or exit falls on it)
N_TRACER = 16
RTD_BINS = 10
# 0.3 t_m is 8 steps of continuous_mode's grid (step = 0.3 t_m / 8); the others are whole numbers of
# steps (12, 16, 32, 64) except 0.77 (20.53 steps), which checks the discretisation bound.
PERIOD_FRACTIONS = [0.3, 0.45, 0.6, 1.2, 2.4, 0.77]
PASSES = 3  # the loop RTD vanishes below 20 windows: 60 / 20 = 3 passes complete the renewal sum
TOLERANCE = 0.1
LAYOUTS = [
    Layout("bottom half", 0.5),
    Layout("six layers", 0.5, sublayers=3),
    Layout("top 40 %", 0.4, blue_at="top"),
]


def conveyor_z(t):
    return BOTTOM + np.mod(Z0[None, :] - SPEED * np.asarray(t)[:, None] - BOTTOM, HEIGHT)


def conveyor_tracks(times=TIMES) -> ClumpTracks:
    z = conveyor_z(times)
    position = np.stack([np.broadcast_to(X0, z.shape), np.zeros_like(z), z], axis=2)
    return ClumpTracks(times=np.asarray(times, dtype=float), clump_id=IDS.astype(np.int64), position=position)


def conveyor_velocity(n_times: int) -> np.ndarray:
    velocity = np.zeros((n_times, N_CLUMPS, 3))
    velocity[:, :, 2] = -SPEED
    return velocity


def windows_of_one_loop(colours) -> np.ndarray:
    """Outlet concentration in the 20 windows of one loop: 5 consecutive crossing clumps per window."""
    return colours[CROSSING_ORDER].reshape(20, 5).mean(axis=1)


@pytest.fixture(scope="module")
def tracks() -> ClumpTracks:
    return conveyor_tracks()


@pytest.fixture(scope="module")
def events(tracks) -> RecirculationEvents:
    return recirculation_events(tracks, OUTLET, BOTTOM, TOP)


@pytest.fixture(scope="module")
def timing(tracks, events) -> LoopTiming:
    return loop_timing(tracks, events, OUTLET)


@pytest.fixture(scope="module")
def result(tracks) -> BlendingResult:
    return analyse_blending(
        tracks, LAYOUTS, BOTTOM, TOP, WINDOW_FRACTION, TRACER_FRACTION, TRACER_START, RTD_BINS, PERIOD_FRACTIONS,
        PASSES, TOLERANCE, outlet_z=OUTLET,
    )


# --------------------------------------------------------------------------- loop timing


@pytest.mark.parametrize("startup_fraction, exits_counted", [(0.1, 270), (0.0, 300), (0.5, 150)])
def test_loop_timing_obeys_littles_law_on_the_conveyor(tracks, events, startup_fraction, exits_counted):
    timing = loop_timing(tracks, events, OUTLET, startup_fraction=startup_fraction)
    assert (timing.t_open, timing.t_end) == (0.0, 30.0)
    assert timing.holdup == 75.0  # 75 clumps above the outlet at every frame
    steady = 30.0 * (1.0 - startup_fraction)
    assert exits_counted == pytest.approx(10.0 * steady)  # no crossing falls on t_start (x.05 s only)
    assert timing.throughput == pytest.approx(exits_counted / steady, rel=1e-12)
    assert timing.throughput == pytest.approx(10.0, rel=1e-12)  # 100 clumps per 10 s loop
    assert timing.residence_time == pytest.approx(PASS_TIME, rel=1e-12)  # Little's law: 75 / 10 s
    assert timing.residence_time == pytest.approx(timing.holdup / timing.throughput, rel=1e-12)
    assert timing.recirculations == pytest.approx(30.0 / 7.5, rel=1e-12)
    assert timing.frame_interval == pytest.approx(FRAME_STEP, rel=1e-9)
    # A steady conveyor does not fluctuate: the holdup is 75 at every frame, and every batch of the discharge
    # spans a whole number of 0.1 s crossing periods from the same phase, so the batch rates are all equal.
    assert timing.holdup_error == 0.0
    assert timing.throughput_error == pytest.approx(0.0, abs=1e-9)
    assert timing.residence_time_error == pytest.approx(0.0, abs=1e-9)


def test_loop_timing_of_a_shorter_run():
    short = conveyor_tracks(TIMES[:601])  # 0 ... 12 s: crossings 1.25 ... 11.95 s after t_start = 1.2 s
    timing = loop_timing(short, recirculation_events(short, OUTLET, BOTTOM, TOP), OUTLET)
    assert timing.t_end == 12.0 and timing.holdup == 75.0
    assert timing.throughput == pytest.approx(108 / 10.8, rel=1e-12)
    assert timing.residence_time == pytest.approx(7.5, rel=1e-12)
    assert timing.recirculations == pytest.approx(1.6, rel=1e-12)


@pytest.mark.parametrize("startup_fraction", [1.0, -0.1, 1.5])
def test_loop_timing_rejects_a_bad_startup_fraction(tracks, events, startup_fraction):
    with pytest.raises(ValueError, match=r"startup_fraction must be in \[0, 1\)"):
        loop_timing(tracks, events, OUTLET, startup_fraction=startup_fraction)


# --------------------------------------------------------------------------- particle RTD


def test_particle_rtd_of_plug_flow_has_a_single_residence_time(events, timing):
    rtd = particle_rtd(events, timing, TRACER_FRACTION, TRACER_START, RTD_BINS, WINDOW)
    assert rtd.n_tracer == N_TRACER == round(TRACER_FRACTION * timing.holdup)
    assert rtd.start_time == pytest.approx(3.0, abs=1e-12)
    # silo tracer: pass 1 of clumps 30 ... 45, re-entering at 0.1 i + 0.05 = 3.05 ... 4.55 s
    np.testing.assert_array_equal(rtd.tracer.clump_index, np.arange(30, 46))
    np.testing.assert_allclose(rtd.tracer.entry_time, 0.1 * np.arange(30, 46) + 0.05, rtol=0, atol=1e-12)
    silo = rtd.silo
    assert silo.n_total == silo.n_exited == N_TRACER
    for value in (silo.t_first, silo.t_last, silo.t_mean):
        assert value == pytest.approx(PASS_TIME, abs=1e-12)
    assert silo.variance == pytest.approx(0.0, abs=1e-24)
    assert silo.ts_over_td == pytest.approx(1.0, abs=1e-12)  # plug flow
    # all of it in the last of the 10 bins over [0, 7.5] s
    np.testing.assert_allclose(silo.E, np.r_[np.zeros(9), 1.0 / 0.75], rtol=1e-12)
    # steady sample for the LTI models: every pass re-entering in [3, 30 - 2 t_res] = [3, 15] s, i.e. pass 1
    # of clumps 30 ... 99 (3.05 ... 9.95 s) and pass 2 of clumps 0 ... 49 (10.05 ... 14.95 s), all 7.5 s
    np.testing.assert_array_equal(rtd.steady.clump_index, np.r_[np.arange(30, 100), np.arange(50)])
    np.testing.assert_allclose(rtd.steady.residence_time, PASS_TIME, rtol=0, atol=1e-12)
    # loop sample: every pass whose previous crossing is in [3, 15] s: pass 1 of clumps 55 ... 99 (previous
    # crossings 3.05 ... 7.45 s), pass 2 of clumps 0 ... 74 (7.55 ... 14.95 s), one loop of 10 s each
    np.testing.assert_array_equal(rtd.loop.clump_index, np.r_[np.arange(55, 100), np.arange(75)])
    np.testing.assert_allclose(rtd.loop.residence_time, LOOP_TIME, rtol=0, atol=1e-12)
    # all of them left by the end (no censored part, no Little tail); tabulated on windows from 0: a single
    # spike in bin 20 = 10 s / 0.5 s, of unit area
    expected_E = np.zeros(22)
    expected_E[20] = 1.0 / WINDOW
    np.testing.assert_allclose(rtd.loop_E_on_windows, expected_E, rtol=1e-12, atol=0)
    # Johanson: V1 = t_first / t_m = 1 is clipped to 0.99; the mode (centre of the last bin, 0.95 t_m)
    # is raised to V1, so the triangle is a jump at 0.99 t_m decaying to 0 at 1.02 t_m
    assert rtd.johanson_V1 == 0.99
    assert rtd.johanson_P == 0.99
    assert np.all(np.isfinite(johanson_rtd(silo.time, silo.t_mean, rtd.johanson_V1, rtd.johanson_P)))


def hand_made_events(residence) -> RecirculationEvents:
    """One pass per clump: re-entry at 10, 11, ... s, exit a residence time later, previous exit 1 s earlier."""
    residence = np.asarray(residence, dtype=float)
    n = residence.size
    index = np.arange(n, dtype=np.int64)
    entry = 10.0 + index
    exit_ = entry + residence
    order = np.argsort(exit_, kind="stable")
    return RecirculationEvents(
        clump_id=index, pass_clump_index=index, pass_clump_id=index, pass_number=np.ones(n, dtype=np.int64),
        entry_time=entry, exit_time=exit_, previous_exit_time=entry - 1.0,
        started_below_outlet=np.zeros(n, dtype=bool), exit_times_all=exit_[order], exit_clump_index=index[order],
        exit_pass_number=np.ones(n, dtype=np.int64), exit_is_pass_exit=np.ones(n, dtype=bool),
        first_exit_time=exit_, n_frames_absent=np.zeros(n, dtype=np.int64), first_frame_time=0.0,
        last_frame_time=100.0, outlet_z=OUTLET, domain_bottom=BOTTOM, domain_top=TOP,
    )


@pytest.mark.parametrize(
    "residence, bins, v1, p",
    [
        # t_m = 5, t_first = 3: V1 = 0.6; the mode is the bin [5, 6) (three passes), centre 5.5: P = 1.1,
        # inside [V1, (3 - V1) / 2] = [0.6, 1.2], so nothing is clipped
        ([3.0, 5.0, 5.0, 5.0, 7.0], 7, 0.6, 1.1),
        # t_m = 81 / 9 = 9, t_first = 1: V1 = 1/9; the mode is the last bin [19, 20], centre 19.5,
        # 19.5 / 9 > (3 - 1/9) / 2 = 13/9: P is clipped to 13/9 (the triangle's end meets its peak)
        ([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 20.0, 20.0, 20.0], 20, 1.0 / 9.0, 13.0 / 9.0),
    ],
)
def test_particle_rtd_johanson_parameters_lie_in_the_models_range(residence, bins, v1, p):
    n = len(residence)
    timing = LoopTiming(t_open=0.0, t_end=100.0, residence_time=5.0, holdup=float(n), throughput=n / 5.0,
                        recirculations=20.0)
    rtd = particle_rtd(hand_made_events(residence), timing, tracer_fraction=1.0, tracer_start=0.0, bins=bins,
                       window=0.5)
    assert rtd.n_tracer == n
    assert rtd.silo.t_mean == pytest.approx(float(np.mean(residence)), rel=1e-12)
    assert rtd.johanson_V1 == pytest.approx(v1, rel=1e-12)
    assert rtd.johanson_P == pytest.approx(p, rel=1e-12)
    # the model accepts them and has unit area (midpoint rule on a fine grid)
    t = (np.arange(400000) + 0.5) * 1e-4
    E = johanson_rtd(t, rtd.silo.t_mean, rtd.johanson_V1, rtd.johanson_P)
    assert float(np.sum(E) * 1e-4) == pytest.approx(1.0, abs=1e-4)


def test_particle_rtd_restores_censored_loops_as_a_little_tail():
    # Four loop passes (previous crossings at 9, 10, 11, 12 s): two take 3 s, two have not come back by the
    # end. Every clump over the throughput, 4 / 0.8 = 5 s, is the mean loop time, so with f_c = 1/2 censored
    # after the longest observed loop T = 3 s: 5 = (1/2) 3 + (1/2)(T + tau), tau = 4 s. On 0.5 s windows:
    # the observed half at lag 6 (3 s), E = 2 / (4 x 0.5) = 1 per s, plus (1/2) exp(-(t - 3) / 4) / 4 from
    # t = 3 s, over ceil((3 + 8 x 4) / 0.5) + 1 = 71 samples.
    timing = LoopTiming(t_open=0.0, t_end=100.0, residence_time=5.0, holdup=4.0, throughput=0.8,
                        recirculations=20.0)
    rtd = particle_rtd(hand_made_events([2.0, 2.0, np.nan, np.nan]), timing, tracer_fraction=1.0,
                       tracer_start=0.0, bins=4, window=0.5)
    assert (rtd.loop.n_tracer, rtd.loop.n_exited) == (4, 2)
    np.testing.assert_allclose(rtd.loop.residence_time, [3.0, 3.0, np.nan, np.nan], rtol=0, atol=1e-12)
    t = np.arange(71) * 0.5
    expected = np.where(t >= 3.0, 0.5 * np.exp(-(t - 3.0) / 4.0) / 4.0, 0.0)
    expected[6] += 1.0
    np.testing.assert_allclose(rtd.loop_E_on_windows, expected, rtol=1e-12, atol=1e-15)


def test_particle_rtd_of_censored_plug_flow_adds_no_tail(events, timing):
    # With a horizon of 1 t_res the loop sample is every pass whose previous crossing is in [3, 22.5] s:
    # 195 passes, of which the 25 from 20.05 s on are not back by 30 s. The 170 observed loops all take
    # 10 s, already 100 clumps / 10 per s: tau = 0, no tail; the histogram keeps its mass 170 / 195.
    rtd = particle_rtd(events, timing, TRACER_FRACTION, TRACER_START, RTD_BINS, WINDOW, horizon_recirculations=1.0)
    assert (rtd.loop.n_tracer, rtd.loop.n_exited) == (195, 170)
    assert rtd.steady.n_tracer == 195  # re-entries 3.05 ... 22.45 s
    expected_E = np.zeros(22)
    expected_E[20] = 170.0 / 195.0 / WINDOW
    np.testing.assert_allclose(rtd.loop_E_on_windows, expected_E, rtol=1e-12, atol=0)


@pytest.mark.parametrize(
    "n_frames, which, nr_run",
    [
        # 10 s run: the tracer re-enters from 3.05 s and leaves from 10.55 s, after the last frame
        (501, "re-entry", "1.33"),
        # 12 s run: the silo tracer partly leaves (10.55 ... 11.95 s), but the loop tracer (previous
        # crossings from 3.05 s) only leaves from 13.05 s
        (601, "loop", "1.60"),
    ],
)
def test_particle_rtd_of_a_too_short_run_says_what_to_change(n_frames, which, nr_run):
    short = conveyor_tracks(TIMES[:n_frames])
    short_events = recirculation_events(short, OUTLET, BOTTOM, TOP)
    timing = loop_timing(short, short_events, OUTLET)
    message = (
        rf"none of the 16 tracer passes \({which} RTD\) entering after Nr = 0.4 left the silo before the end "
        rf"of the run \(Nr = {nr_run}\); run more recirculations \(silo_recirculation.recirculations\)"
    )
    with pytest.raises(ValueError, match=message):
        particle_rtd(short_events, timing, TRACER_FRACTION, TRACER_START, RTD_BINS, WINDOW)


# --------------------------------------------------------------------------- layouts on the conveyor


def test_analyse_blending_timing_window_and_rtd(result):
    assert result.timing.residence_time == pytest.approx(PASS_TIME, rel=1e-12)
    assert result.timing.recirculations == pytest.approx(4.0, rel=1e-12)
    assert result.window == pytest.approx(0.5 * (1.0 - 1e-9), rel=1e-12)
    assert result.rtd.n_tracer == N_TRACER
    assert result.rtd.silo.t_mean == pytest.approx(PASS_TIME, abs=1e-12)
    assert result.events.exit_times_all.size == 300
    assert [layout.layout.name for layout in result.layouts] == [layout.name for layout in LAYOUTS]


def test_layer_colours_of_the_layouts_are_exact(result):
    bottom, six, top = (layout.colours for layout in result.layouts)
    np.testing.assert_array_equal(bottom, INDEX < 50)  # the lowest half, channel included
    # r = (i + 0.5) / 100, blue iff frac(3 r) < 0.5: B 0-16, W 17-32, B 33-49, W 50-66, B 67-82, W 83-99
    np.testing.assert_array_equal(six, (INDEX <= 16) | ((INDEX >= 33) & (INDEX <= 49)) | ((INDEX >= 67) & (INDEX <= 82)))
    assert six.sum() == 50
    np.testing.assert_array_equal(top, INDEX >= 60)  # the highest 40 %


def test_plug_flow_outlet_and_first_exit_concentration_are_exact(result):
    half = result.layouts[0]
    one_loop = np.r_[np.ones(5), np.zeros(10), np.ones(5)]  # clumps 25-49 blue, 50-99 white, 0-24 blue
    np.testing.assert_array_equal(windows_of_one_loop(half.colours), one_loop)
    measured = half.concentration
    np.testing.assert_array_equal(measured.n_total, 5)
    np.testing.assert_array_equal(measured.concentration, np.tile(one_loop, 3))
    np.testing.assert_array_equal(half.first_pass.n_total, 5)
    np.testing.assert_array_equal(half.first_pass.concentration, np.r_[one_loop, np.zeros(40)])
    np.testing.assert_allclose(measured.centres, (np.arange(60) + 0.5) * WINDOW, rtol=1e-12)
    np.testing.assert_allclose(half.recirculation_number, (np.arange(60) + 0.5) / 15.0, rtol=1e-8)
    for layout in result.layouts:  # every layout: the loop pattern repeats with period 20 windows (10 s)
        np.testing.assert_array_equal(layout.concentration.concentration, np.tile(windows_of_one_loop(layout.colours), 3))
        np.testing.assert_array_equal(layout.first_pass.concentration,
                                      np.r_[windows_of_one_loop(layout.colours), np.zeros(40)])


def test_renewal_prediction_equals_the_measurement_in_plug_flow(result):
    for layout in result.layouts:
        measured = layout.concentration.concentration
        # c = c_first + c_first shifted by 20 windows + by 40 windows: the measurement itself
        np.testing.assert_allclose(layout.predicted, measured, rtol=0, atol=1e-12)
        # Johanson's triangle (V1 = P = 0.99, end 1.02 t_m) after the 2.5 s channel lag is non-zero on
        # the window lags only at 20 w = 10 s, so it predicts the same plug
        np.testing.assert_allclose(layout.predicted_johanson, measured, rtol=0, atol=1e-12)
        assert layout.prediction_rms_error() == pytest.approx(0.0, abs=1e-12)


def test_vrr_per_recirculation_of_plug_flow_does_not_grow(result):
    half = result.layouts[0]
    # t_res = 15 windows; the loop of 20 windows is B(5) W(10) B(5), so recirculation 1 sees windows
    # 0-14: 5 blue, 10 white; 2: 15-29: 10 blue, 5 white; 3: 10 blue, 5 white; 4: 5 blue, 10 white.
    # var = (1/3)(2/3) = 2/9 each time, VRR = (1/4) / (2/9) = 9/8 in every recirculation: no blending
    # (not 1, as a t_res window sees 1/3 or 2/3 of blue, not the batch's 1/2, since the channel
    # makes the loop longer than t_res)
    for vrr in (half.vrr, half.vrr_predicted):
        np.testing.assert_array_equal(vrr.recirculation_number, [0.5, 1.5, 2.5, 3.5])
        np.testing.assert_array_equal(vrr.n_windows, 15)
        np.testing.assert_allclose(vrr.vrr, 9.0 / 8.0, rtol=1e-12)
        np.testing.assert_allclose(vrr.sigma_out, math.sqrt(2.0 / 9.0), rtol=1e-12)
        assert vrr.sigma_in == 0.5 and vrr.blue_fraction == 0.5
    for layout in result.layouts:
        np.testing.assert_allclose(layout.vrr_predicted.vrr, layout.vrr.vrr, rtol=1e-12)
        assert math.isnan(layout.homogenised_after)  # 0/1 windows never come within +-10 % of p


def test_discontinuous_model_of_plug_flow_repeats_the_batch(result):
    samples_per_pass = 15.0 / (1.0 - 1e-9)  # t_res / window
    for layout in result.layouts:
        model = layout.model_concentration
        # the silo RTD on window steps is one spike at 15 w (7.5 s): 17 bins, 3 passes of 16 samples each
        assert model.size == 15 + PASSES * 16
        batch = model[15:30]
        np.testing.assert_array_equal(model[:15], 0.0)  # nothing out before one pass time
        np.testing.assert_allclose(model[15:60], np.tile(batch, PASSES), rtol=0, atol=1e-12)
        np.testing.assert_allclose(model[60:], 0.0, atol=1e-12)
        # the batch fed over 15 samples: at most one boundary sample per blue layer off
        assert abs(batch.mean() - layout.layout.blue_fraction) <= layout.layout.sublayers / 15.0
        np.testing.assert_allclose(layout.model_time_nr, np.arange(model.size) / samples_per_pass, rtol=1e-12)
        assert math.isnan(layout.model_homogenised_after)  # plug flow never homogenises
    # top 40 %: r = (i + 0.5) / 15 from the bottom, blue iff 1 - r < 0.4, i.e. samples 9 ... 14
    top = result.layouts[2].model_concentration
    np.testing.assert_allclose(top[15:30], np.r_[np.zeros(9), np.ones(6)], rtol=0, atol=1e-12)


def test_analyse_layout_alone_matches_the_composed_run(result, events, tracks):
    layout = Layout("bottom 30 %", 0.3)
    alone = analyse_layout(layout, tracks.position[0, :, 2], events, result.timing, result.window, result.rtd,
                           PASSES, TOLERANCE)
    np.testing.assert_array_equal(alone.colours, INDEX < 30)
    one_loop = windows_of_one_loop(alone.colours)
    np.testing.assert_array_equal(one_loop, np.r_[np.ones(1), np.zeros(14), np.ones(5)])  # clumps 25-29, 0-24
    np.testing.assert_array_equal(alone.concentration.concentration, np.tile(one_loop, 3))
    np.testing.assert_allclose(alone.predicted, alone.concentration.concentration, rtol=0, atol=1e-12)


# --------------------------------------------------------------------------- continuous mode


def sine_variance_bound(samples_per_period: float, samples: int) -> float:
    """Bound on |var / (A^2 / 2) - 1| for ``samples`` consecutive samples of ``A sin(w j + phi)``, any phi.

    With w = 2 pi / S: sum sin^2 = W / 2 - Re(e^{2 i phi} sum e^{2 i w j}) / 2 and |sum e^{2 i w j}| =
    |sin(w W)| / |sin w|; |sum sin| <= |sin(w W / 2)| / |sin(w / 2)|. Zero when W spans whole periods.
    """
    w = 2.0 * math.pi / samples_per_period
    return (abs(math.sin(w * samples)) / (samples * abs(math.sin(w)))
            + 2.0 * math.sin(0.5 * w * samples) ** 2 / (samples**2 * math.sin(0.5 * w) ** 2))


def test_continuous_mode_of_plug_flow_passes_periodic_inputs_unchanged(result):
    sine, square = continuous_mode(result.rtd, PERIOD_FRACTIONS)
    t_m = result.rtd.silo.t_mean
    for table, waveform in ((sine, "sine"), (square, "square")):
        assert table.waveform == waveform and table.n_periods == 10
        assert table.t_mean == pytest.approx(PASS_TIME, abs=1e-12)
        np.testing.assert_array_equal(table.period_over_tm, PERIOD_FRACTIONS)
        np.testing.assert_allclose(table.period, np.asarray(PERIOD_FRACTIONS) * t_m, rtol=1e-15)
    # The grid step is 0.3 t_m / 8 = 0.28125 s, so the pass time 7.5 s = 26.67 steps lies inside bin 26
    # (not on an edge): the tabulated RTD is one spike and the model an exact delay of 26 samples.
    # Where a period is a whole number of samples the steady window (10 periods) holds the same sine
    # samples as the delayed one, so VRR = 1 to round-off.
    whole = [0, 1, 2, 3, 4]  # 8, 12, 16, 32 and 64 samples per period
    np.testing.assert_allclose(sine.vrr[whole], 1.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(square.vrr[whole], 1.0, rtol=0, atol=1e-9)
    # 0.77 t_m is 20.53 samples: the window of round(205.3) = 205 samples is not whole periods and the
    # delay moves its phase; each variance is within a factor 1 +- b of A^2 / 2 (b = 0.0016 here),
    # so |VRR - 1| <= 2 b / (1 - b)
    samples_per_period = 8.0 * 0.77 / 0.3
    b = sine_variance_bound(samples_per_period, round(10 * samples_per_period))
    assert 0.0 < b < 0.002
    assert abs(sine.vrr[5] - 1.0) <= 2.0 * b / (1.0 - b)
    assert abs(sine.vrr[5] - 1.0) > 1e-6  # the leftover part period is visible: the bound is not vacuous
    # analyse_blending ran the same continuous mode
    np.testing.assert_array_equal(result.vrr_sine.vrr, sine.vrr)
    np.testing.assert_array_equal(result.vrr_square.vrr, square.vrr)


# --------------------------------------------------------------------------- snapshots


def test_snapshot_frames_picks_the_nearest_frames():
    # t_res = 7.5 s: Nr -> 0, 2.5, 7.5, 15.0075, 37.5 (beyond), 30, 30.00975 (within half a frame of the
    # end), 30.015 (beyond half a frame)
    wanted = [0.0, 1.0 / 3.0, 1.0, 2.001, 5.0, 4.0, 4.0013, 4.002]
    assert snapshot_frames(TIMES, 0.0, 7.5, wanted) == [0, 125, 375, 750, 1500, 1500]
    # an opening at 1 s shifts the wanted times: 1 + 0.2 * 7.5 = 2.5 s (frame 125), 1 + 7.5 * 0.99 = 8.425 s
    # (8.42 s, frame 421, nearer than 8.44 s)
    assert snapshot_frames(TIMES, 1.0, 7.5, [0.2, 0.99]) == [125, 421]
    assert snapshot_frames([2.0], 2.0, 1.0, [0.0, 0.1]) == [0]  # one frame: nothing after it is kept
    assert snapshot_frames(TIMES, 0.0, 7.5, []) == []


# --------------------------------------------------------------------------- Eulerian RTD

WIDTH, DEPTH, INLET_WIDTH = 0.2, 0.05, 0.1
DT = 0.01


def test_main_run_eulerian_rtd_of_uniform_downflow_is_height_over_speed(tracks, result):
    # 0.05 m bins: 4 columns x 15 rows over [-0.1, 0.1] x [0, 0.75] m, all holding clumps at every instant,
    # all moving at (0, 0, -0.1) m/s. The inlet region is the top row over |x| <= 0.05 m, 0.1 x 0.05 x 0.05 m;
    # 16 tracers make a 4 x 2 x 2 lattice (spacing 0.025 m) at heights 0.7125 and 0.7375 m: residence
    # times 7.125 and 7.375 s, eight of each.
    rtd = main_run_eulerian_rtd(tracks, conveyor_velocity(TIMES.size), np.ones(N_CLUMPS), result, WIDTH, DEPTH,
                                TOP, INLET_WIDTH, bin_size=0.05, dt=DT, max_recirculations=1.2, bins=4)
    assert rtd.n_total == rtd.n_exited == N_TRACER
    assert rtd.t_first == pytest.approx(7.125, abs=1e-12)
    assert rtd.t_last == pytest.approx(7.375, abs=1e-12)
    assert rtd.t_mean == pytest.approx(7.25, abs=1e-12)
    assert rtd.variance == pytest.approx(0.125**2, abs=1e-12)
    np.testing.assert_allclose(rtd.edges, np.linspace(0.0, 7.375, 5), rtol=0, atol=1e-12)
    np.testing.assert_allclose(rtd.E, [0.0, 0.0, 0.0, 1.0 / (7.375 / 4)], rtol=1e-12)  # both heights in the last bin


def test_main_run_eulerian_rtd_asks_for_more_time_when_no_tracer_leaves(tracks, result):
    # 0.5 t_res = 3.75 s is less than the shortest residence time, 7.125 s
    with pytest.raises(ValueError, match=r"no virtual tracer reached the outlet; raise silo_recirculation.eulerian.max_recirculations"):
        main_run_eulerian_rtd(tracks, conveyor_velocity(TIMES.size), np.ones(N_CLUMPS), result, WIDTH, DEPTH, TOP,
                              INLET_WIDTH, bin_size=0.05, dt=DT, max_recirculations=0.5, bins=4)


# Expected per bin size: residence times of the seeds (lattice order, x slowest and z fastest) and the
# (x, z) start of the three pathlines shown (seeds 0, 7, 15 of 16; 0, 9, 19 of 20).
# 0.25 m bins: 1 column x 3 rows; inlet region 0.2 x 0.05 x 0.25 m, 16 wanted -> a 4 x 1 x 5 lattice of 20
# at heights 0.525 ... 0.725 m.
EULERIAN = {
    0.05: (np.tile([7.125, 7.375], 8), [(-0.0375, 0.7125), (-0.0125, 0.7375), (0.0375, 0.7375)]),
    0.25: (np.tile([5.25, 5.75, 6.25, 6.75, 7.25], 4), [(-0.075, 0.525), (-0.025, 0.725), (0.075, 0.725)]),
}


def test_verify_eulerian_rtd_of_uniform_downflow(tracks):
    verification = verify_eulerian_rtd(
        tracks, conveyor_velocity(TIMES.size), np.ones(N_CLUMPS), WIDTH, DEPTH, BOTTOM, TOP, INLET_WIDTH,
        bin_sizes=[0.05, 0.25], tracer_start=TRACER_START, dt=DT, max_recirculations=1.2, paths_shown=3,
        tracer_fraction=TRACER_FRACTION, outlet_z=OUTLET,
    )
    assert verification.timing.residence_time == pytest.approx(PASS_TIME, rel=1e-12)
    # particles: pass 1 of clumps 30 ... 45, each 7.5 s from the top to the outlet
    assert verification.particle_residence.shape == (N_TRACER,)
    np.testing.assert_allclose(verification.particle_residence, PASS_TIME, rtol=0, atol=1e-12)
    # paths of passes 0, 7, 15 (clumps 30, 37, 45): the frames strictly between re-entry and exit
    assert len(verification.particle_paths) == 3
    for path, clump in zip(verification.particle_paths, (30, 37, 45)):
        entry = 0.1 * clump + 0.05
        frames = (TIMES > entry) & (TIMES < entry + PASS_TIME)
        assert path.shape == (375, 2)  # 7.5 s of 0.02 s frames
        np.testing.assert_allclose(path[:, 0], X0[clump], rtol=0, atol=0)
        np.testing.assert_allclose(path[:, 1], conveyor_z(TIMES[frames])[:, clump], rtol=0, atol=1e-15)
    # Eulerian tracers: height over speed, for every bin size (the field is uniform either way)
    assert sorted(verification.eulerian_residence) == [0.05, 0.25]
    history_steps = np.arange(901)  # ceil(1.2 * 7.5 / 0.01) = 900 steps, recorded every 0.01 s / dt = 1
    for bin_size, (residence, starts) in EULERIAN.items():
        np.testing.assert_allclose(verification.eulerian_residence[bin_size], residence, rtol=0, atol=1e-10)
        lines = verification.pathlines[bin_size]
        assert len(lines) == 3
        for line, (x, z) in zip(lines, starts):
            assert line.shape == (901, 2)
            inside = z - SPEED * DT * history_steps > 0.0  # recorded until the step that crosses z = 0
            np.testing.assert_array_equal(np.isfinite(line[:, 1]), inside)
            np.testing.assert_allclose(line[inside, 0], x, rtol=0, atol=1e-12)
            np.testing.assert_allclose(line[inside, 1], z - SPEED * DT * history_steps[inside], rtol=0, atol=1e-10)


def test_residence_summary_counts_and_moments():
    # mean 2 s, population std 1 s; the sample std sqrt(2) s over sqrt(2) tracers: the mean is 2 +- 1 s
    summary = residence_summary([1.0, 3.0, np.nan])
    assert summary == {"n": 3, "n_exited": 2, "mean_s": 2.0, "mean_s_error": 1.0, "std_s": 1.0}
    assert residence_summary([np.nan]) == {"n": 1, "n_exited": 0, "mean_s": None, "mean_s_error": None,
                                           "std_s": None}
    single = residence_summary([4.0, np.nan])
    assert (single["mean_s"], single["std_s"]) == (4.0, 0.0) and math.isnan(single["mean_s_error"])


def test_a_target_vrr_sizes_the_concentration_window_from_the_throughput(tracks):
    # the conveyor passes 10 clumps/s: a VRR of 12 needs more than 24 clumps per window, 25 clumps = 2.5 s
    sized = analyse_blending(
        tracks, LAYOUTS[:1], BOTTOM, TOP, WINDOW_FRACTION, TRACER_FRACTION, TRACER_START, RTD_BINS, PERIOD_FRACTIONS,
        PASSES, TOLERANCE, outlet_z=OUTLET, window_target_vrr=12.0,
    )
    assert sized.window == pytest.approx(2.5, rel=1e-12)
