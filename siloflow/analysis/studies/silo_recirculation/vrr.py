"""The recirculation number and the variance reduction ratio (VRR) of the outlet concentration, per recirculation.

Pure functions on numpy arrays; no file I/O. SI units: times in s; concentrations are blue fractions [-].

Recirculation number and VRR
----------------------------
``Nr = (t - t_open) / t_res`` with the holdup residence time ``t_res`` = holdup / throughput
(Little's law, :func:`holdup_residence_time`): the turnover time of everything above the outlet, stagnant
zones included. The windows of recirculation k are those with
``k - 1 <= Nr < k``; ``VRR_k = p (1 - p) / var(c)`` over them (:func:`vrr_by_recirculation`), the
input variance being that of the 0/1 batch with blue fraction ``p``.

Counting-noise ceiling
----------------------
Windows of ``n`` clumps cannot show a VRR above about ``n`` (:func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`):
the binomial noise of the blue count is left even in a perfectly mixed outflow. A VRR within a factor 2 of the
ceiling (:meth:`RecirculationVRR.at_ceiling`) is a lower bound of the true VRR, not a measurement of it.

Standard errors
---------------
``t_res`` (:func:`littles_law`): the mean holdup's batch-means error over the frames and the throughput's
batch-rate error over the outlet crossings (:mod:`siloflow.analysis.numerics.uncertainty`), propagated through the
ratio. ``VRR_k`` (:func:`vrr_standard_error`): ``sqrt(2 / (N - 1)) VRR_k`` from the ``N`` windows of the
recirculation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, finite_number, increasing_times, integer_at_least, positive_number
from siloflow.analysis.numerics.uncertainty import Estimate, batch_means, batch_rate, combine_independent
from siloflow.analysis.numerics.vrr_noise import CEILING_FACTOR, vrr_ceiling, vrr_near_ceiling
from siloflow.analysis.studies.silo_recirculation.validation import event_times, open_fraction

__all__ = [
    "RecirculationVRR",
    "LittlesLaw",
    "recirculation_number",
    "holdup_residence_time",
    "littles_law",
    "vrr_by_recirculation",
    "variance_reduction",
    "vrr_standard_error",
    "sampling_noise_vrr_limit",
]


@dataclass(frozen=True, eq=False)
class RecirculationVRR:
    """Variance reduction ratio of the outlet concentration, recirculation by recirculation.

    Attributes
    ----------
    recirculation_number : numpy.ndarray, shape (K,)
        Midpoints ``k - 0.5`` of the recirculation intervals ``[k - 1, k)`` [-].
    vrr : numpy.ndarray, shape (K,)
        ``sigma_in^2 / sigma_out^2`` [-]; inf where ``sigma_out`` is 0, NaN with fewer than 2
        windows.
    sigma_out : numpy.ndarray, shape (K,)
        Population standard deviation of the window concentrations [-]; NaN with fewer than 2
        windows.
    n_windows : numpy.ndarray of int64, shape (K,)
        Windows (with a concentration) in each interval [-].
    sigma_in : float
        Standard deviation of the 0/1 batch, ``sqrt(p (1 - p))`` [-].
    blue_fraction : float
        Blue fraction ``p`` of the batch [-].
    """

    recirculation_number: np.ndarray
    vrr: np.ndarray
    sigma_out: np.ndarray
    n_windows: np.ndarray
    sigma_in: float
    blue_fraction: float

    def rows(self) -> list[dict]:
        """One dict per recirculation (for :func:`siloflow.analysis.io.tables.write_flow_table`)."""
        return [
            {
                "recirculation_number": float(nr),
                "vrr": float(v),
                "sigma_out": float(s),
                "n_windows": int(n),
                "sigma_in": self.sigma_in,
                "blue_fraction": self.blue_fraction,
            }
            for nr, v, s, n in zip(self.recirculation_number, self.vrr, self.sigma_out, self.n_windows)
        ]

    @property
    def vrr_error(self) -> np.ndarray:
        """Standard error of each VRR, ``sqrt(2 / (N - 1)) VRR`` with ``N`` = :attr:`n_windows` [-]
        (:func:`vrr_standard_error`, which states the assumption); NaN where the VRR is NaN or inf."""
        return vrr_standard_error(self.vrr, self.n_windows)

    def ceiling(self, clumps_per_window: float) -> float:
        """Counting-noise ceiling of these VRRs for windows of ``clumps_per_window`` clumps [-].

        :func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling` with the input variance of the 0/1 batch,
        ``p (1 - p)``: the ceiling is ``clumps_per_window`` itself.

        Parameters
        ----------
        clumps_per_window : float
            Outlet crossings per window ``n``, > 0 [-]
            (:func:`siloflow.analysis.studies.silo_recirculation.tables.clumps_per_window`).
        """
        p = self.blue_fraction
        return vrr_ceiling(clumps_per_window, p * (1.0 - p), p)

    def at_ceiling(self, clumps_per_window: float, factor: float = CEILING_FACTOR) -> np.ndarray:
        """Which VRRs are within ``factor`` of the counting-noise ceiling (lower bounds, not measurements).

        Parameters
        ----------
        clumps_per_window : float
            Outlet crossings per window ``n``, > 0 [-].
        factor : float, optional
            ``VRR >= ceiling / factor`` is flagged, >= 1 [-]
            (:func:`siloflow.analysis.numerics.vrr_noise.vrr_near_ceiling`).

        Returns
        -------
        numpy.ndarray of bool, shape (K,)
            False where the VRR is NaN, True where it is inf.
        """
        return np.asarray(vrr_near_ceiling(self.vrr, self.ceiling(clumps_per_window), factor), dtype=bool)


def recirculation_number(t, t_open: float, residence_time: float):
    """Recirculation number ``Nr = (t - t_open) / t_res`` [-].

    Parameters
    ----------
    t : float or array_like
        Times [s].
    t_open : float
        Time the outlet opened (start of the discharge) [s].
    residence_time : float
        Mean residence time ``t_res`` [s], > 0 (:func:`holdup_residence_time`).

    Returns
    -------
    float or numpy.ndarray
        ``Nr``, the shape of ``t`` (a float for a scalar ``t``).
    """
    times = finite_array("t", t, ndim=None)
    t_open = finite_number("t_open", t_open)
    t_res = positive_number("residence_time", residence_time)
    nr = (times - t_open) / t_res
    return float(nr) if nr.ndim == 0 else nr


def holdup_residence_time(n_in_silo, exit_times, t_start: float, t_end: float) -> float:
    """Mean residence time ``t_res`` = mean holdup / throughput (Little's law) [s].

    ``t_res = mean(n_in_silo) / (n_exits / (t_end - t_start))``, with ``n_exits`` the crossings with
    ``t_start <= t <= t_end``. In a steady flow it equals the mean residence time (re-entry to outlet) of
    *all* entering clumps when the holdup counts the clumps above the outlet
    (:func:`siloflow.analysis.studies.silo_recirculation.tracks.clumps_above_outlet`), the few that settle into a
    stagnant zone for longer than any run included. A tracer's mean over the passes that left within a
    finite run is shorter by the stagnant holdup over the throughput; Little's law on the passes that can
    leave within a horizon is :func:`siloflow.analysis.studies.silo_recirculation.transit.transit_littles_law`.

    Parameters
    ----------
    n_in_silo : array_like, shape (n,)
        Clumps in the silo at the frames inside ``[t_start, t_end]`` (the caller restricts it to
        the window), >= 0 [-].
    exit_times : array_like, shape (m,)
        Outlet crossing times [s] (e.g. ``events.exit_times_all``); NaN ignored.
    t_start, t_end : float
        The window [s], ``t_end > t_start``.

    Returns
    -------
    float
        ``t_res`` [s].

    Raises
    ------
    ValueError
        On an empty or negative holdup, a bad window, or no crossing in the window.
    """
    mean_holdup, _, n_exits, duration = _steady_window(n_in_silo, exit_times, t_start, t_end)
    return mean_holdup * duration / n_exits


def _steady_window(n_in_silo, exit_times, t_start: float, t_end: float) -> tuple[float, np.ndarray, int, float]:
    """The checks of :func:`holdup_residence_time`; the mean holdup, the finite crossing times, the crossings in
    the window and its duration ``t_end - t_start``."""
    holdup = finite_array("n_in_silo", n_in_silo, ndim=1)
    if holdup.size == 0:
        raise ValueError("n_in_silo must not be empty")
    if np.any(holdup < 0.0):
        raise ValueError("n_in_silo must contain counts >= 0")
    exits = event_times("exit_times", exit_times)
    exits = exits[np.isfinite(exits)]
    t_start = finite_number("t_start", t_start)
    t_end = finite_number("t_end", t_end)
    if t_end <= t_start:
        raise ValueError(f"t_end must be > t_start = {t_start!r} s, got {t_end!r}")
    n_exits = int(np.count_nonzero((exits >= t_start) & (exits <= t_end)))
    if n_exits == 0:
        raise ValueError(f"exit_times: no outlet crossing in [t_start, t_end] = [{t_start!r}, {t_end!r}] s")
    return float(np.mean(holdup)), exits, n_exits, t_end - t_start


@dataclass(frozen=True)
class LittlesLaw:
    """Mean holdup, throughput and ``t_res`` = holdup / throughput of a steady window, with standard errors.

    Attributes
    ----------
    holdup : Estimate
        Mean clumps in the silo [-]; error from batch means of the holdup series.
    throughput : Estimate
        Outlet crossings per second [1/s]; error from batch rates of the cumulative crossings.
    residence_time : Estimate
        ``t_res`` [s] (:func:`holdup_residence_time`); error propagated from the two.
    """

    holdup: Estimate
    throughput: Estimate
    residence_time: Estimate


def littles_law(frame_times, n_in_silo, exit_times, t_start: float, t_end: float,
                n_batches: int = 10) -> LittlesLaw:
    """Mean holdup, throughput and mean residence time of a steady window, each with its standard error.

    Values: the mean of ``n_in_silo``, ``n_exits / (t_end - t_start)`` (crossings with
    ``t_start <= t <= t_end``) and :func:`holdup_residence_time`. Errors:

    - holdup: :func:`siloflow.analysis.numerics.uncertainty.batch_means` of the holdup series. The holdup is counted
      exactly at every frame (each clump is tracked), so it has no counting noise of its own; what makes its
      mean uncertain is how it wanders over the window.
    - throughput: :func:`siloflow.analysis.numerics.uncertainty.batch_rate` of the cumulative number of crossings at
      the frame times (the slope of the discharge over ``n_batches`` parts of the window).
    - ``t_res``: ``t_res sqrt((u_H / H)^2 + (u_Q / Q)^2)``, holdup and throughput taken as independent.

    Each batch must be longer than the time over which the holdup and the discharge rate stay correlated
    (a fraction of ``t_res`` in a steady silo) for the errors to be honest. With fewer than
    ``2 n_batches`` frames the errors are NaN (unknown).

    Parameters
    ----------
    frame_times : array_like, shape (n,)
        Times of the frames in the window [s], strictly increasing.
    n_in_silo : array_like, shape (n,)
        Clumps in the silo at those frames, >= 0 [-].
    exit_times : array_like, shape (m,)
        Outlet crossing times [s]; NaN ignored.
    t_start, t_end : float
        The window [s], ``t_end > t_start``.
    n_batches : int, optional
        Batches of the batch means and batch rates, >= 2.

    Returns
    -------
    LittlesLaw

    Raises
    ------
    ValueError
        As :func:`holdup_residence_time`, and on frame times of another length than ``n_in_silo``, not
        strictly increasing, or ``n_batches`` not an integer >= 2.
    """
    times = increasing_times("frame_times", frame_times)  # also with too few frames for batch_rate to check
    holdup = finite_array("n_in_silo", n_in_silo, ndim=1)
    if times.shape != holdup.shape:
        raise ValueError(f"frame_times must have the shape of n_in_silo {holdup.shape}, got {times.shape}")
    n_batches = integer_at_least("n_batches", n_batches, 2)
    mean_holdup, exits, n_exits, duration = _steady_window(holdup, exit_times, t_start, t_end)
    residence_time = mean_holdup * duration / n_exits  # holdup_residence_time
    throughput = n_exits / duration
    if times.size >= 2 * n_batches:
        holdup_error = batch_means(holdup, n_batches).std_error
        # crossings up to and including each frame time: any offset drops out of the slopes
        cumulative = np.searchsorted(np.sort(exits), times, side="right").astype(float)
        throughput_error = batch_rate(times, cumulative, n_batches).std_error
    else:
        holdup_error = throughput_error = math.nan
    relative = combine_independent([holdup_error / mean_holdup if mean_holdup > 0.0 else math.nan,
                                    throughput_error / throughput])
    dof = n_batches - 1
    return LittlesLaw(
        holdup=Estimate(value=mean_holdup, std_error=holdup_error, n=n_batches, method="batch means", dof=dof),
        throughput=Estimate(value=throughput, std_error=throughput_error, n=n_batches, method="batch rate",
                            dof=dof),
        residence_time=Estimate(value=residence_time, std_error=residence_time * relative, n=n_batches,
                                method="propagated batch means", dof=dof),
    )


def vrr_by_recirculation(
    window_centres,
    concentration,
    t_open: float,
    residence_time: float,
    blue_fraction: float,
    n_recirculations: int,
) -> RecirculationVRR:
    """Variance reduction ratio of the outlet concentration in each recirculation.

    For k = 1 ... K the windows whose recirculation number ``Nr`` (:func:`recirculation_number` of
    their centres) lies in ``[k - 1, k)`` and whose concentration is not NaN give
    ``sigma_out^2``, the population variance (``ddof = 0``) of their concentrations; the input
    variance is that of the 0/1 batch, ``sigma_in^2 = p (1 - p)``, and ``VRR_k = sigma_in^2 /
    sigma_out^2`` (inf if ``sigma_out`` is 0, NaN with fewer than 2 windows).

    Sampling noise: a window of ``n`` crossings from a perfectly mixed outflow has a binomial blue
    count, so its concentration still varies with variance ``p (1 - p) / n``; the measurable VRR is
    capped at about ``n`` (:meth:`RecirculationVRR.ceiling`, :meth:`RecirculationVRR.at_ceiling`). Windows of
    unequal ``n`` are weighted equally.

    Parameters
    ----------
    window_centres : array_like, shape (n_w,)
        Window centre times [s] (:attr:`siloflow.analysis.studies.silo_recirculation.concentration.OutletConcentration.centres`).
    concentration : array_like, shape (n_w,)
        Blue fraction per window [-]; NaN windows are ignored.
    t_open : float
        Time the outlet opened [s].
    residence_time : float
        Mean residence time [s], > 0.
    blue_fraction : float
        Blue fraction ``p`` of the batch, in (0, 1) [-].
    n_recirculations : int
        Number K of recirculations, >= 1.

    Returns
    -------
    RecirculationVRR
    """
    centres = finite_array("window_centres", window_centres, ndim=1)
    c = np.asarray(concentration, dtype=float)
    if c.shape != centres.shape:
        raise ValueError(f"concentration must have the shape of window_centres {centres.shape}, got {c.shape}")
    if np.any(np.isinf(c)):
        raise ValueError("concentration must not contain infinite values (NaN marks an empty window)")
    p = open_fraction("blue_fraction", blue_fraction)
    k_max = integer_at_least("n_recirculations", n_recirculations, 1)
    nr = np.asarray(recirculation_number(centres, t_open, residence_time), dtype=float)
    sigma_in2 = p * (1.0 - p)
    vrr = np.full(k_max, np.nan)
    sigma_out = np.full(k_max, np.nan)
    n_windows = np.zeros(k_max, dtype=np.int64)
    for k in range(1, k_max + 1):
        vrr[k - 1], sigma_out[k - 1], n_windows[k - 1] = variance_reduction(c[(nr >= k - 1) & (nr < k)], p)
    return RecirculationVRR(
        recirculation_number=np.arange(1, k_max + 1) - 0.5,
        vrr=vrr,
        sigma_out=sigma_out,
        n_windows=n_windows,
        sigma_in=math.sqrt(sigma_in2),
        blue_fraction=p,
    )


def variance_reduction(concentration, blue_fraction: float) -> tuple[float, float, int]:
    """``(VRR, sigma_out, N)`` of one set of window concentrations: ``p (1 - p) / var(c)`` over the ``N`` windows
    that are not NaN, with the population standard deviation ``sigma_out`` of their concentrations [-]; inf without
    variance, NaN (VRR and sigma_out) with fewer than 2 windows."""
    values = np.asarray(concentration, dtype=float)
    values = values[np.isfinite(values)]
    if values.size < 2:
        return math.nan, math.nan, int(values.size)
    variance = float(np.var(values))
    p = float(blue_fraction)
    return (math.inf if variance == 0.0 else p * (1.0 - p) / variance), math.sqrt(variance), int(values.size)


def vrr_standard_error(vrr, n_windows):
    """Standard error of a VRR measured from ``N`` outlet windows: ``sqrt(2 / (N - 1)) VRR`` [-].

    Assumption: the ``N`` window concentrations of the recirculation are independent, normally distributed
    draws about a common mean. The sample variance of ``N`` such values has the relative standard error
    ``sqrt(2 / (N - 1))`` (its distribution is ``sigma^2 chi^2_(N-1) / (N - 1)``), and ``VRR = sigma_in^2 /
    sigma_out^2`` inherits it to first order. Neighbouring windows of a slowly varying outflow are correlated
    and the concentration drifts within a recirculation, so the effective number of independent windows is
    smaller than ``N`` and the error is then a lower estimate. It says nothing about the counting-noise
    ceiling: a VRR near it is a lower bound whatever its error
    (:meth:`RecirculationVRR.at_ceiling`).

    Parameters
    ----------
    vrr : float or array_like
        VRR(s), >= 0, NaN (no VRR) or inf (no output variance) [-].
    n_windows : int or array_like
        Windows behind each VRR, integers >= 0 [-]; broadcast with ``vrr``.

    Returns
    -------
    float or numpy.ndarray
        The error [-] (a float for scalars); NaN where ``N < 2`` or the VRR is NaN or inf.

    Raises
    ------
    ValueError
        On a negative VRR, a window count that is negative or not an integer, or shapes that do not
        broadcast.
    """
    values = np.asarray(vrr, dtype=float)
    if np.any(values < 0.0):
        raise ValueError("vrr must be >= 0 (NaN for no VRR, inf for no output variance)")
    counts = np.asarray(n_windows, dtype=float)
    if np.any(~np.isfinite(counts)) or np.any(counts < 0.0) or np.any(counts != np.round(counts)):
        raise ValueError("n_windows must hold integers >= 0 (windows per recirculation)")
    try:
        values, counts = np.broadcast_arrays(values, counts)
    except ValueError:
        raise ValueError(f"vrr and n_windows must broadcast together, got shapes {values.shape} and "
                         f"{counts.shape}") from None
    known = np.isfinite(values) & (counts >= 2.0)
    error = np.full(values.shape, np.nan)
    error[known] = np.sqrt(2.0 / (counts[known] - 1.0)) * values[known]
    return float(error) if error.ndim == 0 else error


def sampling_noise_vrr_limit(blue_fraction: float, particles_per_window: float) -> float:
    """Largest VRR measurable with ``n`` particles per window: ``p (1 - p) / (p (1 - p) / n) = n`` [-].

    A perfectly mixed outflow still gives window concentrations with the binomial variance
    ``p (1 - p) / n``, so ``sigma_in^2`` over it, i.e. ``n``, is the VRR of perfect mixing as measured
    (a reference line for plots of :func:`vrr_by_recirculation`). The counting-noise ceiling of
    :func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling` for a 0/1 batch input, kept under this name for its callers.

    Parameters
    ----------
    blue_fraction : float
        Blue fraction ``p``, in (0, 1) [-].
    particles_per_window : float
        Mean outlet crossings per window ``n``, > 0 [-]
        (:attr:`siloflow.analysis.studies.silo_recirculation.concentration.OutletConcentration.mean_crossings`).

    Returns
    -------
    float
        The VRR limit [-].
    """
    p = open_fraction("blue_fraction", blue_fraction)
    n = positive_number("particles_per_window", particles_per_window)  # checked here to name the caller's argument
    return vrr_ceiling(n, p * (1.0 - p), p)
