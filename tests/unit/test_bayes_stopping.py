"""Unit tests for siloflow.calibration.bayes.stopping on sample sets that did and did not move."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.calibration.bayes.stopping import posterior_moved, posterior_shift


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
