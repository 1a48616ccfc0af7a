"""The recirculating silo case: presets, sizing, deck (golden file), meshes."""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import numpy as np
import pytest

from siloflow.model.cases import case_for_run
from siloflow.model.cases.silo_recirculation import (
    apply_flow_pattern,
    build_recirculation_case,
    estimated_residence_time,
    recirculation_cases,
)
from siloflow.model.cases.physics import steps_for
from siloflow.engines.config import ConfigError, load_config, validate_config
from siloflow.model.cases.silo_recirculation import recirculation_meshes
from siloflow.engines.liggghts.silo_recirculation import render_recirculation_deck, write_recirculation_inputs
from tests.golden_files import assert_matches_golden

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


@pytest.fixture(scope="module")
def golden_config():
    return load_config(GOLDEN / "silo_recirculation_config.yaml")


def test_recirculation_deck_matches_golden_file(golden_config):
    rendered = render_recirculation_deck(build_recirculation_case(golden_config, "internal_flow"))
    assert_matches_golden(rendered, "silo_recirculation.lmp")


def test_deck_is_periodic_in_z_with_feeder_and_no_lost_clumps(golden_config):
    case = build_recirculation_case(golden_config, "internal_flow")
    deck = render_recirculation_deck(case)
    assert "boundary f f p" in deck
    assert "region domain block -0.04 0.04 0.0 0.012 -0.04 " in deck
    assert "region feeder block -0.012 0.012 INF INF -0.04 -0.02 units box" in deck
    assert "variable feeder_force_z atom mass*(v_feeder_velocity-vz)/dt/2" in deck
    assert "fix feeder all setforce NULL NULL v_feeder_force_z region feeder" in deck
    recirculation = deck[deck.index("# --- recirculate"):]
    assert "thermo_modify lost error" in recirculation
    assert "meshes floor_left floor_right channel_left channel_right" in deck
    # every wall, the channel walls included, writes its force and torque on the particles
    forces = next(line for line in deck.splitlines() if line.startswith("fix wall_forces all ave/time"))
    walls = re.findall(r" v_(\w+)_fx", forces)
    assert walls == ["wall_left", "wall_right", "wall_front", "wall_back", "floor_left", "floor_right",
                     "outlet_gate", "channel_left", "channel_right"]


def test_presets_set_the_study_friction_and_a_dedicated_front_back_material(golden_config):
    case = build_recirculation_case(golden_config, "internal_flow")
    table = case.silo.materials
    assert table.names == ("hdpe", "aluminium", "perspex_front_back")
    friction, rolling = np.array(table.sliding_friction), np.array(table.rolling_friction)
    np.testing.assert_array_equal(friction[0], [0.55, 0.5, 0.5])
    np.testing.assert_array_equal(rolling[0], [0.2, 0.2, 0.2])
    semi = build_recirculation_case(golden_config, "semi_mass_flow").silo.materials
    np.testing.assert_array_equal(np.array(semi.sliding_friction)[0], [0.35, 0.17, 0.0])
    np.testing.assert_array_equal(np.array(semi.rolling_friction)[0], [0.0, 0.0, 0.0])
    # Restitution comes from the original contacts.
    np.testing.assert_array_equal(np.array(semi.restitution)[0], [0.1, 0.1, 0.1])


def test_apply_flow_pattern_leaves_its_input_alone(golden_config):
    before = copy.deepcopy(golden_config)
    apply_flow_pattern(golden_config, golden_config["silo_recirculation"]["presets"]["internal_flow"])
    assert golden_config == before


def test_estimated_residence_time_is_holdup_over_throughput():
    # W H / (B0 V r) = 0.15 * 0.27 / (0.04 * 0.4 * 1) = 2.53125 s (the study's "about 2.75 s").
    assert estimated_residence_time(0.15, 0.27, 0.04, 0.4) == pytest.approx(2.53125, rel=1e-15)
    assert estimated_residence_time(0.15, 0.27, 0.04, 0.4, 0.5) == pytest.approx(5.0625, rel=1e-15)
    with pytest.raises(ValueError, match="feeder_velocity"):
        estimated_residence_time(0.15, 0.27, 0.04, 0.0)


def test_recirculation_time_covers_the_asked_recirculations(golden_config):
    case = build_recirculation_case(golden_config, "internal_flow")
    t_res = 0.08 * 0.05 / (0.024 * 0.4 * 0.5)
    expected = 2.0 * t_res
    assert case.estimated_residence_time == pytest.approx(t_res, rel=1e-12)
    # the study's nominal time: the channel as dense as the fill, whatever channel_density_ratio sized the run
    assert case.nominal_residence_time == pytest.approx(0.08 * 0.05 / (0.024 * 0.4), rel=1e-12)
    assert expected <= case.recirculation_time < expected + case.silo.timestep
    assert case.feeder_zone == (-0.012, 0.012, -0.04, -0.02)
    assert case.silo.sink_depth == 0.04


def _with_final_discharge(config, residence_times):
    raw = copy.deepcopy(config)
    raw["silo_recirculation"]["final_discharge"] = residence_times
    return validate_config(raw)


def test_the_discharge_after_the_recirculations_follows_them_for_its_residence_times(golden_config):
    """final_discharge 1.5: the discharge stage lasts 1.5 a-priori residence times after the 2 recirculations, the
    recirculation itself is unchanged, and a run without it keeps its id."""
    plain = build_recirculation_case(golden_config, "internal_flow")
    case = build_recirculation_case(_with_final_discharge(golden_config, 1.5), "internal_flow")
    dt, t_res = case.silo.timestep, case.estimated_residence_time
    assert case.final_discharge_steps == round(1.5 * t_res / dt)
    assert case.final_discharge_time == pytest.approx(case.final_discharge_steps * dt, rel=1e-15)
    assert case.recirculation_steps + case.final_discharge_steps == case.silo.discharge_steps
    assert abs(case.recirculation_steps - plain.silo.discharge_steps) <= 1
    assert [stage.kind for stage in case.stages()] == ["fill", "settle", "open", "recirculate", "discharge"]
    assert case.stages()[-1].controls["duration_s"] == case.final_discharge_time
    assert case.summary()["final_discharge_time_s"] == case.final_discharge_time
    assert case.run_id != plain.run_id
    assert build_recirculation_case(_with_final_discharge(golden_config, 0.0), "internal_flow").run_id == plain.run_id
    assert plain.final_discharge_steps == 0 and [s.kind for s in plain.stages()][-1] == "recirculate"
    thin = build_recirculation_case(_with_final_discharge(golden_config, 1.5), "internal_flow", "verification")
    assert thin.final_discharge_steps == 0
    assert case.reentry_stop(2.0) == 2.0 + case.recirculation_time and plain.reentry_stop(2.0) is None


def test_the_deck_stops_the_re_entry_then_discharges(golden_config):
    case = build_recirculation_case(_with_final_discharge(golden_config, 1.5), "internal_flow")
    deck = render_recirculation_deck(case)
    tail = deck.split("# --- recirculate")[1]
    assert f"variable reentry_end equal $(step+{case.recirculation_steps})" in tail
    assert 'if "$(step) < ${reentry_end}" then "run ${reentry_end} upto"' in tail
    assert tail.index("SILOFLOW recirculated") < tail.index("change_box all boundary f f f")
    discharge = tail.split("change_box all boundary f f f")[1]
    assert "thermo_modify lost ignore" in discharge and f"run {case.final_discharge_steps}\n" in discharge
    assert discharge.rstrip().endswith('print "SILOFLOW discharged step=$(step) time=$(step*dt) clumps=${n_clumps} '
                                       'ke_per_clump=${ke_per_clump}"')


def test_channel_meshes_face_into_the_channel(golden_config):
    meshes = recirculation_meshes(build_recirculation_case(golden_config, "internal_flow"))
    np.testing.assert_allclose(meshes["channel_left"].normals(), [[1.0, 0.0, 0.0]] * 2)
    np.testing.assert_allclose(meshes["channel_right"].normals(), [[-1.0, 0.0, 0.0]] * 2)
    np.testing.assert_allclose(meshes["channel_left"].area(), 0.012 * 0.04)


def test_runs_are_keyed_by_pattern_and_role(golden_config):
    raw = copy.deepcopy(golden_config)
    raw["silo_recirculation"]["flow_patterns"] = ["internal_flow", "semi_mass_flow"]
    raw["silo_recirculation"]["verification"]["enabled"] = True
    cases = recirculation_cases(raw)
    prefixes = sorted(run.rsplit("-", 1)[0] for run in cases)
    assert prefixes == ["internal_flow", "semi_mass_flow", "thin-semi_mass_flow"]
    thin = next(case for case in cases.values() if case.role == "verification")
    assert thin.silo.depth == raw["silo_recirculation"]["verification"]["depth"]
    with pytest.raises(KeyError, match="it defines"):
        case_for_run(raw, "silo_recirculation", "internal_flow-0000000000")
    raw["silo_recirculation"]["enabled"] = False
    assert recirculation_cases(raw) == {}


def test_write_inputs_writes_deck_meshes_and_case(tmp_path, golden_config):
    case = build_recirculation_case(golden_config, "internal_flow")
    deck = write_recirculation_inputs(case, tmp_path / "deck")
    assert deck.read_text() == render_recirculation_deck(case)
    assert sorted(p.name for p in (tmp_path / "deck" / "meshes").iterdir()) == [
        "channel_left.stl", "channel_right.stl", "floor_left.stl", "floor_right.stl", "outlet_gate.stl"
    ]
    assert '"flow_pattern": "internal_flow"' in (tmp_path / "deck" / "case.json").read_text()


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda b: b.update(flow_patterns=["funnel"]), "silo_recirculation.flow_patterns\\[0\\]': unknown preset 'funnel'"),
        (lambda b: b["verification"].update(flow_pattern="nope"), "silo_recirculation.verification.flow_pattern"),
        (lambda b: b.update(residence_time_ratios={"funnel": 0.5}),
         "silo_recirculation.residence_time_ratios.funnel': unknown preset 'funnel'"),
        (lambda b: b.update(residence_time_ratios={"internal_flow": 0.0}), "residence_time_ratios"),
        (lambda b: b.update(outlet_width=0.2), "silo_recirculation.outlet_width"),
        (lambda b: b.update(layouts=[{"name": "a", "blue_fraction": 0.2}, {"name": "a", "blue_fraction": 0.3}]),
         "used twice"),
        (lambda b: b.update(layouts=[{"name": "a", "blue_fraction": 1.0}]), "silo_recirculation.layouts"),
    ],
)
def test_bad_recirculation_config_is_named(golden_config, edit, message):
    raw = copy.deepcopy(golden_config)
    edit(raw["silo_recirculation"])
    with pytest.raises(ConfigError, match=message):
        validate_config(raw)


def test_clumps_re_entering_at_the_feeder_velocity_set_the_largest_impact(golden_config):
    config = copy.deepcopy(golden_config)
    config["silo_recirculation"]["feeder_velocity"] = 5.0  # faster than the 0.5 m/s pour
    case = build_recirculation_case(config, "internal_flow")
    silo = case.silo
    fall = silo.domain_top - silo.fill_height
    assert silo.timestep_choice.impact_velocity == pytest.approx(math.sqrt(5.0**2 + 2 * 9.81 * fall), rel=1e-12)


def test_a_patterns_residence_time_ratio_scales_its_blending_run_and_not_the_thin_silo(golden_config):
    config = copy.deepcopy(golden_config)
    config["silo_recirculation"]["residence_time_ratios"] = {"internal_flow": 0.5}
    raw = validate_config(config)
    base = validate_config(copy.deepcopy(golden_config))
    scaled, plain = build_recirculation_case(raw, "internal_flow"), build_recirculation_case(base, "internal_flow")
    section = raw["silo_recirculation"]
    expected = 0.5 * section["recirculations"] * scaled.estimated_residence_time
    assert scaled.estimated_residence_time == plain.estimated_residence_time
    assert scaled.silo.discharge_steps == steps_for(expected, scaled.silo.timestep)
    assert plain.silo.discharge_steps == steps_for(2 * expected, plain.silo.timestep)
    assert scaled.run_id != plain.run_id
    thin = build_recirculation_case(raw, section["verification"]["flow_pattern"], role="verification")
    thin_base = build_recirculation_case(base, section["verification"]["flow_pattern"], role="verification")
    assert thin.run_id == thin_base.run_id
