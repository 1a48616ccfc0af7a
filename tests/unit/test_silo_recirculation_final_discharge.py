"""Unit tests for the discharge after the recirculations
(:mod:`siloflow.analysis.studies.silo_recirculation.final_discharge`) and the cut of the tracks at the stop of the
re-entry (:meth:`siloflow.analysis.numerics.clump_tracks.ClumpTracks.until`), on exact cases.

The conveyor of ``test_silo_recirculation_study.py`` (helpers copied here): 100 clumps evenly spaced along z, all moving
down at 0.1 m/s through a domain periodic in z from -0.25 to 0.75 m, outlet at 0; clump i starts at
``z0_i = -0.245 + 0.01 i`` and crosses the outlet at ``0.1 i - 2.45 + 10 j`` s, re-enters at ``0.1 i + 0.05 + 10 j`` s;
75 clumps above the outlet, 10 crossings per second, t_res = 7.5 s. Here the re-entry stops at ``t_stop`` = 20 s (two
whole loops: every clump is back where it started, 0 ... 24 in the channel, 25 ... 99 above the outlet): a clump
that would re-enter after it is gone from then on (NaN). The 75 clumps above the outlet cross at 20.05 ... 27.45 s,
5 per window of 0.5 s, and nothing crosses after: 15 windows, then the flow has faded.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from siloflow.analysis.io.tables import write_json
from siloflow.analysis.numerics.clump_tracks import ClumpTracks, TrackedClumps, clump_tracks, frames_until
from siloflow.analysis.studies.silo_recirculation.concentration import layer_colours
from siloflow.analysis.studies.silo_recirculation.final_discharge import (
    FADE_FRACTION,
    discharge_vrr,
    final_discharge,
    flowing_windows,
)
from siloflow.analysis.studies.silo_recirculation.study import Layout, analyse_blending
from siloflow.analysis.studies.silo_recirculation.tables import blending_summary, summary_rows
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events

# --------------------------------------------------------------------------- the conveyor with a final discharge

BOTTOM, OUTLET, TOP = -0.25, 0.0, 0.75
HEIGHT = TOP - BOTTOM
SPEED = 0.1
N_CLUMPS = 100
TIMES = np.arange(1501) * 0.02  # 0 ... 30 s
IDS = 3 * np.arange(N_CLUMPS) - 150
INDEX = np.arange(N_CLUMPS)
Z0 = BOTTOM + (INDEX + 0.5) / N_CLUMPS * HEIGHT
X0 = -0.075 + 0.05 * (INDEX % 4)
T_STOP = 20.0
# the study's analysis parameters of test_silo_recirculation_study.py: windows of t_res / 15 = 0.5 s (edges 0.05 s from
# the nearest crossing, a hair short so that no round-off moves a crossing across one)
WINDOW_FRACTION = (1.0 - 1.0e-9) / 15.0
LAYOUTS = [Layout("bottom half", 0.5), Layout("six layers", 0.5, sublayers=3), Layout("top 40 %", 0.4, blue_at="top")]


def _wraps(t) -> np.ndarray:
    """How many times each clump has passed the bottom by time t (negative and decreasing) [-]."""
    return np.floor((Z0[None, :] - SPEED * np.asarray(t)[:, None] - BOTTOM) / HEIGHT)


def discharge_tracks(t_stop: float = T_STOP) -> ClumpTracks:
    """The conveyor, each clump gone from the first frame after a re-entry later than ``t_stop``."""
    z = BOTTOM + np.mod(Z0[None, :] - SPEED * TIMES[:, None] - BOTTOM, HEIGHT)
    gone = (TIMES[:, None] > t_stop) & (_wraps(TIMES) < _wraps(np.array([t_stop])))
    z = np.where(gone, np.nan, z)
    position = np.stack([np.where(gone, np.nan, np.broadcast_to(X0, z.shape)), np.where(gone, np.nan, 0.0), z], axis=2)
    return ClumpTracks(times=TIMES.copy(), clump_id=IDS.astype(np.int64), position=position)


@pytest.fixture(scope="module")
def whole() -> ClumpTracks:
    return discharge_tracks()


@pytest.fixture(scope="module")
def result(whole):
    return analyse_blending(whole.until(T_STOP), LAYOUTS, BOTTOM, TOP, WINDOW_FRACTION, 0.21, 0.4, 10,
                            [0.3, 0.6, 1.2], 3, 0.1, outlet_z=OUTLET, with_transit=False)


@pytest.fixture(scope="module")
def discharge(whole, result):
    return final_discharge(whole, result, T_STOP, BOTTOM, TOP, outlet_z=OUTLET)


# --------------------------------------------------------------------------- the cut of the tracks


def test_until_keeps_exactly_the_frames_at_or_before_the_time_and_every_clump_seen_in_them():
    tracks = clump_tracks([0.0, 0.1, 0.2, 0.3], [[4, 9], [4, 9], [9], [4, 9]],
                          [[[0, 0, 0.4], [1, 0, 0.3]], [[0, 0, 0.3], [1, 0, 0.2]], [[1, 0, 0.1]],
                           [[0, 0, 0.1], [1, 0, 0.0]]])
    cut = tracks.until(0.2)  # a frame at exactly the time is kept
    assert cut.times.tolist() == [0.0, 0.1, 0.2] and cut.clump_id.tolist() == [4, 9]
    np.testing.assert_array_equal(cut.position, tracks.position[:3])
    assert tracks.until(np.nextafter(0.2, 0.0)).times.tolist() == [0.0, 0.1]  # a hair before it: not kept
    assert tracks.until(5.0).times.tolist() == [0.0, 0.1, 0.2, 0.3]  # nothing after: all of it
    velocity = np.arange(4 * 2 * 3, dtype=float).reshape(4, 2, 3)
    tracked = TrackedClumps(tracks=tracks, velocity=velocity, mass=np.array([1.0, 2.0]))
    kept = tracked.until(0.15)
    assert kept.tracks.times.tolist() == [0.0, 0.1] and kept.mass.tolist() == [1.0, 2.0]
    np.testing.assert_array_equal(kept.velocity, velocity[:2])
    assert frames_until(tracks.times, 0.3) == 4
    with pytest.raises(ValueError, match="at least 2 are needed"):
        tracks.until(0.05)
    with pytest.raises(ValueError, match="t_last must be a finite number"):
        tracks.until(math.nan)


def test_until_leaves_out_a_clump_first_seen_after_the_time():
    """Clump 12 appears at 0.2 s (what LIGGGHTS leaves of a clump whose sphere a fixed boundary took gets a new id):
    cut at 0.1 s it is no column, nor its velocity or mass."""
    tracks = clump_tracks([0.0, 0.1, 0.2], [[4, 9], [4, 9], [9, 12]],
                          [[[0, 0, 0.4], [1, 0, 0.3]], [[0, 0, 0.3], [1, 0, 0.2]], [[1, 0, 0.1], [0, 0, -0.1]]])
    assert tracks.clump_id.tolist() == [4, 9, 12]
    cut = tracks.until(0.1)
    assert cut.clump_id.tolist() == [4, 9] and np.all(np.isfinite(cut.position))
    velocity = np.arange(3 * 3 * 3, dtype=float).reshape(3, 3, 3)
    kept = TrackedClumps(tracks=tracks, velocity=velocity, mass=np.array([1.0, 2.0, 3.0])).until(0.1)
    assert kept.mass.tolist() == [1.0, 2.0]
    np.testing.assert_array_equal(kept.velocity, velocity[:2, :2])
    # the whole run of the part's clumps, in the part's order
    whole = tracks.of_clumps(cut.clump_id[::-1])
    assert whole.clump_id.tolist() == [9, 4] and whole.times.tolist() == [0.0, 0.1, 0.2]
    np.testing.assert_array_equal(whole.position, tracks.position[:, [1, 0]])
    with pytest.raises(ValueError, match=r"clump ids \[5\] are not clumps of the tracks"):
        tracks.of_clumps([4, 5])


def test_the_recirculating_part_is_the_frames_up_to_the_stop_of_the_re_entry(whole, result):
    cut = whole.until(T_STOP)
    assert cut.n_times == 1001 and cut.times[-1] == T_STOP and np.all(np.isfinite(cut.position))
    # measured on the recirculating part alone: 75 clumps over 10 crossings per second, Nr = 20 / 7.5
    timing = result.timing
    assert (timing.t_open, timing.t_end) == (0.0, T_STOP)
    assert timing.holdup == 75.0 and timing.throughput == pytest.approx(10.0, rel=1e-12)
    assert timing.residence_time == pytest.approx(7.5, rel=1e-12)
    assert timing.recirculations == pytest.approx(8.0 / 3.0, rel=1e-12)
    assert result.window == pytest.approx(0.5, rel=1e-8)


# --------------------------------------------------------------------------- vanished clumps


def test_a_clump_gone_at_the_channel_bottom_is_not_a_re_entry():
    # outlet at 0, domain -0.25 ... 0.75: clump 1 crosses at 0.5 s and is gone after its last frame low in the
    # channel; clump 2 crosses at 0.5 s too and re-enters at the top between 2.0 and 2.5 s
    times = [0.0, 1.0, 2.0, 2.5, 3.0]
    z1 = [0.1, -0.1, -0.24, None, None]
    z2 = [0.1, -0.1, -0.24, 0.7, 0.6]
    ids = [[1, 2] if z is not None else [2] for z in z1]
    positions = [[[0, 0, a], [0, 0, b]] if a is not None else [[0, 0, b]] for a, b in zip(z1, z2)]
    tracks = clump_tracks(times, ids, positions)
    events = recirculation_events(tracks, 0.0, -0.25, 0.75)
    assert events.pass_clump_id.tolist() == [1, 2, 2]  # one pass of clump 1: no re-entry
    np.testing.assert_allclose(events.entry_time, [np.nan, np.nan, 2.0 + 0.5 * 0.01 / 0.06], rtol=1e-12)
    np.testing.assert_allclose(events.exit_times_all, [0.5, 0.5], rtol=1e-12)  # each crossing once
    assert events.n_frames_absent.tolist() == [2, 0]


def test_the_conveyor_s_discharge_has_no_re_entry_and_every_clump_above_the_outlet_crosses_once(whole, discharge):
    events = recirculation_events(whole, OUTLET, BOTTOM, TOP)
    entry = events.entry_time[np.isfinite(events.entry_time)]
    assert entry.max() < T_STOP and discharge.reentries == 0
    after = events.exit_times_all > T_STOP
    np.testing.assert_array_equal(np.sort(events.exit_clump_index[after]), np.arange(25, 100))
    np.testing.assert_allclose(events.exit_times_all[after], 20.05 + 0.1 * np.arange(75), rtol=0, atol=1e-9)
    assert discharge.windows.crossings == 75


# --------------------------------------------------------------------------- windows and VRR in closed form


def test_twelve_clumps_one_per_window_give_the_vrr_in_closed_form():
    # one crossing per 1 s window from t_stop = 10 s, blue in windows 0, 3, 6, 9; a straggler at 24.5 s after the
    # flow has faded; a recirculating window held 2 clumps, so a window needs at least 1
    times = np.r_[10.5 + np.arange(12), 24.5]
    blue = np.r_[np.tile([True, False, False], 4), True]
    windows = flowing_windows(times, 10.0, 26.0, 1.0, 2.0)
    assert windows.n_windows == 12 and windows.n_total.tolist() == [1] * 12 and windows.clumps == 12
    assert windows.faded and windows.threshold == 1.0 and windows.end == 22.0 and windows.crossings == 13
    assert windows.left_out_fraction == pytest.approx(1.0 / 13.0, rel=1e-15)
    result = discharge_vrr(times, blue, 0.25, windows)
    np.testing.assert_array_equal(result.concentration, np.tile([1.0, 0.0, 0.0], 4))
    # var(c) = (1/3)(2/3) = 2/9, VRR = p (1 - p) / var(c) = 0.1875 / (2/9) = 27/32, error sqrt(2 / 11) VRR
    assert result.vrr == pytest.approx(27.0 / 32.0, rel=1e-14)
    assert result.sigma_out == pytest.approx(math.sqrt(2.0) / 3.0, rel=1e-14)
    assert result.vrr_error == pytest.approx(math.sqrt(2.0 / 11.0) * 27.0 / 32.0, rel=1e-14)
    # windows of one clump cannot show a VRR above 1: 27/32 >= 1 / 2 is at the ceiling, a lower bound
    assert result.ceiling == 1.0 and result.at_ceiling
    assert result.summary() == pytest.approx({
        "blue_fraction": 0.25, "vrr": result.vrr, "vrr_error": result.vrr_error, "sigma_out": result.sigma_out,
        "windows": 12, "clumps": 12, "left_out_fraction": 1.0 / 13.0, "vrr_ceiling": 1.0, "at_ceiling": True},
        rel=1e-14)


def test_windows_of_unequal_counts_take_the_harmonic_mean_for_the_ceiling_and_stop_where_the_flow_fades():
    # windows of 1 s from 0: 4 (1 blue), 2 (1 blue), 4 (3 blue), then 1 crossing < 0.5 x 4; the record ends at 5 s
    times = [0.1, 0.2, 0.3, 0.4, 1.5, 1.6, 2.1, 2.2, 2.3, 2.4, 3.5]
    blue = [1, 0, 0, 0, 1, 0, 1, 1, 1, 0, 1]
    windows = flowing_windows(times, 0.0, 5.0, 1.0, 4.0)
    assert windows.n_total.tolist() == [4, 2, 4] and windows.faded
    result = discharge_vrr(times, blue, 0.5, windows)
    c = np.array([0.25, 0.5, 0.75])
    assert result.vrr == pytest.approx(0.25 / np.var(c), rel=1e-14)  # 0.25 / (1/24) = 6
    assert result.ceiling == pytest.approx(3.0 / (1 / 4 + 1 / 2 + 1 / 4), rel=1e-15)  # harmonic mean 3
    assert result.at_ceiling  # 6 >= 3 / 2


def test_a_record_that_ends_before_the_flow_fades_and_a_crossing_on_an_edge():
    # two complete windows of 1 s in [0, 2.5] s, both full; 2.0 falls on the edge of the incomplete third window
    windows = flowing_windows([0.5, 1.0, 1.5, 2.0], 0.0, 2.5, 1.0, 2.0)
    assert windows.n_total.tolist() == [1, 2] and not windows.faded and windows.end == 2.0
    assert windows.left_out_fraction == pytest.approx(0.25, rel=1e-15)
    result = discharge_vrr([0.5, 1.0, 1.5, 2.0], [True, True, False, True], 0.5, windows)
    assert result.n_blue.tolist() == [1, 1] and result.concentration.tolist() == [1.0, 0.5]
    # a window ending on the record's last frame is complete; a crossing before the start is not counted
    assert flowing_windows([-0.5, 0.5, 1.5], 0.0, 2.0, 1.0, 1.0).n_total.tolist() == [1, 1]
    assert flowing_windows([-0.5, 0.5, 1.5], 0.0, 2.0, 1.0, 1.0).crossings == 2


def test_too_few_windows_give_no_vrr_and_bad_arguments_are_named():
    one = flowing_windows([0.5], 0.0, 1.0, 1.0, 1.0)
    result = discharge_vrr([0.5], [True], 0.5, one)
    assert one.n_windows == 1 and math.isnan(result.vrr) and math.isnan(result.vrr_error)
    assert not result.at_ceiling and result.ceiling == 1.0
    none = flowing_windows([0.5], 0.0, 0.5, 1.0, 1.0)  # shorter than a window
    empty = discharge_vrr([0.5], [True], 0.5, none)
    assert none.n_windows == 0 and none.end == 0.0 and none.left_out_fraction == 1.0
    assert math.isnan(empty.vrr) and math.isnan(empty.ceiling) and not empty.at_ceiling
    assert math.isnan(flowing_windows([], 0.0, 3.0, 1.0, 1.0).left_out_fraction)
    constant = flowing_windows([0.5, 1.5], 0.0, 2.0, 1.0, 1.0)
    assert discharge_vrr([0.5, 1.5], [True, True], 0.5, constant).vrr == math.inf
    for kwargs, message in (({"window": 0.0}, "window"), ({"reference_clumps": -1.0}, "reference_clumps"),
                            ({"fade_fraction": 0.0}, "fade_fraction"), ({"fade_fraction": 1.5}, "fade_fraction"),
                            ({"t_end": -1.0}, "t_end")):
        arguments = {"exit_times": [0.5], "t_start": 0.0, "t_end": 2.0, "window": 1.0, "reference_clumps": 1.0,
                     **kwargs}
        with pytest.raises(ValueError, match=message):
            flowing_windows(**arguments)
    with pytest.raises(ValueError, match="is_blue must have the shape"):
        discharge_vrr([0.5, 1.5], [True], 0.5, constant)
    with pytest.raises(ValueError, match="blue_fraction"):
        discharge_vrr([0.5, 1.5], [True, False], 1.0, constant)


# --------------------------------------------------------------------------- the conveyor's discharge


def test_the_conveyor_s_discharge_after_its_recirculations(discharge, result):
    assert discharge.start == T_STOP and discharge.recirculations == pytest.approx(8.0 / 3.0, rel=1e-12)
    windows = discharge.windows
    # 15 windows of 5 crossings, then none: faded, nothing left out
    assert windows.n_total.tolist() == [5] * 15 and windows.faded and windows.left_out_fraction == 0.0
    assert windows.threshold == pytest.approx(FADE_FRACTION * 5.0, rel=1e-8)
    assert windows.end == pytest.approx(T_STOP + 15 * result.window, rel=1e-15)
    # bottom half: clumps 0 ... 49 blue; 25 ... 49 leave first (5 windows of c = 1), then 50 ... 99 (10 of c = 0):
    # var(c) = (1/3)(2/3), VRR = 0.25 / (2/9) = 9/8 over N = 15 windows
    half = discharge.layouts["bottom half"]
    np.testing.assert_array_equal(half.concentration, np.r_[np.ones(5), np.zeros(10)])
    assert half.vrr == pytest.approx(9.0 / 8.0, rel=1e-14)
    assert half.vrr_error == pytest.approx(math.sqrt(2.0 / 14.0) * 9.0 / 8.0, rel=1e-14)
    assert half.ceiling == pytest.approx(5.0, rel=1e-15) and not half.at_ceiling
    # every layout: its colours of clumps 25 ... 99 in that order, 5 to a window
    for layout in LAYOUTS:
        colours = layer_colours(Z0, layout.blue_fraction, layout.sublayers, layout.blue_at)
        c = colours[25:].reshape(15, 5).mean(axis=1)
        p = layout.blue_fraction
        assert discharge.layouts[layout.name].vrr == pytest.approx(p * (1 - p) / np.var(c), rel=1e-12)
    assert list(discharge.layouts) == [layout.name for layout in LAYOUTS]


def test_the_discharge_goes_into_the_blending_summary_and_the_summary_table(tmp_path, result, discharge):
    run = {"run_id": "r1", "flow_pattern": "internal_flow", "estimated_residence_time": 7.5,
           "nominal_residence_time": 3.75}
    without = blending_summary(result, result.rtd.silo, 0.01, **run)
    assert "final_discharge" not in without
    written = json.loads(write_json(tmp_path / "blending.json", blending_summary(
        result, result.rtd.silo, 0.01, **run, final_discharge=discharge)).read_text())
    stored = written["final_discharge"]
    assert {key: stored[key] for key in ("recirculations", "start_s", "faded", "crossings", "reentries",
                                         "fade_fraction")} == pytest.approx(
        {"recirculations": 8.0 / 3.0, "start_s": 20.0, "faded": True, "crossings": 75, "reentries": 0,
         "fade_fraction": 0.5})
    assert stored["end_s"] == pytest.approx(27.5, rel=1e-8) and stored["window_s"] == pytest.approx(0.5, rel=1e-8)
    assert stored["reference_clumps_per_window"] == pytest.approx(5.0, rel=1e-8)
    assert stored["threshold_clumps"] == pytest.approx(2.5, rel=1e-8)
    half = stored["layouts"]["bottom half"]
    assert half == pytest.approx({"blue_fraction": 0.5, "vrr": 1.125, "vrr_error": math.sqrt(1.0 / 7.0) * 1.125,
                                  "sigma_out": math.sqrt(2.0) / 3.0, "windows": 15, "clumps": 75,
                                  "left_out_fraction": 0.0, "vrr_ceiling": 5.0, "at_ceiling": False}, rel=1e-12)
    assert {key for key in written if key != "final_discharge"} == set(json.loads(json.dumps(without, default=str)))
    rows, _ = summary_rows([written])
    assert rows[0]["final_discharge_vrr"] == pytest.approx(1.125, rel=1e-12)
    assert rows[0]["final_discharge_recirculations"] == pytest.approx(8.0 / 3.0, rel=1e-12)
    assert rows[0]["final_discharge_vrr_at_ceiling"] is False


def test_final_discharge_refuses_a_stop_outside_the_record_and_other_clumps(whole, result):
    for t_stop in (0.0, 30.0, math.nan):
        with pytest.raises(ValueError, match="t_stop"):
            final_discharge(whole, result, t_stop, BOTTOM, TOP, outlet_z=OUTLET)
    fewer = ClumpTracks(times=whole.times, clump_id=whole.clump_id[:50], position=whole.position[:, :50])
    with pytest.raises(ValueError, match="colours 100 clumps, the tracks hold 50"):
        final_discharge(fewer, result, T_STOP, BOTTOM, TOP, outlet_z=OUTLET)
