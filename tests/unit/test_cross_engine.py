"""The cross-engine check: its runs, the centreline velocity and the comparison of two engines, against exact
answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.model.frames import ClumpFrame
from siloflow.analysis.studies.cross_engine import centreline_vertical_velocity, compare_engines
from siloflow.model.cases.cross_engine import cross_engine_cases, cross_engine_jenike_cases, jenike_point_label
from siloflow.engines.config import ConfigError, validate_config


def _frame(time, x, z, vz):
    n = len(x)
    return ClumpFrame(time=time, step=int(time * 1000), clump_id=np.arange(n),
                      position=np.column_stack([x, np.zeros(n), z]), velocity=np.column_stack([np.zeros(n),
                                                                                                np.zeros(n), vz]),
                      mass=np.ones(n), n_spheres=np.full(n, 2))


def test_centreline_velocity_averages_the_clumps_in_the_band_and_window_only():
    frames = [
        _frame(0.1, [0.0, 0.001, 0.01], [0.01, 0.0105, 0.01], [-1.0, -3.0, -9.0]),  # the third is off the centreline
        _frame(0.2, [0.0, 0.0], [0.01, 0.02], [-2.0, -9.0]),  # the second is above the band
        _frame(0.9, [0.0], [0.01], [-9.0]),  # after the window
    ]
    assert centreline_vertical_velocity(frames, 0.01, 0.001, 0.002, 0.0, 0.5) == pytest.approx(-2.0)
    with pytest.raises(ValueError, match="no clump"):
        centreline_vertical_velocity(frames, 0.05, 0.001, 0.002, 0.0, 0.5)


def test_compare_engines_by_hand():
    row = compare_engines({"a": [1.0, 2.0, 3.0], "b": [0.0, 0.0, 3.0]}, "q", "kg")
    assert (row["a_mean"], row["a_std"], row["a_seeds"]) == (2.0, 1.0, 3)
    assert row["b_mean"] == 1.0 and row["b_std"] == pytest.approx(math.sqrt(3.0))
    assert row["difference"] == 1.0
    assert row["difference_error"] == pytest.approx(math.sqrt(1.0 / 3.0 + 1.0))
    assert row["difference_in_errors"] == pytest.approx(1.0 / math.sqrt(4.0 / 3.0))
    assert not row["larger_than_2_errors"]
    far = compare_engines({"a": [10.0, 10.2], "b": [1.0, 1.2]}, "q", "kg")
    assert far["larger_than_2_errors"]


def test_compare_engines_needs_two_engines_with_two_seeds():
    with pytest.raises(ValueError, match="two engines"):
        compare_engines({"a": [1.0, 2.0]}, "q", "kg")
    with pytest.raises(ValueError, match="at least two"):
        compare_engines({"a": [1.0], "b": [1.0, 2.0]}, "q", "kg")


def test_the_runs_differ_in_engine_and_seed_only():
    config = validate_config({"cross_engine": {"seeds": 2}})
    cases = cross_engine_cases(config)
    assert list(cases) == ["liggghts", "yade"]
    ligg, yade = (list(runs.values()) for runs in cases.values())
    assert len(ligg) == len(yade) == 2
    assert ligg[0].fill.n_clumps == yade[0].fill.n_clumps
    assert ligg[0].width == config["cross_engine"]["width"]
    assert ligg[0].seeds != ligg[1].seeds and ligg[0].seeds == yade[0].seeds
    assert len({c.run_id for c in ligg + yade}) == 4


def test_one_engine_or_one_seed_is_refused_naming_the_key():
    with pytest.raises(ConfigError, match="cross_engine.engines"):
        validate_config({"cross_engine": {"engines": ["liggghts"]}})
    with pytest.raises(ConfigError, match="cross_engine.seeds"):
        validate_config({"cross_engine": {"seeds": 1}})


def test_the_jenike_runs_are_the_points_in_the_small_cell_differing_in_engine_and_seed_only():
    config = validate_config({"cross_engine": {"seeds": 2}})
    cases = cross_engine_jenike_cases(config)
    assert list(cases) == ["liggghts", "yade"]
    ligg, yade = (list(runs.values()) for runs in cases.values())
    assert len(ligg) == len(yade) == 4  # two points, two seeds
    labels = [label for label, _ in ligg]
    assert labels == ["bulk friction, internal, mu = 0.3, mu_r = 0.1"] * 2 + \
        ["bulk friction, wall (aluminium), mu = 0.3, mu_r = 0.1"] * 2
    first, second = ligg[0][1], ligg[1][1]
    assert first.geometry.inner_radius == 0.5 * config["cross_engine"]["jenike"]["inner_diameter"]
    assert first.geometry.shear_displacement == config["cross_engine"]["jenike"]["shear_displacement"]
    assert first.point["restitution"] == config["jenike"]["sweep"]["restitution"]
    assert first.seeds != second.seeds and first.seeds == yade[0][1].seeds
    assert first.fill.n_clumps == yade[0][1].fill.n_clumps
    assert len({case.run_id for _, case in ligg + yade}) == 8


def test_a_jenike_point_of_an_undefined_wall_material_is_refused_naming_the_point():
    config = validate_config({"cross_engine": {"jenike": {"points": [
        {"test": "glass", "sliding_friction": 0.3, "rolling_friction": 0.1}]}}})
    with pytest.raises(ValueError, match=r"cross_engine.jenike.points .*glass.*material 'glass' is not defined"):
        cross_engine_jenike_cases(config)


def test_a_point_label_names_test_and_frictions():
    assert jenike_point_label({"test": "perspex", "sliding_friction": 0.25, "rolling_friction": 0.0}) == \
        "bulk friction, wall (perspex), mu = 0.25, mu_r = 0"
