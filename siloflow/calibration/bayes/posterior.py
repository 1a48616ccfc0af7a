"""The posterior of the parameters given the measured bulk friction angles: prior, likelihood, MCMC sampling and
summaries of the samples.

Parameters ``theta`` are friction coefficients [-]; observables are bulk friction angles [deg], one per shear test
(``internal`` and each wall material). The likelihood compares the surrogates' prediction of each observable with
its measured target; the posterior is sampled on the surrogates with the affine-invariant ensemble sampler of
:mod:`emcee`, whose cost per step is one (vectorised) surrogate evaluation per walker, not a DEM run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import emcee
import numpy as np
from scipy import stats

from siloflow.calibration.bayes.box import as_box, as_points

__all__ = [
    "Prior",
    "log_likelihood",
    "log_posterior",
    "PosteriorSample",
    "sample_posterior",
    "credible_interval",
    "PosteriorSummary",
    "posterior_summary",
    "in_credible_region",
]

_LOG_2PI = np.log(2.0 * np.pi)


# --- Prior -----------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Prior:
    """Independent priors of the parameters, each uniform within its bounds or a Gaussian truncated to them.

    Parameters
    ----------
    lower, upper : array_like, shape (d,)
        Bounds of each parameter, in its units (friction coefficients [-]); the prior is zero outside.
    mean, sd : array_like, shape (d,), optional
        Mean and standard deviation of a Gaussian prior before truncation, in the parameter's units; NaN (or no
        arrays at all) marks a parameter whose prior is uniform within its bounds.

    Notes
    -----
    The density is normalised over the box (uniform: ``1 / (upper - lower)``; truncated Gaussian:
    :data:`scipy.stats.truncnorm`), so that its log is a proper log-density, though the sampler needs it only up to
    a constant.
    """

    lower: np.ndarray
    upper: np.ndarray
    mean: np.ndarray | None = None
    sd: np.ndarray | None = None
    _gaussian: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        lower, upper = as_box(self.lower, self.upper)
        d = lower.size
        mean = np.full(d, np.nan) if self.mean is None else np.asarray(self.mean, dtype=float).reshape(-1)
        sd = np.full(d, np.nan) if self.sd is None else np.asarray(self.sd, dtype=float).reshape(-1)
        if mean.shape != (d,) or sd.shape != (d,):
            raise ValueError(f"prior mean and sd must have {d} entries, got {mean.shape} and {sd.shape}")
        gaussian = np.isfinite(mean)
        if np.any(gaussian != np.isfinite(sd)):
            raise ValueError("a Gaussian prior needs both its mean and its sd (NaN in both for a uniform prior)")
        if np.any(sd[gaussian] <= 0):
            raise ValueError(f"prior sds must be positive, got {sd}")
        for name, value in (("lower", lower), ("upper", upper), ("mean", mean), ("sd", sd), ("_gaussian", gaussian)):
            object.__setattr__(self, name, value)

    @classmethod
    def uniform(cls, lower, upper) -> "Prior":
        """A prior uniform in the box."""
        return cls(lower, upper)

    @property
    def dimension(self) -> int:
        """Number of parameters ``d``."""
        return self.lower.size

    def _standard_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The bounds of the Gaussian parameters in standard units, as :data:`scipy.stats.truncnorm` takes them."""
        g = self._gaussian
        return (self.lower[g] - self.mean[g]) / self.sd[g], (self.upper[g] - self.mean[g]) / self.sd[g]

    def log_prob(self, theta) -> float | np.ndarray:
        """Log prior density.

        Parameters
        ----------
        theta : array_like, shape (d,) or (m, d)
            Parameter vectors, in the parameters' units.

        Returns
        -------
        float or ndarray, shape (m,)
            Log density (in the inverse units of the parameters' product); ``-inf`` outside the box.
        """
        theta = np.asarray(theta, dtype=float)
        points = theta[np.newaxis, :] if theta.ndim == 1 else theta
        inside = np.all((points >= self.lower) & (points <= self.upper), axis=1)
        u = ~self._gaussian
        log_p = np.full(len(points), -np.sum(np.log(self.upper[u] - self.lower[u])))
        if self._gaussian.any():
            a, b = self._standard_bounds()
            g = self._gaussian
            log_p = log_p + np.sum(stats.truncnorm.logpdf(points[:, g], a, b, loc=self.mean[g], scale=self.sd[g]),
                                   axis=1)
        log_p = np.where(inside, log_p, -np.inf)
        return float(log_p[0]) if theta.ndim == 1 else log_p

    @property
    def standard_deviation(self) -> np.ndarray:
        """Each parameter's prior standard deviation, shape (d,), in its units: ``(upper - lower) / sqrt(12)`` for a
        uniform prior, the truncated Gaussian's for a Gaussian one (the yardstick a posterior's width is measured
        against: its sd over this says how much the data taught)."""
        sd = (self.upper - self.lower) / np.sqrt(12.0)
        if self._gaussian.any():
            a, b = self._standard_bounds()
            g = self._gaussian
            sd[g] = stats.truncnorm.std(a, b, loc=self.mean[g], scale=self.sd[g])
        return sd

    def sample(self, n: int, seed: int) -> np.ndarray:
        """``n`` independent draws from the prior, shape ``(n, d)``, in the parameters' units (e.g. walker starts)."""
        rng = np.random.default_rng(seed)
        draws = rng.uniform(self.lower, self.upper, size=(int(n), self.dimension))
        if self._gaussian.any():
            a, b = self._standard_bounds()
            g = self._gaussian
            draws[:, g] = stats.truncnorm.rvs(a, b, loc=self.mean[g], scale=self.sd[g], size=(int(n), int(g.sum())),
                                              random_state=rng)
        return draws


# --- Likelihood ------------------------------------------------------------------------------------------------------

def log_likelihood(predicted_mean, predicted_std, targets, target_sd, discrepancy_sd=0.0,
                   dof=None) -> float | np.ndarray:
    """Log-likelihood of measured targets given predicted observables, independent per observable.

    Each target ``j`` (a measured mean, or the mean of a twin experiment's runs) lies about the surrogate's mean of the
    observable with variance ``target_sd_j^2 + discrepancy_sd_j^2 + predicted_std_j^2``: the standard error of the
    target's mean, a model-discrepancy term (0: the intervals assume the DEM at the true parameters reproduces the
    measurement up to the other two) and the surrogate's own uncertainty. The surrogate predicts the mean over seeds,
    so the DEM's seed noise is not added again: it enters through the surrogate's fit (each run's noise) and, for a
    twin experiment, through its targets' standard error. As the surrogate's variance depends on ``theta``, the
    normalisation is kept: without it, parameters where the surrogate is unsure would be favoured.

    With ``dof`` (a target standard error estimated from few runs, with that many degrees of freedom) the observable
    follows Student's t with ``dof`` degrees of freedom and that scale instead of a Gaussian: the marginal of a
    Gaussian whose variance is known only from ``dof`` squared deviations, whose heavier tails keep a noise
    estimated from two or three runs from making the posterior overconfident.

    Parameters
    ----------
    predicted_mean, predicted_std : array_like, shape (..., k)
        The surrogates' mean and standard deviation of each of ``k`` observables (bulk friction angles [deg]).
    targets, target_sd : array_like, shape (k,)
        The measured observables and the standard errors of their means, in the same units.
    discrepancy_sd : float or array_like, shape (k,)
        The model-discrepancy standard deviation of each observable, in the same units (0: none).
    dof : float or array_like, shape (k,), optional
        Degrees of freedom of each target's standard error (None, or inf: known, a Gaussian likelihood).

    Returns
    -------
    float or ndarray, shape (...)
        The log-likelihood, summed over the observables.
    """
    mean = np.asarray(predicted_mean, dtype=float)
    variance = (np.asarray(target_sd, dtype=float) ** 2 + np.asarray(discrepancy_sd, dtype=float) ** 2
                + np.asarray(predicted_std, dtype=float) ** 2)
    if np.any(variance <= 0):
        raise ValueError("the likelihood's variance must be positive: give the targets a standard error above zero")
    residual = mean - np.asarray(targets, dtype=float)
    if dof is None:
        log_l = -0.5 * np.sum(residual ** 2 / variance + np.log(variance) + _LOG_2PI, axis=-1)
    else:
        nu = np.broadcast_to(np.asarray(dof, dtype=float), np.shape(targets))
        if np.any(~(nu > 0)):
            raise ValueError(f"degrees of freedom must be positive, got {dof}")
        scale = np.sqrt(variance)
        # an infinite dof is the Gaussian limit, which scipy's t does not take
        gaussian = stats.norm.logpdf(residual, scale=scale)
        student = stats.t.logpdf(residual, np.where(np.isfinite(nu), nu, 1.0), scale=scale)
        log_l = np.sum(np.where(np.isfinite(nu), student, gaussian), axis=-1)
    return float(log_l) if np.ndim(log_l) == 0 else log_l


def log_posterior(prior: Prior, surrogates: Sequence, targets, target_sd, discrepancy_sd=0.0,
                  dof=None) -> Callable:
    """The unnormalised log posterior on surrogates, as a vectorised function for :func:`sample_posterior`.

    Parameters
    ----------
    prior : Prior
        The parameters' prior.
    surrogates : sequence of objects with ``predict(theta) -> (mean, std)``
        One per observable, in the order of ``targets`` (e.g. :class:`siloflow.calibration.bayes.surrogate.Surrogate`);
        each takes the whole parameter vector.
    targets, target_sd, discrepancy_sd, dof : array_like, shape (k,)
        As for :func:`log_likelihood`.

    Returns
    -------
    callable
        ``f(theta)`` for ``theta`` of shape ``(m, d)`` (or ``(d,)``), returning the log prior plus log-likelihood,
        ``-inf`` outside the prior's support; the surrogates are evaluated only inside it.
    """
    targets = np.asarray(targets, dtype=float).reshape(-1)
    if len(surrogates) != len(targets):
        raise ValueError(f"{len(surrogates)} surrogates but {len(targets)} targets")

    def log_probability(theta):
        theta = np.asarray(theta, dtype=float)
        points = theta[np.newaxis, :] if theta.ndim == 1 else theta
        log_p = np.atleast_1d(prior.log_prob(points)).astype(float)
        inside = np.isfinite(log_p)
        if inside.any():
            predictions = [surrogate.predict(points[inside]) for surrogate in surrogates]
            mean = np.column_stack([p[0] for p in predictions])
            std = np.column_stack([p[1] for p in predictions])
            log_p[inside] += log_likelihood(mean, std, targets, target_sd, discrepancy_sd, dof)
        return float(log_p[0]) if theta.ndim == 1 else log_p

    return log_probability


# --- Sampling --------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class PosteriorSample:
    """Posterior samples and the sampler's diagnostics.

    Attributes
    ----------
    samples : ndarray, shape (n_walkers * (n_steps - burn), d)
        The post-burn-in chain, flattened over steps and walkers, in the parameters' units.
    log_probability : ndarray, shape (n_walkers * (n_steps - burn),)
        The log posterior of each sample.
    acceptance_fraction : float
        Mean over the walkers of the fraction of proposals accepted (0.2 to 0.5 is healthy for the stretch move).
    autocorrelation_time : ndarray, shape (d,)
        emcee's estimate of the integrated autocorrelation time of each parameter, in steps. It is reliable only when
        the post-burn-in chain is at least about 50 times longer (emcee then stays quiet; otherwise it logs a warning
        and the estimate is a lower bound).
    n_walkers, n_steps, burn : int
        The run: walkers, steps per walker, and steps discarded as burn-in.
    """

    samples: np.ndarray
    log_probability: np.ndarray
    acceptance_fraction: float
    autocorrelation_time: np.ndarray
    n_walkers: int
    n_steps: int
    burn: int

    @property
    def effective_sample_size(self) -> np.ndarray:
        """Effective number of independent samples of each parameter, ``n_walkers (n_steps - burn) / tau``, shape (d,).

        Monte Carlo error of a posterior mean: ``sd / sqrt(effective_sample_size)``.
        """
        return self.n_walkers * (self.n_steps - self.burn) / self.autocorrelation_time


def sample_posterior(log_probability: Callable, lower, upper, n_walkers: int, n_steps: int, seed: int,
                     burn: int | None = None, *, vectorize: bool = True, initial=None, moves=None) -> PosteriorSample:
    """Sample a posterior with emcee's affine-invariant ensemble sampler.

    Parameters
    ----------
    log_probability : callable
        Log posterior (up to a constant), ``-inf`` where the prior is zero. With ``vectorize=True`` it takes an
        ``(m, d)`` array and returns ``(m,)`` values (as :func:`log_posterior` does); otherwise one ``(d,)`` vector
        and a float.
    lower, upper : array_like, shape (d,)
        The prior box, in the parameters' units; the walkers start inside it.
    n_walkers : int
        Walkers of the ensemble: at least ``2 d``, and the more, the better the ensemble spans a correlated posterior.
    n_steps : int
        Steps of each walker, burn-in included.
    seed : int
        Seed of the starting positions and of the sampler's moves: one seed, one chain.
    burn : int, optional
        Steps discarded at the start of each walker (default ``n_steps // 2``).
    vectorize : bool
        Whether ``log_probability`` takes all walkers at once (much faster for a Gaussian-process surrogate).
    initial : array_like, shape (n_walkers, d), optional
        Starting positions (default: uniform in the box). Starting from the prior (:meth:`Prior.sample`) or from a
        previous posterior shortens the burn-in when the posterior is narrow compared with the box.
    moves : optional
        emcee moves (default: the stretch move).

    Returns
    -------
    PosteriorSample
        The flattened post-burn-in samples and the diagnostics (acceptance fraction, autocorrelation time).
    """
    lower, upper = as_box(lower, upper)
    d = lower.size
    n_walkers, n_steps = int(n_walkers), int(n_steps)
    burn = n_steps // 2 if burn is None else int(burn)
    if n_walkers < 2 * d:
        raise ValueError(f"the ensemble needs at least 2 d = {2 * d} walkers, got {n_walkers}")
    if not 0 <= burn < n_steps:
        raise ValueError(f"burn must lie in [0, n_steps), got burn={burn}, n_steps={n_steps}")
    rng = np.random.default_rng(seed)
    if initial is None:
        start = rng.uniform(lower, upper, size=(n_walkers, d))
    else:
        start = as_points(initial, d, "initial")
        if len(start) != n_walkers:
            raise ValueError(f"initial has {len(start)} rows for {n_walkers} walkers")
    log_start = (np.asarray(log_probability(start), dtype=float) if vectorize
                 else np.array([log_probability(p) for p in start], dtype=float))
    if not np.all(np.isfinite(log_start)):
        raise ValueError(f"{int(np.sum(~np.isfinite(log_start)))} walkers start where the log probability is not "
                         f"finite; give starting positions inside the posterior's support")

    sampler = emcee.EnsembleSampler(n_walkers, d, log_probability, vectorize=vectorize, moves=moves)
    # emcee draws its moves from its own RandomState; seeding it (not the global one) keeps other code undisturbed
    random_state = np.random.RandomState(rng.integers(2**32 - 1)).get_state()
    sampler.run_mcmc(emcee.State(start, random_state=random_state), n_steps, progress=False)
    return PosteriorSample(
        samples=sampler.get_chain(discard=burn, flat=True),
        log_probability=sampler.get_log_prob(discard=burn, flat=True),
        acceptance_fraction=float(np.mean(sampler.acceptance_fraction)),
        autocorrelation_time=np.asarray(sampler.get_autocorr_time(discard=burn, quiet=True), dtype=float),
        n_walkers=n_walkers,
        n_steps=n_steps,
        burn=burn,
    )


# --- Summaries -------------------------------------------------------------------------------------------------------

def _samples(samples) -> np.ndarray:
    samples = np.asarray(samples, dtype=float)
    samples = samples[:, np.newaxis] if samples.ndim == 1 else samples
    if samples.ndim != 2 or len(samples) < 2:
        raise ValueError(f"samples must have shape (n, d) with n >= 2, got {samples.shape}")
    return samples


def credible_interval(samples, level: float = 0.9) -> np.ndarray:
    """Equal-tailed credible interval of each parameter.

    Parameters
    ----------
    samples : array_like, shape (n, d) or (n,)
        Posterior samples, in the parameters' units.
    level : float
        Probability inside the interval, in (0, 1): each tail holds ``(1 - level) / 2``.

    Returns
    -------
    ndarray, shape (d, 2) or (2,)
        Lower and upper end of each parameter's interval (shape ``(2,)`` for one-dimensional samples).
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must lie in (0, 1), got {level}")
    values = np.asarray(samples, dtype=float)
    interval = np.quantile(_samples(values), [(1.0 - level) / 2.0, (1.0 + level) / 2.0], axis=0).T
    return interval[0] if values.ndim == 1 else interval


@dataclass(frozen=True)
class PosteriorSummary:
    """Marginal summaries of each parameter, in its units, and the posterior correlation matrix.

    Attributes
    ----------
    names : tuple of str
        The parameters' names.
    mean, sd, median, q05, q95 : ndarray, shape (d,)
        Mean, standard deviation (``ddof=1``), median and 5 % and 95 % quantiles of each parameter.
    correlation : ndarray, shape (d, d)
        Pearson correlation between the parameters.
    """

    names: tuple[str, ...]
    mean: np.ndarray
    sd: np.ndarray
    median: np.ndarray
    q05: np.ndarray
    q95: np.ndarray
    correlation: np.ndarray

    def to_dict(self) -> dict:
        """Plain floats and lists, by parameter name (e.g. to write as YAML)."""
        return {
            "parameters": {name: {"mean": float(self.mean[i]), "sd": float(self.sd[i]),
                                  "median": float(self.median[i]), "q05": float(self.q05[i]),
                                  "q95": float(self.q95[i])}
                           for i, name in enumerate(self.names)},
            "correlation": {"names": list(self.names), "matrix": self.correlation.tolist()},
        }


def posterior_summary(samples, names: Sequence[str]) -> PosteriorSummary:
    """Mean, sd, median, 5 and 95 % quantiles of each parameter and the correlation matrix of posterior samples.

    Parameters
    ----------
    samples : array_like, shape (n, d)
        Posterior samples, in the parameters' units.
    names : sequence of str, length d
        The parameters' names.
    """
    samples = _samples(samples)
    names = tuple(names)
    if len(names) != samples.shape[1]:
        raise ValueError(f"{len(names)} names for {samples.shape[1]} parameters")
    q05, median, q95 = np.quantile(samples, [0.05, 0.5, 0.95], axis=0)
    return PosteriorSummary(names=names, mean=samples.mean(axis=0), sd=samples.std(axis=0, ddof=1), median=median,
                            q05=q05, q95=q95, correlation=np.atleast_2d(np.corrcoef(samples, rowvar=False)))


def in_credible_region(samples, point, level: float = 0.9) -> bool | np.ndarray:
    """Whether points lie inside the highest-density credible region of the posterior, in a Gaussian approximation.

    The posterior is approximated by the Gaussian of the samples' mean ``m`` and covariance ``C``. Its
    highest-density region of probability ``level`` is the ellipsoid ``(x - m)^T C^-1 (x - m) <= q``, ``q`` the
    ``level`` quantile of a chi-square with ``d`` degrees of freedom: a point is inside when its squared
    Mahalanobis distance is at most ``q``.

    The approximation is exact for a Gaussian posterior. For a skewed one (e.g. truncated by a prior bound) the
    ellipsoid is symmetric where the true region is not, and for a multimodal one it also covers the space between
    the modes; treat the answer as indicative there.

    Parameters
    ----------
    samples : array_like, shape (n, d)
        Posterior samples, in the parameters' units.
    point : array_like, shape (d,) or (m, d)
        The point(s) to test, in the parameters' units.
    level : float
        Probability of the region, in (0, 1).

    Returns
    -------
    bool or ndarray of bool, shape (m,)
        Whether each point is inside (a bool for a single point).
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must lie in (0, 1), got {level}")
    samples = _samples(samples)
    d = samples.shape[1]
    points = np.asarray(point, dtype=float)
    single = points.ndim <= 1 and points.size == d
    points = as_points(points.reshape(1, d) if single else points, d, "point")
    deviation = points - samples.mean(axis=0)
    covariance = np.atleast_2d(np.cov(samples, rowvar=False))
    distance2 = np.einsum("ij,ij->i", deviation, np.linalg.solve(covariance, deviation.T).T)
    inside = distance2 <= stats.chi2.ppf(level, df=d)
    return bool(inside[0]) if single else inside
