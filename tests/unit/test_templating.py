"""Deck rendering: golden files pin the decks; nothing from config can inject an engine command."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import pytest

from siloflow.engines.config import ConfigError, load_config, validate_config
from siloflow.engines.liggghts.inputs import INNER_SPHERE_FRACTION, processor_grid, template_spheres
from siloflow.engines.liggghts.silo_flat import render_silo_deck, silo_deck_context, write_silo_inputs
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.model.rolling import rolling_geometry
from siloflow.engines.templating import (
    UnsafeDeckValue,
    check_context,
    deck_environment,
    deck_integer,
    deck_name,
    deck_number,
    deck_path,
    render_deck,
)
from tests.golden_files import assert_matches_golden

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


def _golden_case():
    return build_silo_case(load_config(GOLDEN / "silo_flat_config.yaml"))


def test_silo_deck_matches_golden_file():
    rendered = render_silo_deck(_golden_case())
    assert_matches_golden(rendered, "silo_flat.lmp")


def test_every_contact_uses_hertz_with_cdt_rolling_friction():
    deck = render_silo_deck(_golden_case())
    contact_lines = [line for line in deck.splitlines() if re.match(r"^(pair_style|fix \S+ all wall/gran)", line)]
    # pair style, four primitive walls, the closed floor and the re-created open floor
    assert len(contact_lines) == 7
    for line in contact_lines:
        assert "model hertz tangential history rolling_friction cdt" in line, line


def test_every_wall_writes_its_force_and_the_gate_leaves_zeros():
    deck = render_silo_deck(_golden_case())
    lines = deck.splitlines()
    primitive = [line for line in lines if " primitive type " in line]
    meshes = [line for line in lines if re.match(r"^fix \S+ all mesh/surface", line)]
    assert len(primitive) == 4 and all(line.endswith(" store_force yes") for line in primitive)
    assert len(meshes) == 3
    assert all("mesh/surface/stress" in line and line.endswith(" reference_point 0.0 0.0 0.0") for line in meshes)
    # torque of the left wall's force taken at the contact point on the plane x = -0.04
    assert "variable wall_left_torque_y atom z*f_force_wall_left[1]-(-0.04)*f_force_wall_left[3]" in lines
    assert "variable floor_left_fz equal -f_floor_left[3]" in lines
    assert "variable floor_left_tz equal -f_floor_left[6]" in lines
    # one sample file through every stage, defined before the fill; the gate's columns become zeros before it goes
    assert deck.index("fix wall_forces all ave/time 434 1 434 ") < deck.index("fix pour")
    assert deck.count("fix wall_forces ") == 1
    opened = deck.split("# --- open the outlet")[1]
    assert opened.index("variable outlet_gate_fz equal 0.0") < opened.index("unfix outlet_gate")


def test_material_matrices_are_rendered_row_major():
    deck = render_silo_deck(_golden_case())
    rolling = next(line for line in deck.splitlines() if "coefficientRollingFriction" in line)
    # types: 1 hdpe, 2 aluminium, 3 perspex; wall-wall pairs get neutral zeros; the study's coefficients 0.1 (pairs,
    # aluminium) and 0.05 (perspex) as LIGGGHTS' CDT gives their torque for the two-sphere clump: pairs times 2 R / r,
    # walls times R / r (siloflow.engines.liggghts.rolling)
    ratio = rolling_geometry(_golden_case().particle.sphere_positions, _golden_case().particle.sphere_radii).ratio
    values = [float(v) for v in rolling.split("peratomtypepair 3 ")[1].split()]
    assert values == pytest.approx([0.2 * ratio, 0.1 * ratio, 0.05 * ratio, 0.1 * ratio, 0.0, 0.0, 0.05 * ratio, 0.0,
                                    0.0], rel=1e-15)
    assert ratio == pytest.approx(1.11510, abs=1e-5)


def test_timestep_is_the_configured_fraction_of_the_rayleigh_time():
    case = _golden_case()
    deck = render_silo_deck(case)
    timestep = float(re.search(r"^timestep (\S+)$", deck, re.M).group(1))
    assert timestep == case.timestep == pytest.approx(0.1 * case.rayleigh_time, rel=1e-15)


def test_write_silo_inputs_writes_deck_meshes_and_case(tmp_path):
    deck = write_silo_inputs(_golden_case(), tmp_path / "deck")
    assert deck.read_text() == (GOLDEN / "silo_flat.lmp").read_text()
    for name in ("floor_left", "floor_right", "outlet_gate"):
        assert (tmp_path / "deck" / "meshes" / f"{name}.stl").stat().st_size > 0
    assert (tmp_path / "deck" / "case.json").exists()
    assert not list(tmp_path.rglob("*.partial"))


INJECTIONS = ["0.5\nshell rm -rf /", "x & shell touch y", "${danger}", "$(v_x)", "a # comment", "../../etc/passwd", "a b"]


@pytest.mark.parametrize("value", INJECTIONS)
def test_filters_refuse_injected_strings(value):
    for render in (deck_number, deck_integer, deck_name):
        with pytest.raises(UnsafeDeckValue):
            render(value)
    with pytest.raises(UnsafeDeckValue):
        deck_path(value)


@pytest.mark.parametrize("value", INJECTIONS)
def test_context_check_refuses_injected_strings_anywhere(value):
    context = silo_deck_context(_golden_case())
    poisoned = copy.deepcopy(context)
    poisoned["settle"]["threshold"] = value
    with pytest.raises(UnsafeDeckValue, match=r"context\.settle\.threshold"):
        render_deck("liggghts/silo_flat.lmp.j2", poisoned)


def test_injected_config_string_never_reaches_a_deck():
    raw = load_config(GOLDEN / "silo_flat_config.yaml")
    raw["silo_flat"]["settle"]["kinetic_energy_threshold"] = "0.5\nshell rm -rf /"
    with pytest.raises(ConfigError, match="silo_flat.settle.kinetic_energy_threshold"):
        validate_config(raw)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), True, None, object()])
def test_number_filter_refuses_non_numbers(value):
    with pytest.raises(UnsafeDeckValue):
        deck_number(value)


def test_numbers_render_so_the_engine_reads_back_the_same_value():
    for value in (0.1, 1e-12, 1.1540372226009369e-05, -0.075, 5e6, 3):
        assert float(deck_number(value)) == value
    assert deck_integer(11003) == "11003"


def test_context_check_accepts_numbers_names_and_relative_paths():
    check_context({"a": 1, "b": [0.5, "wall_left", "deck/meshes/floor.stl", True]})


def test_environment_is_strict_about_undefined_values():
    environment = deck_environment()
    assert environment.undefined.__name__ == "StrictUndefined"
    with pytest.raises(Exception, match="undefined"):
        environment.from_string("{{ missing|num }}").render()


def test_ranks_split_the_wide_horizontal_axes_and_never_gravity():
    planar = {"x": [-0.075, 0.075], "y": [0.0, 0.012], "z": [-0.02, 0.3]}
    cell = {"x": [-0.03, 0.03], "y": [-0.03, 0.03], "z": [0.0, 0.1]}
    assert processor_grid(planar) == [0, 1, 1]
    assert processor_grid(cell) == [0, 0, 1]
    # an axis of exactly half the widest is split; a thinner one is not
    assert processor_grid({"x": [0.0, 2.0], "y": [0.0, 1.0], "z": [0.0, 9.0]}) == [0, 0, 1]
    assert processor_grid({"x": [0.0, 2.0], "y": [0.0, 0.99], "z": [0.0, 9.0]}) == [0, 1, 1]
    with pytest.raises(ValueError, match="positive extent"):
        processor_grid({"x": [0.0, 0.0], "y": [0.0, 1.0], "z": [0.0, 1.0]})


def test_the_silo_deck_names_its_processor_grid_before_the_box(tiny_config):
    deck = render_silo_deck(build_silo_case(tiny_config))
    assert deck.index("\nprocessors * 1 1\n") < deck.index("\ncreate_box ")


def test_a_one_sphere_template_gets_a_concentric_inner_sphere_and_others_are_as_modelled():
    assert template_spheres([(0.001, 0.0, -0.002)], [0.002]) == [[0.001, 0.0, -0.002, 0.002],
                                                               [0.001, 0.0, -0.002, INNER_SPHERE_FRACTION * 0.002]]
    assert INNER_SPHERE_FRACTION == 0.01
    two = template_spheres([(0.0, 0.0, -0.001), (0.0, 0.0, 0.001)], [0.0015, 0.0015])
    assert two == [[0.0, 0.0, -0.001, 0.0015], [0.0, 0.0, 0.001, 0.0015]]


def test_a_silo_poured_at_its_own_friction_switches_to_the_run_s_contacts_before_the_outlet_opens():
    raw = load_config(GOLDEN / "silo_flat_config.yaml")
    raw["silo_flat"].setdefault("fill", {})["sliding_friction"] = 0.15
    case = build_silo_case(validate_config(raw))
    assert case.fill_materials.sliding_friction[0][0] == 0.15
    assert case.fill_materials.sliding_friction[0][1:] == case.materials.sliding_friction[0][1:]
    assert case.fill_materials.rolling_friction == case.materials.rolling_friction
    assert case.run_id != _golden_case().run_id and _golden_case().fill_materials is None
    deck = render_silo_deck(case)
    friction = [line for line in deck.splitlines() if line.startswith("fix material_friction all property/global")]
    # the run's at the top (as every deck), the fill's before the pour, the run's again before the outlet opens
    run, fill, again = friction
    assert fill.split()[7] == "0.15" and run.split()[7] == again.split()[7] != "0.15"
    assert deck.index(fill) < deck.index("fix pour all insert/rate/region") < deck.index(again, deck.index(fill) + 1) \
        < deck.index("unfix floor_wall")
    assert "fix material_friction" not in render_silo_deck(_golden_case()).split("fix pour")[1]
