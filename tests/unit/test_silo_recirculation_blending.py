"""Unit tests for siloflow.analysis.studies.silo_recirculation (tracks, concentration, vrr, tracers) on exact cases.

Most tests use a "conveyor": N clumps evenly spaced along z, all moving down at a constant speed
through the periodic domain, so every crossing, re-entry and pass is known in closed form.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.model.frames import ClumpFrame, ParticleFrame
from siloflow.analysis.numerics.rtd import rtd_from_exit_times
from siloflow.analysis.studies.silo_recirculation.concentration import (
    OutletConcentration,
    batch_inlet_signal,
    first_pass_concentration,
    layer_colours,
    outlet_concentration,
    predicted_concentration_from_first_pass,
)
from siloflow.analysis.studies.silo_recirculation.tracers import TracerPasses, tracer_count, tracer_passes
from siloflow.analysis.numerics.clump_tracks import ClumpTracks, clump_tracks, tracks_from_frames
from siloflow.analysis.studies.silo_recirculation.tracks import RecirculationEvents, clumps_above_outlet, recirculation_events
from siloflow.analysis.studies.silo_recirculation.vrr import (
    RecirculationVRR,
    holdup_residence_time,
    recirculation_number,
    sampling_noise_vrr_limit,
    vrr_by_recirculation,
)

# --------------------------------------------------------------------------- the conveyor

BOTTOM, OUTLET, TOP = -0.25, 0.0, 0.75  # domain height L = 1 m
HEIGHT = TOP - BOTTOM
SPEED = 0.1  # m/s downwards: a loop takes 10 s, a pass (top to outlet) 7.5 s
N_CLUMPS = 100
FRAME_STEP = 0.02
TIMES = np.arange(1501) * FRAME_STEP  # 0 ... 30 s
IDS = 3 * np.arange(N_CLUMPS) - 150  # ascending with the index, negative ones included
Z0 = BOTTOM + (np.arange(N_CLUMPS) + 0.5) / N_CLUMPS * HEIGHT  # -0.245 ... 0.745, clump i at index i
INDEX = np.arange(N_CLUMPS)
# Closed forms (clump i): crossings at 0.1 i - 2.45 + 10 j, re-entries at 0.1 i + 0.05 + 10 j [s].
FIRST_EXIT = np.where(INDEX >= 25, 0.1 * INDEX - 2.45, 0.1 * INDEX + 7.55)


def conveyor_z(t):
    return BOTTOM + np.mod(Z0[None, :] - SPEED * np.asarray(t)[:, None] - BOTTOM, HEIGHT)


def conveyor_frames(seed: int = 0):
    """Per-frame ids (shuffled) and positions of the conveyor."""
    rng = np.random.default_rng(seed)
    z = conveyor_z(TIMES)
    ids_per_frame, positions_per_frame = [], []
    for k in range(TIMES.size):
        order = rng.permutation(N_CLUMPS)
        position = np.stack([0.01 * order, np.zeros(N_CLUMPS), z[k, order]], axis=1)
        ids_per_frame.append(IDS[order])
        positions_per_frame.append(position)
    return ids_per_frame, positions_per_frame


@pytest.fixture(scope="module")
def conveyor_tracks() -> ClumpTracks:
    ids, positions = conveyor_frames()
    return clump_tracks(TIMES, ids, positions)


@pytest.fixture(scope="module")
def conveyor_events(conveyor_tracks) -> RecirculationEvents:
    return recirculation_events(conveyor_tracks, OUTLET, BOTTOM, TOP)


# --------------------------------------------------------------------------- tracks


def test_clump_tracks_sorts_ids_and_places_shuffled_positions(conveyor_tracks):
    assert isinstance(conveyor_tracks, ClumpTracks)
    np.testing.assert_array_equal(conveyor_tracks.clump_id, IDS)
    assert conveyor_tracks.clump_id.dtype == np.int64
    assert conveyor_tracks.position.shape == (TIMES.size, N_CLUMPS, 3)
    np.testing.assert_array_equal(conveyor_tracks.z, conveyor_z(TIMES))
    np.testing.assert_array_equal(conveyor_tracks.position[:, :, 0], np.broadcast_to(0.01 * INDEX, (TIMES.size, N_CLUMPS)))
    assert conveyor_tracks.present.all()
    assert (conveyor_tracks.n_times, conveyor_tracks.n_clumps) == (TIMES.size, N_CLUMPS)


def test_clump_tracks_marks_absent_clumps_with_nan_and_accepts_integral_float_ids():
    tracks = clump_tracks(
        [0.0, 1.0, 2.0],
        [np.array([5.0, -2.0]), np.array([7, 5]), np.array([-2])],
        [[[0, 0, 1.0], [0, 0, 2.0]], [[0, 0, 3.0], [0, 0, 4.0]], [[0, 0, 5.0]]],
    )
    np.testing.assert_array_equal(tracks.clump_id, [-2, 5, 7])
    expected_z = np.array([[2.0, 1.0, np.nan], [np.nan, 4.0, 3.0], [5.0, np.nan, np.nan]])
    np.testing.assert_array_equal(tracks.z, expected_z)
    np.testing.assert_array_equal(tracks.present, np.isfinite(expected_z))


def test_clump_tracks_rejects_bad_input():
    one = [np.array([1, 2])]
    xyz = [np.zeros((2, 3))]
    with pytest.raises(ValueError, match=r"ids_per_frame\[1\] has duplicate clump ids, e.g. 4"):
        clump_tracks([0.0, 1.0], [np.array([1, 2]), np.array([4, 3, 4])], [np.zeros((2, 3)), np.zeros((3, 3))])
    with pytest.raises(ValueError, match="times must be strictly increasing"):
        clump_tracks([1.0, 1.0], one * 2, xyz * 2)
    with pytest.raises(ValueError, match=r"ids_per_frame must hold one array per time \(2\), got 1"):
        clump_tracks([0.0, 1.0], one, xyz * 2)
    with pytest.raises(ValueError, match="positions_per_frame must hold one array per time"):
        clump_tracks([0.0], one, xyz * 2)
    with pytest.raises(ValueError, match=r"positions_per_frame\[0\] must have shape \(2, 3\)"):
        clump_tracks([0.0], one, [np.zeros((3, 3))])
    with pytest.raises(ValueError, match=r"positions_per_frame\[0\] must contain only finite"):
        clump_tracks([0.0], one, [np.full((2, 3), np.nan)])
    with pytest.raises(ValueError, match=r"ids_per_frame\[0\] must hold integer clump ids"):
        clump_tracks([0.0], [np.array([1.5, 2.0])], xyz)


# --------------------------------------------------------------------------- events


def test_conveyor_crossings_equal_the_closed_form(conveyor_events):
    events = conveyor_events
    expected = []
    for i in range(N_CLUMPS):
        for j in range(4):
            t = 0.1 * i - 2.45 + 10.0 * j
            if 0.0 < t <= TIMES[-1]:
                expected.append((t, i))
    expected.sort()
    assert len(expected) == 300
    np.testing.assert_allclose(events.exit_times_all, [t for t, _ in expected], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(events.exit_clump_index, [i for _, i in expected])
    assert events.exit_is_pass_exit.all()  # no clump bounces back up through the outlet
    np.testing.assert_allclose(events.first_exit_time, FIRST_EXIT, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(events.n_frames_absent, 0)
    assert (events.first_frame_time, events.last_frame_time) == (0.0, TIMES[-1])


def test_conveyor_passes_equal_the_closed_form(conveyor_events):
    events = conveyor_events
    assert events.n_passes == 4 * N_CLUMPS  # three re-entries each within 30 s
    np.testing.assert_array_equal(events.pass_clump_index, np.repeat(INDEX, 4))
    np.testing.assert_array_equal(events.pass_clump_id, np.repeat(IDS, 4))
    np.testing.assert_array_equal(events.pass_number, np.tile(np.arange(4), N_CLUMPS))
    entry = np.full((N_CLUMPS, 4), np.nan)
    exit_ = np.full((N_CLUMPS, 4), np.nan)
    for n in (1, 2, 3):
        entry[:, n] = 0.1 * INDEX + 0.05 + 10.0 * (n - 1)
        exit_[:, n] = 0.1 * INDEX + 7.55 + 10.0 * (n - 1)
    exit_[exit_ > TIMES[-1]] = np.nan  # pass 3 of the clumps in the silo at t = 0 is not out by 30 s
    exit_[25:, 0] = 0.1 * INDEX[25:] - 2.45  # initial content of the silo
    np.testing.assert_allclose(events.entry_time, entry.ravel(), rtol=0, atol=1e-12)
    np.testing.assert_allclose(events.exit_time, exit_.ravel(), rtol=0, atol=1e-12)
    below = np.zeros((N_CLUMPS, 4), dtype=bool)
    below[:25, 0] = True  # in the channel at t = 0
    np.testing.assert_array_equal(events.started_below_outlet, below.ravel())
    residence = events.residence_time[np.isfinite(events.residence_time)]
    assert residence.size == 225  # passes 1 and 2 of every clump, pass 3 of clumps 0 ... 24
    np.testing.assert_allclose(residence, 7.5, rtol=0, atol=1e-12)
    loop = events.exit_time - events.previous_exit_time
    loop = loop[np.isfinite(loop)]
    assert loop.size == 200
    np.testing.assert_allclose(loop, 10.0, rtol=0, atol=1e-12)
    crossing_pass = events.exit_pass_number
    np.testing.assert_array_equal(crossing_pass[events.exit_clump_index < 25] >= 1, True)


def test_exit_and_wrap_in_one_interval_and_a_late_arrival():
    # clump 1 falls 0.4 m in 1 s: through the outlet at 0.25 s and the bottom at 0.875 s;
    # clump 2 is absent from the first frame and never moves
    tracks = clump_tracks(
        [0.0, 1.0, 2.0],
        [np.array([1]), np.array([1, 2]), np.array([2, 1])],
        [[[0, 0, 0.1]], [[0, 0, 0.7], [0, 0, 0.5]], [[0, 0, 0.5], [0, 0, 0.6]]],
    )
    events = recirculation_events(tracks, OUTLET, BOTTOM, TOP)
    np.testing.assert_array_equal(events.pass_clump_id, [1, 1, 2])
    np.testing.assert_array_equal(events.pass_number, [0, 1, 0])
    np.testing.assert_allclose(events.exit_time, [0.25, np.nan, np.nan], rtol=0, atol=1e-15)
    np.testing.assert_allclose(events.entry_time, [np.nan, 0.875, np.nan], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(events.started_below_outlet, False)
    np.testing.assert_array_equal(events.n_frames_absent, [0, 1])
    np.testing.assert_allclose(events.first_exit_time, [0.25, np.nan])


def test_missing_frames_hide_only_the_crossings_next_to_them():
    ids, positions = conveyor_frames(seed=1)
    gaps = {30: range(100, 111), 40: (77, 78), 60: range(0, 10)}  # clump 40 crosses at 1.55 s = frame 77.5
    for index, frames in gaps.items():
        for k in frames:
            keep = ids[k] != IDS[index]
            ids[k], positions[k] = ids[k][keep], positions[k][keep]
    events = recirculation_events(clump_tracks(TIMES, ids, positions), OUTLET, BOTTOM, TOP)
    np.testing.assert_array_equal(events.n_frames_absent[[30, 40, 60, 0]], [11, 2, 10, 0])
    first = FIRST_EXIT.copy()
    first[40] = 0.1 * 40 + 7.55  # its first crossing was in the gap: the next one is the first seen
    np.testing.assert_allclose(events.first_exit_time, first, rtol=0, atol=1e-12)
    rows = events.pass_clump_index == 40
    np.testing.assert_allclose(events.exit_time[rows], [np.nan, 11.55, 21.55, np.nan], rtol=0, atol=1e-12)
    rows = events.pass_clump_index == 60  # first seen at 0.2 s, above the outlet: pass 0, unchanged
    np.testing.assert_allclose(events.exit_time[rows][0], 3.55, rtol=0, atol=1e-12)
    assert not events.started_below_outlet[rows][0]
    assert events.exit_times_all.size == 299


def test_recirculation_events_rejects_bad_geometry(conveyor_tracks):
    with pytest.raises(ValueError, match="outlet_z must lie strictly between domain_bottom and domain_top"):
        recirculation_events(conveyor_tracks, 1.0, BOTTOM, TOP)
    with pytest.raises(ValueError, match=r"tracks.position: z must lie in \[domain_bottom, domain_top\]"):
        recirculation_events(conveyor_tracks, OUTLET, -0.1, TOP)


def test_clumps_above_outlet_and_holdup_residence_time_obey_littles_law(conveyor_tracks, conveyor_events):
    holdup = clumps_above_outlet(conveyor_tracks, OUTLET)
    np.testing.assert_array_equal(holdup, 75)
    in_window = (TIMES >= 10.0) & (TIMES <= 20.0)
    t_res = holdup_residence_time(holdup[in_window], conveyor_events.exit_times_all, 10.0, 20.0)
    assert t_res == 7.5  # 75 clumps / (100 exits / 10 s): the pass residence time
    assert holdup_residence_time([3, 5], [0.5, np.nan, 1.5, 9.0], 0.0, 2.0) == 4.0 * 2.0 / 2


def test_holdup_residence_time_rejects_bad_input():
    with pytest.raises(ValueError, match=r"exit_times: no outlet crossing in \[t_start, t_end\]"):
        holdup_residence_time([10], [5.0], 0.0, 1.0)
    with pytest.raises(ValueError, match="n_in_silo must contain counts >= 0"):
        holdup_residence_time([-1], [0.5], 0.0, 1.0)
    with pytest.raises(ValueError, match="n_in_silo must not be empty"):
        holdup_residence_time([], [0.5], 0.0, 1.0)
    with pytest.raises(ValueError, match="t_end must be > t_start"):
        holdup_residence_time([1], [0.5], 1.0, 1.0)


# --------------------------------------------------------------------------- layers


def test_layer_colours_single_layer_counts_are_exact():
    rng = np.random.default_rng(3)
    heights = rng.permutation(1000) * 1e-3
    blue = layer_colours(heights, 0.37)
    assert blue.dtype == bool and blue.sum() == 370
    np.testing.assert_array_equal(blue, heights < 0.370)  # the lowest 37 %
    top = layer_colours(heights, 0.37, blue_at="top")
    np.testing.assert_array_equal(top, heights >= 0.630)  # the highest 37 %
    np.testing.assert_array_equal(layer_colours(np.arange(10.0), 0.3), [1, 1, 1, 0, 0, 0, 0, 0, 0, 0])


def test_layer_colours_six_layers_alternate_from_the_bottom():
    rng = np.random.default_rng(4)
    heights = rng.permutation(600).astype(float)
    blue = layer_colours(heights, 0.5, sublayers=3)
    by_height = blue[np.argsort(heights)]
    pattern = np.repeat([True, False, True, False, True, False], 100)  # B W B W B W from the bottom
    np.testing.assert_array_equal(by_height, pattern)
    top = layer_colours(heights, 0.5, sublayers=3, blue_at="top")[np.argsort(heights)]
    np.testing.assert_array_equal(top, pattern[::-1])  # B W B W B W from the top


def test_layer_colours_ties_are_ranked_by_index():
    np.testing.assert_array_equal(layer_colours(np.zeros(4), 0.5), [True, True, False, False])
    assert layer_colours(np.zeros(0), 0.5).shape == (0,)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"blue_fraction": 0.0}, r"blue_fraction must be a number in \(0, 1\)"),
        ({"blue_fraction": 1.0}, r"blue_fraction must be a number in \(0, 1\)"),
        ({"sublayers": 0}, "sublayers must be an integer >= 1"),
        ({"sublayers": 1.5}, "sublayers must be an integer >= 1"),
        ({"sublayers": True}, "sublayers must be an integer >= 1"),
        ({"blue_at": "middle"}, "blue_at must be 'bottom' or 'top'"),
    ],
)
def test_layer_colours_rejects_bad_arguments(kwargs, message):
    arguments = {"blue_fraction": 0.5, "sublayers": 1, "blue_at": "bottom"} | kwargs
    with pytest.raises(ValueError, match=message):
        layer_colours(np.arange(4.0), **arguments)


def test_layer_colours_rejects_missing_heights():
    with pytest.raises(ValueError, match="initial_height must contain only finite numbers"):
        layer_colours([0.0, np.nan], 0.5)


def test_batch_inlet_signal_is_the_batch_fed_bottom_first():
    time, c_in = batch_inlet_signal(0.5, 3, "bottom", residence_time=3.0, dt=0.005)
    assert time.size == 600
    np.testing.assert_allclose(time, (np.arange(600) + 0.5) * 0.005, rtol=1e-15)
    np.testing.assert_array_equal(c_in, np.repeat([1.0, 0.0, 1.0, 0.0, 1.0, 0.0], 100))
    assert np.mean(c_in) == 0.5
    # the same rule as the colours of 600 clumps at evenly spaced heights
    np.testing.assert_array_equal(c_in == 1.0, layer_colours(np.arange(600.0), 0.5, sublayers=3))
    _, top = batch_inlet_signal(0.3, 1, "top", residence_time=2.0, dt=0.002)
    assert top.size == 1000 and np.mean(top) == 0.3
    np.testing.assert_array_equal(top, np.r_[np.zeros(700), np.ones(300)])  # blue at the top enters last


def test_batch_inlet_signal_mean_is_p_up_to_discretisation():
    _, c_in = batch_inlet_signal(0.37, 2, "bottom", residence_time=1.0, dt=1.0 / 301)
    assert abs(np.mean(c_in) - 0.37) <= 2.0 / 301


def test_batch_inlet_signal_rejects_bad_arguments():
    with pytest.raises(ValueError, match="dt .* must be at most twice residence_time"):
        batch_inlet_signal(0.5, 1, "bottom", residence_time=1.0, dt=3.0)
    with pytest.raises(ValueError, match="residence_time must be a finite number > 0"):
        batch_inlet_signal(0.5, 1, "bottom", residence_time=0.0, dt=0.1)
    with pytest.raises(ValueError, match="blue_at must be"):
        batch_inlet_signal(0.5, 1, "left", residence_time=1.0, dt=0.1)


# --------------------------------------------------------------------------- outlet concentration


def test_outlet_concentration_on_hand_made_crossings():
    exits = [0.1, 0.2, 0.9, 1.0, 1.5, np.nan, 2.7, 3.2, -0.5]
    blue = [True, False, True, True, False, True, True, True, True]
    result = outlet_concentration(exits, blue, window=1.0, t_start=0.0, t_end=5.5)
    assert isinstance(result, OutletConcentration)
    np.testing.assert_array_equal(result.edges, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0])  # [5, 5.5) dropped
    np.testing.assert_array_equal(result.centres, [0.5, 1.5, 2.5, 3.5, 4.5])
    np.testing.assert_array_equal(result.n_total, [3, 2, 1, 1, 0])
    np.testing.assert_array_equal(result.n_blue, [2, 1, 1, 1, 0])
    np.testing.assert_array_equal(result.concentration, [2.0 / 3.0, 0.5, 1.0, 1.0, np.nan])
    assert result.window == 1.0 and result.mean_crossings == 7.0 / 5.0
    rows = result.rows()
    assert rows[0] == {"t_start_s": 0.0, "t_end_s": 1.0, "t_centre_s": 0.5, "n_total": 3, "n_blue": 2,
                       "concentration": 2.0 / 3.0}


def test_outlet_concentration_rejects_bad_input():
    with pytest.raises(ValueError, match=r"is_blue must have shape \(2,\)"):
        outlet_concentration([0.1, 0.2], [True], 1.0, 0.0, 2.0)
    with pytest.raises(ValueError, match="is_blue must be a boolean mask"):
        outlet_concentration([0.1, 0.2], [1, 2], 1.0, 0.0, 2.0)
    with pytest.raises(ValueError, match="exit_times must not contain infinite values"):
        outlet_concentration([0.1, np.inf], [1, 0], 1.0, 0.0, 2.0)
    with pytest.raises(ValueError, match="window must be a finite number > 0"):
        outlet_concentration([0.1], [1], 0.0, 0.0, 2.0)
    with pytest.raises(ValueError, match="t_end must be > t_start"):
        outlet_concentration([0.1], [1], 1.0, 2.0, 2.0)
    with pytest.raises(ValueError, match=r"window \(3.0 s\) must fit at least once"):
        outlet_concentration([0.1], [1], 3.0, 0.0, 2.0)


def test_conveyor_first_pass_and_total_concentration(conveyor_events):
    blue = layer_colours(Z0, 0.5)  # the lower half, channel included: clumps 0 ... 49
    np.testing.assert_array_equal(blue, INDEX < 50)
    events = conveyor_events
    total = outlet_concentration(events.exit_times_all, blue[events.exit_clump_index], 0.5, 0.0, 30.0)
    first = first_pass_concentration(events, blue, 0.5, 0.0, 30.0)
    np.testing.assert_array_equal(total.n_total, 5)
    np.testing.assert_array_equal(first.n_total, total.n_total)
    one_loop = np.zeros(20)
    one_loop[0:5] = 1.0  # clumps 25 ... 49 leave in 0 ... 2.5 s
    one_loop[15:20] = 1.0  # clumps 0 ... 24 leave the channel loop in 7.5 ... 10 s
    np.testing.assert_array_equal(total.concentration, np.tile(one_loop, 3))
    np.testing.assert_array_equal(first.concentration, np.r_[one_loop, np.zeros(40)])
    recycled = total.concentration - first.concentration
    np.testing.assert_array_equal(recycled, np.r_[np.zeros(20), one_loop, one_loop])
    assert first.n_blue.sum() == 50  # each blue clump has exactly one first exit


def test_first_pass_concentration_rejects_colours_of_the_wrong_length(conveyor_events):
    with pytest.raises(ValueError, match=r"is_blue must have shape \(100,\)"):
        first_pass_concentration(conveyor_events, np.ones(99, dtype=bool), 0.5, 0.0, 30.0)


# --------------------------------------------------------------------------- renewal prediction


def test_prediction_with_plug_flow_is_a_sum_of_shifted_copies():
    dt, lag, n = 0.25, 7, 30
    rng = np.random.default_rng(5)
    c_first = rng.random(n)
    E = np.zeros(lag + 1)
    E[lag] = 1.0 / dt
    predicted = predicted_concentration_from_first_pass(c_first, E, dt, passes=5)
    expected = np.zeros(n)
    for j in range(5):
        expected[j * lag :] += c_first[: n - j * lag]
    np.testing.assert_allclose(predicted, expected, rtol=0, atol=1e-13)


def test_prediction_with_a_geometric_loop_rtd_matches_the_renewal_closed_form():
    # E[k] = (1 - a) a^(k - 1) / dt for k >= 1: c = c1 (1 - a z) / (1 - z) by z-transform, i.e. for a
    # unit c_first at sample 0, c = 1, 1 - a, 1 - a, ... (one pass per sample at most: 20 passes exact)
    dt, a, n = 0.1, 0.5, 20
    k = np.arange(60)
    E = np.where(k >= 1, (1.0 - a) * a ** np.maximum(k - 1, 0) / dt, 0.0)
    c_first = np.zeros(n)
    c_first[0] = 1.0
    predicted = predicted_concentration_from_first_pass(c_first, E, dt, passes=n)
    np.testing.assert_allclose(predicted, np.r_[1.0, np.full(n - 1, 1.0 - a)], rtol=0, atol=1e-12)


def test_conveyor_prediction_from_first_pass_and_measured_loop_rtd_equals_the_measurement(conveyor_events):
    events = conveyor_events
    blue = INDEX < 50
    window = 0.5
    total = outlet_concentration(events.exit_times_all, blue[events.exit_clump_index], window, 0.0, 30.0)
    first = first_pass_concentration(events, blue, window, 0.0, 30.0)
    tracer = tracer_passes(events, 0.0, 100, entry_at="outlet")
    np.testing.assert_allclose(tracer.residence_time, 10.0, rtol=0, atol=1e-12)
    edges = (np.arange(31) - 0.5) * window  # bins centred on 0, dt, 2 dt, ...
    rtd = rtd_from_exit_times(tracer.exit_time, t_entry=tracer.entry_time, bins=edges, n_total=tracer.n_tracer)
    np.testing.assert_allclose(rtd.time, np.arange(30) * window, rtol=0, atol=1e-15)
    assert rtd.E[20] == 2.0 and rtd.E.sum() * window == 1.0  # a plug at 10 s
    predicted = predicted_concentration_from_first_pass(first.concentration, rtd.E, window, passes=3)
    np.testing.assert_allclose(predicted, total.concentration, rtol=0, atol=1e-12)


def test_prediction_rejects_bad_input():
    with pytest.raises(ValueError, match="c_first must contain only finite numbers"):
        predicted_concentration_from_first_pass([0.1, np.nan], [1.0], 0.1, 1)
    with pytest.raises(ValueError, match="c_first must have at least 2 samples"):
        predicted_concentration_from_first_pass([0.1], [1.0], 0.1, 1)
    with pytest.raises(ValueError, match="passes must be an integer >= 1"):
        predicted_concentration_from_first_pass([0.1, 0.2], [1.0], 0.1, 0)
    with pytest.raises(ValueError, match="dt must be a finite number > 0"):
        predicted_concentration_from_first_pass([0.1, 0.2], [1.0], -0.1, 1)


# --------------------------------------------------------------------------- recirculation number and VRR


def test_recirculation_number():
    assert recirculation_number(7.0, 1.0, 2.0) == 3.0
    np.testing.assert_array_equal(recirculation_number([1.0, 2.0, 5.0], 1.0, 2.0), [0.0, 0.5, 2.0])
    with pytest.raises(ValueError, match="residence_time must be a finite number > 0"):
        recirculation_number(1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="t_open must be a finite number"):
        recirculation_number(1.0, np.nan, 1.0)


def test_vrr_by_recirculation_on_a_hand_made_series():
    # t_open = 1 s, t_res = 2 s: centres 1.25, 1.75, ... have Nr = 0.125, 0.375, ...
    centres = np.r_[0.5, 1.0 + 0.25 + 0.5 * np.arange(12)]
    c = np.r_[1.0, [0.2, 0.8, 0.2, 0.8], [0.5] * 4, [0.4, np.nan, np.nan, np.nan]]
    result = vrr_by_recirculation(centres, c, t_open=1.0, residence_time=2.0, blue_fraction=0.5, n_recirculations=4)
    assert isinstance(result, RecirculationVRR)
    np.testing.assert_array_equal(result.recirculation_number, [0.5, 1.5, 2.5, 3.5])
    np.testing.assert_array_equal(result.n_windows, [4, 4, 1, 0])  # the window before t_open is left out
    assert result.vrr[0] == pytest.approx(0.25 / 0.09, rel=1e-12)
    assert result.sigma_out[0] == pytest.approx(0.3, rel=1e-12)
    assert result.vrr[1] == math.inf and result.sigma_out[1] == 0.0
    assert np.isnan(result.vrr[2:]).all() and np.isnan(result.sigma_out[2:]).all()
    assert result.sigma_in == 0.5 and result.blue_fraction == 0.5
    assert result.rows()[0]["n_windows"] == 4


def test_plug_flow_recirculation_does_not_blend(conveyor_events):
    blue = INDEX < 50
    events = conveyor_events
    total = outlet_concentration(events.exit_times_all, blue[events.exit_clump_index], 0.5, 0.0, 30.0)
    result = vrr_by_recirculation(total.centres, total.concentration, 0.0, 10.0, 0.5, 3)
    np.testing.assert_array_equal(result.n_windows, 20)
    np.testing.assert_allclose(result.vrr, 1.0, rtol=1e-12)  # the batch leaves as it came in


def test_vrr_by_recirculation_rejects_bad_input():
    with pytest.raises(ValueError, match="concentration must have the shape of window_centres"):
        vrr_by_recirculation([1.0, 2.0], [0.5], 0.0, 1.0, 0.5, 1)
    with pytest.raises(ValueError, match="n_recirculations must be an integer >= 1"):
        vrr_by_recirculation([1.0], [0.5], 0.0, 1.0, 0.5, 0)
    with pytest.raises(ValueError, match=r"blue_fraction must be a number in \(0, 1\)"):
        vrr_by_recirculation([1.0], [0.5], 0.0, 1.0, 1.5, 1)


def test_sampling_noise_vrr_limit_is_the_particles_per_window():
    assert sampling_noise_vrr_limit(0.3, 40) == 40.0
    assert sampling_noise_vrr_limit(0.5, 12.5) == 12.5
    with pytest.raises(ValueError, match="particles_per_window must be a finite number > 0"):
        sampling_noise_vrr_limit(0.5, 0)
    with pytest.raises(ValueError, match="blue_fraction must be a number in"):
        sampling_noise_vrr_limit(0.0, 10)


def test_recirculation_vrr_ceiling_is_the_clumps_per_window_and_flags_from_half_of_it():
    result = RecirculationVRR(recirculation_number=np.array([0.5, 1.5, 2.5, 3.5]),
                              vrr=np.array([20.0, 19.99, np.nan, np.inf]), sigma_out=np.full(4, np.nan),
                              n_windows=np.array([5, 5, 1, 5]), sigma_in=math.sqrt(0.21), blue_fraction=0.3)
    assert result.ceiling(40) == 40.0  # p (1 - p) / (p (1 - p) / 40)
    flags = result.at_ceiling(40)
    assert flags.dtype == bool
    np.testing.assert_array_equal(flags, [True, False, False, True])  # 20 = 40 / 2; NaN never, inf always
    np.testing.assert_array_equal(result.at_ceiling(40, factor=4.0), [True, True, False, True])
    with pytest.raises(ValueError, match="clumps_per_window must be a finite number > 0"):
        result.ceiling(0.0)
    with pytest.raises(ValueError, match="factor must be a finite number >= 1"):
        result.at_ceiling(40, factor=0.5)


# --------------------------------------------------------------------------- tracer


def test_tracer_passes_takes_the_first_entries_after_the_start(conveyor_events):
    tracer = tracer_passes(conveyor_events, 5.0, 100)
    assert isinstance(tracer, TracerPasses) and tracer.entry_at == "wrap"
    order = np.r_[np.arange(50, 100), np.arange(50)]  # pass 1 of clumps 50 ... 99, then pass 2 of 0 ... 49
    np.testing.assert_array_equal(tracer.clump_index, order)
    np.testing.assert_array_equal(tracer.clump_id, IDS[order])
    np.testing.assert_array_equal(conveyor_events.pass_number[tracer.pass_index], np.r_[[1] * 50, [2] * 50])
    expected_entry = np.r_[0.1 * np.arange(50, 100) + 0.05, 0.1 * np.arange(50) + 10.05]
    np.testing.assert_allclose(tracer.entry_time, expected_entry, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tracer.exit_time, expected_entry + 7.5, rtol=0, atol=1e-12)
    assert tracer.n_tracer == 100 and tracer.n_exited == 100


def test_tracer_passes_feed_the_rtd_with_passes_not_out_yet(conveyor_events):
    tracer = tracer_passes(conveyor_events, 15.0, 150)
    assert tracer.n_tracer == 150 and tracer.n_exited == 75  # pass 3 of clumps 25 ... 99 is not out by 30 s
    rtd = rtd_from_exit_times(tracer.exit_time, t_entry=tracer.entry_time, n_total=tracer.n_tracer, bins=4)
    assert rtd.n_total == 150 and rtd.n_exited == 75 and rtd.fraction_exited == 0.5
    assert rtd.t_mean == pytest.approx(7.5, abs=1e-12)
    assert rtd.variance == pytest.approx(0.0, abs=1e-20)
    assert float(np.sum(rtd.E * rtd.widths)) == pytest.approx(0.5, rel=1e-12)


def test_tracer_passes_rejects_too_few_entries_and_bad_arguments(conveyor_events):
    with pytest.raises(ValueError, match=r"n_tracer: only 50 passes enter at or after start_time = 25.0 s"):
        tracer_passes(conveyor_events, 25.0, 100)
    with pytest.raises(ValueError, match="entry_at must be 'wrap' or 'outlet'"):
        tracer_passes(conveyor_events, 0.0, 1, entry_at="top")
    with pytest.raises(ValueError, match="n_tracer must be an integer >= 1"):
        tracer_passes(conveyor_events, 0.0, 0)


def test_tracer_count():
    assert tracer_count(0.01, 0.1, 600.0, 0.001) == 600
    assert tracer_count(1.0, 0.25, 10.0, 1.0) == 3  # 2.5 rounds half up
    assert tracer_count(1.0e-6, 0.01, 600.0, 1.0) == 1  # at least one
    with pytest.raises(ValueError, match=r"tracer_fraction must be a number in \(0, 1\]"):
        tracer_count(1.0, 1.5, 600.0, 0.001)
    with pytest.raises(ValueError, match="silo_volume must be a finite number > 0"):
        tracer_count(-1.0, 0.1, 600.0, 0.001)
    with pytest.raises(ValueError, match="clump_mass must be a finite number > 0"):
        tracer_count(1.0, 0.1, 600.0, 0.0)


# --------------------------------------------------------------------------- tracks from frames


def _spheres(time, clump_id, position, velocity, mass):
    """A frame of spheres (sphere ids 0, 1, ...); ``mass`` is the clump mass carried by each sphere."""
    n = len(clump_id)
    return ParticleFrame(time=time, step=int(round(time * 1000)), id=np.arange(n), type=np.ones(n),
                         clump_id=clump_id, position=position, velocity=velocity, angular_velocity=None,
                         radius=np.full(n, 0.001), mass=mass)


def test_tracks_from_frames_join_straddling_clumps_and_lay_out_velocities_and_masses():
    # Domain periodic in z over [-0.25, 0.75) (L = 1 m). Clump 5 has two spheres; at t = 1 s it straddles the
    # periodic boundary (spheres at z = 0.74 and -0.24, i.e. 0.76 unwrapped): its centre is 0.75 -> wrapped to
    # -0.25. Clump 9 is a single sphere, absent from the last frame.
    frames = [
        _spheres(0.0, [5, 5, 9], [[0.0, 0.0, 0.10], [0.0, 0.0, 0.12], [0.02, 0.0, 0.5]],
                 [[0.0, 0.0, -1.0], [0.0, 0.0, -3.0], [1.0, 0.0, 0.0]], [2.0, 2.0, 1.0]),
        _spheres(1.0, [9, 5, 5], [[0.02, 0.0, 0.4], [0.0, 0.0, 0.74], [0.0, 0.0, -0.24]],
                 [[0.0, 0.0, -0.5], [0.0, 0.0, -2.0], [0.0, 0.0, -2.0]], [1.0, 2.0, 2.0]),
        _spheres(2.0, [5, 5], [[0.0, 0.0, 0.3], [0.0, 0.0, 0.4]], [[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]], [2.0, 2.0]),
    ]
    result = tracks_from_frames(frames, (BOTTOM, TOP))
    np.testing.assert_array_equal(result.tracks.times, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(result.tracks.clump_id, [5, 9])
    np.testing.assert_allclose(result.tracks.z[:, 0], [0.11, -0.25, 0.35], atol=1e-12)
    np.testing.assert_allclose(result.tracks.z[:2, 1], [0.5, 0.4])
    assert np.isnan(result.tracks.z[2, 1])
    np.testing.assert_allclose(result.velocity[:, 0, 2], [-2.0, -2.0, -1.0])
    np.testing.assert_allclose(result.velocity[:2, 1], [[1.0, 0.0, 0.0], [0.0, 0.0, -0.5]])
    assert np.all(np.isnan(result.velocity[2, 1]))
    np.testing.assert_array_equal(result.mass, [2.0, 1.0])


def test_tracks_from_frames_take_clump_frames_as_they_are_and_need_two_frames():
    clumps = [ClumpFrame(time=t, step=k, clump_id=[3], position=[[0.0, 0.0, z]], velocity=[[0.0, 0.0, -0.1]],
                         mass=[0.5], n_spheres=[4]) for k, (t, z) in enumerate([(0.0, 0.2), (0.5, 0.15)])]
    result = tracks_from_frames(iter(clumps), (BOTTOM, TOP))
    np.testing.assert_array_equal(result.tracks.z[:, 0], [0.2, 0.15])
    np.testing.assert_array_equal(result.mass, [0.5])
    with pytest.raises(ValueError, match="at least 2 frames, got 1"):
        tracks_from_frames(clumps[:1], (BOTTOM, TOP))
    with pytest.raises(ValueError, match="domain_z must be"):
        tracks_from_frames(clumps, (TOP, BOTTOM))
