"""siloflow.analysis.io.paraview_state: the ParaView state of a run names exactly the files of its folder, relative to itself,
so a copied run folder opens; with ParaView installed, pvpython runs it and finds every file, time and array."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from siloflow.analysis.io.paraview_state import StateLines, paraview_state_script, write_paraview_state
from siloflow.analysis.io.particle_series import write_particle_series
from siloflow.analysis.io.planar_fields_vtk import write_planar_field_series
from siloflow.analysis.io.vtk_lines import write_force_chains_vtp, write_polylines_vtp
from siloflow.analysis.io.vtk_walls import write_walls_vtp
from siloflow.analysis.numerics.force_chains import ForceChainSegments
from siloflow.analysis.studies.blender.window_fields import PlanarField
from siloflow.model.cases.geometry import horizontal_rectangle
from siloflow.model.frames import ParticleFrame
from tests.paraview_checks import named_files, open_state_in_pvpython

pytest.importorskip("pyvista")

FRAME_TIMES = (1.5, 1.51, 1.52)
FIELD_TIMES = (1.505, 1.515)
#: What the state must open, relative to its folder.
RUN_FILES = {"particles.pvd", "walls.vtp", "fields.pvd", "tracks.vtp", "force_chains.vtp"}


def write_run(run: Path) -> Path:
    """A run's ParaView folder of small synthetic files and its state; returns the state's path."""
    folder = run / "paraview"
    rng = np.random.default_rng(3)
    n = 20
    frames = [ParticleFrame(time=t, step=int(round(t / 1e-4)), id=np.arange(n), type=np.ones(n), clump_id=np.arange(n),
                            position=rng.uniform(0.0, 0.01, (n, 3)), velocity=rng.normal(size=(n, 3)),
                            angular_velocity=None, radius=np.full(n, 0.0015), mass=np.full(n, 1e-5))
              for t in FRAME_TIMES]
    write_particle_series(folder / "particles.pvd", frames)
    write_walls_vtp(folder / "walls.vtp", {"floor": horizontal_rectangle(0.0, 0.01, 0.0, 0.01, 0.0)})
    x, z = np.array([0.0025, 0.0075]), np.array([0.0025, 0.0075])
    fields = [PlanarField(x=x, z=z, v_x=np.zeros((2, 2)), v_z=-np.ones((2, 2)), solid_fraction=np.full((2, 2), 0.5),
                          window=(t, t), n_frames=1) for t in FIELD_TIMES]
    write_planar_field_series(folder / "fields.pvd", fields, FIELD_TIMES, y=0.005)
    write_polylines_vtp(folder / "tracks.vtp", rng.uniform(0.0, 0.01, (5, 3)), np.array([0, 3, 5]),
                        cell_arrays={"residence_time": np.array([0.2, np.nan])})
    write_force_chains_vtp(folder / "force_chains.vtp", ForceChainSegments(
        rng.uniform(0.0, 0.01, (4, 3)), rng.uniform(0.0, 0.01, (4, 3)), np.array([0.1, 0.2, 0.0, 0.3]), np.inf))
    return write_paraview_state(folder / "state.py", "silo_recirculation run demo-0123456789 (liggghts)",
                                folder / "particles.pvd", walls=folder / "walls.vtp", fields=folder / "fields.pvd",
                                lines=[StateLines("tracks", folder / "tracks.vtp", "residence_time"),
                                       StateLines("force_chains", folder / "force_chains.vtp", "normal_force")])


def test_the_state_names_exactly_the_files_of_its_run_relative_to_itself(tmp_path):
    state = write_run(tmp_path / "results" / "run")
    names = named_files(state)
    assert sorted(names) == sorted(RUN_FILES)  # each once
    assert all((state.parent / name).is_file() for name in names)
    text = state.read_text(encoding="utf-8")
    assert str(tmp_path) not in text  # no absolute path: a copied run folder still opens

    copy = shutil.copytree(tmp_path / "results" / "run", tmp_path / "elsewhere" / "run")
    assert all((copy / "paraview" / name).is_file() for name in named_files(copy / "paraview" / "state.py"))


def test_files_outside_the_script_folder_are_named_relative_to_it(tmp_path):
    text = paraview_state_script(tmp_path / "run" / "paraview" / "state.py", "run",
                                 tmp_path / "run" / "paraview" / "particles.pvd",
                                 fields=tmp_path / "run" / "fields" / "fields.pvd")
    script = tmp_path / "state.py"
    script.write_text(text, encoding="utf-8")
    assert named_files(script) == ["particles.pvd", "../fields/fields.pvd"]


@pytest.mark.parametrize("name", ["force chains", "view", "particles", "tracks_display"])
def test_a_pipeline_name_must_be_a_variable_the_state_does_not_use(tmp_path, name):
    with pytest.raises(ValueError, match="identifier the state does not use"):
        paraview_state_script(tmp_path / "state.py", "run", tmp_path / "particles.pvd",
                              lines=[StateLines(name, tmp_path / "chains.vtp", "normal_force")])


@pytest.mark.skipif(shutil.which("pvpython") is None, reason="ParaView (pvpython) is not installed")
def test_pvpython_opens_every_file_of_a_copied_run(tmp_path):
    write_run(tmp_path / "results" / "run")
    copy = shutil.copytree(tmp_path / "results" / "run", tmp_path / "moved" / "run")
    shutil.rmtree(tmp_path / "results")  # the state must not lean on where it was written
    found = open_state_in_pvpython(copy / "paraview" / "state.py", tmp_path)

    assert set(found) == {"walls", "particles", "fields", "tracks", "force_chains"}
    opened = {Path(file).resolve() for source in found.values() for file in source["files"]}
    assert opened == {(copy / "paraview" / name).resolve() for name in RUN_FILES}
    assert found["particles"]["times"] == pytest.approx(FRAME_TIMES, rel=1e-15)
    assert found["fields"]["times"] == pytest.approx(FIELD_TIMES, rel=1e-15)
    assert {"speed", "radius", "velocity", "id"} <= set(found["particles"]["point"])
    assert {"velocity", "solid_fraction", "mask"} <= set(found["fields"]["point"])
    assert found["walls"]["cell"] == ["wall"]
    assert "residence_time" in found["tracks"]["cell"] and "normal_force" in found["force_chains"]["cell"]
    visible = {name for name, source in found.items() if source["visible"]}
    assert visible == {"walls", "particles"}  # fields and lines are loaded, ticked on by the user
