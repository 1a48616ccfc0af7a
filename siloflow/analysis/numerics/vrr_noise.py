"""The counting-noise ceiling of a variance reduction ratio (VRR), and outlet windows sized to stay below it.

Pure functions on numbers and numpy arrays; split from :mod:`siloflow.analysis.numerics.uncertainty` (errors of the
headline figures) so that each module has one job.

A blend sampled in windows of ``n`` particles has window concentrations with at least the binomial variance
``p (1 - p) / n`` even when the output is perfectly mixed, so a measured ``VRR = sigma_in^2 / sigma_out^2``
cannot exceed ``sigma_in^2 / (p (1 - p) / n)`` (:func:`vrr_ceiling`; ``n`` for a 0/1 batch input of blue
fraction ``p``). Since the noise adds to the true output variance, a measured VRR is always a lower bound of
the true one, and a poor one close to the ceiling: :func:`vrr_near_ceiling` flags VRRs within a factor
(default 2) of it, and :func:`window_clumps_for_precision` / :func:`window_duration_for_precision` size the
windows so that a target VRR stays a factor below the ceiling.
"""

from __future__ import annotations

import math

import numpy as np

from siloflow.model.checks import positive_number

__all__ = [
    "CEILING_FACTOR",
    "vrr_ceiling",
    "vrr_near_ceiling",
    "window_clumps_for_precision",
    "window_duration_for_precision",
]

CEILING_FACTOR = 2.0
"""Default factor of :func:`vrr_near_ceiling`: a VRR at or above half its counting-noise ceiling is flagged."""


def vrr_ceiling(clumps_per_window: float, input_variance: float, mean_fraction: float) -> float:
    """The VRR that binomial sampling noise alone gives for a perfectly mixed output [-].

    A window of ``n`` particles drawn from an output of blue fraction ``p`` has a concentration variance of at
    least ``p (1 - p) / n``, so no VRR above ``input_variance / (p (1 - p) / n)`` can be measured. For a 0/1
    batch input of blue fraction ``p`` the input variance is ``p (1 - p)`` and the ceiling is ``n``.

    Windows of unequal size ``n_i`` have the noise variance ``p (1 - p) mean(1 / n_i)``: pass the harmonic mean
    of the ``n_i`` for the exact ceiling (the arithmetic mean, e.g. throughput x window, is at most a few per
    cent higher for steady flow).

    Parameters
    ----------
    clumps_per_window : float
        Particles (clumps) per outlet sampling window ``n``, > 0 [-].
    input_variance : float
        Variance of the input concentration ``sigma_in^2``, >= 0 [-].
    mean_fraction : float
        Mean blue fraction ``p`` of the output, in (0, 1) [-].

    Returns
    -------
    float
        The ceiling [-].

    Raises
    ------
    ValueError
        If ``clumps_per_window <= 0``, ``input_variance < 0`` or ``mean_fraction`` is outside (0, 1).
    """
    n = positive_number("clumps_per_window", clumps_per_window)
    variance = float(input_variance)
    if not math.isfinite(variance) or variance < 0.0:
        raise ValueError(f"input_variance must be a finite number >= 0, got {input_variance!r}")
    p = float(mean_fraction)
    if not 0.0 < p < 1.0:
        raise ValueError(f"mean_fraction must be a number in (0, 1), got {mean_fraction!r}")
    # n times a ratio that is exactly 1 for a batch input, so that the ceiling is then exactly n
    return n * (variance / (p * (1.0 - p)))


def vrr_near_ceiling(vrr, ceiling, factor: float = CEILING_FACTOR):
    """Whether a measured VRR is within ``factor`` of its counting-noise ceiling: ``vrr >= ceiling / factor``.

    Such a VRR is set by the sampling noise as much as by the blending, so it is only a lower bound of the
    true VRR. NaN (no VRR) is never flagged; +inf (no variance left, possible only through sampling) always is.

    Parameters
    ----------
    vrr : float or array_like
        Measured VRR(s), >= 0 or NaN or +inf [-].
    ceiling : float or array_like
        Counting-noise ceiling(s) (:func:`vrr_ceiling`), finite and > 0 [-]; broadcast with ``vrr``.
    factor : float, optional
        How close counts as "at" the ceiling, >= 1 [-].

    Returns
    -------
    bool or numpy.ndarray of bool
        A bool for scalar input, else an array of the broadcast shape.

    Raises
    ------
    ValueError
        On a negative VRR, a ceiling that is not finite and > 0, or ``factor < 1``.
    """
    values = np.asarray(vrr, dtype=float)
    if np.any(values < 0.0):
        raise ValueError("vrr must be >= 0 (NaN for no VRR, inf for no output variance)")
    limits = np.asarray(ceiling, dtype=float)
    if not np.all(np.isfinite(limits)) or np.any(limits <= 0.0):
        raise ValueError("ceiling must be a finite number > 0 (the counting-noise ceiling of the VRR)")
    factor = float(factor)
    if not (math.isfinite(factor) and factor >= 1.0):
        raise ValueError(f"factor must be a finite number >= 1, got {factor!r}")
    try:
        flags = values >= limits / factor  # NaN compares False
    except ValueError:
        raise ValueError(f"vrr and ceiling must broadcast together, got shapes {values.shape} and "
                         f"{limits.shape}") from None
    return bool(flags) if flags.ndim == 0 else flags


def window_clumps_for_precision(target_vrr: float, factor: float = CEILING_FACTOR) -> int:
    """Particles per outlet window needed to measure a VRR of ``target_vrr`` more than ``factor`` below the
    counting-noise ceiling of a batch input: the smallest integer ``n > factor * target_vrr`` [-].

    Strictly above, so that :func:`vrr_near_ceiling` (which flags ``vrr >= n / factor``) does not flag the target
    itself. Windows this size also need enough of them per recirculation to estimate a variance, and must be
    short against the time scale of the concentration changes; those limits are the caller's.

    Parameters
    ----------
    target_vrr : float
        Largest VRR the windows must resolve, > 0 [-].
    factor : float, optional
        Margin below the ceiling, >= 1 [-] (that of :func:`vrr_near_ceiling`).

    Returns
    -------
    int
        Particles per window [-].

    Raises
    ------
    ValueError
        If ``target_vrr`` is not a finite number > 0 or ``factor < 1``.
    """
    target = positive_number("target_vrr", target_vrr)
    factor = float(factor)
    if not (math.isfinite(factor) and factor >= 1.0):
        raise ValueError(f"factor must be a finite number >= 1, got {factor!r}")
    return int(math.floor(factor * target)) + 1


def window_duration_for_precision(target_vrr: float, throughput: float, factor: float = CEILING_FACTOR) -> float:
    """Duration of an outlet window holding :func:`window_clumps_for_precision` particles at a given
    throughput [s].

    Parameters
    ----------
    target_vrr : float
        Largest VRR the windows must resolve, > 0 [-].
    throughput : float
        Particles crossing the outlet per second, > 0 [1/s].
    factor : float, optional
        Margin below the ceiling, >= 1 [-].

    Returns
    -------
    float
        Window duration [s].

    Raises
    ------
    ValueError
        If an argument is out of range (named in the message).
    """
    clumps = window_clumps_for_precision(target_vrr, factor)
    return clumps / positive_number("throughput", throughput)
