"""Standard errors of the blender's headline figures, from the run's own data.

Pure functions on numbers, arrays and :class:`siloflow.analysis.studies.blender.steady_field.BlenderField`; no file I/O.
Every error is a standard error (one standard deviation) in the unit of its figure; NaN means "not known" and is
never replaced by zero. The generic estimators are those of :mod:`siloflow.analysis.numerics.uncertainty`.

Where each error comes from
---------------------------
Mass flow rate
    Batch slopes of the discharged mass over the steady window (:func:`steady_flow_rate_estimate`,
    :func:`siloflow.analysis.numerics.uncertainty.batch_rate`): the discharge of one run is a correlated series, and
    batches long against its correlation time give an honest error where the scatter of single samples would not.
Passage mean vertical velocities
    Batch means of the per-frame passage means over the frames of the steady window
    (:func:`passage_velocity_estimates`, :func:`siloflow.analysis.numerics.uncertainty.batch_means`), so that correlated
    frames are not counted as independent.
RTD mean, spread and ``t_s / t_d``; VRR of the sine inputs
    The finite sample of virtual tracers behind the RTD (:func:`tracer_errors`, :func:`sine_vrr_error`): the
    tracers are treated as independent draws from the RTD, weighted by their solid fraction, with Kish's effective
    number ``n_eff = (sum w)^2 / sum w^2`` (:func:`effective_count`; ``n`` for equal weights). The tracers sit on a
    regular lattice, whose error for a smooth integrand is smaller than that of random draws, so these errors are
    if anything too large for a given field. The field itself is uncertain too: to first order its velocities
    scale together with the flow rate, which scales every residence time inversely, so ``t_m`` also carries the
    flow rate's relative error (:func:`residence_time_error`); the spread, ``t_s / t_d`` and the VRR at a period
    given as a fraction of ``t_m`` do not change under that scaling. Changes of the field's shape are not
    covered: that needs the spread over seeds.
Recirculations to homogenise
    The figure is the last time an oscillating concentration leaves a band around its mean: any noise in the curve
    can add or remove a whole excursion beyond the band, moving the answer by an oscillation period, so a
    linearised error of that threshold crossing would pretend a precision it does not have. Instead
    (:func:`homogenisation_error`) the first-pass concentration is redrawn within its counting noise (each window's
    tracer weight leaving, variance the sum of the squared weights), every draw goes through the same linear
    recycle model and gives its own crossing, and the error is the spread of those crossings, with the window's
    resolution (one window, uniform) added. The field's own uncertainty is not in it: that needs the spread over
    seeds.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, finite_number, integer_at_least, positive_number
from siloflow.analysis.numerics.residence_statistics import appearance_times
from siloflow.analysis.numerics.uncertainty import Estimate, batch_count, batch_means, batch_rate, combine_independent
from siloflow.analysis.studies.blender.profiles import passage_mean_v_z
from siloflow.analysis.studies.blender.steady_field import checked_field
from siloflow.analysis.studies.blender.window_fields import frames_in_window

__all__ = [
    "DEFAULT_BATCHES",
    "TracerErrors",
    "steady_flow_rate_estimate",
    "passage_velocity_estimates",
    "effective_count",
    "tracer_errors",
    "residence_time_error",
    "sine_vrr_error",
    "homogenisation_error",
]

DEFAULT_BATCHES = 10
"""Batches of a steady window: the usual compromise between batches long against the correlation time (few) and
a well-estimated spread of their means (many)."""


def _batches(n_samples: int, per_batch: int, n_batches: int) -> int:
    """The batches that ``n_samples`` allow with at least ``per_batch`` samples each, at most ``n_batches``."""
    return min(batch_count(n_batches), n_samples // per_batch)


def steady_flow_rate_estimate(time, discharged, window: tuple[float, float],
                              n_batches: int = DEFAULT_BATCHES) -> Estimate:
    """Discharge rate over the steady window with its batch-rate standard error [kg/s].

    The samples with ``window[0] <= t <= window[1]`` are cut into batches of at least two samples (as many as
    ``n_batches``, fewer when the window holds fewer than ``2 n_batches`` samples) and
    :func:`siloflow.analysis.numerics.uncertainty.batch_rate` gives the mean of the batch slopes and its standard error.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], strictly increasing.
    discharged : array_like, shape (n,)
        Discharged mass at those times [kg].
    window : tuple of float
        Steady window ``(start, end)``, in the unit and origin of ``time`` [s].
    n_batches : int, optional
        Largest number of batches, >= 2.

    Returns
    -------
    Estimate
        Rate and error [kg/s], ``method="batch rate"``; the error is NaN (``n = 1``) when the window holds fewer
        than 4 samples (two batches of two).

    Raises
    ------
    ValueError
        On arrays of different shape, non-finite values, no sample in the window, or ``n_batches < 2``.
    """
    t = finite_array("time", time, ndim=1)
    mass = finite_array("discharged", discharged, ndim=1)
    if mass.shape != t.shape:
        raise ValueError(f"discharged must have the shape of time {t.shape}, got {mass.shape}")
    selected = frames_in_window(t, window)
    batches = _batches(selected.size, 2, n_batches)
    if batches < 2:
        if selected.size < 2:
            raise ValueError(f"the steady window {window!r} s holds {selected.size} sample; a rate needs two")
        slope = float(np.polyfit(t[selected], mass[selected], 1)[0])
        return Estimate(value=slope, std_error=math.nan, n=1, method="batch rate")
    return batch_rate(t[selected], mass[selected], n_batches=batches)


def passage_velocity_estimates(frames: Sequence, z_value: float, passages: Mapping,
                               n_batches: int = DEFAULT_BATCHES) -> dict[str, Estimate | None]:
    """Mean vertical velocity of each passage over a series of frames, with its batch-means standard error [m/s].

    Each frame gives the passage means at ``z_value`` (:func:`siloflow.analysis.studies.blender.profiles.passage_mean_v_z`);
    a frame in which a passage holds no particle at that height gives it no value and is left out of that
    passage's series (the series keeps its time order). :func:`siloflow.analysis.numerics.uncertainty.batch_means` of the
    series, with as many batches as ``n_batches`` and at most one per value, gives the mean and its error. The
    mean is that of the per-frame means, not the mass-weighted mean of the pooled steady field: a run reports
    the latter and takes only the error from here.

    Parameters
    ----------
    frames : sequence of BlenderField
        Fields of consecutive frames of the steady window, in time order.
    z_value : float
        Height [m] (e.g. one bin inside the insert outlet).
    passages : mapping name -> (x_lo, x_hi)
        Clear intervals at that height [m].
    n_batches : int, optional
        Largest number of batches, >= 2.

    Returns
    -------
    dict
        Name -> :class:`~siloflow.analysis.numerics.uncertainty.Estimate` [m/s] (``method="batch means"``); None for a
        passage with no value in any frame, and an error of NaN (``n = 1``) with a single value.

    Raises
    ------
    ValueError
        On a frame that is not a BlenderField, bad passages or a non-finite height, or ``n_batches < 2``.
    """
    _batches(0, 1, n_batches)
    series: dict[str, list[float]] = {str(name): [] for name in passages}
    for frame in frames:
        for name, mean in passage_mean_v_z(checked_field(frame), z_value, passages).items():
            series[name].append(mean)
    estimates: dict[str, Estimate | None] = {}
    for name, values in series.items():
        values = np.asarray(values, dtype=float)
        values = values[np.isfinite(values)]
        batches = _batches(values.size, 1, n_batches)
        if values.size == 0:
            estimates[name] = None
        elif batches < 2:
            estimates[name] = Estimate(value=float(values[0]), std_error=math.nan, n=1, method="batch means")
        else:
            estimates[name] = batch_means(values, n_batches=batches)
    return estimates


def effective_count(weights) -> float:
    """Kish's effective number of a weighted sample, ``(sum w)^2 / sum w^2`` [-].

    A weighted mean of independent draws has the variance of a plain mean of ``n_eff`` draws; equal weights give
    ``n``, one dominant weight about 1.

    Parameters
    ----------
    weights : array_like, shape (n,)
        Weights of the draws, finite and >= 0, not all 0.

    Returns
    -------
    float
        ``n_eff``, in ``[1, n]`` [-].

    Raises
    ------
    ValueError
        If the weights are not 1-D and finite, any is negative, or all are 0.
    """
    w = finite_array("weights", weights, ndim=1)
    if np.any(w < 0.0) or not np.any(w > 0.0):
        raise ValueError("weights must be >= 0 and not all 0")
    return float(w.sum() ** 2 / np.sum(w * w))


@dataclass(frozen=True)
class TracerErrors:
    """Standard errors of the RTD figures from the virtual-tracer sample (:func:`tracer_errors`).

    Attributes
    ----------
    n_effective : float
        Kish's effective number of the exited tracers [-]; it is also the counting-noise ceiling of the VRR
        (:func:`sine_vrr_error`).
    t_mean : float
        Standard error of the mean residence time ``t_m`` from the tracer sample alone [s] (the field's part:
        :func:`residence_time_error`).
    spread : float
        Standard error of ``sigma / t_m`` [-].
    ts_over_td : float
        Standard error of ``t_s / t_d`` [-].
    """

    n_effective: float
    t_mean: float
    spread: float
    ts_over_td: float


def tracer_errors(residence_time, weights=None, resolution: float = 0.0) -> TracerErrors:
    """Standard errors of ``t_m``, ``sigma / t_m`` and ``t_s / t_d`` from the tracers behind an RTD.

    The exited tracers (finite residence time ``tau_i``, weight ``w_i``) are taken as independent draws from the
    RTD with Kish's effective number ``n = n_eff`` (:func:`effective_count`); the figures are those of
    :func:`siloflow.analysis.studies.blender.tracers.layer_rtd` (weighted mean ``t_m`` and population variance
    ``sigma^2``; first and last exit ``t_s``, ``t_d``).

    - ``t_m`` (a tracer mean, not hold-up over throughput): the standard error of a mean,
      ``sigma / sqrt(n - 1)`` (``std(ddof=1) / sqrt(n)`` for equal weights); the field's own uncertainty adds to it
      (:func:`residence_time_error`).
    - ``s = sigma / t_m``: ``sigma`` has the error ``sigma / sqrt(2 (n - 1))`` (that of a normal sample) and ``t_m``
      the one above; taken as independent (exact for a normal sample; for an RTD skewed to long times the two
      are positively correlated, which makes the ratio's true error smaller), the relative errors add in
      quadrature: ``s sqrt((1/2 + s^2) / (n - 1))``.
    - ``t_s / t_d``: :func:`siloflow.analysis.numerics.rtd.appearance_times`, which combines for each end the gap to the
      next order statistic (an extreme of ``n`` draws scatters by about that much) with the time resolution of
      one residence time: the tracers start at a known instant and their exit is detected within one
      ``resolution`` (uniform, ``resolution / sqrt(12)``; an upper bound, as the integrator interpolates the
      crossing inside its step).

    Parameters
    ----------
    residence_time : array_like, shape (n,)
        Residence time of each tracer [s]; NaN for a tracer that did not exit (left out).
    weights : array_like, shape (n,), optional
        Tracer weights, > 0 (e.g. the bin solid fraction); equal weights by default.
    resolution : float, optional
        Time resolution of the exit detection, >= 0 [s] (the pathline integration step); NaN when not known.

    Returns
    -------
    TracerErrors
        All NaN but ``n_effective`` when ``n_eff <= 1``; ``ts_over_td`` NaN with fewer than 2 exited tracers or an
        unknown resolution.

    Raises
    ------
    ValueError
        On weights of another shape or not > 0, a negative or infinite residence time or resolution, or no
        exited tracer.
    """
    residence = np.asarray(residence_time, dtype=float)
    if residence.ndim != 1:
        raise ValueError(f"residence_time must be a 1-D array, got shape {residence.shape}")
    weight = np.ones(residence.shape) if weights is None else finite_array("weights", weights, ndim=1)
    if weight.shape != residence.shape or np.any(weight <= 0.0):
        raise ValueError(f"weights must be numbers > 0 of shape {residence.shape}, got shape {weight.shape}")
    resolution = float(resolution)
    if math.isinf(resolution) or resolution < 0.0:
        raise ValueError(f"resolution must be a finite number >= 0 or NaN (unknown), got {resolution!r}")
    exited = np.isfinite(residence)
    if np.any(residence[exited] < 0.0) or np.any(np.isinf(residence)):
        raise ValueError("residence_time must be >= 0 or NaN (not exited)")
    if not np.any(exited):
        raise ValueError("residence_time: no tracer exited")
    tau, w = residence[exited], weight[exited]
    n = effective_count(w)
    # the exit is detected within one step, uniformly; the release instant is exact
    ts_over_td = appearance_times(tau, resolution / math.sqrt(12.0)).ts_over_td.std_error
    if not n > 1.0:
        return TracerErrors(n_effective=n, t_mean=math.nan, spread=math.nan, ts_over_td=ts_over_td)
    mean = float(np.average(tau, weights=w))
    sigma = math.sqrt(float(np.average((tau - mean) ** 2, weights=w)))
    spread = sigma / mean if mean > 0.0 else math.nan
    return TracerErrors(
        n_effective=n, t_mean=sigma / math.sqrt(n - 1.0),
        spread=spread * math.sqrt((0.5 + spread * spread) / (n - 1.0)), ts_over_td=ts_over_td,
    )


def residence_time_error(t_mean: float, tracer_error: float, flow_rate: float, flow_rate_error: float) -> float:
    """Standard error of a mean residence time from the tracers and from the steady field's flow rate [s].

    The tracer sample gives ``tracer_error`` (:attr:`TracerErrors.t_mean`). The field's velocities are uncertain as
    well; to first order they scale together with the flow rate ``Q``, and every residence time with ``1 / Q``, so
    ``t_m`` has the relative error of ``Q`` too. The two are independent:
    ``sqrt(tracer_error^2 + (t_m sigma_Q / Q)^2)``.

    Parameters
    ----------
    t_mean : float
        Mean residence time ``t_m`` [s].
    tracer_error : float
        Its error from the tracer sample [s], >= 0 or NaN (unknown).
    flow_rate : float
        Steady mass flow rate ``Q`` [kg/s], non-zero.
    flow_rate_error : float
        Its standard error ``sigma_Q`` [kg/s], >= 0 or NaN (unknown).

    Returns
    -------
    float
        The error [s]; NaN when either part is unknown.

    Raises
    ------
    ValueError
        On a non-finite ``t_mean`` or ``flow_rate``, a zero flow rate, or a negative or infinite error.
    """
    t_mean = finite_number("t_mean", t_mean)
    flow_rate = finite_number("flow_rate", flow_rate)
    if flow_rate == 0.0:
        raise ValueError("flow_rate must be non-zero (the field's relative error is taken from it)")
    flow_rate_error = float(flow_rate_error)
    if flow_rate_error < 0.0 or math.isinf(flow_rate_error):
        raise ValueError(f"flow_rate_error must be a finite number >= 0 or NaN (unknown), got {flow_rate_error!r}")
    return combine_independent([tracer_error, abs(t_mean) * flow_rate_error / abs(flow_rate)])


def sine_vrr_error(vrr, n_effective: float):
    """Standard error of the VRR of a sine input through an RTD sampled by ``n_eff`` tracers [-].

    A sine through a linear blender comes out a sine of the same period whose amplitude is scaled by the modulus
    ``R`` of the RTD's characteristic function ``phi = E[exp(-i omega tau)]``, so ``VRR = 1 / R^2``. From tracers,
    ``phi`` is the weighted mean of ``exp(-i omega tau_i)``, with a complex error of variance
    ``(1 - R^2) / n_eff``; assuming it isotropic (each component ``(1 - R^2) / (2 n_eff)``, exact when the
    tracers' phases at twice the frequency average out), the error of ``R`` is its component along ``phi``, and
    ``VRR = R^-2`` propagates it to

        ``sigma_VRR = VRR sqrt(2 (VRR - 1) / n_eff)``.

    Drawn RTDs bear it out: for tracers from an exponential RTD it matches the half-width of the central 68 % of
    the sampled VRRs to within a few per cent up to ``VRR = n_eff / 4``; beyond, their distribution grows a long
    tail (a ``phi`` estimate near 0 gives a huge VRR) and no standard error describes it well.
    It vanishes for an undamped input (``VRR = 1``, a long period passes whatever the sample) and reaches about
    ``sqrt(2) VRR`` at ``VRR = n_eff``: the counting-noise ceiling of this estimate, where the noise of ``phi``
    (``|phi|^2`` about ``1 / n_eff``) is as large as ``phi`` itself, so that a VRR near ``n_eff`` is set by the
    sample and only a lower bound (flag it with :func:`siloflow.analysis.numerics.vrr_noise.vrr_near_ceiling` against
    the ceiling ``n_eff``). The tracers carry the input's concentration, not a 0/1 colour, so the outlet noise is
    ``sigma_in^2 / n_eff`` rather than the binomial ``p (1 - p) / n`` of
    :func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`, and the ceiling is ``n_eff`` whatever the input's mean and
    amplitude.

    Parameters
    ----------
    vrr : float or array_like
        VRR(s) of sine inputs, >= 0 [-]; NaN or inf give NaN (no error known).
    n_effective : float
        Effective number of tracers behind the RTD (:attr:`TracerErrors.n_effective`), > 0 [-].

    Returns
    -------
    float or numpy.ndarray
        The standard error(s) [-], the shape of ``vrr`` (a float for a scalar).

    Raises
    ------
    ValueError
        On a negative VRR or an ``n_effective`` that is not a finite number > 0.
    """
    values = np.asarray(vrr, dtype=float)
    if np.any(values < 0.0):
        raise ValueError("vrr must be >= 0 (NaN for no VRR)")
    n = float(n_effective)
    if not (math.isfinite(n) and n > 0.0):
        raise ValueError(f"n_effective must be a finite number > 0, got {n_effective!r}")
    with np.errstate(invalid="ignore"):
        error = np.where(np.isfinite(values), values * np.sqrt(2.0 * np.maximum(values - 1.0, 0.0) / n), np.nan)
    return float(error) if error.ndim == 0 else error


def homogenisation_error(first_pass, first_pass_variance, recycle: Callable[[np.ndarray], np.ndarray],
                         homogenised: Callable[[np.ndarray], float], per_pass_length: float, draws: int = 400,
                         seed: int = 0) -> float:
    """Standard error of the recirculations to homogenise from the counting noise of the first pass [-].

    ``draws`` first passes ``first_pass + sqrt(first_pass_variance) z`` (``z`` standard normal, a fixed ``seed`` so
    that a run's figure is reproducible) each go through ``recycle`` (the linear model from a first pass to the
    outlet concentration) and ``homogenised`` (the recirculations after which it stays in its band; NaN: never).
    The error is the sample standard deviation of the finite answers, combined with the resolution of one window,
    ``1 / (per_pass_length sqrt(12))`` (the answer moves in whole windows).

    Parameters
    ----------
    first_pass : array_like, shape (n,)
        First-pass concentration per window [-].
    first_pass_variance : array_like, shape (n,)
        Its variance per window [-], >= 0.
    recycle : callable
        First pass -> outlet concentration.
    homogenised : callable
        Outlet concentration -> recirculations to homogenise [-], NaN if never.
    per_pass_length : float
        Windows per recirculation, > 0.
    draws : int, optional
        Redrawn first passes, >= 2.
    seed : int, optional
        Seed of the draws.

    Returns
    -------
    float
        Standard error [-]; NaN when fewer than half the draws homogenise.

    Raises
    ------
    ValueError
        On arrays of different shapes, a negative or non-finite variance, bad ``per_pass_length`` or ``draws``.
    """
    values = finite_array("first_pass", first_pass, ndim=1)
    variance = finite_array("first_pass_variance", first_pass_variance, ndim=1)
    if variance.shape != values.shape:
        raise ValueError(f"first_pass_variance must have the shape of first_pass {values.shape}, got {variance.shape}")
    if np.any(variance < 0.0):
        raise ValueError("first_pass_variance must be >= 0")
    windows = positive_number("per_pass_length", per_pass_length)
    draws = integer_at_least("draws", draws, 2)
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal((draws, values.size)) * np.sqrt(variance)
    answers = np.array([homogenised(recycle(values + row)) for row in noise], dtype=float)
    finite = answers[np.isfinite(answers)]
    if finite.size < max(2, answers.size / 2):
        return math.nan
    resolution = 1.0 / (windows * math.sqrt(12.0))
    return combine_independent([float(finite.std(ddof=1)), resolution])
