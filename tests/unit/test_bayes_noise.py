"""Unit tests for siloflow.calibration.bayes.noise: the pooled seed-noise variance of replicate runs, by hand."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from siloflow.calibration.bayes.noise import seed_noise


def test_the_pooled_variance_of_hand_computable_groups():
    # sums of squares about each group's own mean: 2 (1, 2, 3) and 2 (10, 12); the lone 5 adds nothing
    variance, dof = seed_noise([[1.0, 2.0, 3.0], [10.0, 12.0], [5.0]])
    assert dof == 3
    assert variance == pytest.approx(4.0 / 3.0, rel=1e-15)


def test_one_group_gives_its_unbiased_variance():
    values = [30.1, 29.4, 30.8, 30.3]
    variance, dof = seed_noise([values])
    assert (variance, dof) == (pytest.approx(np.var(values, ddof=1), rel=1e-14), 3)


def test_groups_of_several_observables_pool_each_column():
    # columns: internal and wall friction angle [deg] of the same runs
    variance, dof = seed_noise([[[30.0, 9.0], [32.0, 9.5]], [[25.0, 8.0], [25.0, 9.0], [28.0, 10.0]]])
    assert dof == 3
    # internal: 2 + 6 = 8; wall: 0.125 + 2 = 2.125; over 1 + 2 degrees of freedom
    np.testing.assert_allclose(variance, [8.0 / 3.0, 2.125 / 3.0], rtol=1e-14)


def test_groups_at_different_means_measure_the_common_scatter():
    rng = np.random.default_rng(0)
    groups = [rng.normal(mean, 0.5, 4) for mean in np.linspace(20.0, 40.0, 50)]
    variance, dof = seed_noise(groups)
    assert dof == 150
    # the 99.9 % chi-square interval of a variance of 0.25 deg^2 on 150 degrees of freedom
    low, high = 0.25 * stats.chi2.ppf([0.0005, 0.9995], dof) / dof
    assert low < variance < high


@pytest.mark.parametrize("groups, message", [
    ([[30.0], [31.0]], "at least one group of two"),
    ([], "at least one group of two"),
    ([[30.0, np.nan]], "finite"),
    ([[30.0, 31.0], [[30.0, 9.0], [31.0, 9.0]]], "one width"),
])
def test_seed_noise_refuses_groups_without_replicates_or_values(groups, message):
    with pytest.raises(ValueError, match=message):
        seed_noise(groups)
