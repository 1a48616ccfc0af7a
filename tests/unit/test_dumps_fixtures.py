"""The dump reader on files LIGGGHTS wrote (tests/fixtures/liggghts; README there for the decks): every style read
against the file read independently (the ASCII text split with Python and converted with numpy, the binary arrays with
numpy's big-endian dtypes at the offsets their header lines give, the text dumps with numpy.loadtxt), and the same frame
from each style equal to the precision the style keeps. Also the mass from the density, clump ids absent and present,
empty dumps, and a text file of several snapshots."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import pyvista

from siloflow.model.frames import ParticleFrame, clumps_from_frame
from siloflow.engines.liggghts.dumps import (
    DumpFormatError,
    parse_legacy_vtk_polydata,
    read_custom_dump,
    read_file_frames,
    read_frame,
    read_frames,
)

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "liggghts"
TIMESTEP = 2.0e-5  # [s], the decks' time step
STEP = 1500
N_SPHERES = 40
DENSITY = {1: 2500.0, 2: 3000.0}  # [kg/m^3] per atom type, in.spheres
# Relative precision of what a style keeps: %g writes 6 significant digits (at most 5e-6 relative error), VTK's ASCII
# doubles 11 (5e-11); the binary positions are float32 (2**-24), and a decimal is then rounded once more to its type.
G6 = 5e-6 + 2.0**-24 + 2.0**-52
G11 = 5e-11 + 2.0**-52
VTK_STYLES = ("spheres_binary_1500.vtk", "spheres_v42_binary_1500.vtk", "spheres_ascii_1500.vtk",
              "spheres_v42_ascii_1500.vtk")


# --------------------------------------------------------------------------- independent reads of the raw files


def vtk_header_index(content: bytes, header: str) -> int:
    """Offset just after the line ``header`` (a section or array line) of a VTK file."""
    marker = f"\n{header}\n".encode()
    assert content.count(marker) == 1, header
    return content.index(marker) + len(marker)


def binary_array(content: bytes, header: str, dtype: str, count: int) -> np.ndarray:
    return np.frombuffer(content, dtype=dtype, count=count, offset=vtk_header_index(content, header)).astype(
        dtype.replace(">", "="))


def ascii_array(content: bytes, header: str, dtype: type, count: int) -> np.ndarray:
    return np.array(content[vtk_header_index(content, header) :].split()[:count], dtype=dtype)


def raw_vtk(path: Path) -> dict[str, np.ndarray]:
    """Positions and the fields of the spheres deck's full VTK dumps, read without the reader under test."""
    content = path.read_bytes()
    n = N_SPHERES
    if b"\nBINARY\n" in content:
        def read(header, dtype, count):
            return binary_array(content, header, dtype, count)
        kinds = {"float": ">f4", "int": ">i4", "double": ">f8"}
    else:
        def read(header, dtype, count):
            return ascii_array(content, header, dtype, count)
        kinds = {"float": np.float32, "int": np.int32, "double": np.float64}
    raw = {"points": read(f"POINTS {n} float", kinds["float"], 3 * n).reshape(n, 3)}
    for name, components, kind in (("id", 1, "int"), ("type", 1, "int"), ("mass", 1, "double"), ("v", 3, "double"),
                                   ("f", 3, "double"), ("radius", 1, "double"), ("omega", 3, "double")):
        values = read(f"{name} {components} {n} {kind}", kinds[kind], components * n)
        raw[name] = values.reshape(n, 3) if components == 3 else values
    return raw


def raw_text(path: Path) -> dict[str, np.ndarray]:
    """The columns of a one-snapshot text dump, by name, with numpy.loadtxt."""
    lines = path.read_text().splitlines()
    assert lines[0] == "ITEM: TIMESTEP" and lines[8].startswith("ITEM: ATOMS ")
    columns = lines[8].split()[2:]
    table = np.loadtxt(path, skiprows=9, ndmin=2)
    return {name: table[:, columns.index(name)] for name in columns}


def assert_frame_matches_raw(frame: ParticleFrame, raw: dict[str, np.ndarray]) -> None:
    np.testing.assert_array_equal(frame.id, raw["id"])
    np.testing.assert_array_equal(frame.type, raw["type"])
    np.testing.assert_array_equal(frame.position, raw["points"])
    np.testing.assert_array_equal(frame.velocity, raw["v"])
    np.testing.assert_array_equal(frame.force, raw["f"])
    np.testing.assert_array_equal(frame.angular_velocity, raw["omega"])
    np.testing.assert_array_equal(frame.radius, raw["radius"])
    np.testing.assert_array_equal(frame.mass, raw["mass"])


def assert_same_frame(frame: ParticleFrame, reference: ParticleFrame, rtol_points: float = 0.0,
                      rtol_values: float = 0.0) -> None:
    """Equal ids, types, clumps and step; positions and floating fields to the relative tolerances given."""
    assert (frame.step, frame.time, len(frame)) == (reference.step, reference.time, len(reference))
    order, reference_order = np.argsort(frame.id), np.argsort(reference.id)
    np.testing.assert_array_equal(frame.id[order], reference.id[reference_order])
    np.testing.assert_array_equal(frame.type[order], reference.type[reference_order])
    np.testing.assert_array_equal(frame.clump_id[order], reference.clump_id[reference_order])
    np.testing.assert_allclose(frame.position[order], reference.position[reference_order], rtol=rtol_points, atol=0)
    for name in ("velocity", "radius", "mass", "angular_velocity", "force"):
        values, expected = getattr(frame, name), getattr(reference, name)
        if values is None or expected is None:
            assert values is None and expected is None, name
            continue
        np.testing.assert_allclose(values[order], expected[reference_order], rtol=rtol_values, atol=0, err_msg=name)


@pytest.fixture(scope="module")
def binary() -> ParticleFrame:
    return read_frame(FIXTURES / "spheres_binary_1500.vtk", TIMESTEP)


# --------------------------------------------------------------------------- each style against its raw file


@pytest.mark.parametrize("name", VTK_STYLES)
def test_each_vtk_style_reads_what_the_file_holds(name):
    path = FIXTURES / name
    frame = read_frame(path, TIMESTEP)
    assert (frame.step, frame.time, len(frame)) == (STEP, STEP * TIMESTEP, N_SPHERES)
    assert_frame_matches_raw(frame, raw_vtk(path))
    np.testing.assert_array_equal(frame.clump_id, frame.id)  # no id_multisphere: each sphere its own clump
    assert set(frame.type.tolist()) == {1, 2} and set(frame.radius.tolist()) == {0.001, 0.0012}


@pytest.mark.parametrize("name", VTK_STYLES)
def test_the_vtk_parser_agrees_with_pyvista(name):
    path = FIXTURES / name
    parsed = parse_legacy_vtk_polydata(path.read_bytes(), str(path))
    mesh = pyvista.read(path)
    assert list(parsed) == ["points", *mesh.point_data.keys()]
    np.testing.assert_array_equal(parsed["points"], np.asarray(mesh.points))
    for field in mesh.point_data:
        np.testing.assert_array_equal(parsed[field], np.asarray(mesh.point_data[field]), err_msg=field)
        assert parsed[field].dtype == np.asarray(mesh.point_data[field]).dtype, field


@pytest.mark.parametrize("name", ["spheres_1500.txt", "spheres_exact_1500.txt"])
def test_each_text_style_reads_what_the_file_holds(name):
    path = FIXTURES / name
    frame = read_frame(path, TIMESTEP)
    raw = raw_text(path)
    assert (frame.step, frame.time, len(frame)) == (STEP, STEP * TIMESTEP, N_SPHERES)
    np.testing.assert_array_equal(frame.id, raw["id"])
    np.testing.assert_array_equal(frame.type, raw["type"])
    np.testing.assert_array_equal(frame.clump_id, raw["id"])
    np.testing.assert_array_equal(frame.position, np.column_stack([raw["x"], raw["y"], raw["z"]]))
    np.testing.assert_array_equal(frame.velocity, np.column_stack([raw["vx"], raw["vy"], raw["vz"]]))
    np.testing.assert_array_equal(frame.force, np.column_stack([raw["fx"], raw["fy"], raw["fz"]]))
    np.testing.assert_array_equal(frame.angular_velocity,
                                  np.column_stack([raw["omegax"], raw["omegay"], raw["omegaz"]]))
    np.testing.assert_array_equal(frame.radius, raw["radius"])
    np.testing.assert_array_equal(frame.mass, raw["mass"])


# --------------------------------------------------------------------------- the same frame from every style


def test_binary_5_1_and_4_2_give_the_same_frame_exactly(binary):
    assert_same_frame(read_frame(FIXTURES / "spheres_v42_binary_1500.vtk", TIMESTEP), binary)


def test_ascii_5_1_and_4_2_give_the_same_frame_exactly():
    assert_same_frame(read_frame(FIXTURES / "spheres_v42_ascii_1500.vtk", TIMESTEP),
                      read_frame(FIXTURES / "spheres_ascii_1500.vtk", TIMESTEP))


def test_ascii_vtk_gives_the_binary_frame_to_its_digits(binary):
    ascii_frame = read_frame(FIXTURES / "spheres_ascii_1500.vtk", TIMESTEP)
    assert_same_frame(ascii_frame, binary, rtol_points=G6, rtol_values=G11)
    assert not np.array_equal(ascii_frame.velocity, binary.velocity)  # the tolerance is needed: 11 digits, not 17


def test_text_dump_at_full_precision_gives_the_binary_frame_exactly(binary):
    exact = read_frame(FIXTURES / "spheres_exact_1500.txt", TIMESTEP)
    # VTK stores LIGGGHTS' double positions as float32: the text's doubles rounded to float32 are the binary's
    np.testing.assert_array_equal(exact.position.astype(np.float32), binary.position.astype(np.float32))
    assert_same_frame(exact, binary, rtol_points=2.0**-24)
    assert not np.array_equal(exact.position, binary.position)


def test_text_dump_with_default_format_gives_the_binary_frame_to_six_digits(binary):
    assert_same_frame(read_frame(FIXTURES / "spheres_1500.txt", TIMESTEP), binary, rtol_points=G6, rtol_values=G6)


def test_tutorial_columns_without_mass_give_the_frame_with_the_mass_from_the_density(binary):
    # id type type x y z ix iy iz vx ... radius: a repeated column, image flags, no mass
    frame = read_frame(FIXTURES / "spheres_nomass_1500.txt", TIMESTEP, density=DENSITY)
    assert_same_frame(frame, binary, rtol_points=G6, rtol_values=G6)
    exact = read_frame(FIXTURES / "spheres_exact_1500.txt", TIMESTEP)
    np.testing.assert_array_equal(frame.mass, exact.mass)  # radii of 0.001 and 0.0012 m survive %g exactly


# --------------------------------------------------------------------------- mass and clumps when the dump lacks them


def test_binary_vtk_without_mass_takes_the_mass_liggghts_computed_from_the_density(binary):
    path = FIXTURES / "spheres_binary_nomass_1500.vtk"
    assert b"mass" not in path.read_bytes()
    with pytest.raises(DumpFormatError, match=r"spheres_binary_nomass_1500\.vtk: missing fields mass"):
        read_frame(path, TIMESTEP)
    frame = read_frame(path, TIMESTEP, density=DENSITY)
    np.testing.assert_array_equal(frame.mass, binary.mass)  # to the last bit
    assert frame.force is None and frame.angular_velocity is None
    np.testing.assert_array_equal(frame.position, binary.position)
    np.testing.assert_array_equal(frame.velocity, binary.velocity)


def test_one_density_for_every_type_and_a_given_sphere_mass(binary):
    path = FIXTURES / "spheres_binary_nomass_1500.vtk"
    small = binary.type == 1
    one_density = read_frame(path, TIMESTEP, density=2500.0)
    np.testing.assert_array_equal(one_density.mass[small], binary.mass[small])
    np.testing.assert_allclose(one_density.mass[~small], binary.mass[~small] * 2500.0 / 3000.0, rtol=1e-15)
    per_type = {1: float(binary.mass[small][0]), 2: float(binary.mass[~small][0])}
    np.testing.assert_array_equal(read_frame(path, TIMESTEP, sphere_mass=per_type).mass, binary.mass)
    np.testing.assert_array_equal(read_frame(path, TIMESTEP, sphere_mass=1e-5).mass, np.full(N_SPHERES, 1e-5))


def test_spheres_without_clump_ids_are_each_their_own_clump(binary):
    clumps = clumps_from_frame(binary)
    assert len(clumps) == N_SPHERES
    np.testing.assert_array_equal(clumps.clump_id, np.sort(binary.id))
    np.testing.assert_array_equal(clumps.n_spheres, np.ones(N_SPHERES))
    np.testing.assert_array_equal(clumps.mass, binary.mass[np.argsort(binary.id)])


def test_multisphere_dumps_carry_the_clumps_and_their_mass():
    binary = read_frame(FIXTURES / "clumps_binary_1500.vtk", TIMESTEP)
    content = (FIXTURES / "clumps_binary_1500.vtk").read_bytes()
    bodies = binary_array(content, "id_multisphere 1 30 int", ">i4", 30)
    np.testing.assert_array_equal(binary.clump_id, bodies)
    clumps = clumps_from_frame(binary)
    np.testing.assert_array_equal(clumps.clump_id, np.arange(1, 16))
    np.testing.assert_array_equal(clumps.n_spheres, np.full(15, 2))
    # the clump's mass on each sphere, less than two whole spheres' as they overlap
    clump_mass = float(binary.mass[0])
    np.testing.assert_array_equal(binary.mass, np.full(30, clump_mass))
    assert 2500.0 * 4.0 / 3.0 * np.pi * 1e-9 < clump_mass < 2 * 2500.0 * 4.0 / 3.0 * np.pi * 1e-9

    text = read_frame(FIXTURES / "clumps_1500.txt", TIMESTEP)
    assert_same_frame(text, binary, rtol_points=G6, rtol_values=G6)

    nomass = FIXTURES / "clumps_ascii_nomass_1500.vtk"
    with pytest.raises(ValueError, match=r"clumps_ascii_nomass_1500\.vtk: no mass field, and 30 spheres belong to "
                                         r"multisphere clumps.*pass sphere_mass"):
        read_frame(nomass, TIMESTEP, density=2500.0)
    assert_same_frame(read_frame(nomass, TIMESTEP, sphere_mass=clump_mass), binary, rtol_points=G6,
                      rtol_values=G11)


# --------------------------------------------------------------------------- empty dumps, snapshots, folders


@pytest.mark.parametrize("name", ["empty_ascii_0.vtk", "empty_binary_0.vtk", "empty_0.txt"])
def test_a_dump_before_the_insertion_is_an_empty_frame(name):
    frame = read_frame(FIXTURES / name, TIMESTEP)
    assert (frame.step, len(frame), frame.position.shape) == (0, 0, (0, 3))
    assert len(clumps_from_frame(frame)) == 0


def test_a_text_file_of_several_snapshots_gives_one_frame_each():
    path = FIXTURES / "series.txt"
    text = path.read_text()
    steps = [int(line) for previous, line in zip(text.splitlines(), text.splitlines()[1:])
             if previous == "ITEM: TIMESTEP"]
    assert steps == [0, 750, 1500]
    frames = read_file_frames(path, TIMESTEP, density=DENSITY)
    assert [(f.step, f.time, len(f)) for f in frames] == [(0, 0.0, 0), (750, 750 * TIMESTEP, 40),
                                                          (1500, 1500 * TIMESTEP, 40)]
    exact = read_frame(FIXTURES / "spheres_exact_1500.txt", TIMESTEP)
    last = frames[-1]
    np.testing.assert_array_equal(last.id, exact.id)
    np.testing.assert_allclose(last.position, exact.position, rtol=G6, atol=0)
    np.testing.assert_allclose(last.velocity, exact.velocity, rtol=G6, atol=0)
    np.testing.assert_array_equal(last.mass, exact.mass)
    assert not np.allclose(frames[1].position, last.position)  # the spheres moved in between
    with pytest.raises(DumpFormatError, match=r"series\.txt: holds 3 snapshots; read them with read_file_frames$"):
        read_frame(path, TIMESTEP, density=DENSITY)
    with pytest.raises(ValueError, match="a text dump holds its own steps"):
        read_file_frames(path, TIMESTEP, step=3)


def test_read_custom_dump_gives_each_snapshot_as_the_file_holds_it():
    path = FIXTURES / "series.txt"
    lines = path.read_text().splitlines()
    snapshots = read_custom_dump(path)
    assert [(s.step, len(s)) for s in snapshots] == [(0, 0), (750, 40), (1500, 40)]
    header = lines.index("ITEM: TIMESTEP", 1)  # the second snapshot's
    assert lines[header + 1] == "750" and lines[header + 8] == "ITEM: ATOMS id type x y z vx vy vz radius "
    table = np.loadtxt(lines[header + 9 : header + 9 + 40])
    middle = snapshots[1]
    assert middle.columns == ("id", "type", "x", "y", "z", "vx", "vy", "vz", "radius")
    np.testing.assert_array_equal(middle.arrays["id"], table[:, 0])
    np.testing.assert_array_equal(middle.arrays["type"], table[:, 1])
    np.testing.assert_array_equal(middle.arrays["points"], table[:, 2:5])
    np.testing.assert_array_equal(middle.arrays["v"], table[:, 5:8])
    np.testing.assert_array_equal(middle.arrays["radius"], table[:, 8])
    np.testing.assert_array_equal(middle.box_bounds, [[-0.01, 0.01], [-0.01, 0.01], [0.0, 0.03]])


def test_read_frames_reads_a_folder_of_text_dumps_and_a_vtk_name_without_a_step(tmp_path, binary):
    for name in ("spheres_1500.txt", "spheres_nomass_1500.txt", "empty_0.txt"):
        shutil.copy(FIXTURES / name, tmp_path / name)
    shutil.copy(FIXTURES / "empty_0.txt", tmp_path / "spheres_0.txt")
    frames = read_frames(tmp_path, "spheres", TIMESTEP, suffix=".txt")
    assert [(f.step, len(f)) for f in frames] == [(0, 0), (1500, 40)]
    # LIGGGHTS' "dump*.vtk" names a file dump1500.vtk: no underscore before the step, which is then passed
    renamed = tmp_path / "dump1500.vtk"
    shutil.copy(FIXTURES / "spheres_binary_1500.vtk", renamed)
    with pytest.raises(ValueError, match=r"dump1500\.vtk: file name does not end in _<step> \(a legacy VTK dump holds "
                                         r"no step: pass it\)"):
        read_frame(renamed, TIMESTEP)
    assert_same_frame(read_frame(renamed, TIMESTEP, step=1500), binary)
