"""The Jenike shear cell: exact geometry, the case derived from config and a sweep point, the deck, the reader."""

from __future__ import annotations

import copy
import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

from siloflow.engines.interface import CaseNotSupported, engine_named

from siloflow.engines.config import ConfigError, load_config, validate_config
from siloflow.model.cases.geometry import read_stl
from siloflow.model.cases.jenike import FILL_SOLID_FRACTION, build_jenike_case, force_sample_every
from siloflow.model.cases.jenike_contacts import LID_TYPE, PARTICLE_TYPE, PLATE_TYPE, RING_TYPE
from siloflow.model.cases.jenike_cell import circle_intersection_area
from siloflow.engines.interface import EngineRunError
from siloflow.engines.markers import Marker
from siloflow.engines.jenike_checks import FORCE_COLUMNS, check_jenike_run, read_jenike_force_history
from siloflow.engines.liggghts.jenike import (
    CONTACT_COLUMNS,
    read_contact_dump,
    jenike_deck_context,
    render_jenike_deck,
    set_aside_previous_jenike_attempt,
    write_jenike_inputs,
)
from siloflow.model.cases.physics import hertz_contact_time, rayleigh_time
from siloflow.engines.templating import UnsafeDeckValue, render_deck
from tests.golden_files import assert_matches_golden

GOLDEN = Path(__file__).resolve().parent.parent / "golden"

POINT = {
    "shape": "sphere2",
    "test": "internal",
    "sliding_friction": 0.5,
    "rolling_friction": 0.1,
    "restitution": 0.1,
    "rotation_blocked": False,
}


def _config(**jenike) -> dict:
    raw = load_config(GOLDEN / "jenike_config.yaml")
    raw = copy.deepcopy(raw)
    raw["jenike"].update(jenike)
    return validate_config(raw)


def _case(point=None, **jenike):
    return build_jenike_case(_config(**jenike), {**POINT, **(point or {})})


def _face_centroids(mesh) -> np.ndarray:
    return mesh.vertices[mesh.faces].mean(axis=1)


def _boundary_edges(mesh, decimals: int = 12) -> list[tuple]:
    """Edges used by exactly one triangle, after merging coincident vertices."""
    keys = [tuple(v) for v in np.round(mesh.vertices, decimals)]
    index = {key: i for i, key in enumerate(dict.fromkeys(keys))}
    ids = np.array([index[k] for k in keys])
    counts: dict[tuple, int] = {}
    for face in ids[mesh.faces]:
        for a, b in ((face[0], face[1]), (face[1], face[2]), (face[2], face[0])):
            edge = (min(a, b), max(a, b))
            counts[edge] = counts.get(edge, 0) + 1
    merged = np.array(list(index))
    return [(merged[a], merged[b]) for (a, b), c in counts.items() if c == 1]


# ---------------------------------------------------------------------------------------------- cell meshes


def test_bottom_ring_is_a_cup_closed_except_at_its_outer_rim():
    case = _case()
    geometry = case.geometry
    mesh = geometry.bottom_ring()
    edges = _boundary_edges(mesh)
    assert len(edges) == geometry.segments
    for a, b in edges:
        for vertex in (a, b):
            assert math.hypot(vertex[0], vertex[1]) == pytest.approx(geometry.inner_radius + geometry.wall_thickness)
            assert vertex[2] == pytest.approx(geometry.bottom_ring_height)
    normals, centroids = mesh.normals(), _face_centroids(mesh)
    floor = np.isclose(centroids[:, 2], 0.0)
    top = np.isclose(centroids[:, 2], geometry.bottom_ring_height)
    np.testing.assert_allclose(normals[floor | top, 2], 1.0)
    wall = ~(floor | top)
    assert np.all(np.sum(normals[wall, :2] * centroids[wall, :2], axis=1) < 0)


def test_shear_ring_sits_on_the_shear_plane_offset_against_the_shear():
    case = _case()
    geometry = case.geometry
    mesh = geometry.shear_ring()
    x0, y0 = geometry.ring_centre
    assert (x0, y0) == (-0.003, 0.0)
    assert mesh.vertices[:, 2].min() == pytest.approx(0.008)
    assert mesh.vertices[:, 2].max() == pytest.approx(0.018)
    r = np.hypot(mesh.vertices[:, 0] - x0, mesh.vertices[:, 1] - y0)
    assert set(np.round(r, 12)) == {0.02, 0.023}
    normals, centroids = mesh.normals(), _face_centroids(mesh)
    bottom = np.isclose(centroids[:, 2], 0.008)
    top = np.isclose(centroids[:, 2], 0.018)
    np.testing.assert_allclose(normals[bottom, 2], -1.0)
    np.testing.assert_allclose(normals[top, 2], 1.0)
    wall = ~(bottom | top)
    radial = centroids[wall, :2] - np.array([x0, y0])
    assert np.all(np.sum(normals[wall, :2] * radial, axis=1) < 0)
    # the study's 3 mm offset: the ring's inner edge lies over the bottom ring's outer edge
    assert x0 - geometry.inner_radius == pytest.approx(-(geometry.inner_radius + geometry.wall_thickness))


def test_wall_test_has_a_plate_and_the_shear_plane_on_it():
    case = _case({"test": "aluminium", "sliding_friction": 0.3})
    geometry = case.geometry
    assert geometry.wall_test and geometry.shear_plane == 0.0 and geometry.ring_top == 0.01
    plate = geometry.plate()
    assert plate.area() == pytest.approx(0.14**2)
    np.testing.assert_allclose(plate.normals()[:, 2], 1.0)
    assert geometry.shear_ring().vertices[:, 2].min() == 0.0
    assert set(geometry.meshes("rigid")) == {"base", "shear_ring", "mould"}
    with pytest.raises(ValueError, match="plate, not a bottom ring"):
        geometry.bottom_ring()


def test_servo_lid_mesh_fits_inside_the_ring_with_the_clearance():
    case = _case(lid="servo")
    geometry = case.geometry
    lid = geometry.meshes("servo")["lid"]
    x0, y0 = geometry.ring_centre
    r = np.hypot(lid.vertices[:, 0] - x0, lid.vertices[:, 1] - y0)
    assert r.max() == pytest.approx(geometry.inner_radius - geometry.lid_clearance, rel=1e-14)
    np.testing.assert_allclose(lid.normals()[:, 2], -1.0)


@pytest.mark.parametrize("test", ["internal", "aluminium"])
def test_every_mesh_lies_inside_the_domain_over_the_whole_shear(test):
    for config in (validate_config({}), _config()):
        case = build_jenike_case(config, {**POINT, "test": test})
        x0, x1, y0, y1, z0, z1 = case.domain
        travel = np.array([case.geometry.shear_displacement, 0.0, 0.0])
        for name, mesh in case.geometry.meshes("servo").items():
            for shift in (np.zeros(3), travel) if name in ("shear_ring", "lid") else (np.zeros(3),):
                v = mesh.vertices + shift
                assert x0 < v[:, 0].min() and v[:, 0].max() < x1, name
                assert y0 < v[:, 1].min() and v[:, 1].max() < y1, name
                assert z0 < v[:, 2].min() and v[:, 2].max() < z1, name
        assert case.fill.region_z[1] < z1


# ---------------------------------------------------------------------------------------------- the case


def test_time_step_is_the_fraction_of_the_rayleigh_time_of_the_smallest_sphere():
    case = _case()
    assert case.rayleigh_time == rayleigh_time(0.0015, 950.0, 5.0e6, 0.4)
    assert case.timestep == 0.1 * case.rayleigh_time


def test_hertz_limit_takes_the_fall_from_the_top_of_the_loose_column():
    case = _case(timestep_fraction=0.5, timestep_hertz_fraction=0.01)
    choice = case.timestep_choice
    assert choice.impact_velocity == pytest.approx(math.sqrt(2 * 9.81 * case.fill.region_z[1]), rel=1e-12)
    assert choice.hertz_time == hertz_contact_time(0.0015, 950.0, 5.0e6, 0.4, choice.impact_velocity)
    assert (choice.limited_by, case.timestep) == ("hertz", 0.01 * choice.hertz_time)


def test_normal_force_steps_and_fill_follow_the_config():
    case = _case()
    assert case.normal_force == pytest.approx(4000.0 * math.pi * 0.04**2 / 4, rel=1e-15)
    assert case.shear_steps * case.timestep >= 0.004 / 0.03 > (case.shear_steps - 1) * case.timestep
    assert (case.ramp_steps + case.hold_steps) * case.timestep == pytest.approx(0.05, abs=2 * case.timestep)
    expected = FILL_SOLID_FRACTION * 1.2 * math.pi * 0.02**2 * 0.018 / case.particle.volume
    assert case.fill.n_clumps == round(expected)
    assert case.fill.level_z == pytest.approx(0.018 - 0.0015)
    assert case.fill.region_radius + case.particle.bounding_radius == pytest.approx(0.02)
    assert case.fill.region_centres == (0.0, -0.003)
    # the column holds the clumps at the insertion solid fraction
    area = circle_intersection_area(case.fill.region_radius, 0.003)
    column = case.fill.region_z[1] - case.fill.region_z[0]
    assert case.fill.n_clumps * case.particle.volume / (area * column) == pytest.approx(0.2)


def test_internal_test_contact_matrices():
    case = _case()
    p, ring, lid = PARTICLE_TYPE - 1, RING_TYPE - 1, LID_TYPE - 1
    test, fill = case.test_contacts, case.fill_contacts
    assert case.materials.names == ("hdpe", "aluminium", "lid")
    assert test.sliding_friction[p] == (0.5, 0.17, 1.0)
    assert test.rolling_friction[p] == (0.1, 0.1, 0.1)
    assert test.restitution[p] == (0.1, 0.1, 0.1)
    assert test.sliding_friction[ring][lid] == 0.0 and test.restitution[ring][lid] == 0.5
    assert fill.sliding_friction[p] == (0.1, 0.1, 0.1)
    assert fill.rolling_friction[p] == (0.0, 0.0, 0.0)
    assert fill.restitution == test.restitution
    for matrix in (test.sliding_friction, test.rolling_friction, test.restitution, fill.sliding_friction):
        assert np.array_equal(np.array(matrix), np.array(matrix).T)


def test_wall_test_contact_matrices_give_the_plate_its_own_type():
    case = _case({"test": "aluminium", "sliding_friction": 0.3, "rolling_friction": 0.05, "restitution": 0.6})
    p, ring, plate = PARTICLE_TYPE - 1, RING_TYPE - 1, PLATE_TYPE - 1
    assert case.materials.names == ("hdpe", "aluminium", "lid", "aluminium")
    test = case.test_contacts
    assert test.sliding_friction[p] == (0.35, 0.17, 1.0, 0.3)  # pp from wall_test_particle_friction
    assert test.sliding_friction[ring][p] == 0.17 and test.sliding_friction[plate][p] == 0.3
    assert test.rolling_friction[p] == (0.05,) * 4
    assert test.restitution[p] == (0.6,) * 4
    assert case.fill_contacts.sliding_friction[p] == (0.1,) * 4


def test_a_sample_poured_at_its_own_friction_fills_with_the_test_s_particle_friction():
    """jenike.fill.sliding_friction null: every particle contact pours with the test's particle-particle friction
    (the internal point's own, the wall test's particle friction), and the run is another run than the dense pour's."""
    fill = copy.deepcopy(_config()["jenike"]["fill"])
    own = _case(fill={**fill, "sliding_friction": None})
    p = PARTICLE_TYPE - 1
    assert own.fill_contacts.sliding_friction[p] == (0.5, 0.5, 0.5)
    assert own.test_contacts == _case().test_contacts and own.run_id != _case().run_id
    wall = _case({"test": "aluminium", "sliding_friction": 0.3, "rolling_friction": 0.05, "restitution": 0.6},
                 fill={**fill, "sliding_friction": None})
    assert wall.fill_contacts.sliding_friction[p] == (0.35,) * 4  # wall_test_particle_friction
    with pytest.raises(ConfigError, match="jenike.fill.sliding_friction"):
        _case(fill={**fill, "sliding_friction": "own"})


def test_the_pour_variant_pours_at_the_point_s_friction_whatever_the_configured_pour():
    """A point of the pour variant (``"pour": "own_friction"``) is the run of ``jenike.fill.sliding_friction`` null:
    same contacts, same run id; the configured point pours at the configured 0.1 and says so."""
    fill = copy.deepcopy(_config()["jenike"]["fill"])
    variant, configured = _case({"pour": "own_friction"}), _case()
    own = _case(fill={**fill, "sliding_friction": None})
    assert variant.fill_contacts == own.fill_contacts and variant.run_id == own.run_id != configured.run_id
    assert configured.fill_contacts.sliding_friction[PARTICLE_TYPE - 1] == (0.1, 0.1, 0.1)
    assert (variant.summary_point["pour"], configured.summary_point["pour"]) == ("own_friction", "configured")
    assert variant.summary()["pour"] == "own_friction" and variant.summary()["point"] == configured.summary()["point"]
    with pytest.raises(ValueError, match="pour must be one of configured, own_friction, got 'dense'"):
        _case({"pour": "dense"})


def test_a_sample_poured_at_a_set_restitution_is_sheared_at_the_point_s_own():
    """jenike.fill.restitution: every particle contact pours at it and tests at the point's restitution; a value
    equal to the point's is the same run as null, and another value another run."""
    fill = copy.deepcopy(_config()["jenike"]["fill"])
    p = PARTICLE_TYPE - 1
    poured = _case({"restitution": 0.6}, fill={**fill, "restitution": 0.1})
    assert poured.fill_contacts.restitution[p] == (0.1, 0.1, 0.1)
    assert poured.test_contacts.restitution[p] == (0.6, 0.6, 0.6)
    assert poured.test_contacts == _case({"restitution": 0.6}).test_contacts
    assert _case({"restitution": 0.6}).fill_contacts.restitution[p] == (0.6, 0.6, 0.6)
    assert poured.run_id != _case({"restitution": 0.6}).run_id
    assert _case(fill={**fill, "restitution": 0.1}).run_id == _case().run_id == _case(fill={**fill, "restitution": None}).run_id
    with pytest.raises(ConfigError, match="jenike.fill.restitution"):
        _case(fill={**fill, "restitution": 0.0})


def test_a_rotation_blocked_sample_may_be_poured_at_a_friction_of_its_own():
    """jenike.fill.rotation_blocked_sliding_friction: a rotation-blocked point pours at it and tests at its own
    friction; a free point pours as sliding_friction says; unset, the run ids are those without the key."""
    fill = {**copy.deepcopy(_config()["jenike"]["fill"]), "sliding_friction": None}
    p = PARTICLE_TYPE - 1
    blocked = {"rotation_blocked": True}
    poured = _case(blocked, fill={**fill, "rotation_blocked_sliding_friction": 0.1})
    assert poured.fill_contacts.sliding_friction[p] == (0.1, 0.1, 0.1)
    assert poured.test_contacts.sliding_friction[p] == (0.5, 0.17, 1.0)
    assert _case(blocked, fill=fill).fill_contacts.sliding_friction[p] == (0.5, 0.5, 0.5)
    free = _case(fill={**fill, "rotation_blocked_sliding_friction": 0.1})
    assert free.fill_contacts.sliding_friction[p] == (0.5, 0.5, 0.5)
    assert free.run_id == _case(fill=fill).run_id and poured.run_id != _case(blocked, fill=fill).run_id
    with pytest.raises(ConfigError, match="rotation_blocked_sliding_friction"):
        _case(fill={**fill, "rotation_blocked_sliding_friction": 1.5})


def test_a_wall_point_may_set_its_particle_friction_and_an_internal_one_may_not():
    wall = {"test": "aluminium", "sliding_friction": 0.3, "rolling_friction": 0.05, "restitution": 0.6}
    case = _case({**wall, "particle_sliding_friction": 0.42})
    p = PARTICLE_TYPE - 1
    assert case.test_contacts.sliding_friction[p] == (0.42, 0.17, 1.0, 0.3)
    assert case.sweep_point["particle_sliding_friction"] == 0.42
    assert case.run_id != _case(wall).run_id
    # a point without it keeps the run id it always had
    assert "particle_sliding_friction" not in _case(wall).sweep_point
    with pytest.raises(ValueError, match="particle_sliding_friction is a wall test's"):
        _case({"particle_sliding_friction": 0.42})


def test_run_id_names_shape_and_test_and_hashes_every_defining_parameter():
    case = _case()
    assert re.fullmatch(r"sphere2-internal-[0-9a-f]{10}", case.run_id)
    assert case.run_id == _case().run_id
    others = {
        _case({"sliding_friction": 0.4}).run_id,
        _case({"rolling_friction": 0.0}).run_id,
        _case({"restitution": 0.6}).run_id,
        _case({"rotation_blocked": True}).run_id,
        _case(lid="servo").run_id,
        _case(seed=2).run_id,
    }
    assert case.run_id not in others and len(others) == 6
    assert _case({"test": "aluminium"}).run_id.startswith("sphere2-aluminium-")


def test_sweep_settings_other_than_the_point_do_not_change_the_run_id():
    config = _config()
    other = copy.deepcopy(config)
    other["jenike"]["sweep"]["sliding_friction"] = [0.2]
    assert build_jenike_case(config, POINT).run_id == build_jenike_case(other, POINT).run_id


def test_a_point_below_the_engines_restitution_limit_is_refused_by_the_engine_naming_the_key():
    # The sweep's values are validated by the schema alone (0 < e <= 1); LIGGGHTS' own limit is the engine's check.
    case = _case({"restitution": 0.05})
    with pytest.raises(CaseNotSupported, match=r"config key 'jenike.sweep.restitution': restitution 0.05 .* LIGGGHTS 3.8"):
        engine_named("liggghts").check_case(case)


def test_missing_point_key_and_missing_contact_pair_are_named():
    with pytest.raises(ValueError, match=r"missing keys \['rotation_blocked'\]"):
        build_jenike_case(_config(), {k: v for k, v in POINT.items() if k != "rotation_blocked"})
    config = _config()
    config["contacts"] = [c for c in config["contacts"] if "lid" not in c["materials"]]
    with pytest.raises(ValueError, match=r"no contact parameters for the pair \[hdpe, lid\]"):
        build_jenike_case(config, POINT)


def test_plate_must_carry_the_ring_over_its_whole_travel():
    with pytest.raises(ValueError, match="plate_size"):
        config = _config(cell={**_config()["jenike"]["cell"], "plate_size": 0.04})
        build_jenike_case(config, {**POINT, "test": "aluminium"})


def test_rigid_lid_loads_exactly_f_n_and_cancels_its_weight():
    case = _case()
    lid = case.rigid_lid
    assert case.servo_lid is None
    assert lid.sphere_radius == case.particle.smallest_radius
    applied = lid.n_spheres * (lid.sphere_weight - lid.load_per_sphere)
    gravity = -lid.mass * 9.81
    assert applied + gravity == pytest.approx(-case.normal_force, rel=1e-12)
    x0, y0 = case.geometry.ring_centre
    rim = np.hypot(lid.positions[:, 0] - x0, lid.positions[:, 1] - y0).max() + lid.sphere_radius
    assert rim == pytest.approx(case.geometry.inner_radius - case.geometry.lid_clearance, rel=1e-12)


def test_servo_lid_proxy_has_the_rigid_lid_mass():
    rigid, servo = _case().rigid_lid, _case(lid="servo").servo_lid
    assert servo.mass == rigid.mass
    volume = 4.0 / 3.0 * math.pi * servo.proxy_radius**3
    assert len(servo.proxy_positions) * volume * servo.proxy_density == pytest.approx(servo.mass, rel=1e-12)


# ---------------------------------------------------------------------------------------------- the deck


def test_jenike_deck_matches_golden_file():
    rendered = render_jenike_deck(_case())
    assert_matches_golden(rendered, "jenike_internal_rigid.lmp")


def test_every_contact_uses_hertz_with_cdt_rolling_friction():
    for case in (_case(), _case(lid="servo"), _case({"test": "aluminium"})):
        deck = render_jenike_deck(case)
        lines = [line for line in deck.splitlines() if re.match(r"^(pair_style|fix \S+ \S+ wall/gran)", line)]
        assert len(lines) == (3 if case.lid_kind == "servo" else 2)
        for line in lines:
            assert "model hertz tangential history rolling_friction cdt" in line, line


def test_fill_coefficients_come_first_and_test_coefficients_replace_them():
    case = _case()
    deck = render_jenike_deck(case)
    friction = [line for line in deck.splitlines() if "coefficientFriction" in line]
    assert len(friction) == 2
    assert friction[0].endswith("peratomtypepair 3 0.1 0.1 0.1 0.1 0.0 0.0 0.1 0.0 0.0")
    assert friction[1].endswith("peratomtypepair 3 0.5 0.17 1.0 0.17 0.0 0.0 1.0 0.0 0.0")
    assert deck.index(friction[1]) > deck.index("SILOFLOW lid_placed") > deck.index("delete_atoms region level_cut")


def test_rotation_blocking_and_lid_kinds_render_their_commands():
    pattern = r"^fix template_sphere2 all particletemplate/multisphere .* type 1( tflag off off off)?$"
    template = re.compile(pattern, re.M)
    assert template.search(render_jenike_deck(_case())).group(1) is None
    assert template.search(render_jenike_deck(_case({"rotation_blocked": True}))).group(1) == " tflag off off off"
    rigid = render_jenike_deck(_case())
    assert rigid.count("create_atoms 3 single") == _case().rigid_lid.n_spheres
    assert "fix lid_body lid rigid single force 1 off off on torque 1 on on on" in rigid
    servo = render_jenike_deck(_case(lid="servo"))
    assert "meshes base shear_ring mould lid" in servo
    assert "compute wall_contacts" in rigid and "compute wall_contacts" not in servo
    assert "dump pair_contact_dump" in rigid and "dump pair_contact_dump" in servo
    assert "unfix cell_walls" not in rigid  # the wall-contact compute forbids re-creating the wall
    assert "move/mesh mesh lid linear/variable v_lid_vx v_lid_vy v_lid_vz" in servo
    assert "torque 1 off off off" in servo


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # meshio probing an ASCII STL
def test_write_jenike_inputs_writes_deck_meshes_and_case(tmp_path):
    case = _case()
    deck = write_jenike_inputs(case, tmp_path / "deck")
    assert deck.read_text() == (GOLDEN / "jenike_internal_rigid.lmp").read_text()
    for name, mesh in case.geometry.meshes("rigid").items():
        loaded = read_stl(tmp_path / "deck" / "meshes" / f"{name}.stl")
        assert loaded.area() == pytest.approx(mesh.area(), rel=1e-6)
    assert (tmp_path / "deck" / "case.json").exists()
    assert not list(tmp_path.rglob("*.partial"))


INJECTIONS = ["0.5\nshell rm -rf /", "x & shell touch y", "${danger}", "$(v_x)", "a # comment", "../../etc/passwd"]


@pytest.mark.parametrize("value", INJECTIONS)
def test_context_check_refuses_injected_values(value):
    context = jenike_deck_context(_case())
    poisoned = copy.deepcopy(context)
    poisoned["fill"]["n_clumps"] = value
    with pytest.raises(UnsafeDeckValue, match=r"context\.fill\.n_clumps"):
        render_deck("liggghts/jenike.lmp.j2", poisoned)
    poisoned = copy.deepcopy(context)
    poisoned["lid"]["positions"][3][1] = value
    with pytest.raises(UnsafeDeckValue, match=r"context\.lid\.positions\[3\]\[1\]"):
        render_deck("liggghts/jenike.lmp.j2", poisoned)


def test_a_bad_name_in_the_case_never_reaches_the_deck():
    case = _case()
    bad = dataclasses.replace(case, particle=dataclasses.replace(case.particle, name="sphere2 shell"))
    with pytest.raises(UnsafeDeckValue):
        render_jenike_deck(bad)


# ---------------------------------------------------------------------------------------------- force history


HEADER = "# Time-averaged data for fix force_history\n# TimeStep v_time_now ...\n"


def _row(step: int, time: float, value: float = 1.0) -> str:
    return " ".join([str(step), repr(time)] + [repr(value)] * (len(FORCE_COLUMNS) - 1))


def test_force_history_reader_returns_named_columns(tmp_path):
    path = tmp_path / "forces.txt"
    path.write_text(HEADER + _row(100, 0.001, 2.0) + "\n" + _row(200, 0.002, 3.0) + "\n")
    history = read_jenike_force_history(path)
    assert set(history) == {"step", *FORCE_COLUMNS}
    np.testing.assert_array_equal(history["time"], [0.001, 0.002])
    np.testing.assert_array_equal(history["mass_above"], [2.0, 3.0])
    np.testing.assert_array_equal(history["step"], [100, 200])


@pytest.mark.parametrize(
    "content, message",
    [
        (HEADER, "no data rows"),
        (HEADER + _row(100, 0.001) + "\n" + _row(200, 0.002)[:25] + "\n", "line 4 has .* columns"),
        (HEADER + _row(100, 0.001).replace("1.0", "abc", 1) + "\n", "line 3, column 3 is not a number$"),
        (HEADER + _row(100, 0.002) + "\n" + _row(200, 0.001) + "\n", "times do not increase"),
        (HEADER + _row(100, 0.001).replace("1.0", "nan", 1) + "\n", "line 3, column 3 is not finite$"),
    ],
)
def test_force_history_reader_names_the_file_on_bad_content(tmp_path, content, message):
    path = tmp_path / "forces.txt"
    path.write_text(content)
    with pytest.raises(ValueError, match=re.escape(str(path)) + ".*" + message):
        read_jenike_force_history(path)


def _markers(created=815, levelled=655, final=655):
    values = lambda clumps, time: {"step": 1.0, "time": time, "clumps": float(clumps), "top": 0.02}  # noqa: E731
    return [
        Marker("filled", values(created, 0.2)),
        Marker("levelled", values(levelled, 0.22)),
        Marker("lid_placed", values(levelled, 0.22)),
        Marker("consolidated", values(levelled, 0.27)),
        Marker("sheared", values(final, 0.4)),
    ]


def test_run_check_accepts_a_complete_run_and_names_each_failure(tmp_path):
    case = _case()
    (tmp_path / "forces.txt").write_text(HEADER + _row(1, 0.23) + "\n" + _row(2, 0.24) + "\n")
    record = check_jenike_run(case, _markers(created=case.fill.n_clumps), tmp_path, tmp_path / 'forces.txt')
    assert record["shear_start_s"] == 0.27 and record["force_samples"] == 2
    with pytest.raises(EngineRunError, match="no 'sheared' stage marker"):
        check_jenike_run(case, _markers(created=case.fill.n_clumps)[:-1], tmp_path, tmp_path / 'forces.txt')
    with pytest.raises(EngineRunError, match="levelling removed no clump"):
        check_jenike_run(case, _markers(created=case.fill.n_clumps, levelled=case.fill.n_clumps), tmp_path, tmp_path / 'forces.txt')
    with pytest.raises(EngineRunError, match="3 clumps were lost"):
        check_jenike_run(case, _markers(created=case.fill.n_clumps, final=652), tmp_path, tmp_path / 'forces.txt')
    with pytest.raises(EngineRunError, match="only 700 of"):
        check_jenike_run(case, _markers(created=700), tmp_path, tmp_path / 'forces.txt')


CONTACT_DUMP = """ITEM: TIMESTEP
36960
ITEM: NUMBER OF ENTRIES
2
ITEM: BOX BOUNDS ff ff ff
-0.0335 0.0335
-0.0335 0.0335
-0.0075 0.0965425
ITEM: ENTRIES c_wall_contacts[1] c_wall_contacts[2] ...
0.00602039 4.16299e-05 4.33681e-19 0.00602039 4.16299e-05 0.00146171 0 0 496 -0 -0 0.0364278 -0.00610482 0.00103967 0
0.0149664 0.00104331 4.33681e-19 0.0149664 0.00104331 0.00145353 1 12 656 -0 -0 0.0485703 -0.00168655 0.00769737 0
"""


def test_contact_dump_reader(tmp_path):
    path = tmp_path / "wall_contacts_36960.txt"
    path.write_text(CONTACT_DUMP)
    contacts = read_contact_dump(path)
    assert set(contacts) == {"step", *CONTACT_COLUMNS}
    np.testing.assert_array_equal(contacts["id3"], [496, 656])
    np.testing.assert_array_equal(contacts["step"], [36960, 36960])
    assert contacts["fn_z"][1] == 0.0485703
    path.write_text(CONTACT_DUMP.rsplit("\n", 2)[0] + "\n")
    with pytest.raises(ValueError, match=re.escape(str(path)) + r": the NUMBER OF ENTRIES of line 4 differs from "
                                                                 "the 1 line after"):
        read_contact_dump(path)
    path.write_text("ITEM: TIMESTEP\n")
    with pytest.raises(ValueError, match="malformed TIMESTEP or NUMBER OF ENTRIES|not a complete LIGGGHTS local dump"):
        read_contact_dump(path)


def test_an_earlier_attempt_is_set_aside_with_its_force_history(tmp_path):
    assert set_aside_previous_jenike_attempt(tmp_path) is None
    (tmp_path / "dumps").mkdir()
    (tmp_path / "dumps" / "particles_1.vtk").write_text("x")
    (tmp_path / "forces.txt").write_text("old")
    (tmp_path / "log.liggghts").write_text("log")
    target = set_aside_previous_jenike_attempt(tmp_path)
    assert target.parent == tmp_path / "failed_attempts"
    assert (target / "forces.txt").read_text() == "old"
    assert (target / "dumps" / "particles_1.vtk").exists() and not (target / "dumps" / "forces.txt").exists()
    assert not (tmp_path / "forces.txt").exists() and not (tmp_path / "dumps").exists()


@pytest.mark.parametrize("output_every, expected", [(87, 3), (100, 10), (9, 1), (120, 12), (7, 1), (10, 1), (20, 2)])
def test_force_samples_divide_the_output_interval_at_least_ten_times(output_every, expected):
    assert force_sample_every(output_every) == expected
    assert output_every % expected == 0


def test_force_sampling_refuses_an_empty_output_interval():
    with pytest.raises(ValueError, match="output_every must be >= 1"):
        force_sample_every(0)


def test_the_liggghts_force_history_averages_the_samples_of_one_output_interval():
    case = _case()
    every = case.force_sample_every
    assert case.output_every % every == 0 and case.output_every // every >= 10
    deck = render_jenike_deck(case)
    assert (f"fix force_history all ave/time {every} {case.output_every // every} {case.output_every} "
            "v_time_now") in deck
