"""The writer of a silo field study's files (siloflow.analysis.io.silo_field_study): every file it names, with what the study
holds, and nothing written when a destination is missing."""

from __future__ import annotations

import json
import warnings
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest
from scipy.optimize import OptimizeWarning

from siloflow.model.frames import ClumpFrame
from siloflow.analysis.io.fields import load_fields_npz, read_fields_vti
import siloflow.analysis.studies.silo_flat.plots as silo_plots
from siloflow.analysis.io.plot_style import StudyNote
from siloflow.analysis.io.silo_field_study import SILO_FIELD_STUDY_FILES, write_silo_field_study
from siloflow.analysis.io.tables import read_table
from tests.plot_data import legend_texts, saved_figures
from siloflow.analysis.studies.silo_flat.field_study import (
    SiloDimensions,
    SiloFieldOptions,
    analyse_silo_fields,
    centreline_rows,
    field_summary,
    profile_rows,
)

WIDTH, DEPTH, OUTLET = 0.04, 0.01, 0.012  # silo width, depth and outlet width (m)
SPACING = 0.002  # lattice spacing (m)
MASS = 1e-5  # clump mass (kg)
SPEED = 0.1  # downward speed of every clump in every frame (m/s)
OPTIONS = SiloFieldOptions(
    spacing=(0.004, 0.005, 0.004), kernel="gaussian", width_radii=3.0, cutoff=3.0, profile_heights=(0.01, 0.015),
    fcb_fractions=(0.05,), subtract_wall_velocity=False, average_window=None, vtk_every=2,
    internal_friction_angle_deg=30.0, side_wall_friction_angle_deg=10.0, front_wall_friction_angle_deg=10.0,
    force_chain_slice=0.004)
OUTFLOW = 2.0  # kg/s


@pytest.fixture(scope="module")
def study():
    # a lattice of clumps 2 mm apart filling the silo 30 mm high, sinking at 0.1 m/s, in 3 frames 10 ms apart
    x = -WIDTH / 2 + SPACING * (np.arange(20) + 0.5)
    y = SPACING * (np.arange(5) + 0.5)
    z = SPACING * (np.arange(15) + 0.5)
    position = np.stack(np.meshgrid(x, y, z, indexing="ij"), axis=-1).reshape(-1, 3)
    n = len(position)
    frames = [ClumpFrame(time=0.01 * k, step=1000 + 100 * k, clump_id=np.arange(1, n + 1), position=position,
                         velocity=np.tile([0.0, 0.0, -SPEED], (n, 1)), mass=np.full(n, MASS),
                         n_spheres=np.full(n, 2)) for k in range(3)]
    silo = SiloDimensions(width=WIDTH, depth=DEPTH, outlet_width=OUTLET, particle_radius=0.001, clump_mass=MASS)
    with warnings.catch_warnings():
        # a flat profile gives the kinematic fit no curvature to fit (scipy warns; B is not asserted here)
        warnings.simplefilter("ignore", OptimizeWarning)
        return analyse_silo_fields(frames, None, silo, OPTIONS, steady_window=(0.0, 0.03), bulk_density=600.0)


def _outputs(folder) -> dict:
    suffixes = {"pvd": "fields/fields.pvd", "arrays": "fields/averaged.npz", "summary": "metrics/fields.json"}
    return {name: folder / suffixes.get(name, f"metrics/{name}.png" if name.endswith("_plot") else f"metrics/{name}.csv")
            for name in SILO_FIELD_STUDY_FILES}


def test_the_study_is_written_to_every_named_file(tmp_path, study):
    outputs = _outputs(tmp_path)
    fields_dir = write_silo_field_study({**outputs, "janssen": tmp_path / "unused.csv"}, study, OPTIONS.vtk_every,
                                        OUTFLOW, WIDTH, OUTLET, "lattice")
    assert fields_dir == tmp_path / "fields"
    assert all(path.is_file() for path in outputs.values()) and not (tmp_path / "unused.csv").exists()
    # every 2nd of the 3 frames, named by step, and the time average
    collection = ElementTree.parse(outputs["pvd"]).getroot().find("Collection")
    assert [(d.get("timestep"), d.get("file")) for d in collection] == [("0.0", "fields_1000.vti"),
                                                                        ("0.02", "fields_1200.vti")]
    assert sorted(p.name for p in fields_dir.glob("*.vti")) == ["averaged.vti", "fields_1000.vti", "fields_1200.vti"]
    np.testing.assert_array_equal(read_fields_vti(fields_dir / "averaged.vti").density, study.averaged.density)
    np.testing.assert_array_equal(load_fields_npz(outputs["arrays"]).velocity, study.averaged.velocity)
    profiles = read_table(outputs["profiles"])
    assert len(profiles) == len(profile_rows(study.profiles, study.front))
    assert [row["v_z_m_s"] for row in profiles] == pytest.approx(
        [row["v_z_m_s"] for row in profile_rows(study.profiles, study.front)], nan_ok=True)
    assert len(read_table(outputs["centreline"])) == len(centreline_rows(study.times, study.heights, study.centreline))
    summary = json.loads(outputs["summary"].read_text())
    assert summary["outflow_mass_flow_rate_kg_s"] == OUTFLOW
    assert summary["profile_mass_flow_rate_kg_s"] == field_summary(study, OUTFLOW)["profile_mass_flow_rate_kg_s"]


def test_a_missing_destination_is_named_and_nothing_is_written(tmp_path, study):
    outputs = _outputs(tmp_path)
    del outputs["kinematic"], outputs["centreline_plot"]
    with pytest.raises(ValueError, match=r"lacks \['kinematic', 'centreline_plot'\]"):
        write_silo_field_study(outputs, study, 1, OUTFLOW, WIDTH, OUTLET, "lattice")
    assert not any(tmp_path.iterdir())


def test_the_kinematic_plot_draws_the_findings_it_is_given(tmp_path, study, monkeypatch):
    figures = saved_figures(monkeypatch, silo_plots)
    write_silo_field_study(_outputs(tmp_path), study, OPTIONS.vtk_every, OUTFLOW, WIDTH, OUTLET, "lattice",
                           kinematic_findings=[StudyNote("S5", "B decreases with height")])
    labels = [text for figure in figures for axes in figure.axes if axes.get_legend() for text in legend_texts(axes)]
    assert labels.count("study (S5): B decreases with height") == 1
