"""Integration: parse dumps written by the real LIGGGHTS binary and compare with VTK (pyvista).

A tiny deck inserts 50 two-sphere clumps (spheres of radius 1.5 mm, centres 0.75 mm apart,
density 950 kg/m^3) above a floor and lets them fall for 2000 steps, dumping every 500 steps
in binary custom/vtk with the fields the project reads.
"""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest
import pyvista

from analysis.data.frames import clumps_from_frame
from engines.liggghts.dumps import dump_step, list_dumps, parse_legacy_vtk_polydata, read_frame, read_frames

from tests.conftest import require_liggghts  # noqa: E402

pytestmark = pytest.mark.integration

TIMESTEP = 1e-5  # [s]
N_STEPS = 2000
DUMP_EVERY = 500
N_CLUMPS = 50
SPHERE_RADIUS = 0.0015  # [m]
CENTRE_DISTANCE = 0.00075  # [m], spheres at x = -0.375 mm and +0.375 mm of the template
DENSITY = 950.0  # [kg/m^3]

DECK = f"""\
atom_style sphere
atom_modify map array sort 0 0
boundary f f f
newton off
communicate single vel yes
units si
region domain block -0.02 0.02 -0.02 0.02 0.0 0.06 units box
create_box 1 domain
neighbor 0.0006 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6
fix m2 all property/global poissonsRatio peratomtype 0.4
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.3
fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1
pair_style gran model hertz tangential history rolling_friction cdt
pair_coeff * *
timestep {TIMESTEP!r}
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix floor all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 zplane 0.0
fix pts1 all particletemplate/multisphere 15485863 atom_type 1 density constant {DENSITY!r} nspheres 2 \
ntry 100000 spheres -0.000375 0 0 {SPHERE_RADIUS!r} 0.000375 0 0 {SPHERE_RADIUS!r} type 1
fix pdd1 all particledistribution/discrete 15485867 1 pts1 1.0
fix integr all multisphere
region fill block -0.015 0.015 -0.015 0.015 0.01 0.05 units box
fix ins all insert/pack seed 32452843 distributiontemplate pdd1 insert_every once overlapcheck yes \
all_in yes particles_in_region {N_CLUMPS} region fill ntry_mc 10000
dump dmp all custom/vtk {DUMP_EVERY} dumps/tiny_*.vtk id type id_multisphere x y z vx vy vz fx fy fz \
omegax omegay omegaz radius mass
dump_modify dmp binary yes
run {N_STEPS}
"""


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    require_liggghts()
    """Folder of one finished LIGGGHTS run of the tiny deck."""
    run_dir = tmp_path_factory.mktemp("liggghts_dumps")
    (run_dir / "dumps").mkdir()
    deck = run_dir / "in.tiny"
    deck.write_text(DECK)
    log = run_dir / "log.liggghts"
    result = subprocess.run(
        ["liggghts", "-in", str(deck), "-log", str(log)],
        cwd=run_dir, capture_output=True, text=True, timeout=600,
    )
    log_text = log.read_text() if log.exists() else ""
    assert result.returncode == 0, (
        f"liggghts failed ({result.returncode}):\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    )
    assert "ERROR" not in log_text, log_text[-3000:]
    return run_dir


def non_empty_dumps(run_dir):
    # the step-0 dump is written before the insertion at step 1 and holds no particles
    return [path for path in list_dumps(run_dir / "dumps", "tiny") if dump_step(path) > 0]


def test_dump_files_and_steps(run_dir):
    dumps = list_dumps(run_dir / "dumps", "tiny")
    assert [dump_step(path) for path in dumps] == list(range(0, N_STEPS + 1, DUMP_EVERY))
    assert any("boundingBox" in path.name for path in (run_dir / "dumps").iterdir())  # written and ignored
    assert len(parse_legacy_vtk_polydata(dumps[0].read_bytes(), str(dumps[0]))["points"]) == 0


def test_parser_agrees_exactly_with_vtk(run_dir):
    for path in non_empty_dumps(run_dir):
        parsed = parse_legacy_vtk_polydata(path.read_bytes(), str(path))
        mesh = pyvista.read(path)
        assert mesh.n_points == 2 * N_CLUMPS
        assert parsed["points"].dtype == np.asarray(mesh.points).dtype == np.float32
        np.testing.assert_array_equal(parsed["points"], np.asarray(mesh.points), err_msg=str(path))
        assert set(parsed) - {"points"} == set(mesh.point_data.keys())
        for name in ("id", "id_multisphere", "type", "mass", "v", "f", "omega", "radius"):
            expected = np.asarray(mesh.point_data[name])
            assert parsed[name].dtype == expected.dtype, (path, name)
            np.testing.assert_array_equal(parsed[name], expected, err_msg=f"{path}: {name}")


def test_frames_clumps_and_times(run_dir, tmp_path):
    frames = read_frames(run_dir / "dumps", "tiny", TIMESTEP, cache_dir=tmp_path / "frames")
    assert [frame.step for frame in frames] == list(range(0, N_STEPS + 1, DUMP_EVERY))
    for frame in frames:
        assert frame.time == frame.step * TIMESTEP

    # exact union volume of two equal spheres: 2 V_sphere - lens, lens = pi (4r + d)(2r - d)^2 / 12
    r, d = SPHERE_RADIUS, CENTRE_DISTANCE
    union_volume = 2 * 4 / 3 * math.pi * r**3 - math.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    for frame in frames[1:]:
        clumps = clumps_from_frame(frame)
        assert len(clumps) == N_CLUMPS
        np.testing.assert_array_equal(clumps.n_spheres, 2)
        # the clump mass is written on both spheres of a clump, identically
        order = np.argsort(frame.clump_id, kind="stable")
        mass_pairs = frame.mass[order].reshape(N_CLUMPS, 2)
        np.testing.assert_array_equal(mass_pairs[:, 0], mass_pairs[:, 1])
        np.testing.assert_array_equal(clumps.mass, mass_pairs[:, 0])
        # LIGGGHTS integrates the clump volume by Monte Carlo: within 1 % of the exact union
        np.testing.assert_allclose(clumps.mass, DENSITY * union_volume, rtol=0.01)
        # the grouping pairs the right spheres: a rigid clump keeps its centre distance
        position_pairs = frame.position[order].reshape(N_CLUMPS, 2, 3)
        distance = np.linalg.norm(position_pairs[:, 0] - position_pairs[:, 1], axis=1)
        np.testing.assert_allclose(distance, CENTRE_DISTANCE, atol=1e-7)  # float32 positions
        np.testing.assert_array_equal(clumps.position, position_pairs.mean(axis=1))


def test_cached_frame_equals_parsed_frame(run_dir, tmp_path):
    path = non_empty_dumps(run_dir)[-1]
    parsed = read_frame(path, TIMESTEP)
    read_frame(path, TIMESTEP, cache_dir=tmp_path)  # writes the entry
    cached = read_frame(path, TIMESTEP, cache_dir=tmp_path)  # reads it
    assert (tmp_path / f"{path.stem}.npz").is_file()
    for name in ("id", "clump_id", "position", "velocity", "angular_velocity", "radius", "mass", "force"):
        np.testing.assert_array_equal(getattr(cached, name), getattr(parsed, name), err_msg=name)
