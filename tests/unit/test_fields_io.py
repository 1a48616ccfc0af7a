"""Unit tests for siloflow.analysis.io.fields: .vti/.pvd open in pyvista with the arrays; .npz round trip is exact."""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pytest

from siloflow.analysis.numerics.grid import Grid
from siloflow.analysis.numerics.coarse_graining import coarse_grain
from siloflow.analysis.numerics.contact_stress import contact_stress
from siloflow.analysis.numerics.field_ops import depth_average
from siloflow.analysis.io.fields import (
    fields_image,
    load_fields_npz,
    read_fields_vti,
    save_fields_npz,
    write_fields_vti,
    write_pvd,
)

pyvista = pytest.importorskip("pyvista")

GRID = Grid.covering((-0.075, 0.0, 0.0), (0.075, 0.04, 0.06))  # 25 x 10 x 10 cells


def make_fields(seed: int = 0):
    rng = np.random.default_rng(seed)
    n = 2000
    positions = rng.uniform(GRID.lower, (0.075, 0.04, 0.04), size=(n, 3))  # upper part empty
    velocities = rng.normal(scale=0.1, size=(n, 3))
    return coarse_grain(positions, rng.uniform(1e-5, 2e-5, n), velocities, GRID, 0.0045)


def assert_same_fields(a, b):
    assert a.grid == b.grid
    for name in ("density", "momentum_density", "velocity", "kinetic_stress", "mask"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.density_threshold == b.density_threshold


@pytest.mark.parametrize("cell_data", [False, True])
@pytest.mark.parametrize("compress", [True, False])
def test_vti_opens_in_pyvista_with_the_arrays_at_the_nodes(tmp_path, cell_data, compress):
    fields = make_fields()
    path = write_fields_vti(tmp_path / "fields.vti", GRID, fields, time=0.25, cell_data=cell_data, compress=compress)
    image = pyvista.read(path)
    assert isinstance(image, pyvista.ImageData)
    data = image.cell_data if cell_data else image.point_data
    assert data["density"].shape == (GRID.n_nodes,)
    assert data["velocity"].shape == (GRID.n_nodes, 3)
    assert data["momentum_density"].shape == (GRID.n_nodes, 3)
    assert data["kinetic_stress"].shape == (GRID.n_nodes, 9)
    assert data["mask"].dtype == np.uint8
    assert image.field_data["TimeValue"][0] == 0.25
    # Where each value sits: VTK points (or cell centres) coincide with the grid nodes, x fastest.
    points = image.cell_centers().points if cell_data else image.points
    nodes = GRID.node_positions().transpose(2, 1, 0, 3).reshape(-1, 3)
    np.testing.assert_allclose(points, nodes, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(data["density"], fields.density.transpose(2, 1, 0).ravel())
    np.testing.assert_array_equal(
        data["kinetic_stress"][:, 5], fields.kinetic_stress[..., 1, 2].transpose(2, 1, 0).ravel()
    )  # row-major: component 5 is yz
    assert_same_fields(read_fields_vti(path), fields)


def test_vti_of_depth_averaged_fields_and_extra_arrays(tmp_path):
    fields = make_fields()
    sigma_c = contact_stress(GRID, [[0.0, 0.02, 0.02]], [[0.003, 0.02, 0.02]], [[-1.0, 0.0, 0.0]], 0.0045)
    write_fields_vti(tmp_path / "full.vti", GRID, fields, extra_arrays={"contact_stress": sigma_c})
    image = pyvista.read(tmp_path / "full.vti")
    assert image.point_data["contact_stress"].shape == (GRID.n_nodes, 9)
    assert image.point_data["contact_stress"][:, 0].sum() * GRID.cell_volume == pytest.approx(0.003, rel=1e-12)

    averaged = depth_average(fields)
    write_fields_vti(tmp_path / "plane.vti", averaged.grid, averaged)
    assert tuple(pyvista.read(tmp_path / "plane.vti").dimensions) == (25, 1, 10)
    assert_same_fields(read_fields_vti(tmp_path / "plane.vti"), averaged)


def test_pvd_time_series_opens_in_pyvista(tmp_path):
    times = [0.5, 0.505, 0.51]
    entries = []
    for index, time in enumerate(times):
        name = f"fields/fields_{index:04d}.vti"
        write_fields_vti(tmp_path / name, GRID, make_fields(index), time=time)
        entries.append((time, name))
    entries[-1] = (times[-1], tmp_path / entries[-1][1])  # an absolute path is made relative
    pvd = write_pvd(tmp_path / "fields.pvd", entries)
    assert "fields/fields_0002.vti" in pvd.read_text()
    reader = pyvista.get_reader(str(pvd))
    assert reader.time_values == pytest.approx(times)
    reader.set_active_time_value(times[1])
    mesh = reader.read()
    image = mesh[0] if isinstance(mesh, pyvista.MultiBlock) else mesh
    np.testing.assert_array_equal(image.point_data["density"], make_fields(1).density.transpose(2, 1, 0).ravel())


def test_npz_round_trip_is_exact(tmp_path):
    fields = make_fields()
    path = save_fields_npz(tmp_path / "fields.npz", fields)
    assert path.exists()
    assert_same_fields(load_fields_npz(path), fields)
    uncompressed = save_fields_npz(tmp_path / "raw.fields", fields, compress=False)
    assert uncompressed.name == "raw.fields"  # no suffix added
    assert_same_fields(load_fields_npz(uncompressed), fields)


def test_writers_are_atomic_and_validate(tmp_path):
    fields = make_fields()
    target = tmp_path / "fields.vti"
    write_fields_vti(target, GRID, fields)
    before = target.read_bytes()
    other = Grid.covering((-0.075, 0.0, 0.0), (0.075, 0.04, 0.12))
    with pytest.raises(ValueError, match="grid"):
        write_fields_vti(target, other, fields)
    with pytest.raises(ValueError, match="extra_arrays"):
        write_fields_vti(target, GRID, fields, extra_arrays={"density": fields.density})
    with pytest.raises(ValueError, match="extra_arrays"):
        write_fields_vti(target, GRID, fields, extra_arrays={"bad": np.zeros((2, 2, 2))})
    with pytest.raises(ValueError, match="time"):
        write_pvd(tmp_path / "series.pvd", [(float("nan"), "fields.vti")])
    with pytest.raises(ValueError, match="entries"):
        write_pvd(tmp_path / "series.pvd", [])
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fields.vti"]  # no temporary files left


def test_load_fields_npz_rejects_other_files(tmp_path):
    np.savez(tmp_path / "other.npz", density=np.zeros(3))
    with pytest.raises(ValueError, match="path"):
        load_fields_npz(tmp_path / "other.npz")


def test_vti_names_its_active_arrays_and_rejects_names_vtk_would_not_escape(tmp_path):
    fields = make_fields()
    image = pyvista.read(write_fields_vti(tmp_path / "fields.vti", GRID, fields))
    assert image.point_data.active_scalars_name == "density"
    assert image.point_data.active_vectors_name == "velocity"
    assert image.point_data.VTKObject.GetTensors().GetName() == "kinetic_stress"
    assert "TimeValue" not in image.field_data  # only written when a time is given
    np.testing.assert_array_equal(image.field_data["grid_spacing"], GRID.spacing)
    for name in ("a<b", "a&b", "", " padded"):
        with pytest.raises(ValueError, match="extra_arrays"):
            write_fields_vti(tmp_path / "bad.vti", GRID, fields, extra_arrays={name: fields.density})
    assert not (tmp_path / "bad.vti").exists()


def test_fields_image_is_what_the_vti_holds(tmp_path):
    fields = make_fields()
    image = fields_image(GRID, fields, time=1.5, cell_data=True)
    assert isinstance(image, pyvista.ImageData)
    assert tuple(image.dimensions) == tuple(n + 1 for n in GRID.shape)
    np.testing.assert_allclose(image.origin, GRID.origin, rtol=0, atol=0)
    written = pyvista.read(write_fields_vti(tmp_path / "cells.vti", GRID, fields, time=1.5, cell_data=True))
    for name in image.cell_data.keys():
        np.testing.assert_array_equal(written.cell_data[name], image.cell_data[name], err_msg=name)
    assert written.field_data["TimeValue"][0] == 1.5


def test_pvd_escapes_file_names_and_keeps_the_order(tmp_path):
    write_fields_vti(tmp_path / "a&b.vti", GRID, make_fields(), time=0.2)
    write_fields_vti(tmp_path / "c.vti", GRID, make_fields(1), time=0.1)
    pvd = write_pvd(tmp_path / "series.pvd", [(0.2, "a&b.vti"), (0.1, "c.vti")])
    assert "a&amp;b.vti" in pvd.read_text()
    written = [(float(d.get("timestep")), d.get("file")) for d in ElementTree.parse(pvd).iter("DataSet")]
    assert written == [(0.2, "a&b.vti"), (0.1, "c.vti")]  # in the order given
    reader = pyvista.get_reader(str(pvd))  # ParaView and pyvista order the series by time
    assert [(d.time, Path(d.path).name) for d in reader.datasets] == [(0.1, "c.vti"), (0.2, "a&b.vti")]
