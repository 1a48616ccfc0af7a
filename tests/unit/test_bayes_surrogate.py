"""Unit tests for siloflow.calibration.bayes.surrogate on a synthetic calibration chart: bulk friction angle [deg] saturating
with particle sliding friction (an arctan) and rising linearly with rolling friction."""

from __future__ import annotations

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.design import space_filling_design
from siloflow.calibration.bayes.surrogate import Surrogate

LOWER = np.array([0.1, 0.0])  # particle sliding friction, rolling friction [-]
UPPER = np.array([1.0, 0.2])

# a length scale or constant at its upper bound is the expected fit of a (near) linear dependence, not a failure
pytestmark = pytest.mark.filterwarnings("ignore::sklearn.exceptions.ConvergenceWarning")


@pytest.fixture(autouse=True, scope="module")
def _one_thread():
    # these small matrices gain nothing from BLAS threads, which only contend with a simulation's cores
    with threadpool_limits(limits=1):
        yield


def bulk_angle(theta):
    """Bulk friction angle [deg]: 12 deg plus up to 22 deg saturating with sliding friction, plus 15 deg per unit
    rolling friction."""
    theta = np.atleast_2d(theta)
    return 12.0 + 22.0 * (2.0 / np.pi) * np.arctan(3.0 * theta[:, 0]) + 15.0 * theta[:, 1]


@pytest.fixture(scope="module")
def fitted():
    runs = space_filling_design(LOWER, UPPER, 15, seed=1)
    return runs, Surrogate(LOWER, UPPER, seed=0).fit(runs, bulk_angle(runs), noise_variance=1e-4)


def test_the_surrogate_predicts_held_out_points(fitted):
    _, surrogate = fitted
    held_out = space_filling_design(LOWER, UPPER, 500, seed=7)
    mean, std = surrogate.predict(held_out)
    error = mean - bulk_angle(held_out)
    # 15 runs of a smooth chart spanning 20 deg: within 0.05 deg everywhere, 0.01 deg RMS
    assert np.max(np.abs(error)) < 0.05
    assert np.sqrt(np.mean(error ** 2)) < 0.01
    # and its uncertainty is honest: no error beyond three of its standard deviations
    assert np.all(np.abs(error) < 3.0 * std)


def test_the_uncertainty_grows_away_from_the_runs():
    runs = np.column_stack([np.linspace(0.1, 0.5, 6), np.full(6, 0.1)])
    surrogate = Surrogate(LOWER, UPPER, seed=0).fit(runs, bulk_angle(runs), noise_variance=0.01)
    probe = np.column_stack([np.linspace(0.5, 1.0, 11), np.full(11, 0.1)])
    _, std = surrogate.predict(probe)
    assert np.all(np.diff(std) > 0)
    assert std[-1] > 10.0 * std[0]
    # at a run the surrogate knows the mean better than one run's noise (sd 0.1 deg)
    _, at_runs = surrogate.predict(runs)
    assert np.all(at_runs < 0.1)


def test_the_given_noise_decides_between_interpolating_and_smoothing():
    runs = space_filling_design(LOWER, UPPER, 12, seed=2)
    scatter = np.random.default_rng(0).normal(0.0, 1.0, len(runs))
    noisy = bulk_angle(runs) + scatter
    exact, _ = Surrogate(LOWER, UPPER, seed=0).fit(runs, noisy, noise_variance=1e-8).predict(runs)
    smooth, _ = Surrogate(LOWER, UPPER, seed=0).fit(runs, noisy, noise_variance=1.0).predict(runs)
    np.testing.assert_allclose(exact, noisy, atol=1e-3)
    # told the runs scatter by 1 deg, it follows the chart more than the scatter
    assert np.sqrt(np.mean((smooth - bulk_angle(runs)) ** 2)) < np.sqrt(np.mean(scatter ** 2))


def test_the_surrogate_scales_with_the_observable_units(fitted):
    # the noise variance is in the observable's units squared (not the GP's normalised units): a change of units
    # (deg to millidegrees) scales the prediction and its std and nothing else
    runs, surrogate = fitted
    scaled = Surrogate(LOWER, UPPER, seed=0).fit(runs, 1000.0 * bulk_angle(runs), noise_variance=1e-4 * 1e6)
    probe = space_filling_design(LOWER, UPPER, 50, seed=9)
    mean, std = surrogate.predict(probe)
    mean_k, std_k = scaled.predict(probe)
    np.testing.assert_allclose(mean_k, 1000.0 * mean, rtol=1e-6)
    np.testing.assert_allclose(std_k, 1000.0 * std, rtol=1e-3)


def test_the_fit_is_fixed_by_its_seed(fitted):
    runs, surrogate = fitted
    again = Surrogate(LOWER, UPPER, seed=0).fit(runs, bulk_angle(runs), noise_variance=1e-4)
    probe = space_filling_design(LOWER, UPPER, 20, seed=9)
    np.testing.assert_array_equal(surrogate.predict(probe)[0], again.predict(probe)[0])
    # one vector in, one prediction out
    mean, std = surrogate.predict(probe[0])
    assert mean.shape == std.shape == (1,)


def test_the_surrogate_refuses_bad_input():
    surrogate = Surrogate(LOWER, UPPER)
    with pytest.raises(RuntimeError, match="not fitted"):
        surrogate.predict([0.5, 0.1])
    with pytest.raises(ValueError, match="shape"):
        surrogate.fit(np.ones((3, 3)), np.ones(3), 0.1)
    with pytest.raises(ValueError, match="values"):
        surrogate.fit(np.ones((3, 2)), np.ones(4), 0.1)
    with pytest.raises(ValueError, match="non-negative"):
        surrogate.fit([[0.2, 0.1], [0.5, 0.1]], [20.0, 25.0], -1.0)
    with pytest.raises(ValueError, match="unknown kernel"):
        Surrogate(LOWER, UPPER, kernel="linear")
