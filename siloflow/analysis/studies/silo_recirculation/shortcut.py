"""The study's shortcut for blending, measured against the full run: the silo RTD from one residence time after the
tracer is marked, then the LTI models for every later recirculation, instead of simulating them.

A recirculation run costs its length: four recirculations (the study's 12 s) are most of a recirculating silo's
engine time. The shortcut needs only the flow to become steady (the tracer is marked at ``Nr = tracer_start``) and one
residence time more, for the tracer to pass. Whether that is enough depends on the flow pattern: in internal flow,
clumps that enter the stagnant zones stay there for several residence times, so one residence time sees only part
of the RTD. This module answers it for a run that did go the full length, by analysing the same tracks cut off where
the shortcut would have stopped (:func:`tracks_until`) and comparing both analyses (:func:`shortcut_rows`): the
mean residence time of the tracer, the discontinuous-mode LTI model (a batch layout recirculated through the silo
RTD) and its recirculations to homogenise, and the continuous mode's VRR against the input period. The full run's
direct measurement of the outlet concentration is the reference beside them.
"""

from __future__ import annotations

import math

import numpy as np

from siloflow.analysis.studies.silo_recirculation.study import BlendingResult
from siloflow.analysis.numerics.clump_tracks import ClumpTracks


def tracks_until(tracks: ClumpTracks, t_end: float) -> ClumpTracks:
    """The frames of ``tracks`` up to and including time ``t_end`` [s], as if the run had stopped there.

    Raises
    ------
    ValueError
        If fewer than two frames are that early, or ``t_end`` is not before the run's last frame (nothing is cut).
    """
    times = np.asarray(tracks.times, dtype=float)
    keep = int(np.searchsorted(times, t_end, side="right"))
    if keep < 2:
        raise ValueError(f"cutting the tracks at t = {t_end:g} s leaves {keep} frame(s); at least 2 are needed")
    if keep >= times.size:
        raise ValueError(f"the run ends at t = {times[-1]:g} s, not after the cut at t = {t_end:g} s: "
                         "the shortcut can be measured only on a longer run")
    return ClumpTracks(times=times[:keep], clump_id=tracks.clump_id, position=tracks.position[:keep])


def _model_on(nr: np.ndarray, model_nr: np.ndarray, model: np.ndarray) -> np.ndarray:
    """A modelled outlet concentration resampled at the recirculation numbers ``nr`` (NaN beyond its end)."""
    return np.interp(nr, model_nr, model, left=np.nan, right=np.nan)


def shortcut_rows(full: BlendingResult, short: BlendingResult) -> list[dict]:
    """Compare the analysis of the full run with the analysis of its tracks cut off where the shortcut stops.

    Parameters
    ----------
    full : BlendingResult
        The analysis of the whole run.
    short : BlendingResult
        The same analysis of the run's tracks cut off at the shortcut's length (:func:`tracks_until`), with the same
        layouts in the same order.

    Returns
    -------
    list of dict
        One row per batch layout, then one ``continuous (sine)`` row. Every row has ``recirculations_full`` and
        ``recirculations_shortcut`` (the runs' lengths, Nr [-]), the tracer's mean residence time from each with its
        standard error (``t_mean_full_s``, ``t_mean_full_error_s``, ``t_mean_shortcut_s``,
        ``t_mean_shortcut_error_s`` [s]), their difference over its combined standard error
        (``t_mean_difference_over_error`` [-]) and the fraction of the shortcut's tracer that left before it stopped
        (``tracer_exited_shortcut`` [-]).
        A layout row adds the full run's directly measured recirculations to homogenise (``homogenised_direct``),
        the LTI model's from the full RTD and from the shortcut's (``homogenised_model_full``,
        ``homogenised_model_shortcut``; NaN when not within the modelled passes) and the RMS difference of the two
        modelled outlet concentrations over the passes both cover, as a fraction of the layout's blue fraction
        (``model_rms_difference`` [-]).
        The continuous row adds the largest relative difference of the sine input's VRR over the periods
        (``vrr_largest_relative_difference`` [-]).
    """
    if [layout.layout.name for layout in full.layouts] != [layout.layout.name for layout in short.layouts]:
        raise ValueError("the full and the shortcut analysis must cover the same batch layouts in the same order")
    full_error, short_error = full.rtd.silo.t_mean_error, short.rtd.silo.t_mean_error
    t_mean_difference = abs(short.rtd.silo.t_mean - full.rtd.silo.t_mean)
    combined_error = math.hypot(full_error, short_error)
    # plug flow has no spread: equal means are then no difference at all, unequal ones infinitely many errors
    over_error = (t_mean_difference / combined_error if combined_error > 0.0 else
                  0.0 if t_mean_difference == 0.0 else math.inf)
    common = {
        "recirculations_full": full.timing.recirculations,
        "recirculations_shortcut": short.timing.recirculations,
        "t_mean_full_s": full.rtd.silo.t_mean,
        "t_mean_full_error_s": full_error,
        "t_mean_shortcut_s": short.rtd.silo.t_mean,
        "t_mean_shortcut_error_s": short_error,
        "t_mean_difference_over_error": over_error,
        "tracer_exited_shortcut": short.rtd.silo.n_exited / short.rtd.silo.n_total,
    }
    rows = []
    for whole, cut in zip(full.layouts, short.layouts):
        shortcut_model = _model_on(whole.model_time_nr, cut.model_time_nr, cut.model_concentration)
        both = np.isfinite(shortcut_model) & np.isfinite(whole.model_concentration)
        difference = shortcut_model[both] - whole.model_concentration[both]
        rows.append({
            "layout": whole.layout.name,
            **common,
            "homogenised_direct": whole.homogenised_after,
            "homogenised_model_full": whole.model_homogenised_after,
            "homogenised_model_shortcut": cut.model_homogenised_after,
            "model_rms_difference": (float(np.sqrt(np.mean(difference**2))) / whole.layout.blue_fraction
                                     if difference.size else math.nan),
            "vrr_largest_relative_difference": math.nan,
        })
    full_vrr, short_vrr = full.vrr_sine, short.vrr_sine
    relative = np.abs(np.asarray(short_vrr.vrr, dtype=float) / np.asarray(full_vrr.vrr, dtype=float) - 1.0)
    rows.append({
        "layout": "continuous (sine)",
        **common,
        "homogenised_direct": math.nan,
        "homogenised_model_full": math.nan,
        "homogenised_model_shortcut": math.nan,
        "model_rms_difference": math.nan,
        "vrr_largest_relative_difference": float(np.nanmax(relative)) if np.isfinite(relative).any() else math.nan,
    })
    return rows
