"""Silo field analysis on synthetic input with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from analysis.numerics.field_ops import depth_average
from analysis.data.frames import ClumpFrame
from analysis.numerics.janssen import janssen_vertical_stress
from analysis.studies.silo_flat.fields import (
    FieldSettings,
    analyse_profiles,
    centreline_velocity,
    clump_fields,
    compare_janssen,
    profile_mass_flow_rate,
    silo_grid,
)


def test_grid_tiles_the_silo_and_rounds_the_top_up_to_whole_cells():
    grid = silo_grid(0.15, 0.012, 0.1, (0.006, 0.004, 0.006))
    assert grid.shape == (25, 3, 17)
    np.testing.assert_allclose(grid.lower, [-0.075, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(grid.upper, [0.075, 0.012, 0.102], rtol=1e-12)


def _lattice_frame(width, depth, height, spacing, mass, velocity):
    xs = -width / 2 + spacing * (np.arange(round(width / spacing)) + 0.5)
    ys = spacing * (np.arange(round(depth / spacing)) + 0.5)
    zs = spacing * (np.arange(round(height / spacing)) + 0.5)
    position = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    below = position.copy()[:5]
    below[:, 2] = -0.01  # discharged clumps below the outlet are not part of the silo's fields
    position = np.vstack([position, below])
    n = len(position)
    return ClumpFrame(time=0.0, step=0, clump_id=np.arange(1, n + 1), position=position,
                      velocity=np.tile(velocity, (n, 1)), mass=np.full(n, mass), n_spheres=np.full(n, 2))


def test_uniform_downflow_gives_the_exact_profile_flow_rate():
    width, depth, height, spacing, mass, speed = 0.06, 0.012, 0.06, 0.002, 1e-5, 0.1
    frame = _lattice_frame(width, depth, height, spacing, mass, (0.0, 0.0, -speed))
    grid = silo_grid(width, depth, height, (0.006, 0.004, 0.006))
    settings = FieldSettings((0.006, 0.004, 0.006), "gaussian", 0.003, 3.0)
    fields = clump_fields(frame, grid, settings)
    inside_mass = mass * (len(frame.clump_id) - 5)
    assert fields.total_mass == pytest.approx(inside_mass, rel=1e-12)
    averaged = depth_average(fields)
    rho = mass / spacing**3
    expected = rho * width * depth * speed
    assert profile_mass_flow_rate(averaged, 0.03, depth) == pytest.approx(expected, rel=1e-9)
    assert centreline_velocity([averaged], [0.03])[0, 0] == pytest.approx(-speed, rel=1e-12)


def test_gaussian_profile_gives_back_B_and_the_flow_channel_boundary():
    B, A = 0.002, 0.2
    x = np.linspace(-0.075, 0.075, 51)
    z = np.array([0.02, 0.04, 0.08])
    v_z = np.array([[-A * math.exp(-xi**2 / (4 * B * zi)) for zi in z] for xi in x])
    analysis = analyse_profiles((x, z, np.zeros_like(v_z), v_z), heights=z, fractions=(0.1,))
    np.testing.assert_allclose(analysis.kinematic_B, B, rtol=0.01)
    cell = x[1] - x[0]
    for i, zi in enumerate(z):
        expected = math.sqrt(-4 * B * zi * math.log(0.1))
        assert abs(analysis.fcb_right[i, 0] - expected) <= cell
        assert abs(analysis.fcb_left[i, 0] + expected) <= cell
    # u = -B dv_z/dx points towards the axis on both sides for downward flow
    assert np.all(analysis.kinematic_u[:, x < -0.01] > 0) and np.all(analysis.kinematic_u[:, x > 0.01] < 0)


def test_janssen_comparison_of_a_janssen_stress_field_is_exact():
    grid = silo_grid(0.15, 0.04, 0.3, (0.006, 0.004, 0.006))
    surface = 0.27
    h = np.clip(surface - grid.z, 0.0, None)
    sigma = janssen_vertical_stress(h, 667.0, 0.15, 0.04, 0.17, 0.2, 30.0)
    stress = np.zeros(grid.shape + (3, 3))
    stress[..., 2, 2] = np.broadcast_to(sigma, grid.shape)
    comparison = compare_janssen(stress, grid, surface, 667.0, 0.15, 0.04, 0.17, 0.2, 30.0, margin=0.01)
    np.testing.assert_allclose(comparison.simulated, comparison.janssen, rtol=1e-12)
    assert comparison.depth_below_surface.min() > 0.01 - 1e-12
