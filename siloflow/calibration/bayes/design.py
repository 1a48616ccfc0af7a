"""Where to run the DEM next: a space-filling first design over the prior box, and later designs where the
posterior has mass.

Both return parameter vectors in the parameters' own units (friction coefficients [-]), one row per run; distances
between points are taken in the box-normalised space (each parameter divided by its prior range), so that a
parameter with a narrow prior range counts as much as one with a wide range.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import qmc
from sklearn.mixture import GaussianMixture

from siloflow.calibration.bayes.box import as_box, as_points, from_unit, to_unit

__all__ = ["space_filling_design", "posterior_design", "fit_mixture", "greedy_maximin"]

_METHODS = ("lhs", "sobol")


def space_filling_design(lower, upper, n: int, seed: int, method: str = "lhs") -> np.ndarray:
    """A space-filling first design over the prior box.

    Parameters
    ----------
    lower, upper : array_like, shape (d,)
        Prior bounds of the parameters, in their units (friction coefficients [-]).
    n : int
        Number of points (runs).
    seed : int
        Seed of the scrambling (and of the optimisation for ``"lhs"``): one seed, one design.
    method : {"lhs", "sobol"}
        ``"lhs"``: a scrambled Latin hypercube whose centred discrepancy is lowered by random coordinate swaps
        (:class:`scipy.stats.qmc.LatinHypercube` with ``optimization="random-cd"``), uniform in each parameter for
        any ``n``. ``"sobol"``: the first ``n`` points of a scrambled Sobol sequence
        (:class:`scipy.stats.qmc.Sobol`), best balanced for ``n`` a power of two (scipy warns otherwise).

    Returns
    -------
    ndarray, shape (n, d)
        The design points inside the box, in the parameters' units.
    """
    lower, upper = as_box(lower, upper)
    if int(n) != n or n < 1:
        raise ValueError(f"the number of points must be a positive integer, got {n}")
    if method not in _METHODS:
        raise ValueError(f"unknown design method {method!r}; known: {_METHODS}")
    rng = np.random.default_rng(seed)
    if method == "lhs":
        engine = qmc.LatinHypercube(d=lower.size, scramble=True, optimization="random-cd", rng=rng)
    else:
        engine = qmc.Sobol(d=lower.size, scramble=True, rng=rng)
    return qmc.scale(engine.random(int(n)), lower, upper)


def fit_mixture(points, seed: int, max_components: int = 5) -> GaussianMixture:
    """The Gaussian mixture, of 1 to ``max_components`` full-covariance components, with the lowest BIC.

    Parameters
    ----------
    points : array_like, shape (m, d)
        Samples to describe (e.g. posterior samples in the box-normalised space).
    seed : int
        Seed of the k-means++ initialisation of each fit.
    max_components : int
        Most components tried; fewer if there are fewer distinct samples.

    Returns
    -------
    sklearn.mixture.GaussianMixture
        The fitted mixture whose Bayesian information criterion is lowest.
    """
    points = np.asarray(points, dtype=float)
    if max_components < 1:
        raise ValueError(f"max_components must be at least 1, got {max_components}")
    n_distinct = len(np.unique(points, axis=0))
    if n_distinct < 2:
        raise ValueError("a mixture needs at least two distinct samples")
    best, best_bic = None, np.inf
    for k in range(1, min(max_components, n_distinct - 1) + 1):
        # k-means++ seeding without Lloyd iterations: EM refines the centres anyway, and Lloyd's OpenMP threads
        # slow the fit many times over on a machine whose cores are busy with a DEM run
        mixture = GaussianMixture(n_components=k, covariance_type="full", init_params="k-means++",
                                  random_state=seed).fit(points)
        bic = mixture.bic(points)
        if bic < best_bic:
            best, best_bic = mixture, bic
    return best


def greedy_maximin(candidates, n: int, existing=None, first: int | None = None) -> np.ndarray:
    """Indices of ``n`` candidates picked one by one, each the farthest from those already picked.

    Parameters
    ----------
    candidates : array_like, shape (m, d)
        Points to choose from (in a space where Euclidean distance is meaningful, e.g. box-normalised).
    n : int
        Number to pick, at most ``m``.
    existing : array_like, shape (k, d), optional
        Points already run: the picks keep away from them as from each other.
    first : int, optional
        Index of the first pick when there are no existing points (default: candidate 0).

    Returns
    -------
    ndarray of int, shape (n,)
        Indices into ``candidates``, in the order picked.
    """
    candidates = np.asarray(candidates, dtype=float)
    if n > len(candidates):
        raise ValueError(f"cannot pick {n} points out of {len(candidates)} candidates")
    nearest = np.full(len(candidates), np.inf)
    if existing is not None and len(existing):
        for point in np.asarray(existing, dtype=float):
            nearest = np.minimum(nearest, np.linalg.norm(candidates - point, axis=1))
    picked = []
    for _ in range(int(n)):
        index = int(np.argmax(nearest)) if np.isfinite(nearest).any() else (first or 0)
        picked.append(index)
        # a picked candidate is at distance 0 from itself, so it is never picked twice
        nearest = np.minimum(nearest, np.linalg.norm(candidates - candidates[index], axis=1))
    return np.asarray(picked, dtype=int)


def posterior_design(samples, n: int, lower, upper, seed: int, existing=None, *, max_components: int = 5,
                     mass: float = 0.9, n_candidates: int | None = None, max_fit_samples: int = 5000) -> np.ndarray:
    """New design points where the posterior has mass, spread out and away from the runs already made.

    A Gaussian mixture (components chosen by BIC, :func:`fit_mixture`) is fitted to the posterior samples in the
    box-normalised space; candidates are drawn from it, those outside the box dropped, and of the rest only the
    ``mass`` fraction of highest mixture density kept; from those, ``n`` are picked by greedy maximin distance
    (:func:`greedy_maximin`), which also keeps them away from ``existing`` points. Without existing points the
    first pick is the candidate of highest density (the posterior's mode, as well as the mixture shows it).

    Parameters
    ----------
    samples : array_like, shape (m, d)
        Posterior samples of the parameters, in their units (friction coefficients [-]).
    n : int
        Number of new points.
    lower, upper : array_like, shape (d,)
        Prior bounds, in the parameters' units.
    seed : int
        Seed of the subsample, the mixture fit and the candidate draws: one seed, one design.
    existing : array_like, shape (k, d), optional
        Parameter vectors already run, in the parameters' units.
    max_components : int
        Most mixture components tried.
    mass : float
        Fraction (0, 1] of the candidates, by highest mixture density, that may be picked. Maximin distance prefers
        the fringe of a cloud of candidates; trimming its low-density tail keeps the picks in the bulk of the
        posterior, inside roughly its ``mass`` highest-density region.
    n_candidates : int, optional
        Candidates inside the box to draw (default ``max(2000, 100 n)``): more fill the region more evenly.
    max_fit_samples : int
        At most this many samples (a seeded random subset) go into the mixture fit, which costs time linear in them
        and gains little beyond a few thousand.

    Returns
    -------
    ndarray, shape (n, d)
        New parameter vectors inside the box, in the parameters' units.
    """
    lower, upper = as_box(lower, upper)
    d = lower.size
    samples = as_points(samples, d, "samples")
    if int(n) != n or n < 1:
        raise ValueError(f"the number of points must be a positive integer, got {n}")
    if not 0.0 < mass <= 1.0:
        raise ValueError(f"mass must lie in (0, 1], got {mass}")
    rng = np.random.default_rng(seed)
    unit = to_unit(samples, lower, upper)
    if len(unit) > max_fit_samples:
        unit = unit[rng.choice(len(unit), size=max_fit_samples, replace=False)]
    mixture = fit_mixture(unit, seed=seed, max_components=max_components)

    wanted = int(n_candidates or max(2000, 100 * int(n)))
    # a stateful generator, so that each batch of draws differs from the last (an int seed would repeat them)
    mixture.set_params(random_state=np.random.RandomState(seed))
    kept, drawn = [], 0
    while sum(len(k) for k in kept) < wanted and drawn < 50 * wanted:
        batch, _ = mixture.sample(wanted)
        drawn += wanted
        kept.append(batch[np.all((batch >= 0.0) & (batch <= 1.0), axis=1)])
    candidates = np.concatenate(kept)[:wanted]
    if len(candidates) < n:
        raise ValueError(f"only {len(candidates)} of {drawn} draws from the posterior's mixture fell inside the box; "
                         f"the posterior has (almost) no mass in it")

    log_density = mixture.score_samples(candidates)
    dense = log_density >= np.quantile(log_density, 1.0 - mass)
    if dense.sum() < n:
        raise ValueError(f"only {int(dense.sum())} candidates lie in the {mass:.0%} highest-density region; "
                         f"ask for fewer points or raise n_candidates")
    candidates, log_density = candidates[dense], log_density[dense]

    existing_unit = None
    if existing is not None:
        existing_unit = to_unit(as_points(existing, d, "existing"), lower, upper)
    picked = greedy_maximin(candidates, int(n), existing=existing_unit, first=int(np.argmax(log_density)))
    return from_unit(candidates[picked], lower, upper)
