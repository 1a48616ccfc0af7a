"""When to stop iterating: the posterior no longer moves between two iterations.

Each iteration adds runs, refits the surrogates and resamples the posterior. Once the new runs no longer change it
(by more than a fraction of its own width) further runs near it buy little: the calibration has converged, to the
precision that the targets' uncertainty, the seed noise and the surrogates allow.
"""

from __future__ import annotations

import numpy as np

__all__ = ["posterior_shift", "posterior_moved"]


def _moments(samples, name: str) -> tuple[np.ndarray, np.ndarray]:
    samples = np.asarray(samples, dtype=float)
    samples = samples[:, np.newaxis] if samples.ndim == 1 else samples
    if samples.ndim != 2 or len(samples) < 2:
        raise ValueError(f"{name} samples must have shape (n, d) with n >= 2, got {samples.shape}")
    sd = samples.std(axis=0, ddof=1)
    if np.any(sd <= 0) or not np.all(np.isfinite(sd)):
        raise ValueError(f"{name} samples have a parameter with zero or undefined spread")
    return samples.mean(axis=0), sd


def posterior_shift(previous, current) -> np.ndarray:
    """How far each parameter's posterior moved between two sample sets.

    Per parameter, the larger of ``|mean_current - mean_previous| / sd_current`` (the mean's shift in units of the
    current posterior's width, the better informed of the two) and ``|log(sd_current / sd_previous)|`` (the change
    of width: 0.1 is a 10 % change). Both are dimensionless, so parameters of different units compare.

    Parameters
    ----------
    previous, current : array_like, shape (n, d) and (m, d)
        Posterior samples of the two iterations, in the parameters' units.

    Returns
    -------
    ndarray, shape (d,)
        The shift of each parameter.
    """
    mean_0, sd_0 = _moments(previous, "previous")
    mean_1, sd_1 = _moments(current, "current")
    if mean_0.shape != mean_1.shape:
        raise ValueError(f"the sample sets have {mean_0.size} and {mean_1.size} parameters")
    return np.maximum(np.abs(mean_1 - mean_0) / sd_1, np.abs(np.log(sd_1 / sd_0)))


def posterior_moved(previous, current, tolerance: float = 0.1) -> tuple[bool, float]:
    """Whether the posterior moved between two iterations.

    Parameters
    ----------
    previous, current : array_like, shape (n, d) and (m, d)
        Posterior samples of the two iterations, in the parameters' units.
    tolerance : float
        Largest shift (:func:`posterior_shift`, dimensionless) still counted as not moving. It should exceed the
        Monte Carlo noise of the shift, about ``sqrt(2 / ESS)`` for effective sample sizes ``ESS`` of the two sets.

    Returns
    -------
    moved : bool
        Whether the largest shift over the parameters exceeds ``tolerance``.
    shift : float
        That largest shift.
    """
    if not tolerance > 0:
        raise ValueError(f"tolerance must be positive, got {tolerance}")
    shift = float(np.max(posterior_shift(previous, current)))
    return shift > tolerance, shift
