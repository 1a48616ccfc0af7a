"""Little's law for the clumps that pass through the recirculating silo, and the stagnant rest of its holdup.

Pure functions on the tracks and events of :mod:`siloflow.analysis.studies.silo_recirculation.tracks`; no file I/O. SI
units: times in s, rates in 1/s, counts in clumps.

Two figures, one control volume
-------------------------------
Both figures of the study count the silo as everything above the outlet plane, with a pass entering at its
re-entry at the top of the periodic domain (so the free fall onto the pile is inside) and leaving at its first
outlet crossing:

- the **holdup residence time** ``t_res = H / Q`` (``residence_time_s``,
  :func:`siloflow.analysis.studies.silo_recirculation.vrr.littles_law`) divides every clump above the outlet by the
  throughput. In steady state it is the mean residence time of all entering clumps, *including* the few that
  settle into the stagnant zones of a flat-bottom silo and stay there far longer than a run (its turnover time,
  or space time; the recirculation number ``Nr`` counts in it);
- the **tracer RTD mean** ``t_m`` averages the tracer passes that left before the end of the run: a censored
  mean, blind to the slow passes.

With stagnant zones the two differ by the holdup of the slow clumps over the throughput (in the 4 s default
runs about 40 % of the clumps above the outlet never left: 860 of 2,196 in internal flow, 781 of 1,787 in
semi-mass flow, so ``t_res`` is about twice ``t_m``). The figures are reconciled on the same
clumps by a horizon ``h`` (:func:`transit_littles_law`): over frames in ``[t_open + h, t_end - h]`` every pass
lasting at most ``h`` that is in progress has a known entry and exit, so the *transit holdup* (passes in
progress with ``exit - entry <= h``) over the *transit throughput* (their exits) is, by Little's law,
``E[t | t <= h]``, the mean the tracer gives when its residence times are cut at the same ``h``
(:func:`siloflow.analysis.numerics.residence_statistics.mean_residence_time_within`). The rest of the holdup
(``slow_holdup``) is the stagnant and slowly creeping material: ``t_res = f t_transit + H_slow / Q`` with ``f``
the fraction of the throughput that passes within ``h``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, finite_number, increasing_times, integer_at_least, positive_number
from siloflow.analysis.numerics.uncertainty import Estimate, batch_means, proportion_error
from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.studies.silo_recirculation.tracks import RecirculationEvents, above_outlet
from siloflow.analysis.studies.silo_recirculation.validation import event_times
from siloflow.analysis.studies.silo_recirculation.vrr import LittlesLaw, littles_law

__all__ = [
    "TransitLittlesLaw",
    "passes_in_progress",
    "transit_horizon",
    "transit_littles_law",
    "stagnant_clumps",
]


@dataclass(frozen=True, eq=False)
class TransitLittlesLaw:
    """Little's law on the passes lasting at most a horizon, and the holdup of the slower rest.

    Attributes
    ----------
    horizon : float
        Longest residence time counted as transit ``h`` [s].
    t_from, t_to : float
        The window of frames and exits, ``[max(t_start, t_open + h), t_end - h]`` [s].
    transit : LittlesLaw
        Holdup of the passes in progress lasting at most ``h`` [-], the throughput of their exits [1/s] and the
        ratio, their mean residence time ``E[t | t <= h]`` [s], each with its standard error.
    whole : LittlesLaw
        The same for every clump above the outlet and every crossing, over the same window: the holdup
        residence time ``t_res`` [s] of that window.
    transit_fraction : Estimate
        Transit crossings over all crossings in the window, ``f`` [-]; binomial error.
    slow_holdup : Estimate
        Mean of ``whole - transit`` holdup over the frames: clumps above the outlet on passes longer than ``h``
        (stagnant zones and slow creep) [-]; batch-means error (NaN with fewer than ``2 n_batches`` frames).
    stagnant_clumps : int
        Clumps above the outlet in every frame of the run: those that never left the silo [-].
    """

    horizon: float
    t_from: float
    t_to: float
    transit: LittlesLaw
    whole: LittlesLaw
    transit_fraction: Estimate
    slow_holdup: Estimate
    stagnant_clumps: int


def passes_in_progress(frame_times, entry_time, exit_time) -> np.ndarray:
    """Number of passes in progress at each frame, ``entry <= t < exit`` [-].

    The holdup that Little's law relates to these passes: the time integral of the count is the sum of the
    passes' residence times inside the frames' span.

    Parameters
    ----------
    frame_times : array_like, shape (n_t,)
        Frame times, strictly increasing [s].
    entry_time, exit_time : array_like, shape (n_p,)
        Entry and exit of each pass, finite, ``exit >= entry`` [s].

    Returns
    -------
    numpy.ndarray of int64, shape (n_t,)

    Raises
    ------
    ValueError
        On times not strictly increasing, passes of unequal length, non-finite times or an exit before its
        entry.
    """
    times = increasing_times("frame_times", frame_times)
    entry = finite_array("entry_time", entry_time, ndim=1)
    exit_ = finite_array("exit_time", exit_time, ndim=1)
    if entry.shape != exit_.shape:
        raise ValueError(f"exit_time must have the shape of entry_time {entry.shape}, got {exit_.shape}")
    if np.any(exit_ < entry):
        raise ValueError("exit_time must not precede entry_time")
    # +1 from the first frame at or after the entry, -1 from the first frame at or after the exit
    steps = np.zeros(times.size + 1, dtype=np.int64)
    np.add.at(steps, np.searchsorted(times, entry, side="left"), 1)
    np.add.at(steps, np.searchsorted(times, exit_, side="left"), -1)
    return np.cumsum(steps[:-1])


def stagnant_clumps(tracks: ClumpTracks, outlet_z: float = 0.0) -> int:
    """Clumps above the outlet plane in every frame: the part of the fill that never left in the run [-].

    A clump absent from a frame is not counted (it cannot be shown to have stayed).
    """
    return _always_above(above_outlet(tracks, outlet_z))


def _always_above(above: np.ndarray) -> int:
    """Clumps above the outlet in every frame of an :func:`above_outlet` mask [-]."""
    return int(np.count_nonzero(above.all(axis=0)))


def transit_horizon(t_open: float, t_end: float, tracer_entry_time, fraction: float = 1.0 / 3.0) -> float:
    """The longest horizon ``h`` both Little's law and the tracer can use: ``min(fraction (t_end - t_open),
    t_end - last tracer entry)`` [s].

    Little's law on the passes lasting at most ``h`` needs the frames in ``[t_open + h, t_end - h]``, so a
    third of the run leaves a third of it as the window; the tracer's residence times cut at ``h`` are not
    censored only when every tracer was followed for ``h``.

    Parameters
    ----------
    t_open, t_end : float
        First and last frame [s], ``t_end > t_open``.
    tracer_entry_time : array_like, shape (n,)
        Entry times of the tracer passes, finite, at most ``t_end`` [s].
    fraction : float, optional
        Part of the run taken as the horizon, in (0, 0.5) [-].

    Returns
    -------
    float
        ``h`` [s], > 0.

    Raises
    ------
    ValueError
        On a bad window or fraction, no tracer, or a tracer entering at the last frame.
    """
    t_open = finite_number("t_open", t_open)
    t_end = finite_number("t_end", t_end)
    if not t_end > t_open:
        raise ValueError(f"t_end must be > t_open = {t_open!r} s, got {t_end!r}")
    fraction = float(fraction)
    if not 0.0 < fraction < 0.5:
        raise ValueError(f"fraction must be a number in (0, 0.5), got {fraction!r}")
    entries = finite_array("tracer_entry_time", tracer_entry_time, ndim=1)
    if entries.size == 0:
        raise ValueError("tracer_entry_time must not be empty")
    followed = t_end - float(entries.max())
    if not followed > 0.0:
        raise ValueError(f"tracer_entry_time: a tracer enters at or after the last frame ({t_end!r} s)")
    return min(fraction * (t_end - t_open), followed)


def transit_littles_law(tracks: ClumpTracks, events: RecirculationEvents, horizon: float, t_start: float,
                        outlet_z: float = 0.0, n_batches: int = 10) -> TransitLittlesLaw:
    """Little's law on the passes lasting at most ``horizon``, beside the whole holdup (see the module docstring).

    Window: frames and crossings in ``[t_from, t_to] = [max(t_start, t_open + h), t_end - h]``. Any pass in
    progress at a frame of the window that lasts at most ``h`` entered after ``t_open`` and leaves before
    ``t_end``, so it is complete in the events; the initial contents (no known entry) and passes still inside
    at the end can then only be longer than ``h``. Transit holdup: :func:`passes_in_progress` of the passes
    with ``exit - entry <= h``; transit throughput: their exits. Both go through
    :func:`siloflow.analysis.studies.silo_recirculation.vrr.littles_law` (batch means and batch rates, ``n_batches``),
    and so does the whole holdup (:func:`siloflow.analysis.studies.silo_recirculation.tracks.clumps_above_outlet`) with
    every crossing.

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres [m].
    events : RecirculationEvents
        Their events (:func:`siloflow.analysis.studies.silo_recirculation.tracks.recirculation_events`).
    horizon : float
        ``h`` [s], > 0 (e.g. :func:`transit_horizon`).
    t_start : float
        Start of the steady part of the run [s].
    outlet_z : float, optional
        Height of the outlet plane [m].
    n_batches : int, optional
        Batches of the errors, >= 2.

    Returns
    -------
    TransitLittlesLaw

    Raises
    ------
    ValueError
        On a window with fewer than 2 frames, no crossing in it, or bad arguments.
    """
    h = positive_number("horizon", horizon)
    t_start = finite_number("t_start", t_start)
    n_batches = integer_at_least("n_batches", n_batches, 2)
    times = finite_array("tracks.times", tracks.times, ndim=1)
    t_from = max(t_start, float(times[0]) + h)
    t_to = float(times[-1]) - h
    in_window = (times >= t_from) & (times <= t_to)
    if np.count_nonzero(in_window) < 2:
        raise ValueError(
            f"horizon {h!r} s leaves fewer than 2 frames in [{t_from!r}, {t_to!r}] s; shorten it or run longer"
        )
    entry = event_times("events.entry_time", events.entry_time)
    exit_ = event_times("events.exit_time", events.exit_time)
    residence = exit_ - entry
    short = np.isfinite(residence) & (residence <= h)
    transit_holdup = passes_in_progress(times, entry[short], exit_[short])[in_window]
    above = above_outlet(tracks, outlet_z)  # one pass over the tracks for the whole holdup and the stagnant clumps
    whole_holdup = np.count_nonzero(above[in_window], axis=1)
    frames = times[in_window]
    transit = littles_law(frames, transit_holdup, exit_[short], t_from, t_to, n_batches)
    crossings = event_times("events.exit_times_all", events.exit_times_all)
    whole = littles_law(frames, whole_holdup, crossings, t_from, t_to, n_batches)
    k = int(np.count_nonzero((exit_[short] >= t_from) & (exit_[short] <= t_to)))
    n = int(np.count_nonzero((crossings >= t_from) & (crossings <= t_to)))
    fraction = Estimate(value=k / n, std_error=proportion_error(k, n), n=n, method="binomial")
    slow = (whole_holdup - transit_holdup).astype(float)
    # the value over every frame, as littles_law takes both holdups, so that whole = transit + slow exactly
    slow_error = batch_means(slow, n_batches).std_error if slow.size >= 2 * n_batches else math.nan
    slow_holdup = Estimate(value=float(slow.mean()), std_error=slow_error, n=n_batches, method="batch means",
                           dof=n_batches - 1)
    return TransitLittlesLaw(horizon=h, t_from=t_from, t_to=t_to, transit=transit, whole=whole,
                             transit_fraction=fraction, slow_holdup=slow_holdup,
                             stagnant_clumps=_always_above(above))
