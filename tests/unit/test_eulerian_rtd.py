"""Exact answers for the Eulerian RTD: bins, bin velocities, inlet region, residence times."""

import numpy as np
import pytest

from siloflow.analysis.numerics.eulerian_rtd import bin_velocity_series, eulerian_residence_times, inlet_bins, silo_bins


def test_silo_bins_tile_the_silo_exactly():
    grid = silo_bins(width=0.15, depth=0.012, top=0.1, bin_size=0.01)
    assert grid.shape == (15, 1, 10)
    np.testing.assert_allclose(grid.origin, (-0.075, 0.0, 0.0))
    np.testing.assert_allclose(grid.spacing, (0.01, 0.012, 0.01))
    stretched = silo_bins(width=0.1, depth=0.004, top=0.1, bin_size=0.015)
    assert stretched.shape == (7, 1, 7)
    np.testing.assert_allclose(stretched.spacing[0] * 7, 0.1)


def test_bin_velocity_is_the_mass_weighted_mean_and_empty_bins_take_their_time_mean():
    grid = silo_bins(width=0.02, depth=0.01, top=0.01, bin_size=0.01)  # two bins: x < 0 and x > 0
    positions = np.array(
        [
            [[-0.005, 0.005, 0.005], [-0.004, 0.005, 0.005], [0.005, 0.005, 0.005]],
            [[-0.005, 0.005, 0.005], [np.nan] * 3, [0.5, 0.0, 0.0]],  # clump 2 outside the bins
        ]
    )
    velocities = np.array(
        [
            [[0.0, 0.0, -1.0], [0.0, 0.0, -4.0], [1.0, 0.0, 0.0]],
            [[0.0, 0.0, -2.0], [np.nan] * 3, [9.0, 9.0, 9.0]],
        ]
    )
    masses = np.array([1.0, 2.0, 3.0])
    velocity, occupied = bin_velocity_series(positions, velocities, masses, grid)
    assert velocity.shape == (2, 2, 1, 1, 3)
    np.testing.assert_array_equal(occupied[:, :, 0, 0], [[True, True], [True, False]])
    np.testing.assert_allclose(velocity[0, 0, 0, 0], [0.0, 0.0, -3.0])  # (1 * -1 + 2 * -4) / 3
    np.testing.assert_allclose(velocity[1, 0, 0, 0], [0.0, 0.0, -2.0])
    np.testing.assert_allclose(velocity[0, 1, 0, 0], [1.0, 0.0, 0.0])
    # Empty at t1: its mass-weighted mean over time (only t0 had clumps).
    np.testing.assert_allclose(velocity[1, 1, 0, 0], [1.0, 0.0, 0.0])


def test_never_occupied_bins_have_zero_velocity():
    grid = silo_bins(width=0.02, depth=0.01, top=0.01, bin_size=0.01)
    positions = np.array([[[-0.005, 0.005, 0.005]]])
    velocity, occupied = bin_velocity_series(positions, np.array([[[0.0, 0.0, -1.0]]]), [1.0], grid)
    np.testing.assert_array_equal(velocity[0, 1, 0, 0], [0.0, 0.0, 0.0])
    assert not occupied[0, 1, 0, 0]


def test_bad_inputs_are_named():
    grid = silo_bins(width=0.02, depth=0.01, top=0.01, bin_size=0.01)
    with pytest.raises(ValueError, match="masses"):
        bin_velocity_series(np.zeros((1, 2, 3)), np.zeros((1, 2, 3)), [1.0, 0.0], grid)
    with pytest.raises(ValueError, match="velocities"):
        bin_velocity_series(np.zeros((1, 2, 3)), np.zeros((1, 3, 3)), [1.0, 1.0], grid)
    with pytest.raises(ValueError, match="bin_size"):
        silo_bins(0.1, 0.01, 0.1, 0.0)


def test_inlet_bins_are_the_top_row_over_the_inlet_width():
    grid = silo_bins(width=0.15, depth=0.012, top=0.1, bin_size=0.01)
    lower, upper = inlet_bins(grid, inlet_width=0.04)
    # Centres are -0.07 + 0.01 i: the five at -0.02 ... 0.02 lie within |x| <= 0.02 (edges included).
    np.testing.assert_allclose(lower, [-0.025, 0.0, 0.09])
    np.testing.assert_allclose(upper, [0.025, 0.012, 0.1])
    narrow_lower, narrow_upper = inlet_bins(grid, inlet_width=0.001)
    np.testing.assert_allclose([narrow_lower[0], narrow_upper[0]], [-0.005, 0.005])


def test_uniform_downflow_gives_height_over_speed_for_every_tracer():
    # Every clump moves down at 0.5 m/s: the bins all carry v = (0, 0, -0.5), so a tracer released at
    # the centre height of the top row, z = 0.095, crosses z = 0 after 0.19 s exactly.
    grid = silo_bins(width=0.04, depth=0.01, top=0.1, bin_size=0.01)
    x = (np.arange(4) + 0.5) * 0.01 - 0.02
    z = (np.arange(10) + 0.5) * 0.01
    xx, zz = np.meshgrid(x, z, indexing="ij")
    centres = np.stack([xx.ravel(), np.full(xx.size, 0.005), zz.ravel()], axis=1)
    times = np.array([0.0, 1.0])
    positions = np.stack([centres, centres])
    velocities = np.tile([0.0, 0.0, -0.5], (2, centres.shape[0], 1))
    result = eulerian_residence_times(
        times, positions, velocities, np.ones(centres.shape[0]), grid, inlet_width=0.02, n_tracers=8,
        release_time=0.0, dt=0.001, max_time=1.0,
    )
    assert result.seeds.shape[0] >= 1
    np.testing.assert_allclose(result.residence_time, (result.seeds[:, 2] - 0.0) / 0.5, rtol=1e-12)
    assert np.all(result.seeds[:, 2] > 0.09) and np.all(np.abs(result.seeds[:, 0]) < 0.02)
