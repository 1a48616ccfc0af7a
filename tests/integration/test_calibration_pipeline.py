"""The calibration stage with the real engine, chained into a silo run through `parameters: calibrated`.

Two tiny shear tests (internal friction, particle friction 0.1 and 0.5) make a two-point chart; a target
between their bulk friction angles is inverted, and a tiny silo runs with the chosen parameters.
"""

from __future__ import annotations

import csv
import json

import pytest
import yaml

from tests.conftest import NO_BLENDER, NO_BLENDING, TINY_SILO, require_liggghts, run_snakemake

pytestmark = pytest.mark.integration

TINY_CALIBRATION = {
    "jenike": {
        "cell": {"inner_diameter": 0.04, "bottom_ring_height": 0.008, "shear_ring_height": 0.01, "plate_size": 0.07},
        "fill": {"settle_time": 0.1},
        "consolidation": {"time": 0.05},
        "shear": {"velocity": 0.03, "displacement": 0.004},
        "sweep": {"shapes": ["sphere2"], "tests": ["internal"], "sliding_friction": [0.1, 0.5], "rolling_friction": [0.0]},
    },
    "calibration": {"targets_deg": {"internal": 24.0, "aluminium": 9.5}, "tolerance_deg": 1.0, "shape": "sphere2",
                    "rolling_friction": 0.0},
    "silo_flat": {**TINY_SILO, "parameters": "calibrated"},
    "silo_recirculation": NO_BLENDING,
    "blender": NO_BLENDER,
}


@pytest.fixture(scope="module")
def calibrated_pipeline(tmp_path_factory):
    require_liggghts()
    workdir = tmp_path_factory.mktemp("calibration")
    config_path = workdir / "calibration.yaml"
    config_path.write_text(yaml.safe_dump(TINY_CALIBRATION))
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return workdir


def test_table_has_one_row_per_point_and_friction_grows(calibrated_pipeline):
    table = list(csv.DictReader((calibrated_pipeline / "results" / "calibration" / "bulk_friction.csv").open()))
    assert sorted((r["lid"], float(r["particle_friction"])) for r in table) == [
        ("rigid", 0.1), ("rigid", 0.5), ("servo", 0.1), ("servo", 0.5)
    ]
    rows = [r for r in table if r["lid"] == "rigid"]
    low, high = (float(r["bulk_friction"]) for r in rows)
    assert high > low > 0.0
    for row in rows:
        assert float(row["ring_sides_relative_difference"]) < 0.10


def test_chart_and_parameters_are_written(calibrated_pipeline):
    calibration = calibrated_pipeline / "results" / "calibration"
    assert (calibration / "charts" / "sphere2_internal.png").read_bytes()[:4] == b"\x89PNG"
    parameters = yaml.safe_load((calibration / "parameters.yaml").read_text())
    assert 0.1 < parameters["particle_particle"]["sliding_friction"] < 0.5
    assert parameters["particle_particle"]["lower"] <= parameters["particle_particle"]["sliding_friction"]
    assert parameters["not_tested"] == ["aluminium"]


def test_the_silo_ran_with_the_calibrated_parameters(calibrated_pipeline):
    parameters = yaml.safe_load((calibrated_pipeline / "results" / "calibration" / "parameters.yaml").read_text())
    (run_dir,) = (calibrated_pipeline / "results" / "silo_flat").iterdir()
    case = json.loads((run_dir / "deck" / "case.json").read_text())
    particle_contact = next(
        c for c in case["parameters"]["contacts"] if c["materials"] == ["hdpe", "hdpe"]
    )
    assert particle_contact["sliding_friction"] == parameters["particle_particle"]["sliding_friction"]
    assert particle_contact["rolling_friction"] == 0.0
    assert (run_dir / "metrics" / "flow.csv").exists()


def test_lids_are_compared_on_the_same_points(calibrated_pipeline):
    calibration = calibrated_pipeline / "results" / "calibration"
    rows = list(csv.DictReader((calibration / "lid_comparison.csv").open()))
    assert [float(r["particle_friction"]) for r in rows] == [0.1, 0.5]
    for row in rows:
        assert float(row["bulk_friction_servo_lid"]) > 0.0
    assert (calibration / "charts" / "lid_comparison.png").exists()


def test_diagnostics_of_the_middle_point(calibrated_pipeline):
    (diagnostics,) = (calibrated_pipeline / "results" / "calibration" / "runs").glob("*/metrics/diagnostics.json")
    summary = json.loads(diagnostics.read_text())
    assert summary["wall_contacts_in_shear_plane"] > 0
    assert summary["mean_angular_speed_rad_s"] > 0.0
    assert (diagnostics.parent.parent / "plots" / "mobilised_friction.png").exists()
    assert (diagnostics.parent.parent / "plots" / "angular_velocity.png").exists()
