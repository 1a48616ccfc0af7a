"""Bulk friction from Jenike direct shear force histories.

Pure functions on numpy arrays; no file I/O (readers and writers live at the edges).
All quantities are SI: forces in N, times in s; friction coefficients are
dimensionless and angles are in degrees unless a name says ``_rad``.

A Jenike shear simulation records, at sample times ``t``, the horizontal forces
along the shear direction on the lid ``F_lid(t)``, on the shear ring
``F_ring(t)`` and on the fixed bottom ring ``F_bottom(t)`` (as magnitudes along
the shear direction: the caller flips the sign of the reaction), the normal
force on the lid ``F_N`` and the weight ``W`` of the solids above the shear
plane. The bulk friction coefficient is

    ``mu = <F_lid + F_ring> / <F_N + W>``

averaged over the steady part of the shear (see :func:`detect_steady_window`),
and independently from the bottom side ``mu_bottom = <F_bottom> / <F_N + W>``;
the two must agree (force balance on the sheared sample). The contact diagnostics of the cell are
:mod:`siloflow.calibration.contact_diagnostics`; a shear test's record of its figures is
:mod:`siloflow.calibration.shear_record`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array
from siloflow.analysis.numerics.uncertainty import batch_means

__all__ = [
    "SteadyWindow",
    "BulkFriction",
    "detect_steady_window",
    "mean_and_standard_error",
    "bulk_friction",
    "friction_angle",
    "friction_angle_error",
    "friction_coefficient",
    "bulk_friction_of_shear",
    "STEADY",
    "SECOND_HALF",
]

#: How a shear test's window was chosen (:func:`bulk_friction_of_shear`).
STEADY, SECOND_HALF = "steady", "second half"


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class SteadyWindow:
    """Steady (plateau) part of a force history.

    Attributes
    ----------
    t_start, t_end : float
        Times of the first and of the last sample in the window [s].
    i_start, i_end : int
        Slice bounds of the window: the samples ``i_start <= i < i_end``.
    plateau : float
        Estimated plateau level of the signal the window was detected on
        (same unit as the signal, normally N).
    """

    t_start: float
    t_end: float
    i_start: int
    i_end: int
    plateau: float


@dataclass(frozen=True)
class BulkFriction:
    """Bulk friction of a sheared sample from the forces of a Jenike cell.

    Attributes
    ----------
    coefficient : float
        ``mu = <F_lid + F_ring> / <F_N + W>`` over the window [-].
    standard_error : float
        Standard error of ``coefficient`` (batch means, see
        :func:`mean_and_standard_error`) [-].
    bottom_coefficient : float
        ``mu_bottom = <F_bottom> / <F_N + W>`` over the window [-].
    bottom_standard_error : float
        Standard error of ``bottom_coefficient`` [-].
    angle_deg : float
        Bulk friction angle ``atan(mu)`` [deg].
    bottom_angle_deg : float
        ``atan(mu_bottom)`` [deg].
    window : SteadyWindow
        Samples used for the averages.
    relative_difference : float
        ``|mu - mu_bottom| / mu`` [-] (0 if both are 0, inf if only ``mu`` is 0).
    shear_force : float
        Mean ``F_lid + F_ring`` over the window [N].
    normal_load : float
        Mean ``F_N + W`` over the window [N].
    """

    coefficient: float
    standard_error: float
    bottom_coefficient: float
    bottom_standard_error: float
    angle_deg: float
    bottom_angle_deg: float
    window: SteadyWindow
    relative_difference: float
    shear_force: float
    normal_load: float

    @property
    def angle_standard_error_deg(self) -> float:
        """Standard error of ``angle_deg`` [deg] (:func:`friction_angle_error`)."""
        return friction_angle_error(self.coefficient, self.standard_error)


# --------------------------------------------------------------------------- validation


def _times(time) -> np.ndarray:
    time = finite_array("time", time)
    if time.size < 2:
        raise ValueError(f"time must contain at least 2 samples, got {time.size}")
    if np.any(np.diff(time) <= 0.0):
        raise ValueError("time must be strictly increasing")
    return time


def _history(name: str, values, n: int) -> np.ndarray:
    array = finite_array(name, values)
    if array.shape != (n,):
        raise ValueError(f"{name} must have the same length as time ({n}), got shape {array.shape}")
    return array


def _scalar_or_history(name: str, values, n: int) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,):
        raise ValueError(f"{name} must be a number or have the same length as time ({n}), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers")
    return array


def _fraction(name: str, value: float, allow_one: bool = True) -> float:
    value = float(value)
    upper_ok = value <= 1.0 if allow_one else value < 1.0
    if not (math.isfinite(value) and value > 0.0 and upper_ok):
        bound = "<= 1" if allow_one else "< 1"
        raise ValueError(f"{name} must be a number > 0 and {bound}, got {value!r}")
    return value


# --------------------------------------------------------------------------- steady window


def _batch_means(values: np.ndarray, cumulative: np.ndarray, start: int, n_batches: int) -> np.ndarray:
    """Means of ``n_batches`` consecutive batches that together cover ``values[start:]``, from prefix sums
    ``cumulative`` (``cumulative[i] = sum(values[:i])``); as :func:`numpy.array_split` cuts them, the first batches
    one sample longer where the samples do not divide evenly."""
    size, longer = divmod(values.size - start, n_batches)
    batches = np.arange(n_batches + 1)
    edges = start + batches * size + np.minimum(batches, longer)
    return np.diff(cumulative[edges]) / np.diff(edges)


def _unsteadiness(time: np.ndarray, signal: np.ndarray, cumulative_time: np.ndarray, cumulative_signal: np.ndarray,
                  start: int, n_batches: int) -> tuple[float, float]:
    """Level and unsteadiness of the window ``start:``: the larger of its drift and its batch means' largest
    distance from their line, relative to the level (see :func:`detect_steady_window`)."""
    centres = _batch_means(time, cumulative_time, start, n_batches)
    means = _batch_means(signal, cumulative_signal, start, n_batches)
    level = float(np.mean(means))
    if level == 0.0:
        return level, math.inf
    centred = centres - np.mean(centres)
    slope = float(np.dot(centred, means - level) / np.dot(centred, centred))
    drift = abs(slope) * (time[-1] - time[start])
    scatter = float(np.max(np.abs(means - level - slope * centred)))
    return level, max(drift, scatter) / abs(level)


def detect_steady_window(
    time,
    signal,
    start_after: float = 0.0,
    max_drift: float = 0.05,
    min_fraction: float = 0.25,
    n_batches: int = 10,
) -> SteadyWindow:
    """Find the steady part of a ramp-then-plateau force history: the longest final window without a trend.

    The shear force of a Jenike test rises while the sample is mobilised and then fluctuates about a steady
    level, often with stick-slip whose excursions exceed any useful band about the level; or it never levels
    off (a sample that keeps dilating, a shear too short); or it passes a peak and softens (a dense sample).
    Only the samples with ``time >= start_after`` are analysed. A candidate window runs from a sample to the
    last one; it is cut into ``n_batches`` consecutive batches covering it (as :func:`numpy.array_split` cuts
    them), and a least-squares line is fitted to the batch means against the batch mean times. Relative to the
    window's level (the mean of the batch means), its *drift* is the line's rise or fall over the window's
    duration and its *scatter* the largest distance of a batch mean from the line:

        ``drift = |slope| (t_end - t_start) / |level|``,
        ``scatter = max_j |mean_j - line(t_j)| / |level|``

    The steady window is the earliest (longest) candidate of at least ``min_fraction`` of the analysed
    samples whose drift and scatter are both at most ``max_drift``. Averaging over batches makes the test blind
    to fluctuations shorter than a batch (stick-slip); the drift sees a trend that a band about the final level
    would accept over a short window; the scatter sees a curve the line cannot follow, such as a rise and a
    fall whose line is level.

    Precision. On a linear signal ``a + b t`` the batch means lie on the same line (scatter 0), so the drift is
    exactly ``|b| (t_end - t_start) / |a + b t_mean|`` (``t_mean``: the mean of the batches' mean times). A
    window that takes in the end of a ramp is accepted only while the ramp's samples keep the first batch mean
    within ``max_drift`` of the line and the line within ``max_drift`` of level, so the window's mean is then
    biased by about ``max_drift / 5`` at most (1 % with the defaults), and by up to about ``max_drift / 4`` where
    a softening after a peak spreads over several batches.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times, strictly increasing [s].
    signal : array_like, shape (n,)
        Force history, e.g. ``F_lid + F_ring`` [N].
    start_after : float, optional
        Ignore samples before this time [s] (default 0).
    max_drift : float, optional
        Largest accepted drift and scatter of a window, relative to its level (default 0.05, i.e. 5 %).
    min_fraction : float, optional
        Smallest accepted window, as a fraction of the analysed samples (default 0.25).
    n_batches : int, optional
        Number of batches the line is fitted to (>= 3, default 10). A window holds at least two samples per
        batch.

    Returns
    -------
    SteadyWindow
        Window times [s], slice bounds and level (``plateau``, the mean of the batch means).

    Raises
    ------
    ValueError
        On malformed input; or (naming ``signal``) if no window of at least ``min_fraction`` of the analysed
        samples has a drift and a scatter of at most ``max_drift``, e.g. a force that keeps growing; the message
        gives the least unsteadiness found (the larger of the two).
    """
    time = _times(time)
    signal = _history("signal", signal, time.size)
    start_after = float(start_after)
    if not math.isfinite(start_after):
        raise ValueError(f"start_after must be a finite time, got {start_after!r}")
    max_drift = float(max_drift)
    if not (math.isfinite(max_drift) and max_drift > 0.0):
        raise ValueError(f"max_drift must be a finite number > 0, got {max_drift!r}")
    min_fraction = _fraction("min_fraction", min_fraction)
    if isinstance(n_batches, bool) or int(n_batches) != n_batches or n_batches < 3:
        raise ValueError(f"n_batches must be an integer >= 3, got {n_batches!r}")
    n_batches = int(n_batches)

    first = int(np.searchsorted(time, start_after, side="left"))
    analysed_time, analysed = time[first:], signal[first:]
    n_analysed = analysed.size
    shortest = max(math.ceil(min_fraction * n_analysed), 2 * n_batches)
    if shortest > n_analysed:
        raise ValueError(
            f"start_after = {start_after:.6g} s leaves {n_analysed} samples of signal; at least "
            f"{shortest} are needed ({2 * n_batches} for {n_batches} batches of two)"
        )
    cumulative_time = np.concatenate([[0.0], np.cumsum(analysed_time)])
    cumulative_signal = np.concatenate([[0.0], np.cumsum(analysed)])
    least = (math.inf, n_analysed)
    for start in range(n_analysed - shortest + 1):
        level, drift = _unsteadiness(analysed_time, analysed, cumulative_time, cumulative_signal, start, n_batches)
        if drift <= max_drift:
            i_start = first + start
            return SteadyWindow(t_start=float(time[i_start]), t_end=float(time[-1]), i_start=i_start,
                                i_end=int(time.size), plateau=level)
        least = min(least, (drift, n_analysed - start))
    raise ValueError(
        f"signal: no steady shear: every window of at least {100.0 * min_fraction:g} % of the {n_analysed} "
        f"samples after start_after = {start_after:.6g} s drifts or scatters by more than {100.0 * max_drift:g} % "
        f"of its level (least: {100.0 * least[0]:.3g} % over the last {least[1]} samples)"
    )


# --------------------------------------------------------------------------- statistics


def mean_and_standard_error(values, n_batches: int = 10) -> tuple[float, float]:
    """Mean of a (possibly autocorrelated) time series and its standard error.

    Successive samples of a shear force are correlated, so the naive error
    ``s / sqrt(n)`` is too small. The method of batch means is used instead:
    the series is cut into ``n_batches`` consecutive batches of ``b = n // n_batches``
    samples (the first ``n - n_batches * b`` samples, the ones nearest the
    transient, are left out of the batches); if the batches are longer than the
    correlation time their means are nearly independent, and the standard error
    is ``std(batch means, ddof=1) / sqrt(n_batches)``. With fewer than
    ``2 * n_batches`` values (20 by default) the naive error
    ``std(values, ddof=1) / sqrt(n)`` is returned. The mean is always the mean of
    all values.

    Parameters
    ----------
    values : array_like, shape (n,)
        The series, n >= 2.
    n_batches : int, optional
        Number of batches (>= 2, default 10).

    Returns
    -------
    tuple of float
        ``(mean, standard_error)`` in the unit of ``values``.
    """
    values = finite_array("values", values)
    if values.size < 2:
        raise ValueError(f"values must contain at least 2 numbers, got {values.size}")
    if isinstance(n_batches, bool) or int(n_batches) != n_batches or n_batches < 2:
        raise ValueError(f"n_batches must be an integer >= 2, got {n_batches!r}")
    n_batches = int(n_batches)

    n = values.size
    mean = float(np.mean(values))
    if n < 2 * n_batches:
        return mean, float(np.std(values, ddof=1)) / math.sqrt(n)
    return mean, batch_means(values, n_batches).std_error


# --------------------------------------------------------------------------- bulk friction


def _ratio_and_error(numerator: np.ndarray, denominator: np.ndarray) -> tuple[float, float]:
    """Ratio of means and its standard error (linearised: residuals ``x - r y``)."""
    mean_denominator = float(np.mean(denominator))
    ratio = float(np.mean(numerator)) / mean_denominator
    _, error = mean_and_standard_error(numerator - ratio * denominator)
    return ratio, error / mean_denominator


def bulk_friction(
    time,
    lid_force,
    ring_force,
    bottom_force,
    normal_force,
    weight_above,
    window: SteadyWindow | tuple[float, float] | None = None,
) -> BulkFriction:
    """Bulk friction coefficient from the forces of a Jenike direct shear test.

    ``mu = <F_lid + F_ring> / <F_N + W>`` and
    ``mu_bottom = <F_bottom> / <F_N + W>``, with ``<.>`` the mean over the steady
    window (a ratio of means, so a fluctuating measured normal force is
    averaged, not divided sample by sample). Standard errors are those of the
    ratio estimator: the batch-means error (:func:`mean_and_standard_error`) of
    the residuals ``F_t - mu (F_N + W)`` divided by ``<F_N + W>``; for a
    constant load this is the error of ``<F_t>`` divided by the load.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times, strictly increasing [s].
    lid_force, ring_force : array_like, shape (n,)
        Horizontal forces on the lid and on the shear ring along the shear
        direction [N].
    bottom_force : array_like, shape (n,)
        Horizontal force on the fixed bottom ring (or wall plate), as a
        magnitude along the shear direction [N].
    normal_force : float or array_like, shape (n,)
        Normal force F_N applied to the lid [N].
    weight_above : float or array_like, shape (n,)
        Weight W of the solids above the shear plane [N].
    window : SteadyWindow or tuple of float, optional
        Averaging window: a :class:`SteadyWindow` (its slice bounds are used)
        or ``(t0, t1)``, the samples with ``t0 <= t <= t1`` [s]. Default:
        :func:`detect_steady_window` on ``F_lid + F_ring`` with its defaults.

    Returns
    -------
    BulkFriction
        Coefficients, standard errors, angles [deg], window and the relative
        difference of the two estimates.

    Raises
    ------
    ValueError
        On malformed input, if ``F_N + W`` is not positive on average over the
        window, or if the window holds fewer than 2 samples.
    """
    time = _times(time)
    n = time.size
    lid = _history("lid_force", lid_force, n)
    ring = _history("ring_force", ring_force, n)
    bottom = _history("bottom_force", bottom_force, n)
    normal = _scalar_or_history("normal_force", normal_force, n)
    weight = _scalar_or_history("weight_above", weight_above, n)
    shear = lid + ring

    if window is None:
        window = detect_steady_window(time, shear)
    elif isinstance(window, SteadyWindow):
        if not (0 <= window.i_start and window.i_start + 2 <= window.i_end <= n):
            raise ValueError(
                f"window: slice [{window.i_start}, {window.i_end}) must hold at least 2 of the {n} samples"
            )
    else:
        if len(window) != 2:
            raise ValueError(f"window must be a SteadyWindow or (t0, t1), got {window!r}")
        t0, t1 = float(window[0]), float(window[1])
        if not (math.isfinite(t0) and math.isfinite(t1)) or t1 <= t0:
            raise ValueError(f"window must be finite with t0 < t1, got {window!r}")
        i_start = int(np.searchsorted(time, t0, side="left"))
        i_end = int(np.searchsorted(time, t1, side="right"))
        if i_end - i_start < 2:
            raise ValueError(f"window ({t0:.6g}, {t1:.6g}) s holds {max(i_end - i_start, 0)} samples; at least 2 are needed")
        window = SteadyWindow(
            t_start=float(time[i_start]),
            t_end=float(time[i_end - 1]),
            i_start=i_start,
            i_end=i_end,
            plateau=float(np.median(shear[i_start:i_end])),
        )

    part = slice(window.i_start, window.i_end)
    load = normal[part] + weight[part]
    normal_load = float(np.mean(load))
    if normal_load <= 0.0:
        raise ValueError(
            f"normal_force: F_N + W must be positive over the window, got a mean of {normal_load:.6g} N"
        )
    mu, mu_error = _ratio_and_error(shear[part], load)
    mu_bottom, mu_bottom_error = _ratio_and_error(bottom[part], load)
    if mu != 0.0:
        relative_difference = abs(mu - mu_bottom) / abs(mu)
    else:
        relative_difference = 0.0 if mu_bottom == 0.0 else math.inf
    return BulkFriction(
        coefficient=mu,
        standard_error=mu_error,
        bottom_coefficient=mu_bottom,
        bottom_standard_error=mu_bottom_error,
        angle_deg=math.degrees(math.atan(mu)),
        bottom_angle_deg=math.degrees(math.atan(mu_bottom)),
        window=window,
        relative_difference=relative_difference,
        shear_force=float(np.mean(shear[part])),
        normal_load=normal_load,
    )


# --------------------------------------------------------------------------- angle <-> coefficient


def friction_angle(mu):
    """Friction angle of a friction coefficient.

    Parameters
    ----------
    mu : float or array_like
        Friction coefficient(s) [-], finite and >= 0.

    Returns
    -------
    float or numpy.ndarray
        ``degrees(atan(mu))`` [deg].
    """
    array = np.asarray(mu, dtype=float)
    if not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ValueError(f"mu must be finite and >= 0, got {mu!r}")
    angle = np.degrees(np.arctan(array))
    return float(angle) if angle.ndim == 0 else angle


def friction_angle_error(mu, standard_error):
    """Standard error of a friction angle ``atan(mu)`` from that of the coefficient, to first order.

    ``d atan(mu) / d mu = 1 / (1 + mu^2)``, so the error is ``degrees(se / (1 + mu^2))``.

    Parameters
    ----------
    mu : float or array_like
        Friction coefficient(s) [-].
    standard_error : float or array_like
        Their standard error(s) [-], NaN where unknown; broadcast with ``mu``.

    Returns
    -------
    float or numpy.ndarray
        The angle's standard error(s) [deg] (a float for scalars), NaN where ``standard_error`` is.
    """
    error = np.degrees(np.asarray(standard_error, dtype=float) / (1.0 + np.asarray(mu, dtype=float) ** 2))
    return float(error) if error.ndim == 0 else error


def friction_coefficient(angle_deg):
    """Friction coefficient of a friction angle.

    Parameters
    ----------
    angle_deg : float or array_like
        Friction angle(s) [deg], ``0 <= angle < 90``.

    Returns
    -------
    float or numpy.ndarray
        ``tan(radians(angle_deg))`` [-].
    """
    array = np.asarray(angle_deg, dtype=float)
    if not np.all(np.isfinite(array)) or np.any(array < 0.0) or np.any(array >= 90.0):
        raise ValueError(f"angle_deg must satisfy 0 <= angle_deg < 90, got {angle_deg!r}")
    coefficient = np.tan(np.radians(array))
    return float(coefficient) if coefficient.ndim == 0 else coefficient


def bulk_friction_of_shear(signals) -> tuple[BulkFriction, str]:
    """Bulk friction of a shear stage: over the detected steady window, else over its second half.

    A short shear (a few millimetres in a small cell) may end before the shear force reaches a plateau;
    then the second half of the shear is the best available estimate, and the returned method says so.

    Parameters
    ----------
    signals : object with ``time``, ``lid_force``, ``ring_force``, ``bottom_force``, ``normal_force``,
        ``weight_above``
        Force histories of the shear stage (s, N), signed as :func:`bulk_friction` expects.

    Returns
    -------
    (BulkFriction, str)
        The estimate and ``"steady"`` or ``"second half"``.
    """
    arguments = (
        signals.time,
        signals.lid_force,
        signals.ring_force,
        signals.bottom_force,
        signals.normal_force,
        signals.weight_above,
    )
    try:
        return bulk_friction(*arguments), STEADY
    except ValueError as error:
        if "no steady shear" not in str(error):
            raise
    time = np.asarray(signals.time, dtype=float)
    half = time[0] + 0.5 * (time[-1] - time[0])
    return bulk_friction(*arguments, window=(half, time[-1])), SECOND_HALF
