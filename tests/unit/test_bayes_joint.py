"""The joint calibration's steps on a synthetic shear test whose angles are known functions of the parameters: the
configuration gives the parameters and targets, a parameter set its Jenike points, and a twin calibration (targets
made by the function at known parameters, with seed noise) brings them back inside its 90 % highest-density region,
while its negative control, the same targets shifted by three of their standard errors, fails."""

from __future__ import annotations


import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.joint import (PREDICTIVE_SEED_OFFSET, TWIN_SEED_OFFSET, calibration_of, draw_estimates,
                                     first_design, iterate, next_sets, points_of_set, point_estimate, predictive_sets,
                                     ridge_sets, twin_sets, twin_targets, twin_truth, with_targets)
from siloflow.calibration.bayes.report import twin_verdict
from siloflow.calibration.bayes.runs import completed_sets, failed_runs, observations, with_runs
from siloflow.calibration.parameters import apply_calibrated_parameters, posterior_draw_configs
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


def test_the_first_design_fills_the_box_and_repeats_its_first_set_each_set_on_its_own_seed():
    calibration = calibration_of(_config())
    sets = first_design(calibration)
    assert len(sets) == 12 + 2
    theta = np.array([s["theta"] for s in sets])
    assert np.all(theta >= calibration.lower) and np.all(theta <= calibration.upper)
    assert [s["replicate"] for s in sets] == list(range(14)) and sets[12]["theta"] == sets[0]["theta"]
    assert sets[13]["theta"] == sets[0]["theta"]
    assert first_design(calibration) == sets


def test_each_test_has_a_surrogate_of_only_the_parameters_its_runs_take():
    calibration = calibration_of(_config())
    assert calibration.inputs_of("internal") == (0, 1)
    assert calibration.inputs_of("aluminium") == (2, 0, 1)
    held = calibration_of(_config(fixed={"rolling_friction": 0.1}))
    assert held.names == ("sliding_friction", "wall_sliding_friction.aluminium")
    assert held.inputs_of("internal") == (0,) and held.inputs_of("aluminium") == (1, 0)


def _twin(shift_in_standard_errors: float, seed: int = 5):
    """A twin calibration of the synthetic shear test, two iterations: the truth's three runs (seed noise 0.4 and
    0.2 deg) give the targets, shifted by ``shift_in_standard_errors`` of their standard error."""
    truth = np.array([0.35, 0.12, 0.3])
    rng = np.random.default_rng(seed)
    seed_sd = np.array([0.4, 0.2])
    truth_runs = _angles(np.tile(truth, (3, 1))) + rng.normal(0.0, seed_sd, size=(3, 2))
    config = _config(twin={"enabled": True, "truth": {"sliding_friction": 0.35, "rolling_friction": 0.12,
                                                       "wall_sliding_friction": 0.3}, "replicates": 3},
                     max_sets=30, sets_per_iteration=6, max_steps=1600)
    plain = calibration_of(config)
    made = twin_targets(plain, truth_runs)
    shifted = {test: made["targets_deg"][test] + shift_in_standard_errors * sd / np.sqrt(3.0)
               for test, sd in zip(plain.tests, seed_sd)}
    calibration = with_targets(plain, shifted, truth_runs)
    sets = first_design(calibration)
    theta = np.array([s["theta"] for s in sets])
    angles = _angles(theta) + rng.normal(0.0, seed_sd, size=(len(theta), 2))
    first = iterate(calibration, theta, angles, np.full_like(angles, 0.1))
    more = next_sets(calibration, first.sample.samples, first.sample.log_probability, theta, len(sets), iteration=1)
    more_theta = np.array([s["theta"] for s in more])
    previous = len(theta)
    theta = np.vstack([theta, more_theta])
    angles = np.vstack([angles, _angles(more_theta) + rng.normal(0.0, seed_sd, size=(len(more_theta), 2))])
    second = iterate(calibration, theta, angles, np.full_like(angles, 0.1), first.sample.samples,
                     previous_count=previous, moved_history=first.moved_history)
    verdict = twin_verdict(calibration, second.sample.samples, second.sample.log_probability, truth,
                           second.truth_log_probability)
    return calibration, first, more, second, verdict


def test_a_twin_calibration_brings_back_the_parameters_that_made_its_targets():
    calibration, first, more, second, verdict = _twin(0.0)
    assert first.moved and first.shift is None and first.agreement is None and not first.stop
    # the seed noise pools the first design's three replicates and the truth's three runs: 4 degrees of freedom; the
    # targets' standard error is it over sqrt(3), with those degrees of freedom (a Student-t likelihood)
    assert first.seed_dof == 4 and first.target_dof == 4.0
    np.testing.assert_allclose(first.target_sd_deg, first.seed_sd_deg / np.sqrt(3.0), rtol=1e-12)
    # the next sets: six where the posterior has mass, two at its mode, each on its own seed
    assert len(more) == 8 and [s["replicate"] for s in more] == list(range(14, 22))
    assert more[-1]["theta"] == more[-2]["theta"]
    assert second.seed_dof == 5 and second.agreement is not None
    assert second.moved_history == (True, second.moved)
    assert verdict["inside_credible_region"] and verdict["hpd_level"] <= 0.9
    # the wall angle pins its friction; the internal angle leaves a ridge of sliding and rolling friction
    assert verdict["parameters"]["wall_sliding_friction.aluminium"]["sd_over_prior_sd"] < 0.3
    assert verdict["axes"][-1]["sd_over_prior_sd"] < verdict["axes"][0]["sd_over_prior_sd"]
    summary = second.summary(calibration)
    assert list(summary["parameters"]) == list(calibration.names)
    assert summary["surrogates"]["internal"]["inputs"] == ["sliding_friction", "rolling_friction"]
    assert summary["target_degrees_of_freedom"] == 5.0 and summary["seed_noise_degrees_of_freedom"] == 5
    draws = predictive_sets(calibration, second.sample.samples, second.predicted_mean, second.predicted_std)
    assert [d["replicate"] for d in draws] == [PREDICTIVE_SEED_OFFSET, PREDICTIVE_SEED_OFFSET + 1]
    assert all(set(d["predicted_deg"]) == {"internal", "aluminium"} for d in draws)


def test_the_twins_negative_control_fails_its_targets_shifted_by_three_standard_errors():
    *_, verdict = _twin(3.0)
    assert not verdict["inside_credible_region"] and verdict["hpd_level"] > 0.9


def test_the_budget_holds_the_runs_at_the_mode_and_the_predictive_draws():
    calibration = calibration_of(_config())
    rng = np.random.default_rng(0)
    samples = rng.uniform(calibration.lower, calibration.upper, size=(200, 3))
    log_p = -np.sum((samples - 0.3) ** 2, axis=1)
    # 20 sets at most, 2 kept for the predictive check: after 14 done, 4 left: 2 where the posterior has mass, 2 at
    # the mode (its sample of highest density)
    chosen = next_sets(calibration, samples, log_p, samples[:5], 14, iteration=1)
    assert [s["replicate"] for s in chosen] == [14, 15, 16, 17]
    assert chosen[2]["theta"] == chosen[3]["theta"] == samples[np.argmax(log_p)].tolist()
    # 17 done: one left, at the mode
    assert [s["theta"] for s in next_sets(calibration, samples, log_p, samples[:5], 17, 2)] == [
        samples[np.argmax(log_p)].tolist()]
    assert next_sets(calibration, samples, log_p, samples[:5], 18, 3) == []


def test_a_twin_experiment_runs_the_truth_with_seeds_apart_and_takes_their_mean_as_targets():
    config = _config(twin={"enabled": True, "truth": {"sliding_friction": 0.35, "rolling_friction": 0.12,
                                                       "wall_sliding_friction": 0.3}, "replicates": 2})
    calibration = calibration_of(config)
    assert twin_truth(calibration).tolist() == [0.35, 0.12, 0.3]
    sets = twin_sets(calibration)
    assert sets == [{"theta": [0.35, 0.12, 0.3], "replicate": TWIN_SEED_OFFSET},
                    {"theta": [0.35, 0.12, 0.3], "replicate": TWIN_SEED_OFFSET + 1}]
    made = twin_targets(calibration, [[28.0, 9.0], [30.0, 10.0]])
    assert made == {"targets_deg": {"internal": 29.0, "aluminium": 9.5},
                    "standard_error_deg": {"internal": 1.0, "aluminium": 0.5},
                    "angles_deg": {"internal": [28.0, 30.0], "aluminium": [9.0, 10.0]}}
    twin = with_targets(calibration, made["targets_deg"], [[28.0, 9.0], [30.0, 10.0]])
    assert twin.targets_deg.tolist() == [29.0, 9.5] and twin.twin and not calibration.twin
    with pytest.raises(ValueError, match=r"no target for the tests \['aluminium'\]"):
        with_targets(calibration, {"internal": 29.0})
    with pytest.raises(ValueError, match="one finite angle per test"):
        with_targets(calibration, made["targets_deg"], [[28.0], [30.0]])


def test_measured_targets_take_their_configured_standard_errors():
    config = _config()
    config["calibration"]["target_sd_deg"] = {"internal": 0.7, "aluminium": 0.4}
    calibration = calibration_of(config)
    assert calibration.target_sd_deg.tolist() == [0.7, 0.4] and not calibration.twin
    raw = {"calibration": {"targets_deg": {"internal": 30.0, "aluminium": 9.5}, "target_sd_deg": {"internal": 1.0}},
           "jenike": {"sweep": {"tests": ["internal", "aluminium"]}}}
    with pytest.raises(ConfigError, match="calibration.target_sd_deg.*aluminium"):
        validate_config(raw)


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
