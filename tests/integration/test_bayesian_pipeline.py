"""The joint Bayesian calibration with the real engines, tiny: one target (the internal angle), two parameters
(particle sliding and rolling friction), single spheres in a 40 mm cell; a first design of three sets with one
replicate, one further iteration of one set, one posterior draw run for the predictive check, on LIGGGHTS (and, in
the physics tier, on LIGGGHTS and YADE side by side), as a twin experiment (the targets are each engine's own mean angle of two runs at known parameters). The numerics are tested on exact answers in tests/unit/test_bayes_*.py; this checks that the runs, the
iterations, the posterior and the report come out of `snakemake bayesian_calibration`, that the seed noise is measured
from the replicate, and that both engines give a posterior; then that a small silo on LIGGGHTS runs at the posterior
mean and at the posterior draw (``silo_flat.posterior_draws``).
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import yaml

from tests.conftest import NO_BLENDER, NO_BLENDING, NO_VERIFICATION, SMALL_SILO, TINY_JENIKE_SWEEP, require_liggghts, require_yade, run_snakemake

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(170)]

TINY_BAYESIAN = {
    "jenike": {**TINY_JENIKE_SWEEP, "sweep": {**TINY_JENIKE_SWEEP["sweep"], "shapes": ["sphere"]}},
    "calibration": {
        "targets_deg": {"internal": 24.0}, "tolerance_deg": 1.0, "shape": "sphere", "rolling_friction": 0.1,
        "bayesian": {"engines": ["liggghts", "yade"], "initial_sets": 3, "replicates": 2, "sets_per_iteration": 1,
                     "max_iterations": 1, "max_sets": 6, "predictive_draws": 1, "walkers": 8, "steps": 400,
                     "max_steps": 400,
                     "stop_shift": 0.001, "compare_with_chart": False,
                     "twin": {"enabled": True, "truth": {"sliding_friction": 0.3, "rolling_friction": 0.1},
                              "replicates": 2},
                     "priors": {"sliding_friction": {"lower": 0.1, "upper": 0.6},
                                "rolling_friction": {"lower": 0.0, "upper": 0.2}}},
    },
    "silo_flat": SMALL_SILO,
    "silo_recirculation": NO_BLENDING,
    "blender": NO_BLENDER,
    "verification": NO_VERIFICATION,
}


#: the fast tier's calibration: LIGGGHTS alone (YADE's Jenike runs, the same orchestration on the other engine, are
#: the physics tier's, with both engines side by side; test_jenike_yade.py runs a YADE shear test in the fast tier)
ON_LIGGGHTS = {**TINY_BAYESIAN, "calibration": {**TINY_BAYESIAN["calibration"], "bayesian": {
    **TINY_BAYESIAN["calibration"]["bayesian"], "engines": ["liggghts"]}}}


def _calibrate(tmp_path_factory, config: dict):
    require_liggghts()
    if "yade" in config["calibration"]["bayesian"]["engines"]:
        require_yade()
    workdir = tmp_path_factory.mktemp("bayesian")
    config_path = workdir / "bayesian.yaml"
    config_path.write_text(yaml.safe_dump(config))
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path), targets=("bayesian_calibration",))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return workdir / "results" / "calibration" / "bayesian"


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    """The calibration on LIGGGHTS alone; yields its results folder."""
    return _calibrate(tmp_path_factory, ON_LIGGGHTS)


@pytest.fixture(scope="module")
def calibrated_on_both(tmp_path_factory):
    """The calibration on LIGGGHTS and YADE (the physics tier); yields its results folder."""
    return _calibrate(tmp_path_factory, TINY_BAYESIAN)


@pytest.mark.parametrize("engine", ["liggghts", pytest.param("yade", marks=pytest.mark.physics)])
def test_each_engine_iterates_to_a_posterior_with_its_seed_noise(request, engine):
    folder = request.getfixturevalue("calibrated" if engine == "liggghts" else "calibrated_on_both") / engine
    first = json.loads((folder / "iteration_0" / "design.json").read_text())
    # every set on its own seed; the first set repeated
    assert len(first["sets"]) == 4 and [s["replicate"] for s in first["sets"]] == [0, 1, 2, 3]
    assert first["sets"][3]["theta"] == first["sets"][0]["theta"]
    second = json.loads((folder / "iteration_1" / "design.json").read_text())
    # the budget: 6 sets less the predictive draw, 4 done: one, at the posterior's mode
    assert len(second["sets"]) == 1 and second["sets"][0]["replicate"] == 4
    stopped = json.loads((folder / "iteration_2" / "design.json").read_text())
    assert stopped["stopped"] and stopped["sets"] == []
    posterior = json.loads((folder / "posterior.json").read_text())
    assert posterior["iteration"] == 1 and posterior["sets"] == 5
    # the first set's replicate and the twin's second run at the truth: two degrees of freedom
    assert posterior["seed_noise_degrees_of_freedom"] == 2 and posterior["seed_sd_deg"]["internal"] >= 0
    assert posterior["surrogates"]["internal"]["inputs"] == ["sliding_friction", "rolling_friction"]
    assert posterior["surrogates"]["internal"]["leave_one_out"]["n"] == 5
    # the chain was held at 400 steps (max_steps): too short for 50 autocorrelation times, and said so
    assert any(warning.startswith("sampler: ") for warning in posterior["warnings"])
    assert set(posterior["parameters"]) == {"sliding_friction", "rolling_friction"}
    for name, bounds in (("sliding_friction", (0.1, 0.6)), ("rolling_friction", (0.0, 0.2))):
        value = posterior["parameters"][name]
        assert bounds[0] <= value["q05"] <= value["mean"] <= value["q95"] <= bounds[1] and value["sd"] > 0
    samples = np.load(folder / "iteration_1" / "posterior.npz")["samples"]
    assert samples.shape == (8 * 200, 2)
    twin = json.loads((folder / "twin" / "targets.json").read_text())
    assert twin["truth"] == {"sliding_friction": 0.3, "rolling_friction": 0.1} and twin["runs"] == 2
    target = twin["targets_deg"]["internal"]
    assert 5.0 < target < 60.0 and twin["standard_error_deg"]["internal"] >= 0
    assert posterior["targets_deg"] == {"internal": target}
    assert set(posterior["twin"]["parameters"]) == {"sliding_friction", "rolling_friction"}
    assert posterior["twin"]["inside_credible_region"] == (posterior["twin"]["hpd_level"] <= 0.9)
    assert posterior["target_degrees_of_freedom"] == 2
    assert posterior["predictive"]["degrees_of_freedom"] == 1
    with open(folder / "predictive.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 1 and rows[0]["test"] == "internal" and float(rows[0]["target_deg"]) == pytest.approx(target)
    for name in ("corner.png", "predictive.png", "intervals.csv"):
        assert (folder / name).stat().st_size > 0
    with open(folder / "ridge.csv", newline="") as handle:
        ridge = list(csv.DictReader(handle))
    assert 1 <= len(ridge) <= 7 and all(float(row["predicted_internal_deg"]) > 0 for row in ridge)


@pytest.mark.physics
def test_the_engines_posteriors_stand_side_by_side(calibrated_on_both):
    with open(calibrated_on_both / "engines.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {row["parameter"] for row in rows} >= {"sliding_friction", "rolling_friction"}


def test_the_silo_runs_at_the_posterior_mean_and_at_each_draw(calibrated):
    workdir = calibrated.parents[2]
    config_path = workdir / "silo_draws.yaml"
    config_path.write_text(yaml.safe_dump({**ON_LIGGGHTS, "silo_flat": {**SMALL_SILO, "parameters": "bayesian",
                                                                         "posterior_draws": True}}))
    summary_path = workdir / "results" / "silo_flat" / "posterior_draws" / "summary.json"
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path),
                           targets=(str(summary_path.relative_to(workdir)),))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    summary = json.loads(summary_path.read_text())
    mean, draw = summary["runs"]
    posterior = json.loads((calibrated / "liggghts" / "posterior.json").read_text())["parameters"]
    assert mean["label"] == "posterior mean" and draw["label"] == "draw 0" and mean["run_id"] != draw["run_id"]
    assert mean["sliding_friction"] == pytest.approx(posterior["sliding_friction"]["mean"])
    predictive = json.loads((calibrated / "liggghts" / "predictive" / "design.json").read_text())["sets"]
    assert [draw["sliding_friction"], draw["rolling_friction"]] == pytest.approx(predictive[0]["theta"])
    for run in (mean, draw):
        flow = json.loads((workdir / "results" / "silo_flat" / run["run_id"] / "metrics" / "flow.json").read_text())
        assert run["mass_flow_rate_kg_s"] == flow["mass_flow_rate_kg_s"] > 0
        with open(workdir / "results" / "silo_flat" / run["run_id"] / "metrics" / "janssen.csv", newline="") as handle:
            janssen = list(csv.DictReader(handle))
        # the deepest bin with an error, else the deepest
        base = max([row for row in janssen if row["sigma_v_dem_Pa_error"]] or janssen,
                   key=lambda row: float(row["depth_below_surface_m"]))
        assert run["base_vertical_stress_Pa"] == pytest.approx(float(base["sigma_v_dem_Pa"]))
        assert run["base_vertical_stress_Pa"] > 0
        # the small silo's fill holds one Janssen bin, which has no neighbour to pair with for an error
        assert run["base_vertical_stress_Pa_error"] is None or run["base_vertical_stress_Pa_error"] >= 0
    # one draw: no spread between draws, so no calibration error bar and no verdict
    assert [row["draws"] for row in summary["spread"]] == [1, 1]
    assert all(row["spread_exceeds_run_error"] is None for row in summary["spread"])
    assert (workdir / "results" / "silo_flat" / "posterior_draws" / "draws.png").stat().st_size > 0
