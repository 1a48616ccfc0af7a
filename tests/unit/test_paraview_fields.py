"""The fields of a run for ParaView: depth-averaged planar fields (blender, recirculating silo) as .vti with a .pvd
(siloflow.analysis.io.planar_fields_vtk), and the flat-bottom silo's field series put on its particles' clock
(siloflow.analysis.studies.silo_flat.field_clock with siloflow.analysis.io.fields.read_pvd / write_pvd). Read back with pyvista."""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.analysis.io.fields import read_pvd, write_fields_vti, write_pvd
from siloflow.analysis.io.planar_fields_vtk import write_planar_field_series, write_planar_field_vti
from siloflow.analysis.io.vtk_xml import write_vtk_xml
from siloflow.analysis.numerics.grid import Fields, Grid
from siloflow.analysis.studies.blender.window_fields import PlanarField
from siloflow.analysis.studies.silo_flat.field_clock import field_clock_origin

pyvista = pytest.importorskip("pyvista")

X = np.array([-0.0125, -0.0075, -0.0025, 0.0025, 0.0075, 0.0125])  # 5 mm bins
Z = np.array([0.003, 0.009, 0.015, 0.021])  # 6 mm bins


def make_planar(t: float, seed: int = 0) -> PlanarField:
    rng = np.random.default_rng(seed)
    v_x, v_z = rng.normal(size=(X.size, Z.size)), -np.abs(rng.normal(size=(X.size, Z.size)))
    v_x[0, -1] = v_z[0, -1] = np.nan  # no clump entered this bin
    solid = rng.uniform(0.4, 0.6, (X.size, Z.size))
    solid[0, -1] = 0.0
    return PlanarField(x=X, z=Z, v_x=v_x, v_z=v_z, solid_fraction=solid, window=(t, t), n_frames=1)


def test_a_planar_field_is_an_image_in_the_x_z_plane_with_its_bins_at_the_nodes(tmp_path):
    field = make_planar(0.25)
    image = pyvista.read(write_planar_field_vti(tmp_path / "field.vti", field, y=0.006, time=1.75))

    assert isinstance(image, pyvista.ImageData)
    assert image.dimensions == (X.size, 1, Z.size)
    assert image.n_points == X.size * Z.size
    assert image.n_cells == (X.size - 1) * (Z.size - 1)
    np.testing.assert_allclose(image.origin, (X[0], 0.006, Z[0]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(image.spacing, (0.005, 0.005, 0.006), rtol=1e-12)
    # each value sits on its bin centre: x varies fastest
    nodes = np.stack(np.meshgrid(X, [0.006], Z, indexing="ij"), axis=-1).transpose(2, 1, 0, 3).reshape(-1, 3)
    np.testing.assert_allclose(image.points, nodes, rtol=0, atol=1e-15)
    entered = np.isfinite(field.v_x)
    velocity = np.stack([np.where(entered, field.v_x, 0.0), np.zeros_like(field.v_x),
                         np.where(entered, field.v_z, 0.0)], axis=-1)
    assert set(image.point_data.keys()) == {"velocity", "solid_fraction", "mask"}
    np.testing.assert_array_equal(image.point_data["velocity"], velocity.transpose(1, 0, 2).reshape(-1, 3))
    np.testing.assert_array_equal(image.point_data["solid_fraction"], field.solid_fraction.T.reshape(-1))
    assert image.point_data["mask"].dtype == np.uint8
    np.testing.assert_array_equal(image.point_data["mask"], entered.T.reshape(-1).astype(np.uint8))
    assert image.point_data.active_vectors_name == "velocity"
    assert image.field_data["TimeValue"][0] == 1.75
    np.testing.assert_array_equal(image.field_data["window"], [0.25, 0.25])
    assert image.field_data["n_frames"][0] == 1


def test_a_planar_series_plays_on_the_times_given(tmp_path):
    fields = [make_planar(t, seed) for seed, t in enumerate((0.2, 0.21, 0.22))]
    times = [1.9, 1.91, 1.92]
    pvd = write_planar_field_series(tmp_path / "paraview" / "fields.pvd", fields, times, y=0.00225)

    reader = pyvista.PVDReader(pvd)
    assert reader.time_values == times
    assert [entry.path for entry in reader.datasets] == [f"fields/fields_{k}.vti" for k in range(3)]
    for k, field in enumerate(fields):
        image = pyvista.read(tmp_path / "paraview" / "fields" / f"fields_{k}.vti")
        assert image.field_data["TimeValue"][0] == times[k]
        np.testing.assert_array_equal(image.point_data["solid_fraction"], field.solid_fraction.T.reshape(-1))
    assert sorted(p.name for p in (tmp_path / "paraview").iterdir()) == ["fields", "fields.pvd"]


@pytest.mark.parametrize("times, message", [([1.0], "one time per field"), ([1.0, 1.0], "strictly increasing"),
                                            ([1.0, np.nan], "finite")])
def test_a_planar_series_without_a_clock_is_refused(tmp_path, times, message):
    with pytest.raises(ValueError, match=message):
        write_planar_field_series(tmp_path / "fields.pvd", [make_planar(0.0), make_planar(0.1)], times)
    assert not list(tmp_path.iterdir())


def test_uneven_bins_are_refused(tmp_path):
    field = make_planar(0.0)
    uneven = PlanarField(x=X + np.array([0, 0, 0, 0.001, 0, 0]), z=Z, v_x=field.v_x, v_z=field.v_z,
                         solid_fraction=field.solid_fraction, window=field.window, n_frames=1)
    with pytest.raises(ValueError, match="evenly spaced"):
        write_planar_field_vti(tmp_path / "field.vti", uneven)


def test_the_silo_fields_are_put_on_the_clock_of_the_particles(tmp_path):
    # the field study times its series from the first frame at or after the opening (step 68275 here)
    dt = 2.3081e-5
    frame_times = [68058 * dt, 68275 * dt, 68492 * dt, 68709 * dt]
    origin = field_clock_origin(frame_times, open_time=68275 * dt * (1 + 1e-15), timestep=dt)
    assert origin == frame_times[1]
    assert field_clock_origin(frame_times, open_time=68100 * dt, timestep=dt) == frame_times[1]
    with pytest.raises(ValueError, match="no frame at or after the opening"):
        field_clock_origin(frame_times, open_time=69000 * dt, timestep=dt)

    grid = Grid(origin=(-0.01, 0.0, 0.0), spacing=(0.005, 0.004, 0.005), shape=(4, 2, 3))
    zero = np.zeros(grid.shape)
    fields = Fields(grid=grid, density=zero + 600.0, momentum_density=np.zeros(grid.shape + (3,)),
                    velocity=np.zeros(grid.shape + (3,)), kinetic_stress=np.zeros(grid.shape + (3, 3)),
                    mask=zero > -1)
    source = tmp_path / "fields" / "fields.pvd"
    for step, time in ((68275, 0.0), (68709, 434 * dt)):
        write_fields_vti(tmp_path / "fields" / f"fields_{step}.vti", grid, fields, time=time)
    write_pvd(source, [(0.0, "fields_68275.vti"), (434 * dt, "fields_68709.vti")])

    target = tmp_path / "paraview" / "fields.pvd"
    write_pvd(target, [(time + origin, file.resolve()) for time, file in read_pvd(source)])
    reader = pyvista.PVDReader(target)
    assert reader.time_values == [0.0 + origin, 434 * dt + origin]
    assert [entry.path for entry in reader.datasets] == ["../fields/fields_68275.vti", "../fields/fields_68709.vti"]
    assert reader.read()[0].n_points == 24  # the same files, read from their own folder


def test_read_pvd_gives_each_entry_with_its_file_beside_the_index(tmp_path):
    for name in ("one", "two"):  # pyvista's reader opens the files it indexes
        write_planar_field_vti(tmp_path / "a" / "x" / f"{name}.vti", make_planar(0.0))
    write_pvd(tmp_path / "a" / "series.pvd", [(0.5, "x/one.vti"), (1.5, "x/two.vti")])
    assert read_pvd(tmp_path / "a" / "series.pvd") == [(0.5, tmp_path / "a" / "x" / "one.vti"),
                                                      (1.5, tmp_path / "a" / "x" / "two.vti")]


def test_the_vtk_writer_takes_images_and_poly_data_only(tmp_path):
    with pytest.raises(ValueError, match="ImageData"):
        write_vtk_xml(tmp_path / "grid.vtu", pyvista.UnstructuredGrid())
    assert not list(tmp_path.iterdir())
