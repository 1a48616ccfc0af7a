"""The recirculation number and the variance reduction ratio (VRR) of the outlet concentration, per recirculation.

Pure functions on numpy arrays; no file I/O. SI units: times in s; concentrations are blue fractions [-].

Recirculation number and VRR
----------------------------
``Nr = (t - t_open) / t_res`` with the mean residence time ``t_res`` = holdup / throughput
(Little's law, :func:`holdup_residence_time`). The windows of recirculation k are those with
``k - 1 <= Nr < k``; ``VRR_k = p (1 - p) / var(c)`` over them (:func:`vrr_by_recirculation`), the
input variance being that of the 0/1 batch with blue fraction ``p``.

Counting-noise ceiling
----------------------
Windows of ``n`` clumps cannot show a VRR above about ``n`` (:func:`analysis.numerics.uncertainty.vrr_ceiling`):
the binomial noise of the blue count is left even in a perfectly mixed outflow. A VRR within a factor 2 of the
ceiling (:meth:`RecirculationVRR.at_ceiling`) is a lower bound of the true VRR, not a measurement of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.checks import finite_array, finite_number, positive_number
from analysis.numerics.uncertainty import CEILING_FACTOR, vrr_ceiling, vrr_near_ceiling
from analysis.studies.silo_recirculation.validation import event_times, integer_at_least, open_fraction

__all__ = [
    "RecirculationVRR",
    "recirculation_number",
    "holdup_residence_time",
    "vrr_by_recirculation",
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
        """One dict per recirculation (for :func:`analysis.io.tables.write_flow_table`)."""
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

    def ceiling(self, clumps_per_window: float) -> float:
        """Counting-noise ceiling of these VRRs for windows of ``clumps_per_window`` clumps [-].

        :func:`analysis.numerics.uncertainty.vrr_ceiling` with the input variance of the 0/1 batch,
        ``p (1 - p)``: the ceiling is ``clumps_per_window`` itself.

        Parameters
        ----------
        clumps_per_window : float
            Outlet crossings per window ``n``, > 0 [-]
            (:func:`analysis.studies.silo_recirculation.tables.clumps_per_window`).
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
            (:func:`analysis.numerics.uncertainty.vrr_near_ceiling`).

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
    ``t_start <= t <= t_end``. In a steady flow it equals the mean pass residence time (re-entry to
    outlet) when the holdup counts the clumps above the outlet
    (:func:`analysis.studies.silo_recirculation.tracks.clumps_above_outlet`).

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
    holdup = finite_array("n_in_silo", n_in_silo, ndim=1)
    if holdup.size == 0:
        raise ValueError("n_in_silo must not be empty")
    if np.any(holdup < 0.0):
        raise ValueError("n_in_silo must contain counts >= 0")
    exits = event_times("exit_times", exit_times)
    t_start = finite_number("t_start", t_start)
    t_end = finite_number("t_end", t_end)
    if t_end <= t_start:
        raise ValueError(f"t_end must be > t_start = {t_start!r} s, got {t_end!r}")
    n_exits = int(np.count_nonzero((exits >= t_start) & (exits <= t_end)))
    if n_exits == 0:
        raise ValueError(f"exit_times: no outlet crossing in [t_start, t_end] = [{t_start!r}, {t_end!r}] s")
    return float(np.mean(holdup)) * (t_end - t_start) / n_exits


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
        Window centre times [s] (:attr:`analysis.studies.silo_recirculation.concentration.OutletConcentration.centres`).
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
        values = c[(nr >= k - 1) & (nr < k) & np.isfinite(c)]
        n_windows[k - 1] = values.size
        if values.size < 2:
            continue
        variance = float(np.var(values))
        sigma_out[k - 1] = math.sqrt(variance)
        vrr[k - 1] = math.inf if variance == 0.0 else sigma_in2 / variance
    return RecirculationVRR(
        recirculation_number=np.arange(1, k_max + 1) - 0.5,
        vrr=vrr,
        sigma_out=sigma_out,
        n_windows=n_windows,
        sigma_in=math.sqrt(sigma_in2),
        blue_fraction=p,
    )


def sampling_noise_vrr_limit(blue_fraction: float, particles_per_window: float) -> float:
    """Largest VRR measurable with ``n`` particles per window: ``p (1 - p) / (p (1 - p) / n) = n`` [-].

    A perfectly mixed outflow still gives window concentrations with the binomial variance
    ``p (1 - p) / n``, so ``sigma_in^2`` over it, i.e. ``n``, is the VRR of perfect mixing as measured
    (a reference line for plots of :func:`vrr_by_recirculation`). The counting-noise ceiling of
    :func:`analysis.numerics.uncertainty.vrr_ceiling` for a 0/1 batch input, kept under this name for its callers.

    Parameters
    ----------
    blue_fraction : float
        Blue fraction ``p``, in (0, 1) [-].
    particles_per_window : float
        Mean outlet crossings per window ``n``, > 0 [-]
        (:attr:`analysis.studies.silo_recirculation.concentration.OutletConcentration.mean_crossings`).

    Returns
    -------
    float
        The VRR limit [-].
    """
    p = open_fraction("blue_fraction", blue_fraction)
    n = positive_number("particles_per_window", particles_per_window)  # checked here to name the caller's argument
    return vrr_ceiling(n, p * (1.0 - p), p)
