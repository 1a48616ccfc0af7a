"""Little's law on hand-built steady loops: the holdup residence time, the tracer's mean and the transit figures.

The loop (:func:`loop_tracks`): a domain periodic in z from -0.1 to 0.1 m with the outlet at 0, so a clump
moving down at a constant speed spends half its loop above the outlet. A *path* ``(W, N)`` is ``N`` clumps
moving at ``0.1 / W`` m/s, so ``W`` s above the outlet per pass and ``2 W`` s per loop, spaced evenly along
it (``2 W / N`` s apart, the first ``0.0025`` s past a re-entry at t = 0, so that no event falls on a frame).
Every path below has a spacing that divides 0.05 s and windows that start and end a multiple of 0.05 s from
the events, so counts are exact:

- path holdup above the outlet: ``N / 2`` at every frame; path throughput ``N / (2 W)`` per second; every pass
  lasts exactly ``W`` (linear motion, so the interpolated events are exact);
- stagnant clumps sit at z = 0.05 m all run: they add to the holdup, never to the throughput.

Hence, with paths ``(W_p, N_p)`` and ``S`` stagnant clumps, ``holdup = sum N_p / 2 + S``, ``throughput =
sum N_p / (2 W_p)``, the flux-weighted mean residence time of the entering clumps ``sum (N_p / 2) / throughput``
and the holdup residence time ``holdup / throughput`` (larger by ``S / throughput``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.residence_statistics import mean_residence_time
from siloflow.analysis.studies.silo_recirculation.study import loop_timing, transit_timing
from siloflow.analysis.studies.silo_recirculation.tracers import tracer_passes
from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events
from siloflow.analysis.studies.silo_recirculation.transit import (
    passes_in_progress,
    stagnant_clumps,
    transit_horizon,
    transit_littles_law,
)

BOTTOM, OUTLET, TOP = -0.1, 0.0, 0.1
FRAME_STEP = 0.01
OFFSET = 0.0025  # first re-entry of every path: a quarter frame past t = 0


def loop_tracks(paths, stagnant: int = 0, t_end: float = 9.0) -> ClumpTracks:
    """Clump tracks of steady paths ``(W, N)`` and ``stagnant`` clumps at rest (see the module docstring)."""
    times = np.arange(int(round(t_end / FRAME_STEP)) + 1) * FRAME_STEP
    columns = []
    for above, n in paths:
        loop = 2.0 * above
        speed = (TOP - OUTLET) / above
        for i in range(n):
            since_entry = np.mod(times - OFFSET - i * loop / n, loop)
            columns.append(TOP - speed * since_entry)
    columns += [np.full(times.size, 0.05)] * stagnant
    z = np.stack(columns, axis=1)
    position = np.zeros(z.shape + (3,))
    position[:, :, 2] = z
    return ClumpTracks(times=times, clump_id=np.arange(z.shape[1]), position=position)


def analysed(paths, stagnant):
    tracks = loop_tracks(paths, stagnant)
    events = recirculation_events(tracks, OUTLET, BOTTOM, TOP)
    # a steady part from 1 s: 8 s of the 9 s run, a whole number of spacings (0.05 s) long
    timing = loop_timing(tracks, events, OUTLET, startup_fraction=1.0 / 9.0)
    return tracks, events, timing


# (paths, stagnant, holdup, throughput, flux-weighted mean residence time of the entering clumps)
LOOPS = {
    # plug flow: every clump 0.5 s above the outlet, 10 of the 20 there at every frame, 20 crossings per second
    "plug flow": ([(0.5, 20)], 0, 10.0, 20.0, 0.5),
    # three paths of equal flux, 0.25, 0.5 and 1 s: a spread RTD with mean (0.25 + 0.5 + 1) / 3
    "spread": ([(0.25, 10), (0.5, 20), (1.0, 40)], 0, 35.0, 60.0, 1.75 / 3.0),
    # plug flow beside a slow path (4 s above the outlet, 2 crossings per second) and 5 stagnant clumps
    "slow path and dead zone": ([(0.5, 20), (4.0, 16)], 5, 23.0, 22.0, 18.0 / 22.0),
}


@pytest.mark.parametrize("name", LOOPS)
def test_holdup_residence_time_and_tracer_mean_obey_littles_law(name):
    paths, stagnant, holdup, throughput, mean_residence = LOOPS[name]
    tracks, events, timing = analysed(paths, stagnant)
    assert timing.holdup == holdup
    assert timing.throughput == pytest.approx(throughput, rel=1e-12)
    assert timing.residence_time == pytest.approx(holdup / throughput, rel=1e-12)
    # the tracer: every pass entering in one spacing-aligned second from t = 1 s, a flux-weighted sample
    tracer = tracer_passes(events, 1.0, int(round(throughput)))
    assert tracer.n_exited == tracer.n_tracer
    tracer_mean = mean_residence_time(tracer.residence_time)
    assert tracer_mean.value == pytest.approx(mean_residence, rel=1e-12)
    # Little's law closes on the clumps that pass through; the stagnant ones are the whole difference
    assert (timing.holdup - stagnant) / timing.throughput == pytest.approx(tracer_mean.value, rel=1e-12)
    assert timing.residence_time - tracer_mean.value == pytest.approx(stagnant / throughput, rel=1e-9)


def test_transit_timing_splits_the_holdup_into_transit_and_slow_clumps():
    paths, stagnant, holdup, throughput, _ = LOOPS["slow path and dead zone"]
    tracks, events, timing = analysed(paths, stagnant)
    tracer = tracer_passes(events, 1.0, 22)  # 20 fast and 2 slow passes, all out by the end of the run
    little, tracer_mean = transit_timing(tracks, events, timing, tracer)
    # horizon: a third of the 9 s run (the tracer was followed for 9 - 1.9525 s); window [3, 6] s
    assert little.horizon == 3.0
    assert (little.t_from, little.t_to) == (3.0, 6.0)
    # only the fast path passes within 3 s: 10 clumps in transit, 20 crossings per second, 0.5 s each
    assert little.transit.holdup.value == 10.0
    assert little.transit.throughput.value == pytest.approx(20.0, rel=1e-12)
    assert little.transit.residence_time.value == pytest.approx(0.5, rel=1e-12)
    # ... and the tracer's residence times up to the same horizon: the same clumps, the same mean
    assert tracer_mean.value == pytest.approx(0.5, rel=1e-12)
    # its error is that of one cohort: the spread over the 5 whole cohorts of 22 passes entering in [1, 6] s (22
    # per second), all alike on these periodic paths
    assert (tracer_mean.method, tracer_mean.n) == ("cohort spread", 5)
    assert tracer_mean.std_error == pytest.approx(0.0, abs=1e-12)
    # the whole holdup over the same window, and its slow rest: 8 on the slow path and the 5 stagnant clumps
    assert little.whole.holdup.value == holdup
    assert little.whole.throughput.value == pytest.approx(throughput, rel=1e-12)
    assert little.transit_fraction.value == pytest.approx(20.0 / 22.0, rel=1e-12)
    assert little.transit_fraction.std_error == pytest.approx(math.sqrt((10 / 11) * (1 / 11) / 66), rel=1e-12)
    assert (little.slow_holdup.value, little.slow_holdup.std_error) == (13.0, 0.0)
    assert little.stagnant_clumps == 5
    # t_res = f t_transit + H_slow / Q
    assert little.whole.residence_time.value == pytest.approx(
        little.transit_fraction.value * little.transit.residence_time.value
        + little.slow_holdup.value / little.whole.throughput.value, rel=1e-12)
    # constant holdups: the residence times' errors are the throughputs' relative errors
    for law in (little.transit, little.whole):
        relative = law.throughput.std_error / law.throughput.value
        assert law.holdup.std_error == 0.0
        assert law.residence_time.std_error == pytest.approx(law.residence_time.value * relative, rel=1e-12)


@pytest.mark.parametrize("name", ["plug flow", "spread"])
def test_without_slow_clumps_the_transit_time_is_the_holdup_residence_time(name):
    paths, _, holdup, throughput, mean_residence = LOOPS[name]
    tracks, events, timing = analysed(paths, 0)
    tracer = tracer_passes(events, 1.0, int(round(throughput)))
    little, tracer_mean = transit_timing(tracks, events, timing, tracer)
    assert little.transit.holdup.value == little.whole.holdup.value == holdup
    assert little.transit.residence_time.value == pytest.approx(timing.residence_time, rel=1e-12)
    assert tracer_mean.value == pytest.approx(mean_residence, rel=1e-12)
    assert (little.transit_fraction.value, little.slow_holdup.value, little.stagnant_clumps) == (1.0, 0.0, 0)


def test_transit_timing_starts_where_the_steady_part_of_the_timing_does():
    tracks = loop_tracks(*LOOPS["plug flow"][:2])
    events = recirculation_events(tracks, OUTLET, BOTTOM, TOP)
    timing = loop_timing(tracks, events, OUTLET, startup_fraction=0.5)
    assert timing.steady_start == 4.5
    little, _ = transit_timing(tracks, events, timing, tracer_passes(events, 1.0, 20))
    # horizon 3 s: the window starts at the steady part (4.5 s), later than t_open + h
    assert (little.horizon, little.t_from, little.t_to) == (3.0, 4.5, 6.0)


def test_passes_in_progress_counts_entry_inclusive_exit_exclusive():
    times = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    # passes [0.5, 2.5), [1.0, 1.0) (no time inside), [1.0, 3.0) and [3.5, 10)
    counts = passes_in_progress(times, [0.5, 1.0, 1.0, 3.5], [2.5, 1.0, 3.0, 10.0])
    np.testing.assert_array_equal(counts, [0, 2, 2, 0, 1])
    np.testing.assert_array_equal(passes_in_progress(times, [], []), [0, 0, 0, 0, 0])


@pytest.mark.parametrize("times, entry, exit_, message", [
    ([0.0, 0.0], [0.0], [1.0], "strictly increasing"),
    ([0.0, 1.0], [0.0, 1.0], [1.0], "shape"),
    ([0.0, 1.0], [1.0], [0.5], "precede"),
    ([0.0, 1.0], [np.nan], [1.0], "entry_time"),
])
def test_passes_in_progress_rejects_bad_input(times, entry, exit_, message):
    with pytest.raises(ValueError, match=message):
        passes_in_progress(times, entry, exit_)


def test_stagnant_clumps_are_those_above_the_outlet_in_every_frame():
    position = np.zeros((3, 4, 3))
    position[:, :, 2] = [[0.1, 0.1, -0.1, 0.1], [0.2, 0.1, 0.1, 0.1], [0.1, -0.0, 0.1, 0.1]]
    position[1, 3] = np.nan  # absent once: not shown to have stayed
    tracks = ClumpTracks(times=np.array([0.0, 1.0, 2.0]), clump_id=np.arange(4), position=position)
    assert stagnant_clumps(tracks, 0.0) == 1


def test_transit_horizon_is_a_third_of_the_run_or_the_time_the_tracer_was_followed():
    assert transit_horizon(0.0, 9.0, [1.0, 2.0]) == 3.0
    assert transit_horizon(0.0, 9.0, [1.0, 7.5]) == 1.5
    assert transit_horizon(1.0, 5.0, [2.0], fraction=0.25) == 1.0


@pytest.mark.parametrize("args, message", [
    ((1.0, 1.0, [0.5]), "t_end"),
    ((0.0, 9.0, []), "empty"),
    ((0.0, 9.0, [9.0]), "last frame"),
    ((0.0, 9.0, [1.0], 0.5), "fraction"),
])
def test_transit_horizon_rejects_bad_input(args, message):
    with pytest.raises(ValueError, match=message):
        transit_horizon(*args)


def test_transit_littles_law_needs_frames_in_its_window():
    tracks, events, _ = analysed([(0.5, 20)], 0)
    with pytest.raises(ValueError, match="fewer than 2 frames"):
        transit_littles_law(tracks, events, 4.5, 1.0)
