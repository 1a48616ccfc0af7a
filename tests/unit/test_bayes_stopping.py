"""Unit tests for siloflow.calibration.bayes.stopping on sample sets that did and did not move, new runs that did and
did not agree with their prediction, and histories of moves."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.calibration.bayes.stopping import posterior_moved, posterior_shift, predictive_agreement, should_stop


def _standardised(n, d, seed):
    """Samples whose every column has mean 0 and sd 1 exactly."""
    z = np.random.default_rng(seed).normal(size=(n, d))
    return (z - z.mean(axis=0)) / z.std(axis=0, ddof=1)


def test_the_shift_is_the_larger_of_the_mean_shift_and_the_width_change():
    previous = _standardised(1000, 2, seed=0) * [0.1, 0.02] + [0.5, 0.1]
    # parameter 0: mean up by half the new sd (0.05), sd unchanged; parameter 1: sd doubled, mean unchanged
    current = previous.copy()
    current[:, 0] += 0.05
    current[:, 1] = 0.1 + 2.0 * (previous[:, 1] - 0.1)
    np.testing.assert_allclose(posterior_shift(previous, current), [0.5, math.log(2.0)], rtol=1e-12)
    moved, shift = posterior_moved(previous, current, tolerance=0.1)
    assert moved and shift == pytest.approx(math.log(2.0), rel=1e-12)
    # the mean's shift is measured in the current sd: halving the width doubles it
    narrowed = previous.copy()
    narrowed[:, 0] = 0.55 + 0.5 * (previous[:, 0] - 0.5)
    np.testing.assert_allclose(posterior_shift(previous, narrowed)[0], 1.0, rtol=1e-12)


def test_two_samples_of_one_posterior_did_not_move():
    rng = np.random.default_rng(1)
    mean, sd = np.array([0.5, 0.1, 0.3]), np.array([0.05, 0.02, 0.04])
    previous = rng.normal(mean, sd, size=(20000, 3))
    current = rng.normal(mean, sd, size=(20000, 3))
    moved, shift = posterior_moved(previous, current, tolerance=0.05)
    # Monte Carlo noise only: about sqrt(2 / 20000) = 0.01 per parameter
    assert not moved and shift < 0.05


def test_a_posterior_that_moved_by_a_third_of_its_width_moved():
    rng = np.random.default_rng(2)
    previous = rng.normal([0.5, 0.1], [0.05, 0.02], size=(20000, 2))
    current = rng.normal([0.5 + 0.05 / 3.0, 0.1], [0.05, 0.02], size=(20000, 2))
    moved, shift = posterior_moved(previous, current, tolerance=0.1)
    assert moved and shift == pytest.approx(1.0 / 3.0, abs=0.05)
    assert not posterior_moved(previous, current, tolerance=0.5)[0]


def test_the_stopping_rule_refuses_bad_input():
    samples = _standardised(100, 2, seed=0)
    with pytest.raises(ValueError, match="tolerance"):
        posterior_moved(samples, samples, tolerance=0.0)
    with pytest.raises(ValueError, match="parameters"):
        posterior_moved(samples, samples[:, :1])
    with pytest.raises(ValueError, match="spread"):
        posterior_moved(samples, np.ones((100, 2)))


# --- Predictive agreement --------------------------------------------------------------------------------------------

def test_new_runs_are_standardised_by_the_surrogate_and_seed_noise_in_quadrature():
    # observable 0: sqrt(0.3^2 + 0.4^2) = 0.5 deg; observable 1: sqrt(0.6^2 + 0.8^2) = 1.0 deg
    new = [[30.5, 25.0], [29.0, 27.5]]
    mean = [[30.0, 26.0], [30.0, 26.0]]
    sd = [[0.3, 0.6], [0.3, 0.6]]
    agreement = predictive_agreement(new, mean, sd, noise_sd=[0.4, 0.8])
    np.testing.assert_allclose(agreement["z"], [[1.0, -1.0], [-2.0, 1.5]], rtol=1e-12)
    assert isinstance(agreement["z"], list) and isinstance(agreement["z"][0], list)
    assert agreement["max_abs_z"] == pytest.approx(2.0, rel=1e-12)
    assert agreement["within"] is True  # |z| = 2 is still within 2 sd
    assert predictive_agreement(new, mean, sd, noise_sd=[0.4, 0.8], within=1.9)["within"] is False


def test_a_run_the_surrogate_did_not_foresee_disagrees():
    # sqrt(1.2^2 + 0.5^2) = 1.3 deg; 33.9 - 30.0 = 3.9 deg = 3 predictive sd
    agreement = predictive_agreement([[30.0], [33.9]], [[30.0], [30.0]], [[1.2], [1.2]], [0.5])
    np.testing.assert_allclose(agreement["z"], [[0.0], [3.0]], rtol=1e-12)
    assert agreement["max_abs_z"] == pytest.approx(3.0, rel=1e-12) and agreement["within"] is False


def test_the_agreement_refuses_bad_input():
    good = np.ones((2, 3))
    with pytest.raises(ValueError, match="new_values"):
        predictive_agreement(np.ones(3), np.ones(3), np.ones(3), np.ones(3))
    with pytest.raises(ValueError, match="predicted_sd"):
        predictive_agreement(good, good, np.ones((3, 2)), np.ones(3))
    with pytest.raises(ValueError, match="noise_sd"):
        predictive_agreement(good, good, good, np.ones(2))
    with pytest.raises(ValueError, match="predicted_mean must be finite"):
        predictive_agreement(good, np.where(np.eye(2, 3) > 0, np.nan, 1.0), good, np.ones(3))
    with pytest.raises(ValueError, match="negative"):
        predictive_agreement(good, good, -good, np.ones(3))
    with pytest.raises(ValueError, match="variance is zero"):
        predictive_agreement(good, good, np.zeros((2, 3)), np.zeros(3))
    with pytest.raises(ValueError, match="within"):
        predictive_agreement(good, good, good, np.ones(3), within=0.0)


# --- When to stop ----------------------------------------------------------------------------------------------------

def test_one_iteration_without_a_move_does_not_stop():
    stop, reason = should_stop([True, False], agreement_within=True)
    assert stop is False and "one more iteration" in reason


def test_two_iterations_without_a_move_and_agreeing_runs_stop():
    stop, reason = should_stop([True, False, False], agreement_within=True)
    assert stop is True
    assert reason == ("the posterior did not move in the last two iterations and the new runs lie within the "
                      "previous surrogates' predictive band")


def test_two_iterations_without_a_move_but_disagreeing_runs_do_not_stop():
    stop, reason = should_stop([True, False, False], agreement_within=False)
    assert stop is False and "outside" in reason


def test_a_move_resets_the_count():
    assert should_stop([True, False, True], agreement_within=True) == (
        False, "the posterior moved in the last iteration")
    assert should_stop([True, False, True, False], agreement_within=True)[0] is False
    assert should_stop([True, False, True, False, False], agreement_within=True)[0] is True


def test_fewer_than_two_iterations_never_stop():
    assert should_stop([], agreement_within=True)[0] is False
    assert should_stop([False], agreement_within=True)[0] is False
    # numpy flags, as posterior_moved's comparisons give, count as booleans
    assert should_stop(np.array([False, False]), agreement_within=np.bool_(True))[0] is True
