"""Unit tests for siloflow.calibration.bayes.surrogate on a synthetic calibration chart: bulk friction angle [deg] saturating
with particle sliding friction (an arctan) and rising linearly with rolling friction."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.design import space_filling_design
from siloflow.calibration.bayes.surrogate import Surrogate

LOWER = np.array([0.1, 0.0])  # particle sliding friction, rolling friction [-]
UPPER = np.array([1.0, 0.2])


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
    # 15 runs of a smooth chart spanning 16 deg: within 0.3 deg everywhere (the largest errors are extrapolations
    # into the corner of low sliding and rolling friction, where the arctan is steepest and a length scale of at
    # most 5 box widths lets the mean bend back), 0.03 deg RMS
    assert np.max(np.abs(error)) < 0.3
    assert np.sqrt(np.mean(error ** 2)) < 0.03
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
    with pytest.raises(ValueError, match="names"):
        Surrogate(LOWER, UPPER, names=["sliding_friction"])
    with pytest.raises(ValueError, match="length_scale_bounds"):
        Surrogate(LOWER, UPPER, length_scale_bounds=(5.0, 0.05))
    for unfitted in (surrogate.kernel_summary, surrogate.loo_residuals, surrogate.loo_check):
        with pytest.raises(RuntimeError, match="not fitted"):
            unfitted()
    assert surrogate.warnings == []


def test_a_fit_raises_no_convergence_warning_but_records_it(fitted):
    # the linear rolling-friction dependence takes its length scale to the upper bound, which scikit-learn warns of
    runs, surrogate = fitted
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        again = Surrogate(LOWER, UPPER, seed=0).fit(runs, bulk_angle(runs), noise_variance=1e-4)
    assert not [record for record in caught if issubclass(record.category, ConvergenceWarning)]
    assert again.warnings == surrogate.warnings
    assert any(message.startswith("scikit-learn: The optimal value found for dimension 1 of parameter "
                                  "k2__length_scale is close to the specified upper bound 5.0")
               for message in again.warnings)


def test_the_leave_one_out_residuals_equal_refits_without_each_run():
    runs = space_filling_design(LOWER, UPPER, 12, seed=3)
    # unequal noise variances, so that a wrong run's alpha would show
    noise = np.linspace(0.005, 0.05, len(runs))
    values = bulk_angle(runs) + np.random.default_rng(4).normal(0.0, np.sqrt(noise))
    surrogate = Surrogate(LOWER, UPPER, seed=0).fit(runs, values, noise)
    gp = surrogate.gp
    refits = []
    for left_out in range(len(runs)):
        kept = np.arange(len(runs)) != left_out
        # the fitted hyperparameters, fixed, and the fit's normalisation: compared in the normalised units
        refit = GaussianProcessRegressor(kernel=gp.kernel_, alpha=gp.alpha[kept], optimizer=None,
                                         normalize_y=False).fit(gp.X_train_[kept], gp.y_train_[kept])
        mean, std = refit.predict(gp.X_train_[[left_out]], return_std=True)
        # the left-out run is a noisy observation: its own noise adds to the predicted variance
        refits.append((gp.y_train_[left_out] - mean[0]) / np.sqrt(std[0] ** 2 + gp.alpha[left_out]))
    np.testing.assert_allclose(surrogate.loo_residuals(), refits, rtol=1e-8)


def test_a_weak_dependence_keeps_its_trend_and_no_dependence_is_reported():
    # 15 runs in a 3-d box: strong in x0 (20 across the box), weak in x1 (1, ten times the noise sd), none in x2
    lower, upper = np.zeros(3), np.ones(3)
    runs = space_filling_design(lower, upper, 15, seed=0)
    truth = 20.0 * runs[:, 0] + 1.0 * runs[:, 1]
    values = truth + np.random.default_rng(0).normal(0.0, 0.1, len(runs))
    surrogate = Surrogate(lower, upper, seed=0, names=["x0", "x1", "x2"]).fit(runs, values, noise_variance=0.01)
    length_scales = surrogate.kernel_summary()["length_scales"]
    assert np.isfinite(list(length_scales.values())).all()
    assert length_scales["x0"] < 5.0
    # x2 at the upper bound: the correct report of no dependence. x1 lies on the same bound (a linear trend needs no
    # shorter length scale), so the flag does not tell weak from none; the mean does, and keeps x1's trend: the
    # posterior's ridge along x1 does not collapse
    flagged = [message.split(" at its upper bound 5 (box units)")[0] for message in surrogate.warnings
               if message.startswith("length scale")]
    assert flagged == ["length scale of parameter x1", "length scale of parameter x2"]
    across = np.array([[0.5, 0.0, 0.5], [0.5, 1.0, 0.5], [0.5, 0.5, 0.0], [0.5, 0.5, 1.0]])
    mean, std = surrogate.predict(across)
    # hypot: the sd of a difference of two independent predictions, an upper bound for these positively correlated
    trend_x1, trend_x2 = mean[1] - mean[0], mean[3] - mean[2]
    assert abs(trend_x1 - 1.0) < 2.0 * np.hypot(std[0], std[1])
    assert trend_x1 > 3.0 * np.hypot(std[0], std[1])
    assert abs(trend_x2) < 2.0 * np.hypot(std[2], std[3])
    check = surrogate.loo_check()
    assert 0.5 <= check["rms"] <= 2.0
    assert check == {"rms": check["rms"], "n": 15, "within": True, "message": None}


def test_a_length_scale_at_its_lower_bound_is_named():
    # white noise told to be exact: the runs vary faster than they resolve, the length scale goes to 0.05
    runs = space_filling_design([0.0], [0.2], 15, seed=1)
    values = 20.0 + np.random.default_rng(0).normal(0.0, 1.0, len(runs))
    surrogate = Surrogate([0.0], [0.2], seed=0, names=["rolling_friction"]).fit(runs, values, noise_variance=1e-6)
    assert surrogate.warnings[0] == (
        "length scale of parameter rolling_friction at its lower bound 0.05 (box units): the observable varies with "
        "it faster than the runs resolve, or the runs' noise variances are too small")
    assert surrogate.warnings[1].startswith("scikit-learn: The optimal value found for dimension 0 of parameter "
                                            "k2__length_scale is close to the specified lower bound 0.05")
    # a new fit reports its own findings, not the last one's
    smooth = space_filling_design([0.0], [0.2], 8, seed=1)
    surrogate.fit(smooth, 20.0 + 50.0 * np.sin(10.0 * smooth[:, 0]), noise_variance=0.01)
    assert not any("lower bound" in message for message in surrogate.warnings)


def test_an_optimiser_warning_is_recorded_once_with_its_count_and_others_pass_through(monkeypatch):
    fit = GaussianProcessRegressor.fit

    def warning_fit(self, X, y):
        # as scikit-learn does when L-BFGS stops early, once per restart
        for _ in range(2):
            warnings.warn("lbfgs failed to converge (status=2): ABNORMAL", ConvergenceWarning)
        warnings.warn("something else", UserWarning)
        return fit(self, X, y)

    monkeypatch.setattr(GaussianProcessRegressor, "fit", warning_fit)
    runs = space_filling_design(LOWER, UPPER, 10, seed=2)
    with pytest.warns(UserWarning, match="something else"):
        surrogate = Surrogate(LOWER, UPPER, seed=0).fit(runs, bulk_angle(runs), noise_variance=0.01)
    assert "scikit-learn: lbfgs failed to converge (status=2): ABNORMAL (2 times)" in surrogate.warnings


def test_the_kernel_summary_is_plain_data_of_the_fitted_kernel(fitted):
    runs, _ = fitted
    surrogate = Surrogate(LOWER, UPPER, seed=0, names=["sliding_friction", "rolling_friction"]).fit(
        runs, bulk_angle(runs), noise_variance=1e-4)
    summary = surrogate.kernel_summary()
    assert json.loads(json.dumps(summary)) == summary
    kernel = surrogate.gp.kernel_
    assert summary["kernel"] == str(kernel)
    assert summary["constant"] == kernel.k1.constant_value
    assert list(summary["length_scales"]) == ["sliding_friction", "rolling_friction"]
    np.testing.assert_array_equal(list(summary["length_scales"].values()), kernel.k2.length_scale)
    assert summary["log_marginal_likelihood"] == surrogate.gp.log_marginal_likelihood_value_
    assert summary["bounds"] == {"length_scale": [0.05, 5.0], "constant": [0.01, 10000.0]}
    assert summary["warnings"] == surrogate.warnings
    assert summary["warnings"][0] == (
        "length scale of parameter rolling_friction at its upper bound 5 (box units): over the prior box the "
        "observable depends on it at most about linearly (the slope is in the mean), or the runs cannot resolve its "
        "dependence")
    # without names, a parameter is its index
    _, unnamed = fitted
    assert list(unnamed.kernel_summary()["length_scales"]) == ["0", "1"]


def test_the_leave_one_out_check_says_which_way_the_surrogate_is_wrong(fitted):
    _, surrogate = fitted
    residuals = surrogate.loo_residuals()
    rms = np.sqrt(np.mean(residuals ** 2))
    assert surrogate.loo_check(low=0.0, high=np.inf) == {"rms": rms, "n": 15, "within": True, "message": None}
    over = surrogate.loo_check(low=0.0, high=rms / 2.0)
    assert not over["within"] and "over-confident" in over["message"]
    under = surrogate.loo_check(low=2.0 * rms, high=np.inf)
    assert not under["within"] and "under-confident" in under["message"]
    # told the runs scatter by 1 deg when they scatter by 0.01 deg, the surrogate is under-confident
    runs = space_filling_design(LOWER, UPPER, 15, seed=1)
    values = bulk_angle(runs) + np.random.default_rng(0).normal(0.0, 0.01, len(runs))
    check = Surrogate(LOWER, UPPER, seed=0).fit(runs, values, noise_variance=1.0).loo_check()
    assert check["rms"] < 0.5 and "under-confident" in check["message"]
