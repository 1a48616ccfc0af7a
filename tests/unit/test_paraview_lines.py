"""Lines and walls of a run for ParaView, read back with pyvista: pathlines (one polyline per tracer, with its
residence time), the recirculating silo's tracks cut into passes (siloflow.analysis.studies.silo_recirculation.pass_paths),
force chains (one two-point line per contact, with its normal force) and the wall meshes of a case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.io.vtk_lines import (
    write_force_chains_vtp,
    write_pass_paths_vtp,
    write_pathlines_vtp,
    write_polylines_vtp,
)
from siloflow.analysis.io.vtk_walls import write_walls_vtp
from siloflow.analysis.numerics.clump_tracks import ClumpTracks, TrackedClumps
from siloflow.analysis.numerics.exit_times import outlet_exits
from siloflow.analysis.numerics.force_chains import force_chain_segments
from siloflow.analysis.numerics.pathlines import EXITED, NOT_EXITED, OUTSIDE, PathlineResult, integrate_pathlines
from siloflow.analysis.studies.silo_recirculation.pass_paths import pass_paths
from siloflow.model.cases.geometry import horizontal_rectangle, vertical_rectangle_x
from siloflow.model.cases.kinds import CASE_KINDS
from siloflow.model.cases.silo_flat import silo_meshes
from siloflow.model.contacts import ContactFrame

pyvista = pytest.importorskip("pyvista")


def cells_of(data) -> list[list[int]]:
    """The point indices of each line cell."""
    return [list(data.get_cell(i).point_ids) for i in range(data.n_cells)]


# --------------------------------------------------------------------------- pathlines


def test_each_tracer_that_was_followed_is_one_line_ending_at_its_exit(tmp_path):
    nan = math.nan
    history = np.full((4, 3, 3), nan)
    history[:3, 0] = [[0.0, 0.5, 0.3], [0.01, 0.5, 0.2], [0.02, 0.5, 0.1]]  # left between records 2 and 3
    history[:, 1] = [[0.05, 0.5, 0.3], [0.05, 0.5, 0.29], [0.05, 0.5, 0.28], [0.05, 0.5, 0.27]]  # still in
    result = PathlineResult(
        residence_time=np.array([0.25, nan, nan]), exit_position=np.array([[0.025, 0.5, 0.0], [nan] * 3, [nan] * 3]),
        status=np.array([EXITED, NOT_EXITED, OUTSIDE], dtype=np.int8), n_steps=np.array([25, 30, 0]),
        t0=2.0, dt=0.01, method="rk2", outlet_z=0.0, max_time=0.3,
        history_time=np.array([2.0, 2.1, 2.2, 2.3]), history=history)

    data = pyvista.read(write_pathlines_vtp(tmp_path / "pathlines.vtp", result, plane_y=0.006))

    assert (data.n_cells, data.n_points, data.n_lines) == (2, 8, 2)  # the seed outside has no line
    assert cells_of(data) == [[0, 1, 2, 3], [4, 5, 6, 7]]
    expected = np.vstack([history[:3, 0], [[0.025, 0.5, 0.0]], history[:, 1]])
    expected[:, 1] = 0.006
    np.testing.assert_array_equal(data.points, expected)
    np.testing.assert_array_equal(data.point_data["time"], [2.0, 2.1, 2.2, 2.25, 2.0, 2.1, 2.2, 2.3])
    np.testing.assert_array_equal(data.cell_data["tracer"], [0, 1])
    np.testing.assert_array_equal(data.cell_data["residence_time"], [0.25, nan])
    np.testing.assert_array_equal(data.cell_data["status"], [EXITED, NOT_EXITED])
    assert {name: data.field_data[name][0] for name in ("t0", "dt", "max_time", "outlet_z")} == {
        "t0": 2.0, "dt": 0.01, "max_time": 0.3, "outlet_z": 0.0}


def test_integrated_pathlines_keep_their_recorded_points(tmp_path):
    # a uniform downward field of 1 m/s: a tracer from z = 0.05 leaves after 0.05 s
    velocity = np.zeros((1, 2, 2, 2, 3))
    velocity[..., 2] = -1.0
    result = integrate_pathlines([[0.0, 0.0, 0.05], [0.01, 0.0, 0.03]], 0.0, velocity, [0.0], (-0.1, -0.1, -0.1),
                                 0.1, 0.005, 0.0, 0.2, record_every=2)
    data = pyvista.read(write_pathlines_vtp(tmp_path / "pathlines.vtp", result))
    assert data.n_cells == 2
    counts = [len(cell) for cell in cells_of(data)]
    assert counts == [int(np.isfinite(result.history[:, i, 2]).sum()) + 1 for i in range(2)]
    np.testing.assert_allclose(data.cell_data["residence_time"], [0.05, 0.03], rtol=1e-9)
    assert data.points[counts[0] - 1, 2] == pytest.approx(0.0, abs=1e-12)  # the first line ends on the outlet


def test_a_result_without_paths_is_refused(tmp_path):
    velocity = np.zeros((1, 2, 2, 2, 3))
    velocity[..., 2] = -1.0
    result = integrate_pathlines([[0.0, 0.0, 0.05]], 0.0, velocity, [0.0], (-0.1, -0.1, -0.1), 0.1, 0.005, 0.0, 0.2)
    with pytest.raises(ValueError, match="record_every"):
        write_pathlines_vtp(tmp_path / "pathlines.vtp", result)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("offsets", [[0, 2], [1, 3], [0, 3, 3], [0.0, 3.0]])
def test_lines_must_cover_the_points_each_with_a_point(tmp_path, offsets):
    with pytest.raises(ValueError, match="offsets"):
        write_polylines_vtp(tmp_path / "lines.vtp", np.zeros((3, 3)), offsets)


# --------------------------------------------------------------------------- tracks cut into passes


def recirculating_tracks() -> TrackedClumps:
    """Two clumps over six frames in a domain periodic in z between -0.1 and 0.2 m, the outlet at 0: clump 7
    leaves, re-enters at the top between frames 2 and 3 and leaves again; clump 9 stays, absent from frame 2."""
    nan = math.nan
    z = np.array([[0.15, 0.1], [0.05, 0.1], [-0.05, nan], [0.18, 0.1], [0.08, 0.1], [-0.02, 0.1]])
    position = np.zeros((6, 2, 3))
    position[..., 0] = [[0.01, -0.02]] * 6
    position[..., 2] = z
    position[2, 1] = nan
    velocity = np.zeros_like(position)
    velocity[..., 2] = -1.0
    velocity[2, 1] = nan
    tracks = ClumpTracks(times=np.arange(6) * 0.1, clump_id=np.array([7, 9]), position=position)
    return TrackedClumps(tracks=tracks, velocity=velocity, mass=np.array([1e-5, 1e-5]))


def test_a_clump_track_is_cut_where_it_re_enters_at_the_top():
    recorded = recirculating_tracks()
    paths = pass_paths(recorded, 0.0, -0.1, 0.2)
    events = outlet_exits(recorded.tracks, 0.0, (-0.1, 0.2))

    assert paths.n_passes == 3
    np.testing.assert_array_equal(paths.offsets, [0, 3, 6, 11])
    np.testing.assert_array_equal(paths.clump_id, [7, 7, 9])
    np.testing.assert_array_equal(paths.pass_number, [0, 1, 0])
    np.testing.assert_array_equal(paths.time, np.array([0, 1, 2, 3, 4, 5, 0, 1, 3, 4, 5]) * 0.1)
    np.testing.assert_array_equal(paths.position[:6, 2], recorded.tracks.position[:, 0, 2])
    np.testing.assert_array_equal(paths.position[6:, 2], [0.1] * 5)  # the absent frame is left out
    np.testing.assert_array_equal(paths.entry_time, events.entry_time)
    np.testing.assert_array_equal(paths.exit_time, events.exit_time)
    assert paths.entry_time[1] == pytest.approx(0.2 + 0.1 * 0.05 / 0.07)  # the wrap, between frames 2 and 3
    assert paths.exit_time[0] == pytest.approx(0.15) and paths.exit_time[1] == pytest.approx(0.48)
    assert paths.residence_time[1] == pytest.approx(0.48 - paths.entry_time[1])
    assert np.isnan(paths.residence_time[0]) and np.isnan(paths.residence_time[2])


def test_passes_read_back_as_one_line_each_with_their_times(tmp_path):
    paths = pass_paths(recirculating_tracks(), 0.0, -0.1, 0.2)
    data = pyvista.read(write_pass_paths_vtp(tmp_path / "tracks.vtp", paths))

    assert (data.n_cells, data.n_points) == (3, 11)
    assert cells_of(data) == [[0, 1, 2], [3, 4, 5], [6, 7, 8, 9, 10]]
    # float32, as tracks.npz stores them: nothing lost
    np.testing.assert_array_equal(data.points, paths.position.astype(np.float32))
    np.testing.assert_array_equal(data.point_data["time"], paths.time)
    np.testing.assert_array_equal(data.point_data["velocity"], paths.velocity.astype(np.float32))
    np.testing.assert_array_equal(data.point_data["speed"], np.ones(11, dtype=np.float32))
    for name in ("clump_id", "pass_number", "entry_time", "exit_time", "residence_time"):
        np.testing.assert_array_equal(data.cell_data[name], getattr(paths, name), err_msg=name)


# --------------------------------------------------------------------------- force chains


def contacts() -> ContactFrame:
    position_i = np.array([[0.0, 0.002, 0.01], [0.003, 0.002, 0.01], [0.0, 0.011, 0.02]])
    position_j = position_i + np.array([[0.003, 0.0, 0.0], [0.0, 0.0, 0.003], [0.0, 0.0, -0.003]])
    # force on i by j: pushing i away from j is compression
    force = np.array([[-0.02, 0.0, 0.0], [0.0, 0.0, -0.5], [0.0, 0.0, -0.01]])  # the third pulls: tension
    return ContactFrame(step=68275, position_i=position_i, position_j=position_j, id_i=np.array([1, 2, 3]),
                        id_j=np.array([2, 4, 5]), force=force)


def test_every_contact_is_a_line_carrying_its_normal_force(tmp_path):
    segments = force_chain_segments(contacts(), 0.0, math.inf, math.inf)
    data = pyvista.read(write_force_chains_vtp(tmp_path / "force_chains.vtp", segments))

    assert (data.n_cells, data.n_points, data.n_lines) == (3, 6, 3)
    assert cells_of(data) == [[0, 1], [2, 3], [4, 5]]
    np.testing.assert_array_equal(data.points[0::2], contacts().position_i)
    np.testing.assert_array_equal(data.points[1::2], contacts().position_j)
    np.testing.assert_allclose(data.cell_data["normal_force"], [0.02, 0.5, 0.0], rtol=1e-12)  # tension: 0
    assert "cap" not in data.field_data


def test_a_slice_and_cap_of_the_chains_are_kept(tmp_path):
    segments = force_chain_segments(contacts(), 0.002, 0.004, 0.1)
    data = pyvista.read(write_force_chains_vtp(tmp_path / "force_chains.vtp", segments))
    assert data.n_cells == 2
    np.testing.assert_allclose(data.cell_data["normal_force"], [0.02, 0.1], rtol=1e-12)
    assert data.field_data["cap"][0] == 0.1


# --------------------------------------------------------------------------- walls


def test_the_walls_are_one_file_with_each_face_naming_its_wall(tmp_path):
    meshes = {"floor": horizontal_rectangle(-0.05, 0.05, 0.0, 0.012, 0.0),
              "channel_left": vertical_rectangle_x(-0.015, 0.0, 0.012, -0.08, 0.0, normal=1)}
    data = pyvista.read(write_walls_vtp(tmp_path / "walls.vtp", meshes))

    assert (data.n_cells, data.n_points) == (4, 8)
    assert all(data.get_cell(i).type == pyvista.CellType.TRIANGLE for i in range(4))
    np.testing.assert_array_equal(data.points, np.vstack([m.vertices for m in meshes.values()]))
    np.testing.assert_array_equal(data.cell_data["wall"], [0, 0, 1, 1])
    assert list(data.field_data["wall_names"]) == ["floor", "channel_left"]
    np.testing.assert_array_equal(data.faces.reshape(-1, 4)[:, 1:],
                                  np.vstack([meshes["floor"].faces, meshes["channel_left"].faces + 4]))


def test_the_registry_gives_each_silo_type_kind_its_walls():
    assert CASE_KINDS["silo_flat"].walls is silo_meshes
    assert all(CASE_KINDS[kind].walls is not None for kind in ("silo_flat", "silo_recirculation", "blender"))
