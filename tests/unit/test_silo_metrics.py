"""Silo discharge metrics on synthetic clump frames with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from analysis.data.frames import ClumpFrame
from analysis.studies.silo_flat.metrics import EscapedParticles, flow_table_row, silo_flow_metrics, vanished_above_outlet

SPACING = 0.004  # m, simple cubic lattice
WIDTH, DEPTH, LAYERS = 0.08, 0.012, 10
CLUMP_MASS = 2.0e-5  # kg
RATE = 6  # clumps discharged per frame
FRAME_INTERVAL = 0.01  # s


def _lattice():
    xs = -WIDTH / 2 + SPACING * (np.arange(round(WIDTH / SPACING)) + 0.5)
    ys = SPACING * (np.arange(round(DEPTH / SPACING)) + 0.5)
    zs = SPACING * (np.arange(LAYERS) + 0.5)
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    # discharge from the top down so that the surface stays level and the remaining fill is a lattice
    return grid[np.lexsort((grid[:, 0], grid[:, 1], -grid[:, 2]))]


def _frames(n_frames, escape_at=None):
    settled = _lattice()
    n = len(settled)
    frames = []
    for k in range(n_frames):
        position = settled.copy()
        position[: k * RATE, 2] = -0.01  # discharged: below the outlet plane, still in the domain
        ids = np.arange(1, n + 1)
        if escape_at is not None and k >= escape_at:
            keep = ids != n  # the last clump (bottom layer, inside the silo) vanishes
            ids, position = ids[keep], position[keep]
        frames.append(
            ClumpFrame(
                time=0.5 + k * FRAME_INTERVAL,
                step=1000 * k,
                clump_id=ids,
                position=position,
                velocity=np.zeros_like(position),
                mass=np.full(len(ids), CLUMP_MASS),
                n_spheres=np.full(len(ids), 2),
            )
        )
    return frames


def test_constant_discharge_gives_the_exact_rate_density_and_beverloo():
    diameter = 0.005  # z_m = 9.5 a - 2 d = 7 a: the control volume ends between two lattice layers
    metrics = silo_flow_metrics(_frames(40), WIDTH, DEPTH, outlet_width=0.03, particle_diameter=diameter)
    assert metrics.bulk_density.density == pytest.approx(CLUMP_MASS / SPACING**3, rel=1e-12)
    assert metrics.bulk_density.measured_height == pytest.approx(7 * SPACING, rel=1e-12)
    assert metrics.fit.mass_flow_rate == pytest.approx(RATE * CLUMP_MASS / FRAME_INTERVAL, rel=1e-9)
    assert metrics.fit.standard_error == pytest.approx(0.0, abs=1e-12)
    assert metrics.initial_mass == pytest.approx(len(_lattice()) * CLUMP_MASS, rel=1e-12)
    rho = CLUMP_MASS / SPACING**3
    beverloo = 0.58 * rho * math.sqrt(9.81) * DEPTH * (0.03 - 1.5 * diameter) ** 1.5
    assert metrics.beverloo_rate == pytest.approx(beverloo, rel=1e-12)
    assert metrics.beverloo_ratio == pytest.approx(metrics.fit.mass_flow_rate / beverloo, rel=1e-12)
    assert metrics.volumetric_flow_rate == pytest.approx(metrics.fit.mass_flow_rate / rho, rel=1e-12)
    row = flow_table_row("sphere2-abc", "sphere2", 600, metrics)
    assert row["mass_flow_rate_kg_s"] == metrics.fit.mass_flow_rate
    assert row["discharged_mass_kg"] == pytest.approx(39 * RATE * CLUMP_MASS, rel=1e-12)


def test_history_time_starts_at_opening():
    metrics = silo_flow_metrics(_frames(5), WIDTH, DEPTH, 0.03, 0.005, steady_window=(0.0, 1.0))
    np.testing.assert_allclose(metrics.history.time, FRAME_INTERVAL * np.arange(5), rtol=0, atol=1e-15)
    np.testing.assert_allclose(metrics.history.discharged_mass, RATE * CLUMP_MASS * np.arange(5), rtol=1e-12)


def test_a_clump_vanishing_inside_the_silo_is_an_escape():
    with pytest.raises(EscapedParticles, match=r"1 clumps vanished above the outlet plane between t = 0.53 s and t = 0.54 s"):
        silo_flow_metrics(_frames(10, escape_at=4), WIDTH, DEPTH, 0.03, 0.005)


def test_vanished_above_outlet_ignores_clumps_that_left_below_it():
    gone = vanished_above_outlet([1, 2, 3, 4], [0.1, -0.01, 0.0, 0.2], [1])
    assert gone.tolist() == [3, 4]


def test_a_single_frame_is_not_a_discharge():
    with pytest.raises(ValueError, match="at least two frames"):
        silo_flow_metrics(_frames(1), WIDTH, DEPTH, 0.03, 0.005)
