"""Uncertainty of the headline figures: counting noise, batch means of a steady window, spread over seeds.

Pure functions on numbers and numpy arrays; no file I/O. Every error is a standard error (one standard
deviation of the estimate) in the unit of the value it belongs to; NaN means "not known" (e.g. the spread of a
single seed) and is never replaced by zero.

Sources of uncertainty
----------------------
Counting noise
    A count ``N`` of independent events has the Poisson error ``sqrt(N)`` (:func:`counting_error`); a fraction
    ``k / n`` of ``n`` independent draws has the binomial error ``sqrt(p (1 - p) / n)``
    (:func:`proportion_error`, and Wilson's interval from :func:`scipy.stats.binomtest` in
    :func:`proportion_interval`).
Batch means of one run
    The samples of a steady time series are correlated, so ``std / sqrt(n_samples)`` underestimates the error
    of their mean. Cutting the series into a few long, non-overlapping batches whose means are nearly
    independent gives ``std(batch means, ddof=1) / sqrt(n_batches)`` (:func:`batch_means`; for a rate, the
    slopes of a cumulative signal, :func:`batch_rate`). The batches must be longer than the correlation time
    of the series; 10 to 20 batches is the usual compromise.
Spread over seeds
    Runs that differ only in their random seed are independent samples: mean, sample standard deviation and
    standard error of the mean (:func:`seed_spread`).
The counting-noise ceiling of a variance reduction ratio is in :mod:`siloflow.analysis.numerics.vrr_noise`.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from siloflow.model.checks import finite_array, finite_number, increasing_times, positive_number

__all__ = [
    "batch_count",
    "Estimate",
    "SeedSpread",
    "Significance",
    "format_estimate",
    "batch_means",
    "batch_rate",
    "counting_error",
    "proportion_error",
    "proportion_interval",
    "seed_spread",
    "combine_independent",
    "difference_significant",
    "line_slope",
]


def format_estimate(value: float, error: float, digits: int = 2) -> str:
    """A value with its uncertainty, the uncertainty rounded to ``digits`` significant digits and the value to
    the same decimal place: ``format_estimate(0.11682, 0.00213)`` gives ``"0.1168 ± 0.0021"``.

    Values whose uncertainty is below 1e-4 or at least 1e5 (in their unit) share one power of ten:
    ``"(3.20 ± 0.11)e-07"``.

    Parameters
    ----------
    value : float
        The estimate, in any unit. A non-finite value is written as it is (``"nan ± 0.1"``).
    error : float
        Its standard error, in the unit of ``value``: >= 0, or NaN for unknown (written ``"± unknown"``, the
        value then with 4 significant digits). Zero is written ``"± 0"`` after the value as it is.
    digits : int, optional
        Significant digits of the uncertainty, >= 1.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        If ``error`` is negative or infinite or ``digits`` is not an integer >= 1.
    """
    if isinstance(digits, bool) or not isinstance(digits, (int, np.integer)) or digits < 1:
        raise ValueError(f"digits must be an integer >= 1, got {digits!r}")
    value, error = float(value), float(error)
    if math.isnan(error):
        return f"{value:.4g} ± unknown"
    if math.isinf(error) or error < 0.0:
        raise ValueError(f"error must be a finite number >= 0 or NaN (unknown), got {error!r}")
    if error == 0.0:
        return f"{value:g} ± 0"
    if not math.isfinite(value):
        return f"{value:g} ± {error:.{digits}g}"
    exponent = math.floor(math.log10(error))
    # Rounding may carry into the next decade (0.0996 -> 0.10): count the digits from the rounded error.
    if round(error, digits - 1 - exponent) >= 10.0 ** (exponent + 1):
        exponent += 1
    if -4 <= exponent < 5:
        places = digits - 1 - exponent  # negative: round to tens, hundreds, ...
        decimals = max(0, places)
        # + 0.0 turns a value rounded to -0 into 0
        return f"{round(value, places) + 0.0:.{decimals}f} ± {round(error, places):.{decimals}f}"
    shared = math.floor(math.log10(abs(value))) if abs(value) >= error else exponent
    scale = 10.0 ** shared
    decimals = max(0, digits - 1 - (exponent - shared))
    return f"({value / scale:.{decimals}f} ± {error / scale:.{decimals}f})e{shared:+03d}"


@dataclass(frozen=True)
class Estimate:
    """A value with its standard error, and where the error comes from.

    Attributes
    ----------
    value : float
        The estimate, in its own unit (finite).
    std_error : float
        Standard error of ``value``, same unit; >= 0, or NaN when it is not known (e.g. one seed).
    n : int
        Independent units behind the error, >= 1: batches, seeds, or the count itself for counting noise.
    method : str
        How the error was obtained: ``"batch means"``, ``"batch rate"``, ``"counting"``, ``"binomial"``,
        ``"seeds"``, ...
    dof : float, optional
        Degrees of freedom of ``std_error`` (``n - 1`` when it is a sample standard deviation); ``inf`` when it
        comes from a model (Poisson, binomial), so that :meth:`interval` uses normal quantiles.
    """

    value: float
    std_error: float
    n: int
    method: str
    dof: float = math.inf

    def __post_init__(self):
        object.__setattr__(self, "value", finite_number("value", self.value))
        error = float(self.std_error)
        if not (math.isnan(error) or (math.isfinite(error) and error >= 0.0)):
            raise ValueError(f"std_error must be a finite number >= 0 or NaN (unknown), got {error!r}")
        object.__setattr__(self, "std_error", error)
        if isinstance(self.n, bool) or not isinstance(self.n, (int, np.integer)) or self.n < 1:
            raise ValueError(f"n must be an integer >= 1 (batches, seeds or counts), got {self.n!r}")
        object.__setattr__(self, "n", int(self.n))
        if not isinstance(self.method, str) or not self.method.strip():
            raise ValueError(f"method must be a non-empty label such as 'batch means', got {self.method!r}")
        dof = float(self.dof)
        if not dof > 0.0:
            raise ValueError(f"dof must be > 0 (inf for a model error), got {self.dof!r}")
        object.__setattr__(self, "dof", dof)

    def format(self, digits: int = 2) -> str:
        """``"value ± error"`` with the error to ``digits`` significant digits (:func:`format_estimate`)."""
        return format_estimate(self.value, self.std_error, digits)

    def interval(self, confidence: float = 0.95) -> tuple[float, float]:
        """Two-sided confidence interval ``value -+ q std_error``, in the unit of ``value``.

        ``q`` is the Student t quantile with :attr:`dof` degrees of freedom (:data:`scipy.stats.t`), the normal
        one for ``dof = inf``. An unknown error gives ``(nan, nan)``.

        Parameters
        ----------
        confidence : float, optional
            Confidence level, in (0, 1) [-].
        """
        confidence = float(confidence)
        if not 0.0 < confidence < 1.0:
            raise ValueError(f"confidence must be a number in (0, 1), got {confidence!r}")
        if math.isnan(self.std_error):
            return (math.nan, math.nan)
        quantile = float(stats.t.ppf(0.5 + 0.5 * confidence, self.dof))
        return (self.value - quantile * self.std_error, self.value + quantile * self.std_error)


def batch_count(n_batches) -> int:
    """``n_batches`` as an int, refusing anything but an integer >= 2 (one batch gives no spread)."""
    if isinstance(n_batches, bool) or not isinstance(n_batches, (int, np.integer)) or n_batches < 2:
        raise ValueError(f"n_batches must be an integer >= 2 (one batch gives no spread), got {n_batches!r}")
    return int(n_batches)


def batch_means(series, n_batches: int = 10) -> Estimate:
    """Mean of a stationary time series and its standard error from non-overlapping batch means.

    The series is cut into ``n_batches`` contiguous batches of ``b = len(series) // n_batches`` samples; the
    first ``len(series) % n_batches`` samples (the oldest, closest to any start-up) are left out. The value is
    the mean of the batch means and its standard error ``std(batch means, ddof=1) / sqrt(n_batches)``. The
    batches must be longer than the correlation time of the series for the error to be honest.

    Parameters
    ----------
    series : array_like, shape (n,)
        Equally spaced samples of a steady signal, finite, in any unit.
    n_batches : int, optional
        Number of batches, >= 2 and <= n.

    Returns
    -------
    Estimate
        ``method="batch means"``, ``n = n_batches``, ``dof = n_batches - 1``; value and error in the unit of
        ``series``.

    Raises
    ------
    ValueError
        If ``series`` is not 1-D and finite, ``n_batches`` is not an integer >= 2, or there are fewer samples
        than batches.
    """
    values = finite_array("series", series, ndim=1)
    n_batches = batch_count(n_batches)
    if values.size < n_batches:
        raise ValueError(f"series has {values.size} samples, too few for {n_batches} batches (at least one "
                         f"sample per batch)")
    size = values.size // n_batches
    means = values[values.size - size * n_batches:].reshape(n_batches, size).mean(axis=1)
    return Estimate(value=float(means.mean()), std_error=float(means.std(ddof=1) / math.sqrt(n_batches)),
                    n=n_batches, method="batch means", dof=n_batches - 1)


def batch_rate(time, cumulative, n_batches: int = 10) -> Estimate:
    """Rate (slope) of a cumulative signal over a steady window, and its standard error from batch slopes.

    The samples are cut into ``n_batches`` contiguous, non-overlapping batches of ``b = n // n_batches``
    samples (the first ``n % n_batches`` samples left out); each batch gives the least-squares slope of
    ``cumulative`` against ``time``. The value is the mean of the batch slopes and its standard error
    ``std(batch slopes, ddof=1) / sqrt(n_batches)`` (batch means of the rate). E.g. the discharged mass [kg]
    against time [s] gives the mass flow rate [kg/s] with its error.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], finite and strictly increasing (not necessarily uniform).
    cumulative : array_like, shape (n,)
        The cumulative signal at those times, finite, in any unit ``U``.
    n_batches : int, optional
        Number of batches, >= 2, with ``n >= 2 n_batches`` (two samples per slope).

    Returns
    -------
    Estimate
        Rate and error [U/s]; ``method="batch rate"``, ``n = n_batches``, ``dof = n_batches - 1``.

    Raises
    ------
    ValueError
        On arrays of different shape, non-finite values, times not strictly increasing, ``n_batches`` not an
        integer >= 2, or fewer than two samples per batch.
    """
    t = finite_array("time", time, ndim=1)
    y = finite_array("cumulative", cumulative, ndim=1)
    if y.shape != t.shape:
        raise ValueError(f"cumulative must have the shape of time {t.shape}, got {y.shape}")
    increasing_times("time", t)
    n_batches = batch_count(n_batches)
    if t.size < 2 * n_batches:
        raise ValueError(f"time has {t.size} samples, too few for {n_batches} batches (at least two samples per "
                         f"batch slope)")
    size = t.size // n_batches
    start = t.size - size * n_batches
    tb = t[start:].reshape(n_batches, size)
    yb = y[start:].reshape(n_batches, size)
    dt = tb - tb.mean(axis=1, keepdims=True)
    slopes = (dt * (yb - yb.mean(axis=1, keepdims=True))).sum(axis=1) / (dt * dt).sum(axis=1)
    return Estimate(value=float(slopes.mean()), std_error=float(slopes.std(ddof=1) / math.sqrt(n_batches)),
                    n=n_batches, method="batch rate", dof=n_batches - 1)


def counting_error(count):
    """Poisson standard error of a count of independent events, ``sqrt(N)`` [counts].

    Parameters
    ----------
    count : float or array_like
        Count(s) ``N`` >= 0 (expected counts need not be integers) [-].

    Returns
    -------
    float or numpy.ndarray
        ``sqrt(N)``, the shape of ``count`` (a float for a scalar).

    Raises
    ------
    ValueError
        If a count is negative or not finite.
    """
    counts = finite_array("count", count, ndim=None)
    if np.any(counts < 0.0):
        raise ValueError("count must be >= 0 (a number of events)")
    error = np.sqrt(counts)
    return float(error) if error.ndim == 0 else error


def _draws(k, n) -> tuple[np.ndarray, np.ndarray]:
    """``k`` and ``n`` as float arrays of integers with ``0 <= k <= n`` and ``n >= 1``, broadcast together."""
    successes = finite_array("k", k, ndim=None)
    trials = finite_array("n", n, ndim=None)
    if np.any(trials < 1.0) or np.any(trials != np.round(trials)):
        raise ValueError("n must be an integer >= 1 (number of draws)")
    if np.any(successes != np.round(successes)):
        raise ValueError("k must be an integer (number of successes)")
    try:
        successes, trials = np.broadcast_arrays(successes, trials)
    except ValueError:
        raise ValueError(f"k and n must broadcast together, got shapes {successes.shape} and {trials.shape}") from None
    if np.any(successes < 0.0) or np.any(successes > trials):
        raise ValueError("k must be in [0, n] (successes among n draws)")
    return successes, trials


def proportion_error(k, n):
    """Binomial standard error of a proportion ``p = k / n``: ``sqrt(p (1 - p) / n)`` [-].

    It is 0 for ``k = 0`` or ``k = n``; use :func:`proportion_interval` there.

    Parameters
    ----------
    k : int or array_like
        Successes (e.g. blue particles in a window), integers in ``[0, n]`` [-].
    n : int or array_like
        Draws (particles in the window), integers >= 1 [-]; broadcast with ``k``.

    Returns
    -------
    float or numpy.ndarray
        The standard error of ``k / n`` [-] (a float for scalars).

    Raises
    ------
    ValueError
        If ``n`` is not an integer >= 1 or ``k`` not an integer in ``[0, n]``.
    """
    successes, trials = _draws(k, n)
    p = successes / trials
    error = np.sqrt(p * (1.0 - p) / trials)
    return float(error) if error.ndim == 0 else error


def proportion_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a proportion ``k / n`` (:meth:`scipy.stats.binomtest` ``proportion_ci``) [-].

    Unlike ``p -+ q`` :func:`proportion_error`, it stays inside [0, 1] and has a width for ``k = 0`` or ``n``.

    Parameters
    ----------
    k, n : int
        Successes in ``[0, n]`` and draws >= 1 [-].
    confidence : float, optional
        Confidence level, in (0, 1) [-].

    Returns
    -------
    tuple of float
        ``(low, high)`` [-].
    """
    successes, trials = _draws(k, n)
    if successes.ndim != 0:
        raise ValueError(f"k and n must be single numbers, got shape {successes.shape}")
    confidence = float(confidence)
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be a number in (0, 1), got {confidence!r}")
    ci = stats.binomtest(int(successes), int(trials)).proportion_ci(confidence_level=confidence, method="wilson")
    return (float(ci.low), float(ci.high))


@dataclass(frozen=True)
class SeedSpread:
    """The spread of one figure over runs that differ only in their seed (:func:`seed_spread`).

    Attributes
    ----------
    mean : float
        Mean over the seeds, in the unit of the figure.
    std : float
        Sample standard deviation (``ddof = 1``), same unit; NaN for one seed.
    std_error : float
        Standard error of the mean, ``std / sqrt(n)``, same unit; NaN for one seed.
    n : int
        Number of seeds, >= 1.
    """

    mean: float
    std: float
    std_error: float
    n: int

    def estimate(self) -> Estimate:
        """The mean as an :class:`Estimate` (``method="seeds"``, ``dof = n - 1``; ``dof`` is inf for one seed,
        whose error is NaN anyway)."""
        return Estimate(value=self.mean, std_error=self.std_error, n=self.n, method="seeds",
                        dof=self.n - 1 if self.n > 1 else math.inf)


def seed_spread(values) -> SeedSpread:
    """Mean, sample standard deviation and standard error of the mean of one figure over N seeds.

    A single seed gives its value as the mean and NaN (unknown), not zero, for the standard deviation and the
    standard error: one run says nothing about the spread.

    Parameters
    ----------
    values : array_like, shape (N,)
        The figure from each seed, finite, N >= 1, in any unit (a failed seed must be left out, not passed as
        NaN).

    Returns
    -------
    SeedSpread
        In the unit of ``values``.

    Raises
    ------
    ValueError
        If ``values`` is empty, not 1-D or holds a non-finite value.
    """
    array = finite_array("values", values, ndim=1)
    if array.size == 0:
        raise ValueError("values must hold the figure of at least one seed")
    if array.size == 1:
        return SeedSpread(mean=float(array[0]), std=math.nan, std_error=math.nan, n=1)
    std = float(array.std(ddof=1))
    return SeedSpread(mean=float(array.mean()), std=std, std_error=std / math.sqrt(array.size), n=int(array.size))


def combine_independent(errors) -> float:
    """Standard error of a sum or difference of independent estimates, ``sqrt(sum e_i^2)``.

    Parameters
    ----------
    errors : array_like, shape (m,)
        Standard errors in one common unit, each >= 0 or NaN (unknown), m >= 1.

    Returns
    -------
    float
        The combined error, in that unit; NaN when any error is unknown.

    Raises
    ------
    ValueError
        If ``errors`` is empty, not 1-D, or holds a negative or infinite value.
    """
    array = np.asarray(errors, dtype=float)
    if array.ndim != 1 or array.size == 0:
        raise ValueError(f"errors must be a non-empty 1-D list of standard errors, got shape {array.shape}")
    known = array[~np.isnan(array)]
    if np.any(np.isinf(known)) or np.any(known < 0.0):
        raise ValueError("errors must be finite numbers >= 0 or NaN (unknown)")
    if known.size < array.size:
        return math.nan
    return float(np.sqrt(np.sum(array * array)))


class Significance(str, enum.Enum):
    """Outcome of :func:`difference_significant`; the values are the labels tables print.

    Members have no truth value (``if result:`` raises): an unknown outcome must not pass silently as "not
    significant", so compare with a member.
    """

    SIGNIFICANT = "significant"
    NOT_SIGNIFICANT = "not significant"
    UNKNOWN = "unknown"

    def __bool__(self):
        raise TypeError("a Significance has no truth value; compare it with Significance.SIGNIFICANT")


def difference_significant(a: float, ua: float, b: float, ub: float, k: float = 2.0) -> Significance:
    """Whether two independent estimates differ by more than ``k`` combined standard errors.

    ``SIGNIFICANT`` if ``|a - b| > k sqrt(ua^2 + ub^2)`` (strictly), ``NOT_SIGNIFICANT`` otherwise, and
    ``UNKNOWN`` when either error is NaN: an unknown error (e.g. a single seed) can neither confirm nor rule out
    a difference.

    Parameters
    ----------
    a, b : float
        The two values, finite, in one common unit.
    ua, ub : float
        Their standard errors, same unit, >= 0 or NaN (unknown).
    k : float, optional
        Coverage factor, > 0 [-] (2: about 95 % for normal errors).

    Returns
    -------
    Significance

    Raises
    ------
    ValueError
        On a non-finite value, a negative or infinite error, or ``k <= 0``.
    """
    a = finite_number("a", a)
    b = finite_number("b", b)
    k = positive_number("k", k)
    for name, error in (("ua", ua), ("ub", ub)):
        error = float(error)
        if not (math.isnan(error) or (math.isfinite(error) and error >= 0.0)):
            raise ValueError(f"{name} must be a finite number >= 0 or NaN (unknown), got {error!r}")
    combined = combine_independent([ua, ub])
    if math.isnan(combined):
        return Significance.UNKNOWN
    return Significance.SIGNIFICANT if abs(a - b) > k * combined else Significance.NOT_SIGNIFICANT


def line_slope(x, y, sigma=None) -> tuple[float, float]:
    """Least-squares slope of ``y`` on ``x`` and its standard error (unit of y over unit of x).

    With ``sigma``, the standard errors of ``y`` (all finite and > 0), a fit weighted by them as known errors
    (:func:`numpy.polyfit`, unscaled covariance). Without, an unweighted fit whose error comes from the scatter about
    the line (:func:`scipy.stats.linregress`, ``n - 2`` degrees of freedom), NaN for two points.

    Parameters
    ----------
    x, y : array_like
        Equal 1-D arrays, ``x`` with two distinct values at least.
    sigma : array_like, optional
        Standard error of each ``y``.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.ndim != 1 or x.shape != y.shape or np.unique(x).size < 2:
        raise ValueError("x and y must be equal 1-D arrays with two distinct x at least")
    if sigma is not None:
        sigma = np.asarray(sigma, dtype=float)
        if sigma.shape != y.shape or not (np.all(np.isfinite(sigma)) and np.all(sigma > 0)):
            raise ValueError("sigma must be one finite standard error > 0 for each y")
        coefficients, covariance = np.polyfit(x, y, 1, w=1.0 / sigma, cov="unscaled")
        return float(coefficients[0]), float(math.sqrt(covariance[0, 0]))
    if x.size == 2:
        return float((y[1] - y[0]) / (x[1] - x[0])), math.nan
    fit = stats.linregress(x, y)
    return float(fit.slope), float(fit.stderr)
