"""The DEM's own seed noise, measured from replicate runs.

Two runs at one parameter vector with different seeds (particle insertion, initial packing) give different bulk
friction angles; that scatter is part of every run's error and of the mismatch between a run and the measurement.
It is measured, not assumed: runs are repeated at one or more parameter vectors, and the replicates' variances pooled.
"""

from __future__ import annotations

import numpy as np

__all__ = ["seed_noise"]


def seed_noise(groups) -> tuple[np.ndarray | float, int]:
    """Pooled unbiased variance of replicate groups.

    Each group holds an observable of runs at one parameter vector with different seeds. The groups may sit at
    different parameter vectors (different means); the seed noise is assumed to be the same at all of them, so
    their sums of squares about their own means are pooled:

        ``s^2 = sum_g sum_i (x_gi - mean_g)^2 / sum_g (n_g - 1)``,

    unbiased for a common variance, with ``sum_g (n_g - 1)`` degrees of freedom. A group of one run has no spread
    and contributes nothing.

    Parameters
    ----------
    groups : sequence of array_like, each of shape (n_g,) or (n_g, k)
        The observable of each group's runs (e.g. a bulk friction angle [deg]); with ``k`` columns, ``k``
        observables of the same runs at once.

    Returns
    -------
    variance : float or ndarray, shape (k,)
        Pooled seed-noise variance, in the observable's units squared (deg^2).
    degrees_of_freedom : int
        ``sum_g (n_g - 1)``: the number of independent deviations behind the variance (a chi-square with this many
        degrees of freedom gives its confidence interval).

    Raises
    ------
    ValueError
        If no group has two runs, a value is not finite, or the groups' columns differ.
    """
    arrays = [np.asarray(group, dtype=float) for group in groups]
    columns = {a.shape[1:] for a in arrays}
    if len(columns) > 1 or any(a.ndim not in (1, 2) for a in arrays):
        raise ValueError(f"replicate groups must be vectors, or matrices of one width; got shapes "
                         f"{[a.shape for a in arrays]}")
    if any(not np.all(np.isfinite(a)) for a in arrays):
        raise ValueError("replicate values must be finite")
    replicated = [a for a in arrays if len(a) >= 2]
    if not replicated:
        raise ValueError("the seed noise needs at least one group of two or more runs at one parameter vector")
    squares = sum(np.sum((a - a.mean(axis=0)) ** 2, axis=0) for a in replicated)
    dof = sum(len(a) - 1 for a in replicated)
    variance = squares / dof
    return (float(variance) if np.ndim(variance) == 0 else variance), int(dof)
