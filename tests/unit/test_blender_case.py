"""The blender case: sizing, gravity scaling, checks, meshes and the deck (golden file)."""

from __future__ import annotations

import copy
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from siloflow.model.cases import case_for_run
from siloflow.model.cases.blender import (
    blender_cases, blender_mesh_set, build_blender_case, fill_cross_section_area,
)
from siloflow.model.cases.blender_geometry import blender_geometry
from siloflow.model.cases.blender_meshes import is_watertight
from siloflow.engines.config import ConfigError, load_config, validate_config
from siloflow.engines.liggghts.blender import render_blender_deck, write_blender_inputs
from tests.golden_files import assert_matches_golden

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


@pytest.fixture(scope="module")
def golden_config():
    return load_config(GOLDEN / "blender_config.yaml")


def changed(config, edit):
    config = copy.deepcopy(config)
    edit(config["blender"])
    return config


def test_blender_deck_matches_golden_file(golden_config):
    rendered = render_blender_deck(build_blender_case(golden_config, "straight"))
    assert_matches_golden(rendered, "blender.lmp")


def test_continuous_deck_is_periodic_and_loses_no_clump_batch_deck_drains(golden_config):
    continuous = render_blender_deck(build_blender_case(golden_config, "straight"))
    assert "boundary f f p" in continuous
    assert "thermo_modify lost error" in continuous[continuous.index("# --- continuous discharge"):]
    batch_config = changed(golden_config, lambda b: b["discharge"].update(mode="batch"))
    batch = render_blender_deck(build_blender_case(batch_config, "straight"))
    assert "boundary f f f" in batch
    assert "thermo_modify lost ignore" in batch[batch.index("# --- batch discharge"):]
    # every wall mesh in the wall fix; the gate only until the outlet opens
    assert ("meshes hopper_left hopper_right insert_left insert_right tube_left tube_right outlet_gate"
            in continuous)
    opened = continuous[continuous.index("# --- open the outlet"):]
    assert "meshes hopper_left hopper_right insert_left insert_right tube_left tube_right store_force yes\n" in opened
    # every wall writes its force and torque on the particles: the front and back planes, then each mesh
    forces = next(line for line in continuous.splitlines() if line.startswith("fix wall_forces all ave/time"))
    assert re.findall(r" v_(\w+)_fx", forces) == ["wall_front", "wall_back", "hopper_left", "hopper_right", "insert_left",
                                                "insert_right", "tube_left", "tube_right", "outlet_gate"]
    assert opened.index("variable outlet_gate_fx equal 0.0") < opened.index("unfix outlet_gate")


def test_gravity_factor_scales_gravity_stiffness_and_times_at_the_same_steps(golden_config):
    base = build_blender_case(golden_config, "straight", 1.0)
    fast = build_blender_case(golden_config, "straight", 4.0)
    assert fast.gravity == pytest.approx(4 * 9.81)
    # every modulus times f: E / (rho g d) and so the overlaps stay as at 1 g, and the time step (as 1 / sqrt(E))
    # halves with the flow times, so the run makes the same steps
    assert fast.silo.materials.youngs_modulus == tuple(4 * e for e in base.silo.materials.youngs_modulus)
    assert fast.silo.materials.poisson_ratio == base.silo.materials.poisson_ratio
    assert fast.silo.timestep == pytest.approx(base.silo.timestep / 2, rel=1e-12)
    assert fast.silo.discharge_steps == pytest.approx(base.silo.discharge_steps, abs=1)
    assert fast.silo.dump_every == pytest.approx(base.silo.dump_every, abs=1)
    assert fast.steady_window == pytest.approx((0.25, 0.5))
    assert fast.silo.settle_threshold == pytest.approx(4 * base.silo.settle_threshold)
    assert fast.silo.fill.insertion_velocity == base.silo.fill.insertion_velocity
    assert "fix gravity all gravity 39.24 vector" in render_blender_deck(fast)
    assert fast.run_id != base.run_id and fast.run_id.startswith("straight-g4-")
    # the factor of the moduli defines the runs it changes; those at 1 g keep their ids
    assert fast.defining_parameters["youngs_modulus_factor"] == 4.0
    assert "youngs_modulus_factor" not in base.defining_parameters


def test_at_fixed_moduli_a_faster_run_keeps_the_material_and_its_own_id(golden_config):
    fixed = changed(golden_config, lambda b: b.update(gravity_moduli="fixed"))
    base, fast = build_blender_case(fixed, "straight", 1.0), build_blender_case(fixed, "straight", 4.0)
    scaled_fast = build_blender_case(golden_config, "straight", 4.0)
    # the study's series: the same moduli at every factor, gravity and the flow times as under the other rule
    assert fast.silo.materials.youngs_modulus == base.silo.materials.youngs_modulus
    assert fast.gravity == pytest.approx(4 * 9.81) and fast.steady_window == scaled_fast.steady_window
    assert "youngs_modulus_factor" not in fast.defining_parameters
    # the stiffer rule's run is another run; at 1 g both rules make the same run
    assert fast.run_id != scaled_fast.run_id
    assert base.run_id == build_blender_case(golden_config, "straight", 1.0).run_id
    # the time step follows the Hertz limit of the faster pour, not a stiffer contact: longer than the scaled run's
    assert scaled_fast.silo.timestep < fast.silo.timestep <= base.silo.timestep


def test_fill_area_of_an_empty_hopper_is_the_trapezoid_plus_the_rectangle():
    geometry = blender_geometry(0.2, 0.01, 0.2, 30.0, 0.02, 0.002, tube_width=0, insert="none")
    tan30 = math.tan(math.radians(30.0))
    z_t = (0.1 - 0.01) / tan30
    assert geometry.z_transition == pytest.approx(z_t)
    assert fill_cross_section_area(geometry, 0.05) == pytest.approx(0.02 * 0.05 + 0.05**2 * tan30)
    assert fill_cross_section_area(geometry, z_t + 0.03) == pytest.approx(0.5 * (0.02 + 0.2) * z_t + 0.2 * 0.03)
    with pytest.raises(ValueError, match="above the top"):
        fill_cross_section_area(geometry, 1.0)


def test_internal_walls_take_their_cross_section_from_the_fill(golden_config):
    case = build_blender_case(golden_config, "straight")
    empty = blender_geometry(0.225, 0.0045, 0.21, 30.0, 0.02, 0.0025, tube_width=0, insert="none")
    geometry = case.geometry
    walls = 0.0
    for (x_low, z_low), (x_up, z_up) in geometry.internal_wall_spans():
        walls += 2 * 0.0025 * math.hypot(x_up - x_low, z_up - z_low)  # all below the fill height here
    assert case.fill_area == pytest.approx(fill_cross_section_area(empty, 0.235) - walls)
    assert case.silo.fill.n_clumps == round(667.0 * case.fill_area * 0.0045 / case.silo.particle.mass)


def test_meshes_are_closed_walls_plus_the_gate(golden_config):
    meshes = blender_mesh_set(build_blender_case(golden_config, "straight"))
    assert sorted(meshes) == sorted(["hopper_left", "hopper_right", "insert_left", "insert_right", "tube_left",
                                     "tube_right", "outlet_gate"])
    assert all(is_watertight(mesh) for name, mesh in meshes.items() if name != "outlet_gate")
    none = changed(golden_config, lambda b: b.update(configurations=["none"]))
    assert sorted(blender_mesh_set(build_blender_case(none, "none"))) == ["hopper_left", "hopper_right", "outlet_gate"]


def test_written_inputs_record_the_achieved_area_ratios(tmp_path, golden_config):
    case = build_blender_case(golden_config, "straight")
    deck = write_blender_inputs(case, tmp_path / "deck")
    summary = json.loads((deck.parent / "case.json").read_text())
    assert summary["geometry"]["interior_ratio"] == pytest.approx(1.0)
    assert summary["geometry"]["exterior_ratio"] == pytest.approx(1.72)
    assert summary["gravity_factor"] == 1.0 and summary["mode"] == "continuous"
    assert len(list((deck.parent / "meshes").glob("*.stl"))) == 7


def test_a_passage_narrower_than_the_limit_is_refused_naming_it(golden_config):
    narrow = changed(golden_config, lambda b: b.update(min_passage_clumps=6.0))
    with pytest.raises(ValueError, match="interior annulus|tube|outlet"):
        build_blender_case(narrow, "straight")


def test_a_pour_zone_above_the_silo_is_refused(golden_config):
    short = changed(golden_config, lambda b: b.update(vertical_height=0.1))
    with pytest.raises(ValueError, match="blender.vertical_height"):
        build_blender_case(short, "straight")


def test_config_names_unknown_configurations_and_shadowed_presets(golden_config):
    with pytest.raises(ConfigError, match=r"blender.configurations\[0\].*unknown insert configuration 'conical'"):
        validate_config(changed(golden_config, lambda b: b.update(configurations=["conical"])))
    with pytest.raises(ConfigError, match="built-in preset"):
        validate_config(changed(golden_config, lambda b: b["inserts"].update(straight={"interior_ratio": 1, "exterior_ratio": 2})))
    with pytest.raises(ConfigError, match="steady_window"):
        validate_config(changed(golden_config, lambda b: b["discharge"].update(steady_window=[0.5, 2.0])))
    with pytest.raises(ConfigError, match="release_height"):
        validate_config(changed(golden_config, lambda b: b["pathlines"].update(release_height=0.3)))


def test_user_inserts_by_ratios_or_end_points_build(golden_config):
    config = changed(golden_config, lambda b: b.update(
        configurations=["wide", "plates"],
        inserts={"wide": {"interior_ratio": 1.2, "exterior_ratio": 1.5},
                 "plates": {"inlet": [0.05, 0.2], "outlet": [0.045, 0.13]}},
    ))
    cases = blender_cases(validate_config(config))
    wide = next(c for c in cases.values() if c.configuration == "wide")
    assert wide.geometry.interior_ratio == pytest.approx(1.2) and wide.geometry.exterior_ratio == pytest.approx(1.5)
    plates = next(c for c in cases.values() if c.configuration == "plates")
    np.testing.assert_allclose(plates.geometry.insert_inlet, (0.05, 0.2))


def test_runs_are_configurations_times_gravity_factors_and_analysis_keys_do_not_rerun(golden_config):
    config = changed(golden_config, lambda b: b.update(configurations=["straight", "converging"], gravity_factors=[1.0, 4.0]))
    cases = blender_cases(validate_config(config))
    assert sorted((c.configuration, c.gravity_factor) for c in cases.values()) == [
        ("converging", 1.0), ("converging", 4.0), ("straight", 1.0), ("straight", 4.0)]
    run = build_blender_case(golden_config, "straight").run_id
    tweaked = changed(golden_config, lambda b: (b.update(bin_size=0.02), b["rtd"].update(bins=10)))
    assert build_blender_case(tweaked, "straight").run_id == run
    assert case_for_run(golden_config, "blender", run).configuration == "straight"
    with pytest.raises(KeyError, match="defines"):
        case_for_run(golden_config, "blender", "straight-g1-0000000000")
    disabled = changed(golden_config, lambda b: b.update(enabled=False))
    assert blender_cases(disabled) == {}


def test_gravity_configurations_run_every_factor_and_the_others_the_lowest_only(golden_config):
    config = changed(golden_config, lambda b: b.update(configurations=["straight", "converging"], gravity_factors=[5.0, 1.0, 50.0],
                                                       gravity_configurations=["converging"]))
    cases = blender_cases(validate_config(config))
    assert sorted((c.configuration, c.gravity_factor) for c in cases.values()) == [
        ("converging", 1.0), ("converging", 5.0), ("converging", 50.0), ("straight", 1.0)]
    # the choice says how many runs to make; it does not define one
    assert build_blender_case(validate_config(config), "straight").run_id == build_blender_case(golden_config, "straight").run_id
    with pytest.raises(ConfigError, match=r"blender.gravity_configurations\[0\]': 'diverging' is not among blender.configurations"):
        validate_config(changed(config, lambda b: b.update(gravity_configurations=["diverging"])))


def test_continuous_blender_impact_adds_the_fall_through_the_sink_and_scales_with_gravity(golden_config):
    config = copy.deepcopy(golden_config)
    config["blender"]["discharge"]["mode"] = "continuous"
    configuration = config["blender"]["configurations"][0]
    for factor in (1.0, 50.0):
        case = build_blender_case(config, configuration, factor)
        silo, g = case.silo, 9.81 * factor
        reentry_squared = 2 * g * config["blender"]["sink_depth"]
        expected = math.sqrt(max(silo.fill.insertion_velocity**2, reentry_squared)
                             + 2 * g * (silo.domain_top - silo.fill_height))
        assert silo.timestep_choice.impact_velocity == pytest.approx(expected, rel=1e-12)
