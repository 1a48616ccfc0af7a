"""The discharge after the recirculations: the outflow of a recirculating silo once its re-entry stops, and the VRR
of its outlet concentration, the study's VRR "at the end of Nr recirculations" (thesis §6.4.2, Fig. 6.9).

Pure functions on numpy arrays; no file I/O. SI units: times in s; concentrations are blue fractions [-].

A run with a final discharge (``silo_recirculation.final_discharge`` > 0) recirculates until ``t_stop``, the opening
plus its ``recirculation_time``; from then on a clump leaving the channel bottom is gone (absent from the later frames,
NaN in its track) and the feeder keeps discharging at V_out until the silo holds only its stagnant zones. Every
other figure of the study is of the recirculating part, the frames at or before ``t_stop``
(:meth:`siloflow.analysis.numerics.clump_tracks.TrackedClumps.until`); this module measures the discharge on the whole
tracks.

Events
------
The outlet crossings are those of :func:`siloflow.analysis.studies.silo_recirculation.tracks.recirculation_events` on
the whole tracks. Events are looked for only between frames in which a clump is present
(:mod:`siloflow.analysis.numerics.exit_times`), so a clump that leaves the domain after ``t_stop`` and is absent from
then on is neither a re-entry nor a crossing. Its outlet crossing, a channel length above the bottom, is found as
long as the frames are close enough that the clump is saved once below the outlet plane before it goes (a channel
of 80 mm at 0.4 m/s takes 0.2 s against frames every few ms). Re-entries found after ``t_stop``
(:attr:`FinalDischarge.reentries`) are 0 in a run whose re-entry stopped, but for a wrap just before ``t_stop``
whose time, interpolated between the frames around it, falls a little after.

Windows and the fading flow
---------------------------
The outlet concentration is taken in windows of the passes' width (``BlendingResult.window``: the configured
``concentration_window`` x t_res, or as sized for the target VRR) from ``t_stop`` on. As the silo empties the
outflow fades and stops at the stagnant zones; the last windows hold few clumps and their concentrations are mostly
counting noise. The rule (:func:`flowing_windows`): **the windows from ``t_stop`` on, up to but not including the
first that holds fewer than ``fade_fraction`` (by default half) of the clumps of a recirculating window**, the steady
throughput times the window (the ``clumps_per_window`` of the summary). The rest of the outflow (that window, every
later one and the incomplete last window of the record) is left out, and its fraction of the crossings after
``t_stop`` is reported. When no window falls below before the record ends, the run ended before the flow faded
(:attr:`DischargeWindows.faded` False): the VRR is of the part of the discharge the run saw.

VRR
---
``VRR = p (1 - p) / var(c)`` over the windows kept, ``p`` the layout's blue fraction (the input variance of the 0/1
batch) and ``var`` the population variance (``ddof = 0``), as for a recirculation pass
(:func:`siloflow.analysis.studies.silo_recirculation.vrr.vrr_by_recirculation`); inf without variance, NaN with fewer
than 2 windows. Its standard error is ``sqrt(2 / (N - 1)) VRR`` over the ``N`` windows
(:func:`~siloflow.analysis.studies.silo_recirculation.vrr.vrr_standard_error`, which states the assumption). Its
counting-noise ceiling is that of windows of the harmonic mean of their clump counts, exact for windows of unequal
size (:func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`), flagged as by
:func:`~siloflow.analysis.numerics.vrr_noise.vrr_near_ceiling`. ``Nr`` of the discharge is the recirculations done by
``t_stop``, ``(t_stop - t_open) / t_res`` in the holdup residence time of the recirculating part.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number, positive_number
from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.numerics.vrr_noise import CEILING_FACTOR, vrr_ceiling, vrr_near_ceiling
from siloflow.analysis.studies.silo_recirculation.study import BlendingResult
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events
from siloflow.analysis.studies.silo_recirculation.validation import event_times, open_fraction
from siloflow.analysis.studies.silo_recirculation.concentration import outlet_concentration
from siloflow.analysis.studies.silo_recirculation.vrr import (recirculation_number, variance_reduction,
                                                               vrr_standard_error)

__all__ = ["FADE_FRACTION", "DischargeWindows", "DischargeVRR", "FinalDischarge", "flowing_windows", "discharge_vrr",
           "final_discharge"]

#: Part of a recirculating window's clumps below which a window of the discharge counts as the flow faded [-].
FADE_FRACTION = 0.5


@dataclass(frozen=True, eq=False)
class DischargeWindows:
    """The outlet windows of the discharge after the recirculations that its VRR uses (:func:`flowing_windows`).

    Attributes
    ----------
    edges : numpy.ndarray, shape (n_w + 1,)
        Edges of the windows kept, ``t_start + i window``; window i is ``[edges[i], edges[i + 1])`` [s]. Only
        ``t_start`` when none is kept.
    n_total : numpy.ndarray of int64, shape (n_w,)
        Outlet crossings in each window kept [-].
    threshold : float
        Fewest crossings of a window kept, ``fade_fraction`` x the clumps of a recirculating window [-].
    faded : bool
        True when a window below the threshold ended them; False when the record ended first.
    crossings : int
        Every outlet crossing at or after ``t_start`` [-].
    """

    edges: np.ndarray
    n_total: np.ndarray
    threshold: float
    faded: bool
    crossings: int

    @property
    def n_windows(self) -> int:
        """Number of windows kept [-]."""
        return int(self.n_total.size)

    @property
    def clumps(self) -> int:
        """Outlet crossings in the windows kept [-]."""
        return int(self.n_total.sum())

    @property
    def start(self) -> float:
        """Start of the first window, ``t_start`` [s]."""
        return float(self.edges[0])

    @property
    def end(self) -> float:
        """End of the last window kept (``t_start`` when none is) [s]."""
        return float(self.edges[-1])

    @property
    def left_out_fraction(self) -> float:
        """Part of the crossings at or after ``t_start`` that fall outside the windows kept [-]; NaN without any."""
        return 1.0 - self.clumps / self.crossings if self.crossings else math.nan


def flowing_windows(exit_times, t_start: float, t_end: float, window: float, reference_clumps: float,
                    fade_fraction: float = FADE_FRACTION) -> DischargeWindows:
    """The windows of a discharge from ``t_start`` until its flow fades (the module docstring's rule).

    The span ``[t_start, t_end]`` is cut into its complete windows ``[t_start + i window, t_start + (i + 1) window)``;
    they are kept from the first on, up to but not including the first window with fewer than ``fade_fraction x
    reference_clumps`` crossings.

    Parameters
    ----------
    exit_times : array_like, shape (n,)
        Outlet crossing times [s]; NaN entries are ignored.
    t_start : float
        Start of the discharge, the first window's start [s].
    t_end : float
        End of the record (last frame) [s].
    window : float
        Window length [s], > 0.
    reference_clumps : float
        Crossings of a window of the recirculating flow, throughput x window [-], > 0.
    fade_fraction : float, optional
        Fraction of ``reference_clumps`` below which a window ends the discharge, in (0, 1] [-].

    Returns
    -------
    DischargeWindows

    Raises
    ------
    ValueError
        On an argument out of range (named in the message), or ``t_end`` before ``t_start``.

    Examples
    --------
    Four crossings a second, then one: windows of 1 s from 10 s, a recirculating window holding 4.

    >>> windows = flowing_windows([10.1, 10.3, 10.5, 10.7, 11.2, 11.4, 11.6, 11.8, 12.5], 10.0, 13.5, 1.0, 4.0)
    >>> windows.n_total.tolist(), windows.faded, windows.end, round(windows.left_out_fraction, 4)
    ([4, 4], True, 12.0, 0.1111)
    """
    exits = event_times("exit_times", exit_times)
    exits = exits[np.isfinite(exits)]
    t_start = finite_number("t_start", t_start)
    t_end = finite_number("t_end", t_end)
    if t_end < t_start:
        raise ValueError(f"t_end must be >= t_start = {t_start!r} s, got {t_end!r}")
    window = positive_number("window", window)
    reference = positive_number("reference_clumps", reference_clumps)
    fade = float(fade_fraction)
    if not 0.0 < fade <= 1.0:
        raise ValueError(f"fade_fraction must be a number in (0, 1], got {fade_fraction!r}")
    # the tolerance keeps a window whose end falls on t_end up to round-off, as outlet_concentration does
    n_complete = int(math.floor((t_end - t_start) / window + 1.0e-9))
    edges = t_start + window * np.arange(n_complete + 1)
    counts = np.histogram(exits, bins=edges)[0].astype(np.int64) if n_complete else np.zeros(0, dtype=np.int64)
    if n_complete:
        # np.histogram closes its last bin on the right; the windows are all half-open
        counts[-1] -= int(np.count_nonzero(exits == edges[-1]))
    threshold = fade * reference
    below = np.flatnonzero(counts < threshold)
    kept = int(below[0]) if below.size else n_complete
    return DischargeWindows(edges=edges[: kept + 1], n_total=counts[:kept], threshold=threshold,
                            faded=bool(below.size), crossings=int(np.count_nonzero(exits >= t_start)))


@dataclass(frozen=True, eq=False)
class DischargeVRR:
    """The VRR of the outlet concentration of one batch layout over the discharge's windows (:func:`discharge_vrr`).

    Attributes
    ----------
    windows : DischargeWindows
        The windows used.
    n_blue : numpy.ndarray of int64, shape (n_w,)
        Blue crossings in each window [-].
    concentration : numpy.ndarray, shape (n_w,)
        Blue fraction of each window's crossings [-].
    blue_fraction : float
        Blue fraction ``p`` of the batch [-].
    vrr : float
        ``p (1 - p) / var(c)`` [-]; inf without variance, NaN with fewer than 2 windows.
    vrr_error : float
        ``sqrt(2 / (N - 1)) VRR`` [-]; NaN where the VRR is NaN or inf.
    sigma_out : float
        Population standard deviation of the window concentrations [-]; NaN with fewer than 2 windows.
    ceiling : float
        Counting-noise ceiling of windows of the harmonic mean of their crossings [-]; NaN without windows.
    at_ceiling : bool
        The VRR lies within the flag factor of the ceiling: a lower bound, not a measurement.
    """

    windows: DischargeWindows
    n_blue: np.ndarray
    concentration: np.ndarray
    blue_fraction: float
    vrr: float
    vrr_error: float
    sigma_out: float
    ceiling: float
    at_ceiling: bool

    def summary(self) -> dict:
        """``blue_fraction`` [-], ``vrr`` with ``vrr_error`` [-], ``sigma_out`` [-], ``windows`` and ``clumps``
        used [-], ``left_out_fraction`` of the outflow [-], ``vrr_ceiling`` [-] and ``at_ceiling`` (bool)."""
        return {"blue_fraction": self.blue_fraction, "vrr": self.vrr, "vrr_error": self.vrr_error,
                "sigma_out": self.sigma_out, "windows": self.windows.n_windows, "clumps": self.windows.clumps,
                "left_out_fraction": self.windows.left_out_fraction, "vrr_ceiling": self.ceiling,
                "at_ceiling": self.at_ceiling}


def discharge_vrr(exit_times, is_blue, blue_fraction: float, windows: DischargeWindows,
                  factor: float = CEILING_FACTOR) -> DischargeVRR:
    """VRR of the blue outlet concentration over the windows of a discharge, with its error and ceiling flag.

    Parameters
    ----------
    exit_times : array_like, shape (n,)
        Outlet crossing times [s]; NaN entries are ignored (e.g. ``events.exit_times_all``).
    is_blue : array_like of bool, shape (n,)
        Colour of each crossing clump (e.g. ``colours[events.exit_clump_index]``).
    blue_fraction : float
        Blue fraction ``p`` of the batch, in (0, 1) [-].
    windows : DischargeWindows
        The windows (:func:`flowing_windows` of the same crossings).
    factor : float, optional
        A VRR at or above ``ceiling / factor`` is flagged, >= 1 [-].

    Returns
    -------
    DischargeVRR

    Examples
    --------
    One crossing per window, blue in 4 of 12: ``c`` is 0 or 1 with variance ``(1/3)(2/3) = 2/9``, so for a batch of
    ``p = 0.25`` the VRR is ``0.1875 / (2/9) = 27/32``.

    >>> times = 10.5 + np.arange(12)
    >>> windows = flowing_windows(times, 10.0, 25.0, 1.0, 1.0)
    >>> result = discharge_vrr(times, [1, 0, 0] * 4, 0.25, windows)
    >>> round(result.vrr, 12) == 27 / 32, result.windows.n_windows, result.ceiling
    (True, 12, 1.0)
    """
    exits = event_times("exit_times", exit_times)
    if np.shape(is_blue) != exits.shape:
        raise ValueError(f"is_blue must have the shape of exit_times {exits.shape}, got {np.shape(is_blue)}")
    p = open_fraction("blue_fraction", blue_fraction)
    edges, n_total = windows.edges, windows.n_total
    if n_total.size:
        # the kept windows are outlet_concentration's over [their first start, their last end]
        measured = outlet_concentration(exits, is_blue, (edges[-1] - edges[0]) / n_total.size, edges[0], edges[-1])
        n_blue, concentration = measured.n_blue, measured.concentration
    else:
        n_blue, concentration = np.zeros(0, dtype=np.int64), np.zeros(0)
    vrr, sigma_out, n_windows = variance_reduction(concentration, p)
    error = float(vrr_standard_error(vrr, n_windows))
    counts = n_total[n_total > 0]
    # the noise variance of windows of n_i clumps is p (1 - p) mean(1 / n_i): the harmonic mean is the exact n
    ceiling = (vrr_ceiling(counts.size / float(np.sum(1.0 / counts)), p * (1.0 - p), p) if counts.size
               else math.nan)
    at_ceiling = bool(vrr_near_ceiling(vrr, ceiling, factor)) if math.isfinite(ceiling) else False
    return DischargeVRR(windows=windows, n_blue=n_blue, concentration=concentration, blue_fraction=p, vrr=vrr,
                        vrr_error=error, sigma_out=sigma_out, ceiling=ceiling, at_ceiling=at_ceiling)


@dataclass(frozen=True, eq=False)
class FinalDischarge:
    """The discharge after the recirculations of one run, per batch layout (:func:`final_discharge`).

    Attributes
    ----------
    start : float
        ``t_stop``, when the re-entry stopped [s].
    recirculations : float
        ``Nr`` of the discharge, ``(t_stop - t_open) / t_res`` [-].
    window : float
        Window length [s], that of the recirculation passes.
    reference_clumps : float
        Crossings of a recirculating window, throughput x window [-].
    fade_fraction : float
        The rule's fraction of ``reference_clumps`` [-].
    windows : DischargeWindows
        The windows used.
    reentries : int
        Re-entries found after ``t_stop`` [-] (see the module docstring).
    layouts : dict
        Layout name -> :class:`DischargeVRR`, in the order of the result's layouts.
    """

    start: float
    recirculations: float
    window: float
    reference_clumps: float
    fade_fraction: float
    windows: DischargeWindows
    reentries: int
    layouts: dict

    def summary(self) -> dict:
        """The ``final_discharge`` entry of ``blending.json``.

        Returns
        -------
        dict
            ``recirculations`` (Nr [-]), ``start_s`` (``t_stop``) and ``end_s`` (end of the windows used) [s],
            ``window_s`` [s], ``reference_clumps_per_window`` [-], ``fade_fraction`` [-], ``threshold_clumps``
            (fewest clumps of a window used [-]), ``faded`` (bool: False when the record ended before the flow
            faded), ``crossings`` (outlet crossings after ``t_stop`` [-]), ``reentries`` [-], and ``layouts``: name
            -> :meth:`DischargeVRR.summary`.
        """
        windows = self.windows
        return {"recirculations": self.recirculations, "start_s": self.start, "end_s": windows.end,
                "window_s": self.window, "reference_clumps_per_window": self.reference_clumps,
                "fade_fraction": self.fade_fraction, "threshold_clumps": windows.threshold, "faded": windows.faded,
                "crossings": windows.crossings, "reentries": self.reentries,
                "layouts": {name: result.summary() for name, result in self.layouts.items()}}


def final_discharge(tracks: ClumpTracks, result: BlendingResult, t_stop: float, domain_bottom: float,
                    domain_top: float, outlet_z: float = 0.0, fade_fraction: float = FADE_FRACTION,
                    factor: float = CEILING_FACTOR) -> FinalDischarge:
    """The VRR of the discharge after the recirculations, per batch layout of ``result``.

    Parameters
    ----------
    tracks : ClumpTracks
        The whole run's tracks, from the opening to the end of the discharge, the same clump columns as the tracks
        ``result`` was measured on [m].
    result : BlendingResult
        The study of the recirculating part (the tracks up to ``t_stop``): its timing (``t_open``, ``t_res``,
        throughput), window and layouts' colours.
    t_stop : float
        When the re-entry stopped [s], in the tracks' clock.
    domain_bottom, domain_top : float
        Periodic bounds of the domain in z [m].
    outlet_z : float, optional
        Height of the outlet plane [m].
    fade_fraction : float, optional
        The rule's fraction of a recirculating window's clumps (:func:`flowing_windows`) [-].
    factor : float, optional
        Ceiling flag factor (:func:`discharge_vrr`) [-].

    Returns
    -------
    FinalDischarge

    Raises
    ------
    ValueError
        If ``t_stop`` is not after the opening and before the last frame, or the tracks do not have the clumps of the
        result's layouts.
    """
    times = np.asarray(tracks.times, dtype=float)
    timing = result.timing
    t_stop = finite_number("t_stop", t_stop)
    if not timing.t_open < t_stop < times[-1]:
        raise ValueError(f"t_stop must lie after the opening at {timing.t_open!r} s and before the last frame at "
                         f"{times[-1]!r} s (the discharge needs frames after it), got {t_stop!r}")
    events = recirculation_events(tracks, outlet_z, domain_bottom, domain_top)
    exits = np.asarray(events.exit_times_all, dtype=float)
    clump = np.asarray(events.exit_clump_index, dtype=np.int64)
    reference = timing.throughput * result.window
    windows = flowing_windows(exits, t_stop, float(times[-1]), result.window, reference, fade_fraction)
    layouts = {}
    for layout in result.layouts:
        colours = np.asarray(layout.colours, dtype=bool)
        if colours.shape != (events.n_clumps,):
            raise ValueError(f"layout {layout.layout.name!r} colours {colours.size} clumps, the tracks hold "
                             f"{events.n_clumps}: give the whole run's tracks of the same clumps")
        layouts[layout.layout.name] = discharge_vrr(exits, colours[clump], layout.layout.blue_fraction, windows,
                                                    factor)
    entry = np.asarray(events.entry_time, dtype=float)
    return FinalDischarge(
        start=t_stop, recirculations=recirculation_number(t_stop, timing.t_open, timing.residence_time),
        window=result.window, reference_clumps=reference, fade_fraction=float(fade_fraction), windows=windows,
        reentries=int(np.count_nonzero(np.isfinite(entry) & (entry > t_stop))), layouts=layouts,
    )
