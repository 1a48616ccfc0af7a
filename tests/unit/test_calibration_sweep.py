"""Expansion of the calibration sweep grid."""

import pytest

from siloflow.calibration.sweep import chart_rows, lid_comparison
from siloflow.model.cases.jenike_sweep import (CALIBRATION_CHART, CHECK, SHAPE_CHART, diagnostic_points, is_chart_point,
                                        point_role, sweep_points)
from siloflow.engines.config import ConfigError, validate_config


def test_default_sweep_is_shape_x_test_x_sliding_x_rolling():
    sweep = {**validate_config({})["jenike"]["sweep"], "lid_comparison": False}
    points = sweep_points(sweep)
    assert len(points) == 1 * 2 * 3 * 2
    assert points[0] == {
        "shape": "sphere2",
        "test": "internal",
        "sliding_friction": 0.1,
        "rolling_friction": 0.0,
        "restitution": 0.1,
        "rotation_blocked": False,
    }
    assert {p["test"] for p in points} == {"internal", "aluminium"}
    assert all(is_chart_point(p, sweep["restitution"]) for p in points)


def test_sensitivity_and_rotation_blocked_points_are_added_once():
    sweep = {
        "shapes": ["sphere", "sphere2"],
        "tests": ["internal"],
        "sliding_friction": [0.1, 0.5, 0.3],
        "rolling_friction": [0.05, 0.2],
        "restitution": 0.1,
        "restitution_sensitivity": [0.1, 0.6, 1.0],
        "rotation_blocked": True,
        "lid_comparison": False,
        "wall_test_particle_friction": 0.35,
    }
    points = sweep_points(sweep)
    grid = 2 * 1 * 3 * 2
    # restitution 0.1 duplicates a grid point; 0.6 and 1.0 are new: middle friction 0.3, rolling 0.05
    sensitivity = [p for p in points if p["restitution"] != 0.1]
    assert len(sensitivity) == 2 * 2
    assert {(p["sliding_friction"], p["rolling_friction"]) for p in sensitivity} == {(0.3, 0.05)}
    blocked = [p for p in points if p["rotation_blocked"]]
    assert len(blocked) == 2 * 3
    assert len(points) == grid + 4 + 6
    assert not any(is_chart_point(p, 0.1) for p in sensitivity + blocked)


def test_lid_comparison_runs_the_internal_points_with_the_other_lid():
    sweep = validate_config({})["jenike"]["sweep"]
    points = sweep_points(sweep, lid="rigid")
    compared = [p for p in points if "lid" in p]
    assert len(points) == 12 + 3
    assert {p["lid"] for p in compared} == {"servo"}
    assert sorted(p["sliding_friction"] for p in compared) == [0.1, 0.3, 0.5]
    assert all(p["test"] == "internal" and p["rolling_friction"] == 0.0 for p in compared)
    assert not any(is_chart_point(p, sweep["restitution"]) for p in compared)
    assert {p["lid"] for p in sweep_points(sweep, lid="servo") if "lid" in p} == {"rigid"}


def test_lid_comparison_pairs_rows_of_both_lids():
    base = {"shape": "sphere2", "test": "internal", "rolling_friction": "0.0", "restitution": "0.1",
            "rotation_blocked": "False", "shear_velocity": "0.03"}
    rows = [
        {**base, "particle_friction": "0.1", "lid": "rigid", "bulk_friction": "0.40"},
        {**base, "particle_friction": "0.1", "lid": "servo", "bulk_friction": "0.46"},
        {**base, "particle_friction": "0.3", "lid": "rigid", "bulk_friction": "0.55"},
        {**base, "test": "wall", "particle_friction": "0.1", "lid": "servo", "bulk_friction": "0.2"},
        # the shear-speed study's point: in neither the pairs nor the chart
        {**base, "particle_friction": "0.3", "lid": "servo", "bulk_friction": "0.7", "shear_velocity": "0.015"},
        {**base, "particle_friction": "0.3", "lid": "rigid", "bulk_friction": "0.7", "shear_velocity": "0.015"},
    ]
    (pair,) = lid_comparison(rows, 0.1, 0.03)
    assert pair["particle_friction"] == 0.1
    assert pair["servo_minus_rigid"] == 0.46 - 0.40
    assert [r["lid"] for r in chart_rows(rows, 0.1, "rigid", 0.03)] == ["rigid", "rigid"]


def test_diagnostic_points_are_the_middle_friction_of_each_curve():
    sweep = validate_config({})["jenike"]["sweep"]
    points = sweep_points(sweep, lid="rigid")
    chosen = diagnostic_points(points, sweep, "rigid")
    assert len(chosen) == 2 * 2  # two tests x two rolling frictions
    assert {p["sliding_friction"] for p in chosen} == {0.3}
    assert diagnostic_points(points, sweep, "servo") == []
    assert diagnostic_points(points, {**sweep, "diagnostics": "all"}, "rigid") == [
        p for p in points if "lid" not in p
    ]


def test_wall_tests_and_sensitivity_studies_can_be_kept_to_some_shapes_and_tests():
    sweep = {
        "shapes": ["sphere", "sphere2", "sphere4"],
        "tests": ["internal", "aluminium"],
        "wall_test_shapes": ["sphere2"],
        "sensitivity_shapes": ["sphere2"],
        "sensitivity_tests": ["internal"],
        "sliding_friction": [0.1, 0.3, 0.5, 0.8],
        "rolling_friction": [0.0, 0.1],
        "restitution": 0.1,
        "restitution_sensitivity": [0.6],
        "rotation_blocked": True,
        "lid_comparison": True,
        "wall_test_particle_friction": 0.35,
    }
    points = sweep_points(sweep)
    chart = [p for p in points if is_chart_point(p, 0.1)]
    # internal curves for every shape, the wall test for sphere2 only: 3 x 8 + 8
    assert len(chart) == 3 * 2 * 4 + 2 * 4
    assert {p["shape"] for p in chart if p["test"] == "aluminium"} == {"sphere2"}
    others = [p for p in points if not is_chart_point(p, 0.1)]
    # restitution (1) + rotation blocked (4) + other lid (4), all on sphere2's internal test
    assert len(others) == 1 + 4 + 4
    assert {(p["shape"], p["test"]) for p in others} == {("sphere2", "internal")}
    assert len(points) == len(chart) + len(others)


def test_sweep_subsets_must_name_shapes_and_tests_of_the_sweep():
    config = {"jenike": {"sweep": {"shapes": ["sphere2"], "wall_test_shapes": ["sphere4"]}}}
    with pytest.raises(ConfigError, match=r"jenike.sweep.wall_test_shapes\[0\]': 'sphere4' is not among jenike.sweep.shapes"):
        validate_config(config)
    config = {"jenike": {"sweep": {"tests": ["internal"], "sensitivity_tests": ["aluminium"]}}}
    with pytest.raises(ConfigError, match=r"jenike.sweep.sensitivity_tests\[0\]': 'aluminium' is not among jenike.sweep.tests"):
        validate_config(config)


def test_each_sweep_point_has_one_role_and_only_chart_points_are_on_a_chart():
    sweep = {**validate_config({})["jenike"]["sweep"], "shapes": ["sphere", "sphere2"], "sensitivity_shapes": ["sphere2"],
             "reference_replicates": 2, "shear_velocity_sensitivity": [0.01]}
    points = sweep_points(sweep, lid="rigid")
    roles = [point_role(p, sweep["restitution"], "sphere2") for p in points]
    charts = [p for p, role in zip(points, roles) if role != CHECK]
    # a chart point, or another seed of one: each shape's charts carry a spread between seeds of their own
    assert all(is_chart_point({k: v for k, v in p.items() if k != "replicate"}, sweep["restitution"]) for p in charts)
    assert {p["shape"] for p, role in zip(points, roles) if role == CALIBRATION_CHART} == {"sphere2"}
    assert {p["shape"] for p, role in zip(points, roles) if role == SHAPE_CHART} == {"sphere"}
    replicated = [(p["shape"], role) for p, role in zip(points, roles) if "replicate" in p]
    assert replicated == [("sphere2", CALIBRATION_CHART), ("sphere", SHAPE_CHART)]
    checks = [p for p, role in zip(points, roles) if role == CHECK]
    # the reference point's slower shear is a check, as are the lid and sensitivity points
    assert any(p.get("shear_velocity") == 0.01 for p in checks) and not any("replicate" in p for p in checks)
    assert all(p["shape"] == "sphere2" for p in checks)
    # the diagnostics take chart points only: not the reference point's other seed
    assert not any("replicate" in p for p in diagnostic_points(points, sweep, "rigid"))


def test_the_pour_variant_pours_the_internal_sensitivity_points_at_their_own_friction():
    sweep = {**validate_config({})["jenike"]["sweep"], "lid_comparison": False, "own_pour_variant": True,
             "sliding_friction": [0.1, 0.3, 0.5]}
    points = sweep_points(sweep, pour_friction=0.1)
    variant = [p for p in points if "pour" in p]
    # the point at 0.1 poured at its own friction is the chart's own point, poured at 0.1
    assert [(p["sliding_friction"], p["rolling_friction"], p["test"]) for p in variant] == [
        (0.3, 0.0, "internal"), (0.5, 0.0, "internal")]
    assert {p["pour"] for p in variant} == {"own_friction"}
    assert not any(is_chart_point(p, sweep["restitution"]) for p in variant)
    assert all(point_role(p, sweep["restitution"], "sphere2") == CHECK for p in variant)
    assert sweep_points(sweep, pour_friction=None) == [p for p in points if "pour" not in p]


def test_the_pour_variant_needs_a_configured_pour_friction():
    with pytest.raises(ConfigError, match="jenike.sweep.own_pour_variant.*jenike.fill.sliding_friction"):
        validate_config({"jenike": {"fill": {"sliding_friction": None}, "sweep": {"own_pour_variant": True}}})


def test_the_chart_rows_and_the_lid_comparison_leave_out_the_pour_variant():
    row = {"shape": "sphere2", "test": "internal", "lid": "rigid", "rolling_friction": "0.0", "restitution": "0.1",
           "rotation_blocked": "False", "shear_velocity": "0.03", "particle_friction": "0.3", "bulk_friction": "0.5"}
    variant = {**row, "pour": "own_friction", "lid": "servo"}
    legacy = {key: value for key, value in row.items() if key != "pour"}
    assert chart_rows([{**row, "pour": "configured"}, variant, legacy], 0.1, "rigid", 0.03) == [
        {**row, "pour": "configured"}, legacy]
    assert lid_comparison([row, variant], 0.1, 0.03) == []
