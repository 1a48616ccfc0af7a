"""The Jenike cell on YADE without running it: the rendered script (golden file, Python, the case's numbers), the
engine-neutral force history it writes, and its contact snapshots read back exactly."""

from __future__ import annotations

import ast

import numpy as np
import pytest

from siloflow.model.cases.jenike import build_jenike_case, jenike_cases
from siloflow.engines.config import validate_config
from siloflow.engines.interface import engine_named
from siloflow.engines.jenike_checks import FORCE_COLUMNS, JENIKE_WALLS, jenike_wall_forces, read_jenike_force_history
from siloflow.engines.yade.jenike import (
    jenike_script_context, read_pair_contacts, read_wall_contacts, render_jenike_script,
)
from siloflow.engines.yade.outputs import DamagedOutput
from tests.golden_files import assert_matches_golden

POINT = {"shape": "sphere2", "test": "internal", "sliding_friction": 0.3, "rolling_friction": 0.1,
         "restitution": 0.1, "rotation_blocked": False}


def _case(lid="rigid", test="internal"):
    config = validate_config({"jenike": {"engine": "yade", "lid": lid}})
    return build_jenike_case(config, {**POINT, "test": test})


@pytest.mark.parametrize("lid, test, golden", [("rigid", "internal", "jenike_yade.py"),
                                                ("servo", "aluminium", "jenike_yade_servo_wall.py")])
def test_jenike_script_matches_golden_file_and_is_python(lid, test, golden):
    rendered = render_jenike_script(_case(lid, test))
    assert_matches_golden(rendered, golden)
    ast.parse(rendered)


def test_the_script_takes_the_fill_contacts_first_and_the_test_contacts_under_the_lid():
    case = _case()
    context = jenike_script_context(case)
    fill = {(p["i"], p["j"]): p["sliding_friction"] for p in context["fill_contacts"]["pairs"]}
    test = {(p["i"], p["j"]): p["sliding_friction"] for p in context["materials"]["pairs"]}
    assert fill[(0, 0)] == 0.1 and test[(0, 0)] == 0.3  # jenike.fill.sliding_friction, the point's
    assert context["fill_contacts"]["rolling_friction"] == 0.0 and context["fill_contacts"]["rolling_stiffness"] == 0.0
    # eta is the study's 0.1 times the two-sphere clump's lever arm over its spheres' radius (siloflow.model.rolling)
    assert context["materials"]["rolling_friction"] == pytest.approx(0.1 * 1.11510, abs=1e-6)
    assert context["materials"]["rolling_stiffness"] > 0.0
    # restitution is the same in both: the script refuses to change it on contacts that exist
    assert [p["restitution"] for p in context["fill_contacts"]["pairs"]] == \
        [p["restitution"] for p in context["materials"]["pairs"]]


def test_the_script_has_the_cases_meshes_and_lid():
    case = _case("rigid", "aluminium")
    context = jenike_script_context(case)
    meshes = {m["id"]: m for m in context["meshes"]}
    assert sorted(meshes) == ["base", "mould", "shear_ring"]
    assert meshes["base"]["material"] == 3 and meshes["shear_ring"]["material"] == 1  # plate, ring (0-based)
    assert context["lid"]["mass"] == case.rigid_lid.mass
    servo = jenike_script_context(_case("servo"))["lid"]
    assert servo["kind"] == "servo" and servo["mass"] == _case("servo").servo_lid.mass


def test_yade_accepts_every_jenike_point_of_the_default_sweep():
    config = validate_config({"jenike": {"engine": "yade"}})
    for case in jenike_cases(config).values():
        engine_named("yade").check_case(case)


def test_the_force_history_a_yade_script_writes_reads_as_the_neutral_walls(tmp_path):
    # the script's title lines, then step and the FORCE_COLUMNS (forces of the particles ON the walls)
    path = tmp_path / "jenike_force_history.txt"
    rows = [[100, 0.001, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 0.02, 0.5],
            [200, 0.002, -1.0, -2.0, -3.0, -4.0, -5.0, -6.0, -7.0, -8.0, -9.0, 0.019, 0.25]]
    path.write_text("# siloflow Jenike force history (forces of the particles on the walls, N)\n# step time "
                    + " ".join(FORCE_COLUMNS[1:]) + "\n" + "".join(" ".join(map(repr, r)) + "\n" for r in rows))
    history = jenike_wall_forces(read_jenike_force_history(path))
    assert history.walls == JENIKE_WALLS
    assert history.force["lid"].tolist() == [[-1.0, -2.0, -3.0], [1.0, 2.0, 3.0]]
    assert history.force["base"][0].tolist() == [-7.0, -8.0, -9.0]
    assert history.signals["mass_above"].tolist() == [0.5, 0.25]


def test_pair_contacts_read_back_exactly(tmp_path):
    table = np.array([[0.0, 0.0, 0.0, 0.003, 0.0, 0.0, 5, 9, 0.5, 0.25, -1.0],
                      [1.0, 1.0, 1.0, 1.0, 1.003, 1.0, 6, 11, 0.0, 2.0, 0.0]])
    np.savez(tmp_path / "pair_contacts_400.npz", step=400, contacts=table)
    frame = read_pair_contacts(tmp_path / "pair_contacts_400.npz")
    assert frame.step == 400 and frame.id_i.tolist() == [5, 6] and frame.id_j.tolist() == [9, 11]
    assert frame.position_j[0].tolist() == [0.003, 0.0, 0.0]
    assert frame.force.tolist() == [[0.5, 0.25, -1.0], [0.0, 2.0, 0.0]]


def test_wall_contacts_read_back_exactly_with_their_wall_names(tmp_path):
    walls = np.array(["base", "shear_ring", "mould", "lid"])
    table = np.array([[0.1, 0.0, 0.0, 0.1, 0.0, 0.0015, 0, 42, 0.0, 0.0, 2.0, 0.5, 0.0, 0.0],
                      [0.0, 0.02, 0.01, 0.0, 0.0185, 0.01, 1, 43, 0.0, -1.0, 0.0, 0.0, 0.0, 0.25]])
    np.savez(tmp_path / "wall_contacts_400.npz", step=400, contacts=table, walls=walls)
    frame = read_wall_contacts(tmp_path / "wall_contacts_400.npz")
    assert frame.wall.tolist() == ["base", "shear_ring"] and frame.particle_id.tolist() == [42, 43]
    assert frame.normal_force.tolist() == [[0.0, 0.0, 2.0], [0.0, -1.0, 0.0]]
    assert frame.tangential_force[1].tolist() == [0.0, 0.0, 0.25]
    bad = table.copy()
    bad[0, 6] = 7.0
    np.savez(tmp_path / "wall_contacts_500.npz", step=500, contacts=bad, walls=walls)
    with pytest.raises(DamagedOutput, match="wall_contacts_500.npz: a wall index outside 0..3"):
        read_wall_contacts(tmp_path / "wall_contacts_500.npz")
    np.savez(tmp_path / "wall_contacts_600.npz", step=600, contacts=table)
    with pytest.raises(DamagedOutput, match="wall_contacts_600.npz: the archive has no 'walls'"):
        read_wall_contacts(tmp_path / "wall_contacts_600.npz")


def test_written_inputs_hold_the_cells_meshes_as_triangle_corners(tmp_path):
    case = _case("servo", "aluminium")
    engine_named("yade").write_inputs(case, tmp_path)
    with np.load(tmp_path / "deck" / "geometry.npz") as meshes:
        assert sorted(meshes.files) == ["base", "mould", "shear_ring"]  # the servo lid is a plane, not a mesh
        plate = case.geometry.plate()
        assert np.array_equal(meshes["base"], plate.vertices[plate.faces])
    rigid = _case("rigid")
    engine_named("yade").write_inputs(rigid, tmp_path / "rigid")
    with np.load(tmp_path / "rigid" / "deck" / "geometry.npz") as arrays:
        assert np.array_equal(arrays["lid_sphere_positions"], rigid.rigid_lid.positions)
    assert (tmp_path / "deck" / "case.json").exists() and (tmp_path / "deck" / "run.py").exists()
