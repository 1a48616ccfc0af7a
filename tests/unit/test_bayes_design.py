"""Unit tests for siloflow.calibration.bayes.design: the first design fills the prior box, later designs sit where a known
posterior has mass, spread out and away from the runs already made."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from scipy.spatial.distance import cdist, pdist
from scipy.stats import qmc
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.design import fit_mixture, greedy_maximin, posterior_design, space_filling_design

LOWER = np.array([0.0, 0.0, 0.0])
UPPER = np.array([1.0, 0.2, 0.8])  # sliding, rolling, wall friction [-]
MEAN = np.array([0.5, 0.08, 0.3])
SD = np.array([0.05, 0.02, 0.06])
CORRELATION = np.array([[1.0, 0.6, 0.0], [0.6, 1.0, -0.3], [0.0, -0.3, 1.0]])
COVARIANCE = CORRELATION * np.outer(SD, SD)


@pytest.fixture(autouse=True, scope="module")
def _one_thread():
    # these small matrices gain nothing from BLAS/OpenMP threads, which only contend with a simulation's cores
    with threadpool_limits(limits=1):
        yield


def _unit(points):
    return (points - LOWER) / (UPPER - LOWER)


def _mahalanobis2(points):
    deviation = points - MEAN
    return np.einsum("ij,jk,ik->i", deviation, np.linalg.inv(COVARIANCE), deviation)


@pytest.fixture(scope="module")
def posterior_samples():
    return np.random.default_rng(0).multivariate_normal(MEAN, COVARIANCE, 20000)


# --- space_filling_design ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("method, n", [("lhs", 20), ("sobol", 16)])
def test_the_first_design_lies_in_the_box_and_is_fixed_by_its_seed(method, n):
    design = space_filling_design(LOWER, UPPER, n, seed=3, method=method)
    assert design.shape == (n, 3)
    assert np.all(design >= LOWER) and np.all(design <= UPPER)
    np.testing.assert_array_equal(design, space_filling_design(LOWER, UPPER, n, seed=3, method=method))
    assert not np.allclose(design, space_filling_design(LOWER, UPPER, n, seed=4, method=method))


def test_the_latin_hypercube_puts_one_point_in_each_stratum_of_each_parameter():
    n = 20
    strata = np.floor(_unit(space_filling_design(LOWER, UPPER, n, seed=3)) * n).astype(int)
    for column in strata.T:
        assert sorted(column) == list(range(n))


@pytest.mark.parametrize("method, n", [("lhs", 20), ("sobol", 16)])
def test_the_first_design_fills_the_box_better_than_uniform_draws(method, n):
    unit = _unit(space_filling_design(LOWER, UPPER, n, seed=3, method=method))
    rng = np.random.default_rng(0)
    uniform = [rng.uniform(size=(n, 3)) for _ in range(50)]
    # lower discrepancy and a larger smallest gap than every one of 50 plain uniform draws of the same size
    assert qmc.discrepancy(unit) < min(qmc.discrepancy(u) for u in uniform)
    assert pdist(unit).min() > np.median([pdist(u).min() for u in uniform])


@pytest.mark.parametrize("kwargs, message", [
    ({"lower": [0.0, 1.0], "upper": [1.0, 1.0]}, "below its upper"),
    ({"lower": [0.0], "upper": [1.0, 2.0]}, "one length"),
    ({"n": 0}, "positive integer"),
    ({"method": "grid"}, "unknown design method"),
])
def test_the_first_design_refuses_bad_arguments(kwargs, message):
    arguments = {"lower": [0.0, 0.0], "upper": [1.0, 1.0], "n": 4, "seed": 0, **kwargs}
    with pytest.raises(ValueError, match=message):
        space_filling_design(**arguments)


# --- greedy_maximin and fit_mixture -----------------------------------------------------------------------------------

def test_greedy_maximin_picks_the_farthest_candidate_each_time():
    line = np.array([[0.0], [0.1], [0.5], [0.9], [1.0]])
    # from the middle: both ends are 0.5 away (the first wins the tie), then the other end
    np.testing.assert_array_equal(greedy_maximin(line, 3, first=2), [2, 0, 4])
    # a run at 0 already: the far end first, then the middle
    np.testing.assert_array_equal(greedy_maximin(line, 2, existing=[[0.0]]), [4, 2])
    with pytest.raises(ValueError, match="cannot pick"):
        greedy_maximin(line, 6)


def test_the_mixture_has_as_many_components_as_the_samples_have_modes(posterior_samples):
    rng = np.random.default_rng(1)
    two_modes = np.vstack([rng.multivariate_normal(MEAN, COVARIANCE, 5000),
                           rng.multivariate_normal(MEAN + [0.3, 0.0, 0.0], COVARIANCE, 5000)])
    assert fit_mixture(_unit(posterior_samples), seed=0).n_components == 1
    assert fit_mixture(_unit(two_modes), seed=0).n_components == 2


# --- posterior_design -------------------------------------------------------------------------------------------------

def test_the_posterior_design_lies_where_the_posterior_has_mass(posterior_samples):
    design = posterior_design(posterior_samples, 10, LOWER, UPPER, seed=3)
    assert design.shape == (10, 3)
    assert np.all(design >= LOWER) and np.all(design <= UPPER)
    np.testing.assert_array_equal(design, posterior_design(posterior_samples, 10, LOWER, UPPER, seed=3))
    # picks come from the 90 % highest-density region of the mixture (here the Gaussian): inside its 97 % ellipsoid
    assert np.all(_mahalanobis2(design) < stats.chi2.ppf(0.97, df=3))
    # the first pick is the mode
    assert _mahalanobis2(design[:1])[0] < 0.5
    # a smaller mass keeps the picks closer in
    tight = posterior_design(posterior_samples, 10, LOWER, UPPER, seed=3, mass=0.5)
    assert np.all(_mahalanobis2(tight) < stats.chi2.ppf(0.6, df=3))


def test_the_posterior_design_spreads_its_points_out(posterior_samples):
    design = _unit(posterior_design(posterior_samples, 10, LOWER, UPPER, seed=3))
    rng = np.random.default_rng(5)
    random_picks = [_unit(posterior_samples[rng.choice(len(posterior_samples), 10)]) for _ in range(20)]
    assert pdist(design).min() > 2.0 * max(pdist(p).min() for p in random_picks)


def test_the_posterior_design_keeps_away_from_existing_runs(posterior_samples):
    existing = np.vstack([MEAN, MEAN + 0.5 * SD])
    without = posterior_design(posterior_samples, 10, LOWER, UPPER, seed=3)
    design = posterior_design(posterior_samples, 10, LOWER, UPPER, seed=3, existing=existing)
    # without them the mode is picked, next to the existing runs; with them no pick comes within 1.5 sd
    assert np.sqrt(_mahalanobis2(without)).min() < 0.5
    assert np.min([np.sqrt(_mahalanobis2(design + MEAN - run)) for run in existing]) > 1.5
    assert cdist(_unit(design), _unit(existing)).min() > 3.0 * cdist(_unit(without), _unit(existing)).min()


def test_the_posterior_design_covers_both_modes_of_a_bimodal_posterior():
    rng = np.random.default_rng(1)
    samples = np.vstack([rng.multivariate_normal(MEAN, COVARIANCE, 5000),
                         rng.multivariate_normal(MEAN + [0.3, 0.0, 0.0], COVARIANCE, 5000)])
    design = posterior_design(samples, 10, LOWER, UPPER, seed=3)
    high = design[:, 0] > MEAN[0] + 0.15
    assert 3 <= high.sum() <= 7
    assert np.all(np.abs(design[:, 0] - np.where(high, MEAN[0] + 0.3, MEAN[0])) < 3 * SD[0])


def test_the_posterior_design_stays_in_the_box_when_the_posterior_spills_out():
    samples = np.random.default_rng(0).multivariate_normal([0.97, 0.1, 0.3], COVARIANCE, 20000)
    design = posterior_design(samples, 10, LOWER, UPPER, seed=3)
    assert np.all(design >= LOWER) and np.all(design <= UPPER)
    assert np.all(design[:, 0] > 0.97 - 3 * SD[0])


def test_the_posterior_design_refuses_a_posterior_outside_the_box():
    samples = np.random.default_rng(0).multivariate_normal([3.0, 0.1, 0.3], COVARIANCE, 2000)
    with pytest.raises(ValueError, match="no mass"):
        posterior_design(samples, 4, LOWER, UPPER, seed=3, n_candidates=200)
