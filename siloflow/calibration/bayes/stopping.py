"""When to stop iterating: the posterior no longer moves, twice in a row, and the new runs agree with the
surrogates that placed them.

Each iteration adds runs, refits the surrogates and resamples the posterior. Once the new runs no longer change it
(by more than a fraction of its own width, :func:`posterior_moved`) further runs near it buy little: the calibration
has converged, to the precision that the targets' uncertainty, the seed noise and the surrogates allow.

One iteration without a move is not enough: with few runs the posterior can stand still by chance (a handful of
new runs may be too few to shift it), and the loop would stop after a handful of parameter sets.
:func:`should_stop` therefore asks for two consecutive iterations without a move, and for the last iteration's new
runs to lie within a few predictive standard deviations of the previous iteration's surrogates
(:func:`predictive_agreement`): runs the surrogates did not foresee mean they were wrong where the posterior has its
mass, whatever the posterior did.
"""

from __future__ import annotations

import numpy as np

__all__ = ["posterior_shift", "posterior_moved", "predictive_agreement", "should_stop"]


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


def predictive_agreement(new_values, predicted_mean, predicted_sd, noise_sd, within: float = 2.0) -> dict:
    """Whether new runs' observables lie within the previous iteration's predictive band.

    For each new run ``i`` and observable ``j`` the standardised residual is

        ``z_ij = (y_ij - m_ij) / sqrt(s_ij^2 + noise_j^2)``,

    ``m`` and ``s`` the previous iteration's surrogate mean and sd at the run's parameters and ``noise`` the seed
    noise, as a single run scatters about the mean the surrogate predicts.

    Parameters
    ----------
    new_values : array_like, shape (n, k)
        The observables of ``n`` new runs, ``k`` per run (bulk friction angles [deg]).
    predicted_mean, predicted_sd : array_like, shape (n, k)
        The previous iteration's surrogate mean and standard deviation at each run's parameters [deg].
    noise_sd : array_like, shape (k,)
        The seed-noise standard deviation of each observable [deg].
    within : float
        Largest ``|z|`` (dimensionless, in predictive standard deviations) still counted as agreeing.

    Returns
    -------
    dict
        ``{"z": list of n lists of k floats, "max_abs_z": float, "within": bool}``: the standardised residuals
        (dimensionless), the largest of their absolute values, and whether all of them are at most ``within``.

    Raises
    ------
    ValueError
        If the shapes differ, a value is not finite, a standard deviation is negative, a predictive variance is
        zero, or ``within`` is not positive.
    """
    if not within > 0:
        raise ValueError(f"within must be positive, got {within}")
    values = np.asarray(new_values, dtype=float)
    mean = np.asarray(predicted_mean, dtype=float)
    sd = np.asarray(predicted_sd, dtype=float)
    noise = np.asarray(noise_sd, dtype=float)
    if values.ndim != 2 or values.shape[0] < 1 or values.shape[1] < 1:
        raise ValueError(f"new_values must have shape (n, k) with n, k >= 1, got {values.shape}")
    for name, array in (("predicted_mean", mean), ("predicted_sd", sd)):
        if array.shape != values.shape:
            raise ValueError(f"{name} must have the shape of new_values, {values.shape}, got {array.shape}")
    if noise.shape != values.shape[1:]:
        raise ValueError(f"noise_sd must have shape ({values.shape[1]},), one per observable, got {noise.shape}")
    for name, array in (("new_values", values), ("predicted_mean", mean), ("predicted_sd", sd), ("noise_sd", noise)):
        if not np.all(np.isfinite(array)):
            raise ValueError(f"{name} must be finite")
    if np.any(sd < 0) or np.any(noise < 0):
        raise ValueError("predicted_sd and noise_sd must not be negative")
    scale = np.sqrt(sd**2 + noise**2)
    if np.any(scale == 0):
        raise ValueError("a predictive variance is zero: give a surrogate or seed-noise sd above zero")
    z = (values - mean) / scale
    max_abs_z = float(np.max(np.abs(z)))
    return {"z": z.tolist(), "max_abs_z": max_abs_z, "within": bool(max_abs_z <= within)}


def should_stop(history, agreement_within: bool) -> tuple[bool, str]:
    """Whether the iterations can stop: two consecutive iterations without a move, and the new runs agreed.

    Parameters
    ----------
    history : sequence of bool
        Whether the posterior moved (:func:`posterior_moved`) at each iteration so far, oldest first, the current
        one last (the first iteration, with nothing to compare, counts as moved).
    agreement_within : bool
        Whether the current iteration's new runs lay within the previous iteration's predictive band
        (``predictive_agreement(...)["within"]``).

    Returns
    -------
    stop : bool
        True only when the last two iterations both did not move and the new runs agreed; never with fewer than
        two iterations.
    reason : str
        A sentence saying why.
    """
    moved = [bool(flag) for flag in history]
    if len(moved) < 2:
        return False, (f"{len(moved)} iteration(s) so far: stopping needs two consecutive iterations in which the "
                       f"posterior did not move")
    if moved[-1]:
        return False, "the posterior moved in the last iteration"
    if moved[-2]:
        return False, ("the posterior did not move in the last iteration but did in the one before: one more "
                       "iteration without a move is needed")
    if not agreement_within:
        return False, ("the posterior did not move in the last two iterations, but the new runs lie outside the "
                       "previous surrogates' predictive band: the surrogates are still wrong where the posterior is")
    return True, ("the posterior did not move in the last two iterations and the new runs lie within the previous "
                  "surrogates' predictive band")
