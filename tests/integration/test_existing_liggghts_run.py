"""Integration: a flat-bottom silo run siloflow did not make, analysed from the folder a user's LIGGGHTS run left.

The deck below is written the way a user writes one, not rendered by siloflow: a 40 x 9 mm box silo in the user's own
coordinates (x from 0 to 40 mm, the floor at z = 10 mm), side, front and back walls as primitives, a floor of two STL
plates with a 12 mm slot, shut by a plane wall while about 400 spheres (1.5 mm radius, 2500 kg/m^3) fill it and settle
for 0.2 s; the gate is then removed (``unfix``) and the silo discharges for 0.3 s, the spheres leaving through the open
bottom of the domain. The particles are dumped every 10 ms, without mass and without clump ids, in LIGGGHTS' default
ASCII legacy VTK (``dump custom/vtk`` to ``post/silo*.vtk``) and as text ``dump custom`` into one file
(``post/silo.txt``). LIGGGHTS runs it directly (as ``make_fixtures.py`` does), in a few seconds on one core.

Then the library call (the engine's dump reader, then the silo study) and the Snakemake route (``existing_runs`` with
``--cores 1``) analyse that folder; the figures that can be checked exactly are: the fill's mass (n x density x sphere
volume, and LIGGGHTS' own insertion report), and the discharged mass (nondecreasing, and at the end the mass missing
from the silo in the last dump). A description without the density the dumps lack stops the workflow before anything
runs, naming the key.
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
import yaml

from siloflow.model.existing_run import ExistingSiloRun
from siloflow.analysis.io.tables import read_table
from siloflow.analysis.studies.silo_flat.existing_run import analyse_existing_run
from siloflow.analysis.studies.silo_flat.field_study import SiloFieldOptions
from siloflow.engines.config import validate_config
from siloflow.engines.existing_runs import check_existing_run, read_existing_frames
from siloflow.engines.layout import existing_run_dir
from tests.conftest import require_liggghts, run_snakemake

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(15)]

WIDTH, DEPTH, OUTLET = 0.04, 0.009, 0.012  # m
FLOOR_Z = 0.01  # m, the outlet plane in the user's coordinates
RADIUS, DENSITY = 0.0015, 2500.0  # m, kg/m3
TIMESTEP, OPEN_STEP = 2.0e-5, 10000  # s, -

DECK = f"""# flat-bottom silo: a {WIDTH * 1e3:g} x {DEPTH * 1e3:g} mm box, a {OUTLET * 1e3:g} mm slot in its floor
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si

region domain block -0.001 0.041 -0.001 0.010 -0.01 0.13 units box
create_box 1 domain
neighbor 0.0006 bin
neigh_modify delay 0

fix m1 all property/global youngsModulus peratomtype 5.0e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.3
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5

pair_style gran model hertz tangential history
pair_coeff * *
timestep {TIMESTEP}
fix gravity all gravity 9.81 vector 0.0 0.0 -1.0

fix side_a all wall/gran model hertz tangential history primitive type 1 xplane 0.0
fix side_b all wall/gran model hertz tangential history primitive type 1 xplane {WIDTH}
fix front all wall/gran model hertz tangential history primitive type 1 yplane 0.0
fix back all wall/gran model hertz tangential history primitive type 1 yplane {DEPTH}
fix left all mesh/surface file left.stl type 1
fix right all mesh/surface file right.stl type 1
fix floor all wall/gran model hertz tangential history mesh n_meshes 2 meshes left right
fix gate all wall/gran model hertz tangential history primitive type 1 zplane {FLOOR_Z}

fix pts all particletemplate/sphere 15485863 atom_type 1 density constant {DENSITY} radius constant {RADIUS}
fix pdd all particledistribution/discrete 32452843 1 pts 1.0
region fill block 0.002 0.038 0.0015 0.0075 0.012 0.12 units box
fix ins all insert/pack seed 32452867 distributiontemplate pdd insert_every once overlapcheck yes all_in yes &
    vel constant 0.0 0.0 -0.3 region fill particles_in_region 400
fix integrate all nve/sphere
thermo 1000
thermo_modify lost ignore norm no

dump vtk all custom/vtk 500 post/silo*.vtk id type x y z vx vy vz radius
dump txt all custom 500 post/silo.txt id type x y z vx vy vz radius
run {OPEN_STEP}
unfix gate
run 15000
"""


def _plate(x0: float, x1: float) -> str:
    """An ASCII STL rectangle in the floor plane, across the depth and a little beyond the walls."""
    y0, y1 = -0.001, DEPTH + 0.001
    facets = ""
    for triangle in (((x0, y0), (x1, y0), (x1, y1)), ((x0, y0), (x1, y1), (x0, y1))):
        vertices = "".join(f"      vertex {x} {y} {FLOOR_Z}\n" for x, y in triangle)
        facets += f"  facet normal 0 0 1\n    outer loop\n{vertices}    endloop\n  endfacet\n"
    return f"solid plate\n{facets}endsolid plate\n"


@pytest.fixture(scope="module")
def user_run(tmp_path_factory) -> Path:
    """The folder of the user's run: deck, meshes, LIGGGHTS' log and the dumps in post/."""
    require_liggghts()
    folder = tmp_path_factory.mktemp("user_run")
    (folder / "in.silo").write_text(DECK)
    (folder / "left.stl").write_text(_plate(-0.001, (WIDTH - OUTLET) / 2))
    (folder / "right.stl").write_text(_plate((WIDTH + OUTLET) / 2, WIDTH + 0.001))
    (folder / "post").mkdir()
    environment = dict(os.environ)
    if os.geteuid() == 0:  # as siloflow/engines/liggghts/run.py: Open MPI refuses root unless told
        environment.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    result = subprocess.run(["liggghts", "-in", "in.silo", "-log", "log.liggghts"], cwd=folder, env=environment,
                            capture_output=True, text=True, check=False, timeout=300)
    assert result.returncode == 0 and "ERROR" not in result.stdout, result.stdout[-3000:] + result.stderr[-2000:]
    return folder


def _run(folder: Path, dumps: str) -> ExistingSiloRun:
    return ExistingSiloRun(name="user", engine="liggghts", folder=str(folder), dumps=dumps, width=WIDTH, depth=DEPTH,
                           outlet_width=OUTLET, timestep=TIMESTEP, open_step=OPEN_STEP,
                           origin=(WIDTH / 2, 0.0, FLOOR_Z), density=DENSITY, profile_heights=(0.01, 0.02))


def _inserted(folder: Path) -> tuple[int, float]:
    """The spheres and their mass (kg) LIGGGHTS reports it inserted."""
    log = (folder / "log.liggghts").read_text()
    found = re.search(r"inserted (\d+) particle templates \(mass ([0-9.eE+-]+)\)", log)
    assert found, "LIGGGHTS' log reports no insertion"
    return int(found.group(1)), float(found.group(2))


def test_the_library_call_analyses_the_folder_of_a_users_run(user_run):
    run = _run(user_run, "post/silo*.vtk")
    files = check_existing_run(run)
    assert files[0].step == 0 and files[-1].step == 25000 and len(files) == 51
    frames = read_existing_frames(run)
    options = SiloFieldOptions.from_config(validate_config({})["silo_flat"]["fields"])
    result = analyse_existing_run(frames, run, options)
    flow, metrics = result.flow, result.flow.metrics

    # the fill at the opening: every sphere LIGGGHTS inserted, each of mass density x 4/3 pi r^3
    n, logged_mass = _inserted(user_run)
    assert flow.settled_step == OPEN_STEP and flow.n_particles == n and 300 <= n <= 400
    sphere_mass = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3
    assert metrics.initial_mass == pytest.approx(n * sphere_mass, rel=1e-12)
    assert metrics.initial_mass == pytest.approx(logged_mass, rel=1e-6)  # the log prints 7 digits

    # discharged mass: nondecreasing, and at the end the mass missing from the silo in the last dump
    discharged = metrics.history.discharged_mass
    assert discharged[0] == 0.0 and np.all(np.diff(discharged) >= 0.0) and discharged[-1] > 0.1 * n * sphere_mass
    last = frames[-1]
    still_in = float(np.sum(last.mass[last.position[:, 2] >= FLOOR_Z]))
    assert discharged[-1] == pytest.approx(metrics.initial_mass - still_in, rel=1e-12)
    np.testing.assert_allclose(metrics.history.time, 0.01 * np.arange(len(discharged)), rtol=0, atol=1e-12)
    assert metrics.fit.mass_flow_rate > 0.0 and 0.0 < metrics.fit.t_start < metrics.fit.t_end <= 0.3 + 1e-12

    # fields without contacts: profiles and boundaries, no Janssen, no force chains
    study = result.fields
    assert study.heights == [0.01, 0.02] and study.janssen is None and study.segments is None
    assert np.all(study.profiles.v_z[:, len(study.profiles.x) // 2] < 0.0)  # downwards on the axis
    assert {s.analysis for s in result.skipped} == {"settled contact stress", "Janssen comparison", "force chains",
                                                    "fill force balance"}

    # the same run read from its one text dump of every snapshot gives the same discharge
    text = analyse_existing_run(read_existing_frames(_run(user_run, "post/silo.txt")), _run(user_run, "post/silo.txt"),
                                options)
    np.testing.assert_array_equal(text.flow.metrics.history.discharged_mass, discharged)


def test_the_snakemake_route_writes_the_silo_products_and_refuses_a_run_it_cannot_weigh(user_run, tmp_path):
    description = {"folder": os.path.relpath(user_run, tmp_path), "dumps": "post/silo*.vtk", "width": WIDTH,
                   "depth": DEPTH, "outlet_width": OUTLET, "origin": [WIDTH / 2, 0.0, FLOOR_Z], "timestep": TIMESTEP,
                   "open_time": OPEN_STEP * TIMESTEP, "profile_heights": [0.01, 0.02]}
    config = tmp_path / "existing.yaml"

    # without the density the dumps lack, nothing runs and the message names the key
    config.write_text(yaml.safe_dump({"estimates": {"disk_check": False},
                                      "silo_flat": {"existing_runs": {"user": description}}}))
    refused = run_snakemake(tmp_path, "--cores", "1", "--configfile", str(config), targets=("existing_runs",))
    assert refused.returncode != 0
    assert "config key 'silo_flat.existing_runs.user.density': required: the dumps carry no mass" in refused.stderr
    assert not (tmp_path / "results").exists()

    config.write_text(yaml.safe_dump({"estimates": {"disk_check": False},
                                      "silo_flat": {"existing_runs": {"user": {**description, "density": DENSITY}}}}))
    result = run_snakemake(tmp_path, "--cores", "1", "--configfile", str(config), targets=("existing_runs",))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    folder = tmp_path / existing_run_dir("silo_flat", "user")
    analyses = json.loads((folder / "metrics" / "analyses.json").read_text())
    for name in analyses["made"]:
        assert (folder / name).is_file(), name
    assert {"metrics/flow.csv", "plots/discharge.png", "fields/fields.pvd", "metrics/profiles.csv",
            "metrics/flow_channel_boundary.csv", "plots/profiles.png"} <= set(analyses["made"])
    assert [s["analysis"] for s in analyses["skipped"]] == ["settled contact stress", "Janssen comparison",
                                                            "force chains", "fill force balance"]
    assert not (folder / "metrics" / "janssen.csv").exists() and not (folder / "plots" / "force_chains.png").exists()
    assert analyses["open_step"] == OPEN_STEP and analyses["settled_step"] == OPEN_STEP

    # the workflow's figures are the library's
    run = _run(user_run, "post/silo*.vtk")
    library = analyse_existing_run(read_existing_frames(run), run,
                                   SiloFieldOptions.from_config(validate_config({})["silo_flat"]["fields"]))
    row = read_table(folder / "metrics" / "flow.csv")[0]
    assert row["run_id"] == "user" and row["n_clumps"] == library.flow.n_particles
    assert row["mass_flow_rate_kg_s"] == pytest.approx(library.flow.metrics.fit.mass_flow_rate, rel=1e-12)
    assert row["discharged_mass_kg"] == pytest.approx(library.flow.metrics.history.discharged_mass[-1], rel=1e-12)
    fields = json.loads((folder / "metrics" / "fields.json").read_text())
    assert fields["contacts"] is None and fields["profile_heights_m"] == [0.01, 0.02]
