"""Unit tests for siloflow.calibration.bayes.posterior: the prior and likelihood by hand, the sampler against the analytic
posterior of a linear Gaussian model, and the summaries on known Gaussian samples."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.posterior import (
    Prior,
    credible_interval,
    in_credible_region,
    log_likelihood,
    log_posterior,
    posterior_summary,
    sample_posterior,
)


@pytest.fixture(autouse=True, scope="module")
def _one_thread():
    # these small matrices gain nothing from BLAS threads, which only contend with a simulation's cores
    with threadpool_limits(limits=1):
        yield


# --- Prior -----------------------------------------------------------------------------------------------------------

def test_a_uniform_prior_is_the_inverse_volume_of_the_box_inside_and_zero_outside():
    prior = Prior.uniform([0.0, 0.0], [1.0, 0.2])
    assert prior.log_prob([0.5, 0.1]) == pytest.approx(-np.log(0.2), rel=1e-15)
    np.testing.assert_array_equal(prior.log_prob([[1.5, 0.1], [0.5, -0.01]]), [-np.inf, -np.inf])
    draws = prior.sample(1000, seed=0)
    assert np.all((draws >= [0.0, 0.0]) & (draws <= [1.0, 0.2]))


def test_a_gaussian_prior_is_truncated_to_its_bounds_and_mixes_with_uniform_ones():
    prior = Prior([0.0, 0.0], [1.0, 0.2], mean=[np.nan, 0.05], sd=[np.nan, 0.1])
    theta = np.array([[0.3, 0.0], [0.9, 0.15]])
    truncated = stats.truncnorm((0.0 - 0.05) / 0.1, (0.2 - 0.05) / 0.1, loc=0.05, scale=0.1)
    np.testing.assert_allclose(prior.log_prob(theta), truncated.logpdf(theta[:, 1]), rtol=1e-12)
    draws = prior.sample(20000, seed=0)
    assert np.all((draws >= [0.0, 0.0]) & (draws <= [1.0, 0.2]))
    assert draws[:, 1].mean() == pytest.approx(truncated.mean(), abs=4 * truncated.std() / np.sqrt(20000))


def test_a_gaussian_prior_with_far_bounds_is_the_plain_gaussian():
    prior = Prior([-10.0], [10.0], mean=[0.5], sd=[0.1])
    assert prior.log_prob([0.62]) == pytest.approx(stats.norm.logpdf(0.62, 0.5, 0.1), rel=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    ({"mean": [0.5, np.nan], "sd": [np.nan, np.nan]}, "both its mean and its sd"),
    ({"mean": [0.5, 0.1], "sd": [0.1, 0.0]}, "positive"),
    ({"mean": [0.5], "sd": [0.1]}, "2 entries"),
])
def test_the_prior_refuses_incomplete_gaussians(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Prior([0.0, 0.0], [1.0, 0.2], **kwargs)


# --- Likelihood ------------------------------------------------------------------------------------------------------

def test_the_likelihood_is_a_product_of_gaussians_with_the_variances_added():
    targets, target_sd, seed_sd = np.array([30.0, 9.5]), np.array([1.0, 0.5]), np.array([0.4, 0.2])
    mean = np.array([[29.0, 10.0], [31.5, 9.0], [30.0, 9.5]])
    std = np.array([[0.1, 0.3], [0.0, 0.0], [2.0, 0.1]])
    expected = np.sum(stats.norm.logpdf(targets, loc=mean, scale=np.sqrt(target_sd**2 + seed_sd**2 + std**2)), axis=1)
    np.testing.assert_allclose(log_likelihood(mean, std, targets, target_sd, seed_sd), expected, rtol=1e-13)
    assert log_likelihood(mean[0], std[0], targets, target_sd, seed_sd) == pytest.approx(expected[0], rel=1e-13)
    # an unsure surrogate at the target is penalised by the normalisation, not favoured
    assert expected[2] < expected[0] + 10 and log_likelihood([30.0, 9.5], [0.0, 0.0], targets, target_sd, seed_sd) > \
        log_likelihood([30.0, 9.5], [2.0, 0.0], targets, target_sd, seed_sd)
    with pytest.raises(ValueError, match="positive"):
        log_likelihood(mean, np.zeros_like(std), targets, [0.0, 0.0], [0.0, 0.0])


class _Linear:
    """A surrogate of one observable, a linear function of theta with a constant std, counting its calls."""

    def __init__(self, row, std=0.0):
        self.row, self.std, self.evaluated = np.asarray(row, dtype=float), std, 0

    def predict(self, theta):
        theta = np.atleast_2d(theta)
        self.evaluated += len(theta)
        return theta @ self.row, np.full(len(theta), self.std)


def test_the_log_posterior_adds_prior_and_likelihood_and_skips_points_outside_the_prior():
    prior = Prior.uniform([0.0, 0.0], [1.0, 1.0])
    surrogates = [_Linear([30.0, 5.0], std=0.5), _Linear([0.0, 12.0])]
    targets, target_sd, seed_sd = [20.0, 6.0], [1.0, 0.5], [0.3, 0.2]
    f = log_posterior(prior, surrogates, targets, target_sd, seed_sd)
    theta = np.array([[0.5, 0.5], [2.0, 0.5], [0.6, 0.4]])
    values = f(theta)
    inside = theta[[0, 2]]
    mean = np.column_stack([inside @ s.row for s in surrogates])
    std = np.column_stack([np.full(2, s.std) for s in surrogates])
    np.testing.assert_allclose(values[[0, 2]], log_likelihood(mean, std, targets, target_sd, seed_sd), rtol=1e-13)
    assert values[1] == -np.inf
    assert [s.evaluated for s in surrogates] == [2, 2]
    assert f(theta[0]) == pytest.approx(values[0], rel=1e-15)


# --- Sampling: a linear Gaussian model with an analytic posterior ----------------------------------------------------

# Four bulk friction angles [deg], linear in three friction coefficients (A in deg per unit friction)
A = np.array([[30.0, 15.0, 0.0], [0.0, 0.0, 12.0], [20.0, 12.0, 5.0], [5.0, 0.0, 15.0]])
TARGET_SD = np.array([1.0, 0.5, 1.0, 0.8])
SEED_SD = np.array([0.8, 0.4, 0.8, 0.6])  # comparable to the targets' sds, so that leaving it out would show
PRIOR_MEAN, PRIOR_SD = np.array([0.5, 0.1, 0.3]), np.array([0.1, 0.05, 0.1])
TRUTH = np.array([0.45, 0.12, 0.35])


@pytest.fixture(scope="module")
def linear_gaussian():
    noise_variance = TARGET_SD**2 + SEED_SD**2
    targets = A @ TRUTH + np.random.default_rng(0).normal(0.0, np.sqrt(noise_variance))
    # analytic posterior: precision A^T S^-1 A + S0^-1, mean Sigma (A^T S^-1 y + S0^-1 m0)
    precision = A.T @ np.diag(1 / noise_variance) @ A + np.diag(1 / PRIOR_SD**2)
    covariance = np.linalg.inv(precision)
    mean = covariance @ (A.T @ (targets / noise_variance) + PRIOR_MEAN / PRIOR_SD**2)
    # bounds 20 prior sds away: the truncation is immaterial
    prior = Prior(PRIOR_MEAN - 20 * PRIOR_SD, PRIOR_MEAN + 20 * PRIOR_SD, mean=PRIOR_MEAN, sd=PRIOR_SD)
    surrogates = [_Linear(row) for row in A]
    log_probability = log_posterior(prior, surrogates, targets, TARGET_SD, SEED_SD)
    result = sample_posterior(log_probability, prior.lower, prior.upper, n_walkers=32, n_steps=2500, seed=1, burn=500,
                              initial=prior.sample(32, seed=2))
    return result, mean, covariance, log_probability, prior


def test_the_sampled_posterior_matches_the_analytic_one(linear_gaussian):
    result, mean, covariance, _, _ = linear_gaussian
    assert result.samples.shape == (32 * 2000, 3)
    assert 0.2 < result.acceptance_fraction < 0.8  # the stretch move accepts about 0.6 in three dimensions
    # the chain is long enough for emcee's estimate (50 autocorrelation times) and gives a few thousand samples' worth
    assert np.all(2000 > 50 * result.autocorrelation_time)
    ess = result.effective_sample_size.min()
    assert ess > 1000
    sd = np.sqrt(np.diag(covariance))
    # the mean within 4 Monte Carlo standard errors, sd / sqrt(ESS)
    np.testing.assert_array_less(np.abs(result.samples.mean(axis=0) - mean), 4 * sd / np.sqrt(ess))
    sampled = np.cov(result.samples, rowvar=False)
    # the variances within 4 standard errors, sqrt(2 / ESS) of the variance
    np.testing.assert_array_less(np.abs(np.diag(sampled) / sd**2 - 1), 4 * np.sqrt(2 / ess))
    # the correlations within 4 standard errors, (1 - rho^2) / sqrt(ESS)
    rho = covariance / np.outer(sd, sd)
    rho_sampled = sampled / np.outer(np.sqrt(np.diag(sampled)), np.sqrt(np.diag(sampled)))
    assert np.abs(rho).max(initial=0, where=~np.eye(3, dtype=bool)) > 0.3  # the test has correlations to check
    np.testing.assert_array_less(np.abs(rho_sampled - rho), 4 * (1 - rho**2) / np.sqrt(ess) + 1e-12)
    np.testing.assert_allclose(result.log_probability, linear_gaussian[3](result.samples), rtol=1e-12)


def test_the_sampler_is_fixed_by_its_seed_and_runs_unvectorised(linear_gaussian):
    _, mean, covariance, log_probability, prior = linear_gaussian
    start = prior.sample(8, seed=3)
    first = sample_posterior(log_probability, prior.lower, prior.upper, 8, 300, seed=4, initial=start)
    scalar = sample_posterior(lambda theta: log_probability(theta), prior.lower, prior.upper, 8, 300, seed=4,
                              initial=start, vectorize=False)
    np.testing.assert_array_equal(first.samples, scalar.samples)
    assert first.samples.shape == (8 * 150, 3)  # burn defaults to half the steps


def test_walkers_start_uniformly_in_the_box_by_default():
    # a flat posterior on the box: the walkers never leave it and fill it uniformly
    result = sample_posterior(lambda t: np.where(np.all((t >= 0) & (t <= [1.0, 0.2]), axis=1), 0.0, -np.inf),
                              [0.0, 0.0], [1.0, 0.2], 16, 400, seed=0)
    assert np.all((result.samples >= 0.0) & (result.samples <= [1.0, 0.2]))
    np.testing.assert_array_less(np.abs(result.samples.mean(axis=0) / [1.0, 0.2] - 0.5), 0.05)


def test_the_sampler_refuses_starts_outside_the_support_and_too_few_walkers():
    prior = Prior.uniform([0.0, 0.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="not finite"):
        sample_posterior(prior.log_prob, [0.0, 0.0], [1.0, 1.0], 8, 10, seed=0, initial=np.full((8, 2), 2.0))
    with pytest.raises(ValueError, match="walkers"):
        sample_posterior(prior.log_prob, [0.0, 0.0], [1.0, 1.0], 3, 10, seed=0)
    with pytest.raises(ValueError, match="burn"):
        sample_posterior(prior.log_prob, [0.0, 0.0], [1.0, 1.0], 8, 10, seed=0, burn=10)


# --- Summaries on known Gaussian samples -----------------------------------------------------------------------------

MEAN = np.array([0.5, 0.1])
COVARIANCE = np.array([[0.05**2, 0.7 * 0.05 * 0.02], [0.7 * 0.05 * 0.02, 0.02**2]])


@pytest.fixture(scope="module")
def gaussian():
    return np.random.default_rng(0).multivariate_normal(MEAN, COVARIANCE, 200000)


def test_the_credible_interval_is_equal_tailed():
    # 1 .. 100, linear interpolation: the 5 % and 95 % quantiles are 1 + 0.05 * 99 and 1 + 0.95 * 99
    np.testing.assert_allclose(credible_interval(np.arange(1.0, 101.0), 0.9), [5.95, 95.05], rtol=1e-14)
    columns = np.column_stack([np.arange(1.0, 101.0), np.arange(1.0, 101.0) * 2])
    np.testing.assert_allclose(credible_interval(columns, 0.5), [[25.75, 75.25], [51.5, 150.5]], rtol=1e-14)
    with pytest.raises(ValueError, match="level"):
        credible_interval(columns, 1.0)


def test_the_credible_interval_of_a_gaussian_sample(gaussian):
    sd = np.sqrt(np.diag(COVARIANCE))
    expected = np.column_stack([MEAN - stats.norm.ppf(0.95) * sd, MEAN + stats.norm.ppf(0.95) * sd])
    # Monte Carlo error of a 5 % quantile of 200,000 samples: sqrt(0.05 0.95 / n) / pdf = 0.0024 sd
    np.testing.assert_allclose(credible_interval(gaussian, 0.9), expected, atol=0.01 * sd.max())


def test_the_summary_of_a_known_sample():
    values = np.arange(0.0, 101.0)
    summary = posterior_summary(np.column_stack([values, 2 * values + 1, -values]), ["sliding", "rolling", "wall"])
    np.testing.assert_allclose(summary.mean, [50.0, 101.0, -50.0])
    np.testing.assert_allclose(summary.median, [50.0, 101.0, -50.0])
    np.testing.assert_allclose(summary.sd, np.std(values, ddof=1) * np.array([1.0, 2.0, 1.0]))
    np.testing.assert_allclose(summary.q05, [5.0, 11.0, -95.0])
    np.testing.assert_allclose(summary.q95, [95.0, 191.0, -5.0])
    np.testing.assert_allclose(summary.correlation, [[1, 1, -1], [1, 1, -1], [-1, -1, 1]], atol=1e-14)
    written = summary.to_dict()
    assert written["parameters"]["rolling"] == {"mean": 101.0, "sd": pytest.approx(2 * np.std(values, ddof=1)),
                                                "median": 101.0, "q05": 11.0, "q95": 191.0}
    assert written["correlation"]["names"] == ["sliding", "rolling", "wall"]
    with pytest.raises(ValueError, match="names"):
        posterior_summary(np.ones((5, 2)), ["one"])


def test_the_summary_of_a_gaussian_sample(gaussian):
    summary = posterior_summary(gaussian, ["sliding", "rolling"])
    np.testing.assert_allclose(summary.mean, MEAN, atol=4 * 0.05 / np.sqrt(len(gaussian)))
    assert summary.correlation[0, 1] == pytest.approx(0.7, abs=4 * (1 - 0.49) / np.sqrt(len(gaussian)))


def test_points_inside_and_outside_the_highest_density_region(gaussian):
    # along a direction the correlation makes narrow: the region's boundary is at sqrt(chi2_0.9(2)) Mahalanobis units
    radius = np.sqrt(stats.chi2.ppf(0.9, df=2))
    direction = np.linalg.cholesky(COVARIANCE) @ np.array([1.0, -1.0]) / np.sqrt(2.0)
    assert in_credible_region(gaussian, MEAN, 0.9) is True
    assert in_credible_region(gaussian, MEAN + 0.97 * radius * direction, 0.9) is True
    assert in_credible_region(gaussian, MEAN + 1.03 * radius * direction, 0.9) is False
    # a point outside the 90 % region lies inside the 99 % one
    assert in_credible_region(gaussian, MEAN + 1.03 * radius * direction, 0.99) is True
    # fresh draws of the same Gaussian fall inside 90 % of the time (binomial sd 0.3 % for 10,000 draws)
    fresh = np.random.default_rng(1).multivariate_normal(MEAN, COVARIANCE, 10000)
    inside = in_credible_region(gaussian, fresh, 0.9)
    assert inside.shape == (10000,)
    assert inside.mean() == pytest.approx(0.9, abs=0.012)
