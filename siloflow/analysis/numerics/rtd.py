"""Residence time distributions (RTD) of a silo: from tracer exit times, from tabulated curves, and models.

Pure functions on numpy arrays; no file I/O. SI units: times in s, E in 1/s.

Definitions (Danckwerts; the blending study of thesis ch. 6)
---------------------------------------------------------------------
A tracer of ``N0`` particles (or virtual tracers) enters at ``t_entry``; particle ``i`` leaves at
``t_exit_i`` and its residence time is ``tau_i = t_exit_i - t_entry_i``. Then

- ``E(t) = (1 / N0) dN/dt`` [1/s], the exit-age density; ``integral E dt`` is the fraction of the
  tracer that has left (1 once all of it has left);
- ``t_m`` the mean residence time and ``sigma^2`` its variance [s, s^2];
- ``theta = t / t_m`` and ``E(theta) = t_m E(t)`` the dimensionless forms
  (``integral E(theta) dtheta = integral E dt``);
- ``t_s / t_d``: first appearance ``t_s`` (shortest residence time) over the time ``t_d`` needed to
  discharge all of the tracer (longest residence time). 1 for plug flow, 0 for a perfect mixer.

Models: the perfect mixer ``E = exp(-t/tau)/tau``, plug flow (a narrow pulse at ``tau``) and
a triangular reading of Johanson's two-parameter blending model. Carson and Royal's recycling of a
measured first-pass curve (repeated convolution) is :func:`siloflow.analysis.numerics.lti.carson_royal_recycle`.

Uncertainty of a measured RTD: :attr:`RTD.t_mean_error` here; the statistics of tracer residence times (means
with their errors, first and last appearance) are in :mod:`siloflow.analysis.numerics.residence_statistics`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import trapezoid

from siloflow.model.checks import finite_array, positive_number

__all__ = [
    "RTD",
    "RTDMoments",
    "rtd_from_exit_times",
    "rtd_moments",
    "perfect_mixer_rtd",
    "plug_flow_rtd",
    "johanson_rtd",
]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True, eq=False)
class RTD:
    """Residence time distribution measured from tracer exit times.

    Attributes
    ----------
    time : numpy.ndarray, shape (n_bins,)
        Bin centres of residence time [s].
    edges : numpy.ndarray, shape (n_bins + 1,)
        Bin edges of residence time [s].
    E : numpy.ndarray, shape (n_bins,)
        Exit-age density ``(1 / N0) dN/dt`` per bin [1/s]: ``sum(E * widths)`` equals
        :attr:`fraction_exited`.
    t_mean : float
        Mean residence time ``t_m`` of the tracers that left, from the sample itself (not from the
        histogram) [s].
    variance : float
        Variance of the residence times of the tracers that left, from the sample (population
        variance, ``ddof = 0``) [s^2].
    t_first : float
        First appearance ``t_s``: the shortest residence time [s].
    t_last : float
        Time to discharge all the tracer ``t_d``: the longest residence time [s].
    n_exited : int
        Number of tracers that left.
    n_total : int
        Number of tracers injected ``N0``.
    """

    time: np.ndarray
    edges: np.ndarray
    E: np.ndarray
    t_mean: float
    variance: float
    t_first: float
    t_last: float
    n_exited: int
    n_total: int

    @property
    def widths(self) -> np.ndarray:
        """Bin widths [s]."""
        return np.diff(self.edges)

    @property
    def fraction_exited(self) -> float:
        """Fraction of the tracer that left, ``n_exited / n_total`` [-]."""
        return self.n_exited / self.n_total

    @property
    def theta(self) -> np.ndarray:
        """Dimensionless time ``t / t_m`` at the bin centres [-]."""
        return self.time / self.t_mean

    @property
    def E_theta(self) -> np.ndarray:
        """Dimensionless RTD ``E(theta) = t_m E(t)`` [-]."""
        return self.t_mean * self.E

    @property
    def sigma_theta2(self) -> float:
        """Dimensionless variance ``sigma^2 / t_m^2`` [-]."""
        return self.variance / self.t_mean**2

    @property
    def ts_over_td(self) -> float:
        """``t_s / t_d = t_first / t_last`` [-]."""
        return self.t_first / self.t_last

    @property
    def t_mean_error(self) -> float:
        """Standard error of :attr:`t_mean`, ``s / sqrt(n_exited)`` with the sample standard deviation ``s``
        (``ddof = 1``) of the residence times that left, i.e. ``sqrt(variance / (n_exited - 1))`` [s]; NaN for a
        single tracer. Assumes independent tracers (see :func:`siloflow.analysis.numerics.residence_statistics.mean_residence_time`)."""
        if self.n_exited < 2:
            return math.nan
        return math.sqrt(self.variance / (self.n_exited - 1))


@dataclass(frozen=True)
class RTDMoments:
    """Moments of a tabulated RTD curve (trapezoid rule).

    Attributes
    ----------
    area : float
        ``integral E dt`` [-] (the fraction of tracer the curve accounts for).
    mean : float
        Mean residence time ``integral t E dt / area`` [s].
    variance : float
        ``integral (t - mean)^2 E dt / area`` [s^2].
    """

    area: float
    mean: float
    variance: float

    @property
    def sigma_theta2(self) -> float:
        """Dimensionless variance ``variance / mean^2`` [-]."""
        return self.variance / self.mean**2


# --------------------------------------------------------------------------- measured RTD


def rtd_from_exit_times(exit_times, t_entry=0.0, bins=None, n_total: int | None = None) -> RTD:
    """RTD from the exit times of tracer particles (or virtual tracers).

    Parameters
    ----------
    exit_times : array_like, shape (n,)
        Time at which each tracer left the silo [s]. NaN marks a tracer that did not leave (it
        counts in ``n_total`` but not in the histogram or the moments); infinite values are
        rejected. :class:`siloflow.analysis.numerics.pathlines.PathlineResult` residence times (NaN for tracers that
        never exit) can be passed with ``t_entry = 0``.
    t_entry : float or array_like, shape (n,), optional
        Injection time, one for all tracers or one per tracer [s]; default 0. Residence times
        ``exit_times - t_entry`` must be >= 0.
    bins : None, int or array_like, optional
        ``None`` (default): numpy's ``"auto"`` number of equal bins over ``[0, t_last]``.
        An int: that many equal bins over ``[0, t_last]``. An array: increasing bin edges of
        residence time [s] that must cover ``[t_first, t_last]`` (unequal widths allowed).
    n_total : int, optional
        Number of tracers injected ``N0``, when more were injected than ``exit_times`` lists
        (e.g. only the ones that left were recorded). Default ``len(exit_times)``; so with no NaN
        and no ``n_total``, ``sum(E * widths) = 1``.

    Returns
    -------
    RTD
        ``E = counts / (N0 * width)`` per bin; mean, variance, first and last residence time from
        the sample.

    Raises
    ------
    ValueError
        On an empty or non-1-D ``exit_times``, infinite values, negative residence times, no tracer
        that left, bad ``bins`` or ``n_total`` smaller than the number of tracers that left.
    """
    exits = np.asarray(exit_times, dtype=float)
    if exits.ndim != 1 or exits.size == 0:
        raise ValueError(f"exit_times must be a non-empty 1-D array, got shape {exits.shape}")
    if np.any(np.isinf(exits)):
        raise ValueError("exit_times must not contain infinite values (use NaN for tracers that did not leave)")
    entry = np.asarray(t_entry, dtype=float)
    if entry.ndim == 0:
        entry = np.full(exits.shape, float(entry))
    if entry.shape != exits.shape:
        raise ValueError(f"t_entry must be a scalar or have shape {exits.shape}, got shape {entry.shape}")
    if not np.all(np.isfinite(entry)):
        raise ValueError("t_entry must contain only finite numbers")
    exited = np.isfinite(exits)
    n_exited = int(exited.sum())
    if n_exited == 0:
        raise ValueError("exit_times: no tracer left (all entries are NaN)")
    residence = exits[exited] - entry[exited]
    if np.any(residence < 0.0):
        raise ValueError("exit_times must not precede t_entry (negative residence time)")

    if n_total is None:
        total = int(exits.size)
    else:
        if isinstance(n_total, (bool, np.bool_)) or int(n_total) != n_total:
            raise ValueError(f"n_total must be an integer, got {n_total!r}")
        total = int(n_total)
        if total < n_exited:
            raise ValueError(f"n_total ({total}) must be >= the number of tracers that left ({n_exited})")

    t_first = float(residence.min())
    t_last = float(residence.max())
    if isinstance(bins, str):
        raise ValueError(f"bins must be None, an integer >= 1 or an array of edges, got {bins!r}")
    if bins is None or np.ndim(bins) == 0:
        if t_last <= 0.0:
            raise ValueError("exit_times: all residence times are 0; give bins as explicit edges")
        if bins is None:
            edges = np.histogram_bin_edges(residence, bins="auto", range=(0.0, t_last))
        else:
            if isinstance(bins, (bool, np.bool_)) or int(bins) != bins or int(bins) < 1:
                raise ValueError(f"bins must be None, an integer >= 1 or an array of edges, got {bins!r}")
            edges = np.linspace(0.0, t_last, int(bins) + 1)
    else:
        edges = finite_array("bins", bins, ndim=1)
        if edges.size < 2 or np.any(np.diff(edges) <= 0.0):
            raise ValueError("bins must be at least 2 strictly increasing edges")
        if edges[0] > t_first or edges[-1] < t_last:
            raise ValueError(
                f"bins must cover all residence times [{t_first!r}, {t_last!r}] s, "
                f"got edges from {edges[0]!r} to {edges[-1]!r}"
            )
    counts, edges = np.histogram(residence, bins=edges)
    widths = np.diff(edges)
    density = counts / (total * widths)
    return RTD(
        time=0.5 * (edges[1:] + edges[:-1]),
        edges=edges,
        E=density,
        t_mean=float(np.mean(residence)),
        variance=float(np.var(residence)),
        t_first=t_first,
        t_last=t_last,
        n_exited=n_exited,
        n_total=total,
    )


def rtd_moments(time, E) -> RTDMoments:
    """Area, mean and variance of a tabulated RTD curve by the trapezoid rule.

    Parameters
    ----------
    time : array_like, shape (n,)
        Residence times, strictly increasing [s] (any spacing).
    E : array_like, shape (n,)
        RTD values at ``time`` [1/s]; need not be normalised (the moments are divided by the area).

    Returns
    -------
    RTDMoments

    Raises
    ------
    ValueError
        If the arrays differ in shape, are not finite, ``time`` is not increasing, or the area is
        not positive.
    """
    t = finite_array("time", time, ndim=1)
    e = finite_array("E", E, ndim=1)
    if e.shape != t.shape:
        raise ValueError(f"E must have the shape of time {t.shape}, got {e.shape}")
    if t.size < 2 or np.any(np.diff(t) <= 0.0):
        raise ValueError("time must have at least 2 strictly increasing samples")
    area = float(trapezoid(e, t))
    if not area > 0.0:
        raise ValueError(f"E must have a positive area, got {area!r}")
    mean = float(trapezoid(t * e, t)) / area
    variance = float(trapezoid((t - mean) ** 2 * e, t)) / area
    return RTDMoments(area=area, mean=mean, variance=variance)


# --------------------------------------------------------------------------- models


def perfect_mixer_rtd(t, tau: float) -> np.ndarray:
    """RTD of a perfect mixer (continuous stirred tank): ``E = exp(-t / tau) / tau`` for t >= 0, else 0.

    Parameters
    ----------
    t : array_like
        Residence times [s].
    tau : float
        Mean residence time [s], > 0.

    Returns
    -------
    numpy.ndarray
        ``E(t)`` [1/s], the shape of ``t``.
    """
    tau = positive_number("tau", tau)
    t = finite_array("t", t, ndim=None)
    return np.where(t >= 0.0, np.exp(-np.maximum(t, 0.0) / tau) / tau, 0.0)


def plug_flow_rtd(t, tau: float, width: float | None = None) -> np.ndarray:
    """Plug flow as a narrow normalised pulse: a Gaussian of standard deviation ``width`` centred at ``tau``.

    Ideal plug flow is a Dirac pulse ``delta(t - tau)``; on a time grid it is represented by the
    Gaussian ``exp(-(t - tau)^2 / (2 width^2)) / (sqrt(2 pi) width)``, normalised analytically
    (unit area over the real line). Sampled with a step ``dt <= width`` and ``tau`` several widths
    away from the ends of the grid, the discrete sum ``sum(E) dt`` is 1 to better than 1e-8 (Poisson
    summation: the error is about ``2 exp(-2 pi^2 width^2 / dt^2)``). As a filter it damps a sine of
    angular frequency ``w`` by ``exp(-w^2 width^2 / 2)``.

    Parameters
    ----------
    t : array_like, shape (n,)
        Residence times [s].
    tau : float
        Plug-flow residence time (the position of the pulse) [s], > 0.
    width : float, optional
        Standard deviation of the pulse [s], > 0. Default: the smallest step of ``t`` (the
        narrowest pulse the grid resolves; ``t`` must then have at least 2 samples).

    Returns
    -------
    numpy.ndarray
        ``E(t)`` [1/s], the shape of ``t``.
    """
    tau = positive_number("tau", tau)
    t = finite_array("t", t, ndim=None)
    if width is None:
        flat = np.sort(t.ravel())
        steps = np.diff(flat)
        steps = steps[steps > 0.0]
        if steps.size == 0:
            raise ValueError("width: give it explicitly when t has fewer than 2 distinct samples")
        width = float(steps.min())
    width = positive_number("width", width)
    return np.exp(-0.5 * ((t - tau) / width) ** 2) / (math.sqrt(2.0 * math.pi) * width)


def johanson_rtd(t, tau: float, V1: float, P: float) -> np.ndarray:
    """Johanson's two-parameter blending RTD, in its triangular form.

    Johanson's in-bin blending model describes the outflow of a bin by the fraction of the
    throughput discharged before the first tracer appears and by where the outflow of the
    tracer peaks. The definition used here (documented because the model is quoted in several
    forms) works in the throughput ``theta = t / tau = V_discharged / V_bin``:

    - ``V1``: first appearance, the volume discharged before the tracer appears, as a fraction of
      the bin volume (``0 <= V1 < 1``);
    - ``P``: the mode, the throughput at which the outflow concentration peaks (``P >= V1``);
    - the tracer is all out at ``theta_end = 3 - V1 - P``, which makes the mean residence time
      exactly ``tau`` (the mean residence time theorem ``t_m = V / Q``); hence
      ``P <= (3 - V1) / 2`` so that the peak is not after the end.

    ``E(theta)`` is the triangle rising linearly from 0 at ``V1`` to its peak at ``P`` and falling to 0
    at ``theta_end`` (unit area); ``E(t) = E(theta) / tau``. Mass flow (narrow RTD) has ``V1`` near 1
    and ``P`` near 1; funnel flow has an early first appearance (small ``V1``) and a long tail.
    ``P = V1`` gives a jump at first appearance followed by a linear decay.

    Parameters
    ----------
    t : array_like
        Residence times [s].
    tau : float
        Mean residence time ``V_bin / Q`` [s], > 0.
    V1 : float
        First-appearance throughput fraction, ``0 <= V1 < 1`` [-].
    P : float
        Throughput fraction at the peak, ``V1 <= P <= (3 - V1) / 2`` [-].

    Returns
    -------
    numpy.ndarray
        ``E(t)`` [1/s], the shape of ``t``; variance ``tau^2 (a^2 + b^2 + c^2 - ab - ac - bc) / 18``
        with ``a = V1, c = P, b = 3 - V1 - P``.
    """
    tau = positive_number("tau", tau)
    t = finite_array("t", t, ndim=None)
    v1 = float(V1)
    p = float(P)
    if not math.isfinite(v1) or not 0.0 <= v1 < 1.0:
        raise ValueError(f"V1 must be a number in [0, 1), got {V1!r}")
    end = 3.0 - v1 - p
    if not math.isfinite(p) or p < v1 or p > end:
        raise ValueError(f"P must be a number in [V1, (3 - V1) / 2] = [{v1!r}, {(3.0 - v1) / 2.0!r}], got {P!r}")
    theta = t / tau
    base = end - v1
    e_theta = np.zeros_like(theta)
    if p > v1:
        rising = (theta >= v1) & (theta < p)
        e_theta[rising] = 2.0 * (theta[rising] - v1) / (base * (p - v1))
    if end > p:
        falling = (theta >= p) & (theta <= end)
        e_theta[falling] = 2.0 * (end - theta[falling]) / (base * (end - p))
    return e_theta / tau
