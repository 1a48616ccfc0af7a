"""Exact answers for the blender's window-averaged fields and discharged mass."""

import numpy as np
import pytest

from siloflow.analysis.numerics.grid import Grid
from siloflow.analysis.studies.blender.window_fields import (
    PlanarField,
    discharged_mass_history,
    frame_fields,
    frames_in_window,
    WALL_LAYER_DIAMETERS,
    mean_velocity_history,
    wall_layer_depth,
    wall_layer_positions,
    window_average_field,
)
from siloflow.analysis.studies.blender.window_fields_io import (
    read_frame_fields,
    read_planar_fields,
    read_wall_layer_fields,
    write_frame_fields,
    write_planar_fields,
    write_wall_layer_fields,
)
from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.numerics.eulerian_rtd import silo_bins


def test_frames_in_window_selects_inclusive_bounds_and_names_an_empty_window():
    times = np.array([0.0, 0.1, 0.2, 0.3])
    np.testing.assert_array_equal(frames_in_window(times, (0.1, 0.2)), [1, 2])
    with pytest.raises(ValueError, match="no frame"):
        frames_in_window(times, (0.31, 0.4))
    with pytest.raises(ValueError, match="increasing"):
        frames_in_window(times, (0.2, 0.1))


def test_window_average_pools_clumps_of_all_frames_mass_weighted():
    # Two bins 0.01 m wide (x < 0, x > 0), one row 0.01 m high, depth 0.01 m: bin volume 1e-6 m^3.
    grid = silo_bins(width=0.02, depth=0.01, top=0.01, bin_size=0.01)
    positions = np.array([
        [[-0.005, 0.005, 0.005], [0.005, 0.005, 0.005]],
        [[-0.005, 0.005, 0.005], [np.nan] * 3],          # clump 1 absent
        [[0.5, 0.0, 0.0], [0.005, 0.005, 0.005]],         # clump 0 outside the bins; frame outside the window
    ])
    velocities = np.array([
        [[0.0, 0.0, -1.0], [2.0, 0.0, -2.0]],
        [[0.0, 0.0, -4.0], [np.nan] * 3],
        [[9.0, 9.0, 9.0], [9.0, 9.0, 9.0]],
    ])
    masses = np.array([1.0e-3, 3.0e-3])
    field = window_average_field(positions, velocities, masses, [0.0, 0.1, 0.2], grid, (0.0, 0.1), 1000.0)
    assert field.n_frames == 2 and field.window == (0.0, 0.1)
    np.testing.assert_allclose(field.x, [-0.005, 0.005])
    np.testing.assert_allclose(field.z, [0.005])
    np.testing.assert_allclose(field.v_z[:, 0], [-2.5, -2.0])   # (-1 - 4) / 2 with equal masses
    np.testing.assert_allclose(field.v_x[:, 0], [0.0, 2.0])
    # solid fraction: mean mass per frame / (rho V): left (1 + 1) g / 2 / (1000 * 1e-6) = 1.0, right 3 g / 2 / 1e-3
    np.testing.assert_allclose(field.solid_fraction[:, 0], [1.0, 1.5])


def test_frame_fields_give_each_frame_of_the_window_alone():
    grid = silo_bins(width=0.02, depth=0.01, top=0.01, bin_size=0.01)
    positions = np.array([
        [[-0.005, 0.005, 0.005], [0.005, 0.005, 0.005]],
        [[-0.005, 0.005, 0.005], [np.nan] * 3],          # clump 1 absent
        [[0.5, 0.0, 0.0], [0.005, 0.005, 0.005]],         # frame outside the window
    ])
    velocities = np.array([
        [[0.0, 0.0, -1.0], [2.0, 0.0, -2.0]],
        [[0.0, 0.0, -4.0], [np.nan] * 3],
        [[9.0, 9.0, 9.0], [9.0, 9.0, 9.0]],
    ])
    first, second = frame_fields(positions, velocities, [1.0e-3, 3.0e-3], [0.0, 0.1, 0.2], grid, (0.0, 0.1), 1000.0)
    assert (first.window, first.n_frames, second.window, second.n_frames) == ((0.0, 0.0), 1, (0.1, 0.1), 1)
    np.testing.assert_allclose(first.v_z[:, 0], [-1.0, -2.0])
    np.testing.assert_allclose(first.v_x[:, 0], [0.0, 2.0])
    np.testing.assert_allclose(second.v_z[:, 0], [-4.0, np.nan])
    # solid fraction of one frame: 1 g / (1000 kg/m^3 x 1e-6 m^3) = 1.0, 3 g: 3.0; the empty bin 0
    np.testing.assert_allclose(first.solid_fraction[:, 0], [1.0, 3.0])
    np.testing.assert_allclose(second.solid_fraction[:, 0], [1.0, 0.0])
    with pytest.raises(ValueError, match="no frame"):
        frame_fields(positions, velocities, [1.0e-3, 3.0e-3], [0.0, 0.1, 0.2], grid, (0.3, 0.4), 1000.0)


def test_a_bin_no_clump_entered_is_nan_and_a_grid_with_depth_bins_is_refused():
    grid = silo_bins(width=0.02, depth=0.01, top=0.01, bin_size=0.01)
    positions = np.array([[[-0.005, 0.005, 0.005]]])
    field = window_average_field(positions, np.zeros((1, 1, 3)), [1.0], [0.0, ], grid, (0.0, 1.0), 1000.0)
    assert np.isnan(field.v_z[1, 0]) and field.solid_fraction[1, 0] == 0.0
    with pytest.raises(ValueError, match="one bin across the depth"):
        window_average_field(positions, np.zeros((1, 1, 3)), [1.0], [0.0], Grid(origin=(0, 0, 0), spacing=(0.01, 0.005, 0.01), shape=(2, 2, 1)),
                             (0.0, 1.0), 1000.0)


def test_batch_discharged_mass_is_the_loss_of_mass_above_the_outlet():
    times = np.array([0.0, 1.0, 2.0])
    position = np.full((3, 3, 3), np.nan)
    position[:, :, 2] = [[0.1, 0.2, 0.3], [-0.01, 0.1, 0.2], [np.nan, np.nan, 0.05]]
    tracks = ClumpTracks(times=times, clump_id=np.arange(3), position=position)
    time, discharged = discharged_mass_history(tracks, [1.0, 2.0, 4.0], "batch")
    np.testing.assert_allclose(time, times)
    np.testing.assert_allclose(discharged, [0.0, 1.0, 3.0])


def test_continuous_discharged_mass_counts_outlet_crossings():
    # One clump falling at 1 m/s through the outlet (z = 0) of a domain periodic in [-0.1, 0.9]: it crosses at
    # t = 0.5 and again one domain height (1 s) later.
    times = np.arange(0.0, 2.01, 0.05)
    z = 0.5 - times
    wrapped = (z + 0.1) % 1.0 - 0.1
    position = np.zeros((times.size, 1, 3))
    position[:, 0, 2] = wrapped
    tracks = ClumpTracks(times=times, clump_id=np.array([7]), position=position)
    _, discharged = discharged_mass_history(tracks, [2.0], "continuous", 0.0, (-0.1, 0.9))
    expected = 2.0 * ((times >= 0.5 - 1e-9).astype(float) + (times >= 1.5 - 1e-9))
    np.testing.assert_allclose(discharged, expected)
    with pytest.raises(ValueError, match="domain_z"):
        discharged_mass_history(tracks, [2.0], "continuous")
    with pytest.raises(ValueError, match="mode"):
        discharged_mass_history(tracks, [2.0], "steady")


def test_planar_fields_round_trip(tmp_path):
    def field(value, window):
        return PlanarField(x=np.array([-0.5, 0.5]), z=np.array([0.1, 0.2, 0.3]), v_x=np.full((2, 3), value),
                           v_z=np.arange(6.0).reshape(2, 3) * value, solid_fraction=np.full((2, 3), 0.6),
                           window=window, n_frames=3)

    steady, windows = field(1.0, (1.0, 2.0)), [field(2.0, (0.0, 1.0)), field(3.0, (1.0, 2.0))]
    path = write_planar_fields(tmp_path / "fields.npz", steady, windows)
    loaded, loaded_windows = read_planar_fields(path)
    np.testing.assert_array_equal(loaded.v_z, steady.v_z)
    assert loaded.window == (1.0, 2.0) and len(loaded_windows) == 2
    np.testing.assert_array_equal(loaded_windows[1].v_x, windows[1].v_x)
    # frame fields: the same store without a steady field
    frames = read_frame_fields(write_frame_fields(tmp_path / "frames.npz", windows))
    assert [f.window for f in frames] == [(0.0, 1.0), (1.0, 2.0)] and [f.n_frames for f in frames] == [3, 3]
    np.testing.assert_array_equal(frames[0].v_z, windows[0].v_z)
    other = PlanarField(x=np.array([0.5]), z=np.array([0.1]), v_x=np.zeros((1, 1)), v_z=np.zeros((1, 1)),
                        solid_fraction=np.ones((1, 1)), window=(0.0, 0.0), n_frames=1)
    with pytest.raises(ValueError, match="same bins"):
        write_frame_fields(tmp_path / "bad.npz", [windows[0], other])
    with pytest.raises(ValueError, match="steady field"):
        write_planar_fields(tmp_path / "bad.npz", steady, [other])
    with pytest.raises(ValueError, match="at least one"):
        write_frame_fields(tmp_path / "bad.npz", [])
    assert not (tmp_path / "bad.npz").exists()


def test_mean_velocity_history_weights_the_clumps_above_the_outlet_by_mass():
    times = np.array([0.0, 1.0])
    position = np.zeros((2, 3, 3))
    position[:, :, 2] = [[0.1, 0.2, -0.01], [np.nan, 0.1, 0.3]]
    velocity = np.zeros((2, 3, 3))
    velocity[:, :, 2] = [[-1.0, -2.0, -9.0], [-5.0, -0.5, -1.0]]
    tracks = ClumpTracks(times=times, clump_id=np.arange(3), position=position)
    history = mean_velocity_history(tracks, velocity, [1.0, 3.0, 2.0])
    # frame 0: clump 2 is below the outlet, (1 * -1 + 3 * -2) / 4; frame 1: clump 0 absent, (3 * -0.5 + 2 * -1) / 5
    np.testing.assert_allclose(history, [-1.75, -0.7])


def test_the_wall_layer_is_one_diameter_from_either_wall_folded_onto_the_front():
    assert WALL_LAYER_DIAMETERS == 1.0 and wall_layer_depth(0.0033) == 0.0033
    with pytest.raises(ValueError, match="equivalent_diameter"):
        wall_layer_depth(0.0)
    # depth 12 mm: y 1, 11 and 6 mm fold onto 1, 1 and 6 mm; x, z and an absent clump are kept
    positions = np.array([[[0.01, 0.001, 0.02], [-0.01, 0.011, 0.03], [0.0, 0.006, 0.04], [np.nan] * 3]])
    folded = wall_layer_positions(positions, 0.012)
    np.testing.assert_allclose(folded[0, :3], [[0.01, 0.001, 0.02], [-0.01, 0.001, 0.03], [0.0, 0.006, 0.04]],
                               rtol=0, atol=1e-15)
    assert np.isnan(folded[0, 3]).all() and positions[0, 1, 1] == 0.011  # a copy
    with pytest.raises(ValueError, match="last axis of 3"):
        wall_layer_positions(np.zeros((2, 2)), 0.012)
    # binned on a grid one layer (3.3 mm) deep: the front clump (-1 m/s) and the back one (-3 m/s) pool in the left
    # bin's layer; the mid-depth clump (6 mm from both walls) is left out of the right bin
    grid = silo_bins(width=0.04, depth=wall_layer_depth(0.0033), top=0.04, bin_size=0.02)
    positions = np.array([[[-0.01, 0.001, 0.01], [-0.01, 0.0115, 0.01], [0.01, 0.006, 0.01]]])
    velocities = np.array([[[0.0, 0.0, -1.0], [0.0, 0.0, -3.0], [0.0, 0.0, -7.0]]])
    field = window_average_field(wall_layer_positions(positions, 0.012), velocities, [1e-3, 1e-3, 1e-3], [0.0], grid,
                                 (0.0, 1.0), 1000.0)
    assert field.v_z[0, 0] == pytest.approx(-2.0) and np.isnan(field.v_z[1, 0])


def test_wall_layer_fields_round_trip(tmp_path):
    def field(value, window):
        return PlanarField(x=np.array([-0.5, 0.5]), z=np.array([0.1]), v_x=np.zeros((2, 1)),
                           v_z=np.full((2, 1), value), solid_fraction=np.full((2, 1), 0.5), window=window, n_frames=1)

    steady, frames = field(-1.0, (0.0, 0.2)), [field(-0.9, (0.0, 0.0)), field(-1.1, (0.2, 0.2))]
    loaded, loaded_frames = read_wall_layer_fields(write_wall_layer_fields(tmp_path / "wall_layer.npz", steady, frames))
    assert loaded.window == (0.0, 0.2) and [f.window for f in loaded_frames] == [(0.0, 0.0), (0.2, 0.2)]
    np.testing.assert_array_equal(loaded_frames[1].v_z, frames[1].v_z)
    with pytest.raises(ValueError, match="at least one"):
        write_wall_layer_fields(tmp_path / "bad.npz", steady, [])
    assert not (tmp_path / "bad.npz").exists()
