"""The blending study of one recirculation run, composed from the modules of
:mod:`siloflow.analysis.studies.silo_recirculation` (tracks, concentration, vrr, tracers), :mod:`siloflow.analysis.numerics.rtd`,
:mod:`siloflow.analysis.numerics.lti` and :mod:`siloflow.analysis.numerics.eulerian_rtd`.

Pure computation on arrays; the workflow scripts read the tracks and write tables and plots. SI units.

Steps (thesis ch. 6):

1. Events: re-entries at the top and outlet crossings of every clump
   (:func:`siloflow.analysis.studies.silo_recirculation.tracks.recirculation_events`);
   the holdup residence time ``t_res`` = holdup / throughput over the steady part of the run (after the first
   ``startup_fraction`` of it). It counts every clump above the outlet, the stagnant zones included: the
   turnover time of the contents, in which ``Nr`` is counted, and not the mean of a tracer that can leave
   within the run (step 5).
2. Direct measurement, per batch layout: colours from the heights at the opening, outlet concentration in windows
   of ``window_fraction t_res``, ``Nr = (t - t_open) / t_res``, VRR per recirculation, and the first-exit
   concentration of the initial contents.
3. RTD from particle ids: a tracer of ``tracer_fraction`` of the holdup, the first passes re-entering after
   ``Nr = tracer_start``; ``E(t)``, moments, ``t_s / t_d``. The loop RTD (outlet to outlet) of the same passes
   feeds the LTI prediction.
4. LTI: the direct concentration against the renewal (Carson and Royal) prediction from the first-exit
   concentration with the measured loop RTD; continuous mode (sine and square VRR against period), discontinuous
   mode (layered batch fed over one t_res and recirculated), and Johanson's triangular RTD fitted to the first
   appearance and the mode of the measured one.
5. Little's law on the same clumps as the tracer
   (:func:`siloflow.analysis.studies.silo_recirculation.transit.transit_littles_law`): over a horizon ``h`` (a third of
   the run, :func:`siloflow.analysis.studies.silo_recirculation.transit.transit_horizon`) the holdup of the passes lasting
   at most ``h`` over their throughput against the tracer's mean of its residence times up to ``h``
   (:func:`siloflow.analysis.numerics.residence_statistics.mean_residence_time_within`); the holdup of the slower rest
   (stagnant zones) is what makes ``t_res`` exceed the tracer's ``t_m``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.numerics.eulerian_rtd import eulerian_residence_times, silo_bins
from siloflow.analysis.numerics.lti import VRRTable, recirculate, recirculations_to_homogenise, vrr_versus_period
from siloflow.analysis.numerics.rtd import RTD, johanson_rtd, rtd_from_exit_times
from siloflow.analysis.numerics.residence_statistics import cohort_means_within, mean_residence_time, mean_residence_time_within
from siloflow.analysis.numerics.uncertainty import Estimate
from siloflow.analysis.numerics.vrr_noise import window_duration_for_precision
from siloflow.analysis.studies.silo_recirculation.concentration import (
    OutletConcentration,
    batch_inlet_signal,
    first_pass_concentration,
    layer_colours,
    outlet_concentration,
    predicted_concentration_from_first_pass,
)
from siloflow.analysis.studies.silo_recirculation.tracers import TracerPasses, tracer_passes
from siloflow.analysis.studies.silo_recirculation.transit import TransitLittlesLaw, transit_horizon, transit_littles_law
from siloflow.analysis.studies.silo_recirculation.tracks import RecirculationEvents, clumps_above_outlet, recirculation_events
from siloflow.analysis.studies.silo_recirculation.vrr import (
    RecirculationVRR,
    littles_law,
    recirculation_number,
    vrr_by_recirculation,
)


@dataclass(frozen=True)
class Layout:
    """A batch colouring: blue fraction, number of blue sub-layers and where the first one lies."""

    name: str
    blue_fraction: float
    sublayers: int = 1
    blue_at: str = "bottom"


#: Part of the run, from the outlet opening, left out of every steady-state figure [-].
STARTUP_FRACTION = 0.1


@dataclass(frozen=True, eq=False)
class LoopTiming:
    """Steady-state timing of a recirculation run.

    Attributes
    ----------
    t_open, t_end : float
        First and last frame (outlet opening, end of run) [s].
    residence_time : float
        Holdup over throughput in the steady part [s]: the holdup residence time of everything above the outlet,
        stagnant zones included (the turnover time; the mean residence time of the clumps that pass through is
        :attr:`BlendingResult.transit`).
    holdup : float
        Mean number of clumps above the outlet plane in the steady part [-].
    throughput : float
        Outlet crossings per second in the steady part [1/s].
    recirculations : float
        ``(t_end - t_open) / t_res``: recirculations the run covers [-].
    residence_time_error, holdup_error, throughput_error : float
        Standard errors of ``residence_time`` [s], ``holdup`` [-] and ``throughput`` [1/s]
        (:func:`siloflow.analysis.studies.silo_recirculation.vrr.littles_law`); NaN when not known.
    frame_interval : float
        Median time between the saved frames of the steady part [s], the time resolution of every event;
        NaN when not known.
    startup_fraction : float
        Part of the run, from ``t_open``, left out of the steady part [-] (:attr:`steady_start`).
    """

    t_open: float
    t_end: float
    residence_time: float
    holdup: float
    throughput: float
    recirculations: float
    residence_time_error: float = math.nan
    holdup_error: float = math.nan
    throughput_error: float = math.nan
    frame_interval: float = math.nan
    startup_fraction: float = STARTUP_FRACTION

    @property
    def steady_start(self) -> float:
        """Start of the steady part, ``t_open + startup_fraction (t_end - t_open)`` [s]."""
        return self.t_open + self.startup_fraction * (self.t_end - self.t_open)


@dataclass(frozen=True, eq=False)
class LayoutResult:
    """Direct measurement and LTI prediction of one batch layout."""

    layout: Layout
    colours: np.ndarray
    concentration: OutletConcentration
    first_pass: OutletConcentration
    predicted: np.ndarray
    predicted_johanson: np.ndarray
    vrr: RecirculationVRR
    vrr_predicted: RecirculationVRR
    homogenised_after: float
    model_time_nr: np.ndarray
    model_concentration: np.ndarray
    model_homogenised_after: float
    recirculation_number: np.ndarray

    def prediction_rms_error(self) -> float:
        """RMS difference between the predicted and the measured concentration over the windows with data [-]."""
        measured = self.concentration.concentration
        valid = np.isfinite(measured)
        return float(np.sqrt(np.mean((self.predicted[valid] - measured[valid]) ** 2))) if valid.any() else math.nan


@dataclass(frozen=True, eq=False)
class ParticleRTD:
    """RTD from particle ids: the tracer's silo RTD (re-entry to outlet), and the large steady samples of passes
    (``steady``: re-entry to outlet, ``loop``: outlet to outlet) that feed the LTI models, with the kernels
    tabulated once on the concentration windows: the loop RTD, the silo RTD, and Johanson's triangle shifted by
    the channel-and-fall lag."""

    tracer: TracerPasses
    silo: RTD
    loop: TracerPasses
    loop_E_on_windows: np.ndarray
    start_time: float
    n_tracer: int
    johanson_V1: float
    johanson_P: float
    steady: TracerPasses
    silo_E_on_windows: np.ndarray
    johanson_loop_E_on_windows: np.ndarray


@dataclass(frozen=True, eq=False)
class BlendingResult:
    """Everything measured and predicted for one recirculation run.

    ``transit`` is Little's law on the passes lasting at most its horizon and ``tracer_transit_mean`` the
    tracer's mean residence time up to the same horizon [s]: the two agree, while ``timing.residence_time``
    also counts the stagnant clumps (``transit.slow_holdup``). None when not computed.
    """

    timing: LoopTiming
    events: RecirculationEvents
    window: float
    rtd: ParticleRTD
    layouts: list[LayoutResult] = field(default_factory=list)
    vrr_sine: VRRTable | None = None
    vrr_square: VRRTable | None = None
    transit: TransitLittlesLaw | None = None
    tracer_transit_mean: Estimate | None = None


def loop_timing(tracks: ClumpTracks, events: RecirculationEvents, outlet_z: float = 0.0,
                startup_fraction: float = STARTUP_FRACTION, n_batches: int = 10) -> LoopTiming:
    """Holdup, throughput and holdup residence time over the run after its first ``startup_fraction``, with their
    standard errors from ``n_batches`` batches of that steady part
    (:func:`siloflow.analysis.studies.silo_recirculation.vrr.littles_law`), and the frame interval.

    The holdup is every clump above the outlet, so with stagnant zones the residence time exceeds the mean of a
    tracer that leaves within the run (see :func:`transit_timing`)."""
    if not 0.0 <= startup_fraction < 1.0:
        raise ValueError(f"startup_fraction must be in [0, 1), got {startup_fraction!r}")
    times = tracks.times
    t_open, t_end = float(times[0]), float(times[-1])
    t_start = t_open + startup_fraction * (t_end - t_open)
    steady = times >= t_start
    holdup_counts = clumps_above_outlet(tracks, outlet_z)[steady]
    exits = np.asarray(events.exit_times_all, dtype=float)
    little = littles_law(times[steady], holdup_counts, exits, t_start, t_end, n_batches)
    t_res = little.residence_time.value
    # the median, as the first interval (the outlet opening) may be cut short
    frame_interval = float(np.median(np.diff(times[steady]))) if np.count_nonzero(steady) > 1 else math.nan
    return LoopTiming(
        t_open=t_open,
        t_end=t_end,
        residence_time=t_res,
        holdup=little.holdup.value,
        throughput=little.throughput.value,
        recirculations=(t_end - t_open) / t_res,
        residence_time_error=little.residence_time.std_error,
        holdup_error=little.holdup.std_error,
        throughput_error=little.throughput.std_error,
        frame_interval=frame_interval,
        startup_fraction=startup_fraction,
    )


def transit_timing(tracks: ClumpTracks, events: RecirculationEvents, timing: LoopTiming, tracer: TracerPasses,
                   horizon_fraction: float = 1.0 / 3.0, outlet_z: float = 0.0,
                   n_batches: int = 10) -> tuple[TransitLittlesLaw, Estimate]:
    """Little's law on the passes lasting at most a horizon, and the tracer's mean over the same passes.

    The horizon is :func:`siloflow.analysis.studies.silo_recirculation.transit.transit_horizon` (``horizon_fraction`` of
    the run, at most the time the last tracer pass was followed); Little's law over the steady part of ``timing``
    (from :attr:`LoopTiming.steady_start`, :func:`siloflow.analysis.studies.silo_recirculation.transit.transit_littles_law`)
    and the tracer's residence times up to it
    (:func:`siloflow.analysis.numerics.residence_statistics.mean_residence_time_within`) then refer to the same control
    volume, entry and exit events and clumps, and agree within their errors in a steady run. The tracer's error is
    that of one cohort: the spread of the means of the later cohorts of its size
    (:func:`siloflow.analysis.numerics.residence_statistics.cohort_means_within`), where the run holds two or more.
    """
    horizon = transit_horizon(timing.t_open, timing.t_end, tracer.entry_time, horizon_fraction)
    little = transit_littles_law(tracks, events, horizon, timing.steady_start, outlet_z, n_batches)
    # the error of one cohort's mean: the spread over the cohorts of the tracer's size entering from its start on
    # and followed for the horizon
    entry = np.asarray(events.entry_time, dtype=float)
    followed = np.isfinite(entry) & (entry >= float(np.min(tracer.entry_time))) & (entry <= timing.t_end - horizon)
    residence = np.asarray(events.exit_time, dtype=float)[followed] - entry[followed]
    cohorts = cohort_means_within(entry[followed], residence, horizon, tracer.entry_time.size)
    return little, mean_residence_time_within(tracer.residence_time, horizon, cohorts)


def _johanson_parameters(rtd: RTD) -> tuple[float, float]:
    """Johanson's V1 (first appearance) and P (mode) in throughput units, clipped to the model's range."""
    v1 = min(max(rtd.t_first / rtd.t_mean, 0.0), 0.99)
    mode = float(rtd.time[int(np.argmax(rtd.E))]) / rtd.t_mean
    return v1, min(max(mode, v1), 0.5 * (3.0 - v1))


def _steady_passes(events: RecirculationEvents, start: float, t_end: float, horizon: float, at_least: int,
                   entry_at: str) -> TracerPasses:
    """Every pass entering in ``[start, t_end - horizon]`` (at least ``at_least``): a large sample whose passes all
    had ``horizon`` to leave, so the right-censoring by the end of the run is as small as for the tracer."""
    entry = np.asarray(events.entry_time if entry_at == "wrap" else events.previous_exit_time, dtype=float)
    in_window = int(np.count_nonzero(np.isfinite(entry) & (entry >= start) & (entry <= t_end - horizon)))
    return tracer_passes(events, start, max(at_least, in_window), entry_at=entry_at)


def particle_rtd(events: RecirculationEvents, timing: LoopTiming, tracer_fraction: float, tracer_start: float,
                 bins: int, window: float, horizon_recirculations: float = 2.0) -> ParticleRTD:
    """RTD from particle ids: the first ``tracer_fraction`` x holdup passes re-entering after ``Nr = tracer_start``.

    The silo RTD of the study uses that tracer, with the re-entry at the top as the entry; its mean ``t_m`` is over
    the tracer passes that left by the end of the run, so it leaves out the clumps held in the stagnant zones
    and is shorter than the holdup residence time ``timing.residence_time`` (:func:`transit_timing` compares
    like with like). The LTI models need a
    smoother RTD than a 10 % tracer gives: they take every pass entering between the tracer's start and
    ``horizon_recirculations`` t_res before the end of the run (at least the tracer's count), for the silo
    (re-entry to outlet) and for the whole loop (previous outlet crossing to exit, which the renewal equation
    needs), tabulated on bins of width ``window`` from 0.
    """
    n_tracer = max(1, int(round(tracer_fraction * timing.holdup)))
    start = timing.t_open + tracer_start * timing.residence_time
    tracer = tracer_passes(events, start, n_tracer, entry_at="wrap")
    horizon = horizon_recirculations * timing.residence_time
    loop = _steady_passes(events, start, timing.t_end, horizon, n_tracer, "outlet")
    steady = _steady_passes(events, start, timing.t_end, horizon, n_tracer, "wrap")
    for passes, what in ((tracer, "re-entry"), (loop, "loop")):
        if not np.any(np.isfinite(passes.exit_time)):
            raise ValueError(
                f"none of the {passes.exit_time.size} tracer passes ({what} RTD) entering after Nr = {tracer_start:g} "
                f"left the silo before the end of the run (Nr = {timing.recirculations:.2f}); run more "
                "recirculations (silo_recirculation.recirculations) or mark the tracer earlier "
                "(silo_recirculation.tracer.start_recirculations)"
            )
    silo = rtd_from_exit_times(tracer.exit_time, t_entry=tracer.entry_time, bins=bins, n_total=n_tracer)
    loop_E = _with_little_tail(loop, window, events.n_clumps / timing.throughput)
    v1, p = _johanson_parameters(silo)
    # Johanson's triangle stands in for the silo part of the loop; the loop adds the channel and the fall.
    loop_lag = max(0.0, float(np.nanmean(loop.exit_time - loop.entry_time)) - silo.t_mean)
    lags = np.arange(loop_E.size) * window
    johanson = np.where(lags >= loop_lag, johanson_rtd(np.maximum(lags - loop_lag, 0.0), silo.t_mean, v1, p), 0.0)
    return ParticleRTD(
        tracer=tracer, silo=silo, loop=loop, loop_E_on_windows=loop_E, start_time=start, n_tracer=n_tracer,
        johanson_V1=v1, johanson_P=p, steady=steady, silo_E_on_windows=_histogram_from_zero(steady, window),
        johanson_loop_E_on_windows=johanson,
    )


def _with_little_tail(passes: TracerPasses, step: float, mean_loop_time: float, max_tail_steps: int = 20000) -> np.ndarray:
    """Loop RTD on bins of width ``step`` from 0, its censored part restored as an exponential tail.

    Passes still in the loop at the end of the run (slow paths along the walls) are missing from the histogram;
    normalising it would shorten the mean loop time and make the renewal prediction recycle too fast. In a
    closed loop the mean loop time is known exactly, every clump over the throughput (Little's law, assuming
    the stagnant zones exchange clumps with the flow rather than hold them for ever), so the
    missing fraction ``f_c`` is put back as ``f_c exp(-(t - T) / tau) / tau`` after the longest observed loop
    time ``T``, with ``tau`` chosen so that the whole RTD has that mean. Without a censored part, or when the
    observed part already has the mean, the histogram is returned as it is.
    """
    residence = passes.exit_time - passes.entry_time
    exited = np.isfinite(residence)
    E = _histogram_from_zero(passes, step)
    censored = 1.0 - exited.sum() / residence.size
    if censored <= 0.0:
        return E
    longest = float(residence[exited].max())
    observed_mean = float(residence[exited].mean())
    tau = (mean_loop_time - (1.0 - censored) * observed_mean) / censored - longest
    if not tau > 0.0:
        return E
    n_tail = min(max_tail_steps, int(math.ceil((longest + 8.0 * tau) / step)) + 1)
    t = np.arange(n_tail) * step
    tail = np.where(t >= longest, censored * np.exp(-(t - longest) / tau) / tau, 0.0)
    tail[: E.size] += E[: min(E.size, n_tail)]
    return tail


def _histogram_from_zero(passes: TracerPasses, step: float) -> np.ndarray:
    """E of a sample of passes on bins of width ``step`` from 0 (unexited passes count in the total)."""
    residence = passes.exit_time - passes.entry_time
    edges = np.arange(0.0, float(np.nanmax(residence)) + 2.0 * step, step)
    return rtd_from_exit_times(passes.exit_time, t_entry=passes.entry_time, bins=edges,
                               n_total=passes.exit_time.size).E


def analyse_layout(layout: Layout, initial_height, events: RecirculationEvents, timing: LoopTiming, window: float,
                   rtd: ParticleRTD, passes: int, tolerance: float) -> LayoutResult:
    """Direct measurement, renewal prediction and discontinuous LTI model of one batch layout."""
    colours = layer_colours(initial_height, layout.blue_fraction, layout.sublayers, layout.blue_at)
    exits = np.asarray(events.exit_times_all, dtype=float)
    crossing_blue = colours[np.asarray(events.exit_clump_index, dtype=np.int64)]
    measured = outlet_concentration(exits, crossing_blue, window, timing.t_open, timing.t_end)
    first = first_pass_concentration(events, colours, window, timing.t_open, timing.t_end)
    c_first = np.nan_to_num(first.concentration, nan=0.0)
    predicted = predicted_concentration_from_first_pass(c_first, rtd.loop_E_on_windows, window, passes)
    johanson = rtd.johanson_loop_E_on_windows
    predicted_johanson = (
        predicted_concentration_from_first_pass(c_first, johanson, window, passes) if johanson.sum() > 0 else
        np.full_like(c_first, np.nan)
    )
    n_recirculations = max(1, int(math.floor(timing.recirculations)))
    vrr = vrr_by_recirculation(measured.centres, measured.concentration, timing.t_open, timing.residence_time,
                               layout.blue_fraction, n_recirculations)
    vrr_predicted = vrr_by_recirculation(measured.centres, predicted, timing.t_open, timing.residence_time,
                                         layout.blue_fraction, n_recirculations)
    homogenised = _homogenised_after(measured, timing, layout.blue_fraction, tolerance)
    # Discontinuous mode: the batch fed over one t_res, then recirculated with the measured silo RTD.
    _, c_in = batch_inlet_signal(layout.blue_fraction, layout.sublayers, layout.blue_at, timing.residence_time,
                                 window)
    model = recirculate(c_in, rtd.silo_E_on_windows, np.arange(c_in.size) * window, passes)
    samples_per_pass = timing.residence_time / window
    model_nr = np.arange(model.concentration.size) / samples_per_pass
    model_after = recirculations_to_homogenise(model.concentration[: int(passes * samples_per_pass)],
                                               mean=layout.blue_fraction, tolerance=tolerance,
                                               per_pass_length=samples_per_pass)
    return LayoutResult(
        layout=layout, colours=colours, concentration=measured, first_pass=first, predicted=predicted,
        predicted_johanson=predicted_johanson, vrr=vrr, vrr_predicted=vrr_predicted, homogenised_after=homogenised,
        model_time_nr=model_nr, model_concentration=model.concentration, model_homogenised_after=model_after,
        recirculation_number=recirculation_number(measured.centres, timing.t_open, timing.residence_time),
    )


def _homogenised_after(measured: OutletConcentration, timing: LoopTiming, blue_fraction: float,
                       tolerance: float) -> float:
    """Nr from which every measured window stays within +-tolerance of the blue fraction (NaN if never)."""
    c = measured.concentration
    inside = np.isfinite(c) & (np.abs(c - blue_fraction) <= tolerance * blue_fraction)
    outside = np.flatnonzero(~inside)
    if outside.size == 0:
        return 0.0
    last_outside = outside[-1]
    if last_outside == c.size - 1:
        return math.nan
    return float((measured.edges[last_outside + 1] - timing.t_open) / timing.residence_time)


def continuous_mode(rtd: ParticleRTD, period_fractions, samples_per_shortest_period: int = 8) -> tuple[VRRTable, VRRTable]:
    """VRR of sine and square inputs against their period (over the tracer's t_m), through the steady silo RTD."""
    fractions = np.asarray(period_fractions, dtype=float)
    step = float(fractions.min()) * rtd.silo.t_mean / samples_per_shortest_period
    E = _histogram_from_zero(rtd.steady, step)
    time = np.arange(E.size) * step
    t_mean = rtd.silo.t_mean
    return (
        vrr_versus_period(E, time, fractions, waveform="sine", t_mean=t_mean),
        vrr_versus_period(E, time, fractions, waveform="square", t_mean=t_mean),
    )


def analyse_blending(tracks: ClumpTracks, layouts, domain_bottom: float, domain_top: float, window_fraction: float,
                     tracer_fraction: float, tracer_start: float, rtd_bins: int, period_fractions, passes: int,
                     tolerance: float, outlet_z: float = 0.0, window_target_vrr: float | None = None,
                     with_transit: bool = True) -> BlendingResult:
    """The whole direct + RTD + LTI analysis of one recirculation run (see the module docstring).

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres from the outlet opening (first frame) to the end of the run [m]; of a run with a discharge
        after its recirculations, to the stop of the re-entry (:meth:`ClumpTracks.until`): every figure here is of
        the recirculating silo, and the discharge's VRR is
        :func:`siloflow.analysis.studies.silo_recirculation.final_discharge.final_discharge`.
    layouts : sequence of Layout
        Batch colourings.
    domain_bottom, domain_top : float
        Periodic bounds of the domain in z [m].
    window_fraction : float
        Concentration window as a fraction of the measured t_res [-].
    tracer_fraction, tracer_start : float
        Tracer size (fraction of the holdup) and the Nr after which it is marked [-].
    rtd_bins : int
        Bins of the silo RTD histogram [-].
    period_fractions : sequence of float
        Input periods over t_m for the continuous mode [-].
    passes : int
        Recirculations summed by the LTI models [-].
    tolerance : float
        Relative band that counts as homogenised [-].
    outlet_z : float, optional
        Height of the outlet plane [m].
    window_target_vrr : float or None, optional
        When given, the concentration window is sized from it instead of ``window_fraction``: long enough that a VRR
        of this size lies a factor :data:`~siloflow.analysis.numerics.vrr_noise.CEILING_FACTOR` below the counting-noise
        ceiling of the windows (:func:`~siloflow.analysis.numerics.vrr_noise.window_duration_for_precision` at the measured
        throughput) [-].
    with_transit : bool, optional
        False leaves out Little's law on the passes within a horizon (``transit`` and ``tracer_transit_mean`` are
        then None): a run cut off at the shortcut's length (:mod:`siloflow.analysis.studies.silo_recirculation.shortcut`) may
        hold no pass that short.
    """
    events = recirculation_events(tracks, outlet_z, domain_bottom, domain_top)
    timing = loop_timing(tracks, events, outlet_z)
    if window_target_vrr is None:
        window = window_fraction * timing.residence_time
    else:
        window = window_duration_for_precision(window_target_vrr, timing.throughput)
    rtd = particle_rtd(events, timing, tracer_fraction, tracer_start, rtd_bins, window)
    initial_height = tracks.position[0, :, 2]
    results = [analyse_layout(layout, initial_height, events, timing, window, rtd, passes, tolerance)
               for layout in layouts]
    sine, square = continuous_mode(rtd, period_fractions)
    transit, tracer_transit_mean = (transit_timing(tracks, events, timing, rtd.tracer, outlet_z=outlet_z)
                                    if with_transit else (None, None))
    return BlendingResult(timing=timing, events=events, window=window, rtd=rtd, layouts=results, vrr_sine=sine,
                          vrr_square=square, transit=transit, tracer_transit_mean=tracer_transit_mean)


def snapshot_frames(times, t_open: float, residence_time: float, recirculation_numbers) -> list[int]:
    """Index of the frame nearest to each wanted Nr (those beyond the run are dropped)."""
    times = np.asarray(times, dtype=float)
    indices = []
    for nr in recirculation_numbers:
        wanted = t_open + float(nr) * residence_time
        if wanted <= times[-1] + 0.5 * (times[-1] - times[-2] if times.size > 1 else 0.0):
            indices.append(int(np.argmin(np.abs(times - wanted))))
    return indices


@dataclass(frozen=True, eq=False)
class VerificationResult:
    """Particle tracks against Eulerian pathlines in the one-particle-thick silo.

    Attributes
    ----------
    particle_residence : numpy.ndarray
        Residence times (re-entry to outlet) of the tracer passes [s], NaN if not out by the end.
    eulerian_residence : dict
        Bin size [m] -> residence times of the virtual tracers [s] (NaN: not out within the time followed).
    particle_paths : list of numpy.ndarray
        (n_i, 2) arrays of (x, z) of a few tracer clumps from re-entry to exit [m].
    pathlines : dict
        Bin size [m] -> list of (n_i, 2) arrays of (x, z) of a few virtual tracers [m].
    timing : LoopTiming
        Holdup, throughput and t_res of the run.
    """

    particle_residence: np.ndarray
    eulerian_residence: dict
    particle_paths: list
    pathlines: dict
    timing: LoopTiming


def residence_summary(times) -> dict:
    """Count, count exited, mean, its standard error and the standard deviation of a residence-time sample.

    ``n`` and ``n_exited`` [-], ``mean_s`` [s], ``mean_s_error`` (``s / sqrt(n_exited)`` with ``ddof = 1``,
    :func:`siloflow.analysis.numerics.residence_statistics.mean_residence_time`, which states the assumption; NaN for one
    exited tracer) [s] and ``std_s`` (population, ``ddof = 0``) [s]. NaN in ``times`` means not out; without any
    exited tracer the moments are None.
    """
    times = np.asarray(times, dtype=float)
    finite = times[np.isfinite(times)]
    if not finite.size:
        return {"n": int(times.size), "n_exited": 0, "mean_s": None, "mean_s_error": None, "std_s": None}
    mean = mean_residence_time(finite)
    return {"n": int(times.size), "n_exited": int(finite.size), "mean_s": mean.value,
            "mean_s_error": mean.std_error, "std_s": float(finite.std())}


def _clump_path(tracks: ClumpTracks, column: int, t_from: float, t_to: float) -> np.ndarray:
    """(x, z) of one clump between two times, with a NaN row where it wraps through the periodic boundary."""
    inside = (tracks.times >= t_from) & (tracks.times <= t_to)
    path = tracks.position[inside, column][:, [0, 2]]
    jumps = np.flatnonzero(np.abs(np.diff(path[:, 1])) > 0.5 * (np.nanmax(tracks.z) - np.nanmin(tracks.z)))
    return np.insert(path, jumps + 1, np.nan, axis=0) if jumps.size else path


def verify_eulerian_rtd(tracks: ClumpTracks, velocity, mass, width: float, depth: float, domain_bottom: float,
                        domain_top: float, inlet_width: float, bin_sizes, tracer_start: float, dt: float,
                        max_recirculations: float, paths_shown: int, tracer_fraction: float = 0.1,
                        outlet_z: float = 0.0) -> VerificationResult:
    """Residence times and paths of real clumps against virtual tracers through bin velocities of several sizes.

    The particle side takes the passes re-entering after ``Nr = tracer_start`` (as many as ``tracer_fraction`` of
    the holdup); the Eulerian side seeds the same number of virtual tracers in the inlet bins at the same time.
    """
    events = recirculation_events(tracks, outlet_z, domain_bottom, domain_top)
    timing = loop_timing(tracks, events, outlet_z)
    start = timing.t_open + tracer_start * timing.residence_time
    n_tracer = max(1, int(round(tracer_fraction * timing.holdup)))
    tracer = tracer_passes(events, start, n_tracer, entry_at="wrap")
    residence = tracer.exit_time - tracer.entry_time
    shown = np.flatnonzero(np.isfinite(residence))
    shown = shown[np.linspace(0, shown.size - 1, min(paths_shown, shown.size)).astype(int)] if shown.size else shown
    particle_paths = [
        _clump_path(tracks, int(tracer.clump_index[i]), tracer.entry_time[i], tracer.exit_time[i]) for i in shown
    ]
    max_time = max_recirculations * timing.residence_time
    record_every = max(1, int(round(0.01 / dt)))
    eulerian, pathlines = {}, {}
    for bin_size in bin_sizes:
        grid = silo_bins(width, depth, domain_top, bin_size)
        result = eulerian_residence_times(
            tracks.times, tracks.position, velocity, mass, grid, inlet_width, n_tracer, start, dt, max_time,
            outlet_z=outlet_z, record_every=record_every,
        )
        eulerian[float(bin_size)] = result.residence_time
        history = result.pathlines.history
        chosen = np.linspace(0, result.seeds.shape[0] - 1, min(paths_shown, result.seeds.shape[0])).astype(int)
        pathlines[float(bin_size)] = [history[:, i][:, [0, 2]] for i in chosen]
    return VerificationResult(particle_residence=residence, eulerian_residence=eulerian,
                              particle_paths=particle_paths, pathlines=pathlines, timing=timing)


def main_run_eulerian_rtd(tracks: ClumpTracks, velocity, mass, result: BlendingResult, width: float, depth: float,
                          domain_top: float, inlet_width: float, bin_size: float, dt: float,
                          max_recirculations: float, bins: int, outlet_z: float = 0.0) -> RTD:
    """The Eulerian RTD of a blending run: as many virtual tracers as the particle tracer, released when it starts."""
    grid = silo_bins(width, depth, domain_top, bin_size)
    eulerian = eulerian_residence_times(
        tracks.times, tracks.position, velocity, mass, grid, inlet_width, result.rtd.n_tracer, result.rtd.start_time,
        dt, max_recirculations * result.timing.residence_time, outlet_z=outlet_z,
    )
    residence = eulerian.residence_time
    if not np.any(np.isfinite(residence)):
        raise ValueError("no virtual tracer reached the outlet; raise silo_recirculation.eulerian.max_recirculations")
    return rtd_from_exit_times(residence, t_entry=0.0, bins=bins, n_total=residence.size)
