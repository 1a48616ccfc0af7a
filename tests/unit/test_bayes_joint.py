"""The joint calibration's steps on a synthetic shear test whose angles are known functions of the parameters: the
configuration gives the parameters and targets, a parameter set its Jenike points, and a twin calibration (targets
made by the function at known parameters) brings them back inside its 90 % credible region."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.joint import (calibration_of, draw_estimates, first_design, iterate, next_sets, points_of_set,
                                     point_estimate, predictive_sets, ridge_sets, twin_sets, twin_targets, twin_truth,
                                     with_targets)
from siloflow.calibration.bayes.runs import completed_sets, failed_runs, observations, with_runs
from siloflow.calibration.parameters import apply_calibrated_parameters, posterior_draw_configs
from siloflow.calibration.bayes.posterior import in_credible_region
from siloflow.engines.config import ConfigError, validate_config
from siloflow.model.cases.jenike import build_jenike_case


@pytest.fixture(autouse=True)
def one_thread():
    with threadpool_limits(1):
        yield


def _config(**bayesian):
    raw = {"calibration": {"targets_deg": {"internal": 30.0, "aluminium": 9.5, "perspex": 11.0}, "tolerance_deg": 1.0,
                           "bayesian": {"initial_sets": 12, "replicates": 3, "walkers": 16, "steps": 800,
                                        "sets_per_iteration": 3, "max_sets": 20, "predictive_draws": 2, **bayesian}},
           "jenike": {"sweep": {"tests": ["internal", "aluminium"]}}}
    return validate_config(raw)


def _angles(theta):
    """A synthetic shear test (deg): internal friction saturating in particle friction and rising with rolling
    friction; wall friction following the wall friction, a little raised by the particle friction."""
    theta = np.atleast_2d(theta)
    sliding, rolling, wall = theta[:, 0], theta[:, 1], theta[:, 2]
    internal = np.degrees(np.arctan(0.25 + 0.6 * np.tanh(2.0 * sliding) + 0.8 * rolling))
    wall_angle = np.degrees(np.arctan(0.9 * wall + 0.05 * sliding))
    return np.column_stack([internal, wall_angle])


def test_the_configuration_names_the_parameters_and_targets_of_the_tests_it_runs():
    calibration = calibration_of(_config())
    assert calibration.names == ("sliding_friction", "rolling_friction", "wall_sliding_friction.aluminium")
    assert calibration.tests == ("internal", "aluminium")  # perspex is no test of the sweep
    assert calibration.targets_deg.tolist() == [30.0, 9.5]
    assert calibration.lower.tolist() == [0.05, 0.0, 0.05] and calibration.upper.tolist() == [0.6, 0.2, 0.6]


def test_a_parameter_set_runs_one_point_per_test_and_its_replicates_other_seeds():
    config = _config()
    calibration = calibration_of(config)
    internal, wall = points_of_set(calibration, [0.3, 0.1, 0.4], replicate=2)
    assert internal == {"shape": "sphere2", "test": "internal", "sliding_friction": 0.3, "rolling_friction": 0.1,
                        "restitution": 0.1, "rotation_blocked": False, "replicate": 2}
    assert wall == {"shape": "sphere2", "test": "aluminium", "sliding_friction": 0.4, "rolling_friction": 0.1,
                    "restitution": 0.1, "rotation_blocked": False, "particle_sliding_friction": 0.3, "replicate": 2}
    case = build_jenike_case(config, wall)
    assert case.test_contacts.sliding_friction[0][0] == 0.3 and case.test_contacts.sliding_friction[0][-1] == 0.4
    assert case.seeds != build_jenike_case(config, points_of_set(calibration, [0.3, 0.1, 0.4])[1]).seeds


def test_the_first_design_fills_the_box_and_repeats_its_first_set():
    calibration = calibration_of(_config())
    sets = first_design(calibration)
    assert len(sets) == 12 + 2
    theta = np.array([s["theta"] for s in sets])
    assert np.all(theta >= calibration.lower) and np.all(theta <= calibration.upper)
    assert [s["replicate"] for s in sets[12:]] == [1, 2] and sets[12]["theta"] == sets[0]["theta"]
    assert first_design(calibration) == sets


def test_a_twin_calibration_brings_back_the_parameters_that_made_its_targets():
    truth = np.array([0.35, 0.12, 0.3])
    targets = _angles(truth)[0]
    config = _config()
    config["calibration"]["targets_deg"] = {"internal": float(targets[0]), "aluminium": float(targets[1])}
    calibration = calibration_of(config)
    rng = np.random.default_rng(5)
    seed_sd = np.array([0.4, 0.2])
    sets = first_design(calibration)
    theta = np.array([s["theta"] for s in sets])
    angles = _angles(theta) + rng.normal(0.0, seed_sd, size=(len(theta), 2))
    errors = np.full_like(angles, 0.1)
    first = iterate(calibration, theta, angles, errors)
    assert first.moved and first.shift is None
    # the seed noise is measured from the three replicates (two degrees of freedom), not assumed
    assert first.seed_dof == 2 and np.all(first.seed_sd_deg > 0)
    more = next_sets(calibration, first.sample.samples, theta, len(sets), iteration=1)
    assert len(more) == 3
    more_theta = np.array([s["theta"] for s in more])
    theta = np.vstack([theta, more_theta])
    angles = np.vstack([angles, _angles(more_theta) + rng.normal(0.0, seed_sd, size=(3, 2))])
    second = iterate(calibration, theta, angles, np.full_like(angles, 0.1), first.sample.samples)
    assert second.shift is not None and second.shift >= 0
    # the internal angle fixes a ridge in (sliding, rolling); the wall angle fixes the wall friction
    assert in_credible_region(second.sample.samples, truth, 0.9)
    summary = second.summary(calibration)
    assert list(summary["parameters"]) == list(calibration.names)
    wall = summary["parameters"]["wall_sliding_friction.aluminium"]
    assert abs(wall["mean"] - truth[2]) < 3 * wall["sd"]
    assert summary["seed_noise_degrees_of_freedom"] == 2 and summary["moved"] == (summary["shift"] > 0.2)
    # the budget: 17 sets done of 20, 2 kept for the predictive check -> one more
    assert len(next_sets(calibration, second.sample.samples, theta, 17, iteration=2)) == 1
    draws = predictive_sets(calibration, second.sample.samples)
    assert len(draws) == 2 and all(np.all(np.isin(d["theta"], second.sample.samples)) for d in draws)


def test_a_twin_experiment_runs_the_truth_with_seeds_apart_and_takes_their_mean_as_targets():
    config = _config(twin={"enabled": True, "truth": {"sliding_friction": 0.35, "rolling_friction": 0.12,
                                                       "wall_sliding_friction": 0.3}, "replicates": 2})
    calibration = calibration_of(config)
    assert twin_truth(calibration).tolist() == [0.35, 0.12, 0.3]
    sets = twin_sets(calibration)
    assert sets == [{"theta": [0.35, 0.12, 0.3], "replicate": 100}, {"theta": [0.35, 0.12, 0.3], "replicate": 101}]
    made = twin_targets(calibration, [[28.0, 9.0], [30.0, 10.0]])
    assert made == {"targets_deg": {"internal": 29.0, "aluminium": 9.5},
                    "standard_error_deg": {"internal": 1.0, "aluminium": 0.5}}
    assert with_targets(calibration, made["targets_deg"]).targets_deg.tolist() == [29.0, 9.5]
    with pytest.raises(ValueError, match=r"no target for the tests \['aluminium'\]"):
        with_targets(calibration, {"internal": 29.0})


def test_a_silo_takes_the_posterior_mean_in_the_layout_of_the_chart_inversion():
    config = _config()
    calibration = calibration_of(config)
    summary = {"parameters": {"sliding_friction": {"mean": 0.31, "sd": 0.04},
                              "rolling_friction": {"mean": 0.12, "sd": 0.02},
                              "wall_sliding_friction.aluminium": {"mean": 0.22, "sd": 0.03}}}
    parameters = point_estimate(calibration, summary, "yade")
    assert parameters == {
        "source": "the joint Bayesian calibration's posterior mean on yade", "shape": "sphere2",
        "rolling_friction": 0.12, "rolling_friction_error": 0.02,
        "particle_particle": {"sliding_friction": 0.31, "sliding_friction_error": 0.04},
        "particle_wall": {"aluminium": {"sliding_friction": 0.22, "sliding_friction_error": 0.03}},
    }
    silo = apply_calibrated_parameters(config, parameters, "hdpe")
    pairs = {tuple(sorted(c["materials"])): c for c in silo["contacts"]}
    assert (pairs[("hdpe", "hdpe")]["sliding_friction"], pairs[("hdpe", "hdpe")]["rolling_friction"]) == (0.31, 0.12)
    assert pairs[("aluminium", "hdpe")]["sliding_friction"] == 0.22


def test_a_set_with_a_failed_run_is_left_out_and_named():
    config = _config()
    calibration = calibration_of(config)
    sets = with_runs(config, calibration, [{"theta": [0.3, 0.1, 0.4], "replicate": 0},
                                           {"theta": [0.5, 0.15, 0.2], "replicate": 0}], "liggghts")
    good, bad = sets
    summaries = {run: {"run_id": run, "bulk_friction_angle_deg": 25.0, "bulk_friction_angle_deg_error": 0.2}
                 for run in good["runs"].values()}
    summaries[bad["runs"]["internal"]] = {"run_id": bad["runs"]["internal"], "bulk_friction_angle_deg": 30.0,
                                          "bulk_friction_angle_deg_error": 0.3}
    summaries[bad["runs"]["aluminium"]] = {"run_id": bad["runs"]["aluminium"], "failed": True, "error": "Lost atoms"}
    assert failed_runs(sets, summaries) == [{"theta": [0.5, 0.15, 0.2], "replicate": 0, "test": "aluminium",
                                             "run_id": bad["runs"]["aluminium"], "error": "Lost atoms"}]
    assert completed_sets(sets, summaries) == [good]
    theta, angles, errors = observations(calibration, completed_sets(sets, summaries), summaries)
    assert theta.tolist() == [[0.3, 0.1, 0.4]] and angles.tolist() == [[25.0, 25.0]] and errors.tolist() == [[0.2, 0.2]]
    with pytest.raises(ValueError, match=f"the run {bad['runs']['aluminium']} failed: Lost atoms"):
        observations(calibration, sets, summaries)


class _Line:
    """A surrogate whose angle is 20 + 10 (sliding + rolling) deg, sd 0.5 deg."""

    def predict(self, theta):
        theta = np.atleast_2d(theta)
        return 20.0 + 10.0 * (theta[:, 0] + theta[:, 1]), np.full(len(theta), 0.5)


def test_the_ridge_runs_along_the_posterior_and_each_set_reproduces_the_target():
    config = _config()
    config["jenike"]["sweep"]["tests"] = ["internal"]
    calibration = calibration_of(config)
    rng = np.random.default_rng(1)
    # a ridge sliding + rolling = 0.4: every set on it gives the same angle, 24 deg
    sliding = rng.uniform(0.25, 0.4, 4000)
    samples = np.column_stack([sliding, 0.4 - sliding + rng.normal(0, 0.002, 4000)])
    log_probability = -((samples.sum(axis=1) - 0.4) / 0.002) ** 2
    ridge = ridge_sets(calibration, samples, log_probability, [_Line()], count=5)
    assert [row["position"] for row in ridge] == [0.1, 0.3, 0.5, 0.7, 0.9]
    slidings = [row["sliding_friction"] for row in ridge]
    assert slidings == sorted(slidings) or slidings == sorted(slidings, reverse=True)
    assert max(slidings) - min(slidings) > 0.1  # it spans the ridge
    for row in ridge:
        assert row["sliding_friction"] + row["rolling_friction"] == pytest.approx(0.4, abs=0.002)
        assert row["predicted_deg"]["internal"] == pytest.approx([24.0, 0.5], abs=0.02)


def test_a_parameter_held_fixed_has_no_dimension_and_every_run_takes_it():
    config = _config(fixed={"rolling_friction": 0.1})
    calibration = calibration_of(config)
    assert calibration.names == ("sliding_friction", "wall_sliding_friction.aluminium")
    assert calibration.fixed == {"rolling_friction": 0.1}
    assert calibration.lower.tolist() == [0.05, 0.05] and calibration.upper.tolist() == [0.6, 0.6]
    internal, wall = points_of_set(calibration, [0.3, 0.4])
    assert (internal["sliding_friction"], internal["rolling_friction"]) == (0.3, 0.1)
    assert (wall["sliding_friction"], wall["rolling_friction"], wall["particle_sliding_friction"]) == (0.4, 0.1, 0.3)
    summary = {"parameters": {"sliding_friction": {"mean": 0.31, "sd": 0.04},
                              "wall_sliding_friction.aluminium": {"mean": 0.22, "sd": 0.03}}}
    estimate = point_estimate(calibration, summary, "liggghts")
    assert (estimate["rolling_friction"], estimate["rolling_friction_error"]) == (0.1, 0.0)
    assert estimate["particle_wall"] == {"aluminium": {"sliding_friction": 0.22, "sliding_friction_error": 0.03}}
    with pytest.raises(ConfigError, match="every parameter is held fixed"):
        _config(fixed={"rolling_friction": 0.1, "sliding_friction": 0.3, "wall_sliding_friction": 0.2})


def test_the_posterior_draws_reach_a_silo_each_as_one_parameter_set_with_the_fixed_ones():
    config = _config(fixed={"rolling_friction": 0.07})
    calibration = calibration_of(config)
    assert calibration.names == ("sliding_friction", "wall_sliding_friction.aluminium")
    draws = draw_estimates(calibration, [{"theta": [0.31, 0.22], "replicate": 0},
                                         {"theta": [0.45, 0.18], "replicate": 0}], "liggghts")
    assert draws[1] == {
        "source": "posterior draw 1 of the joint Bayesian calibration on liggghts", "shape": "sphere2",
        "rolling_friction": 0.07, "rolling_friction_error": 0.0,
        "particle_particle": {"sliding_friction": 0.45, "sliding_friction_error": 0.0},
        "particle_wall": {"aluminium": {"sliding_friction": 0.18, "sliding_friction_error": 0.0}},
    }
    configs = posterior_draw_configs(config, draws)
    assert [label for label, _ in configs] == ["draw 0", "draw 1"]
    for (_, silo), (mu, mu_wall) in zip(configs, [(0.31, 0.22), (0.45, 0.18)]):
        pairs = {tuple(sorted(c["materials"])): c for c in silo["contacts"]}
        assert (pairs[("hdpe", "hdpe")]["sliding_friction"], pairs[("hdpe", "hdpe")]["rolling_friction"]) == (mu, 0.07)
        assert pairs[("aluminium", "hdpe")]["sliding_friction"] == mu_wall
    with pytest.raises(ValueError, match="one value per parameter|zip"):
        draw_estimates(calibration, [{"theta": [0.3], "replicate": 0}], "liggghts")


def test_silo_runs_at_posterior_draws_need_the_bayesian_parameters():
    with pytest.raises(ConfigError, match="silo_flat.posterior_draws.*parameters: bayesian"):
        validate_config({"silo_flat": {"posterior_draws": True}})
    assert validate_config({"silo_flat": {"posterior_draws": True, "parameters": "bayesian"},
                            "calibration": {"bayesian": {"engines": ["liggghts"]}}})["silo_flat"]["posterior_draws"]
