"""Silo discharge metrics on synthetic clump frames with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.model.frames import ClumpFrame
from siloflow.analysis.numerics.flow import DischargeHistory, steady_flow_rate
from siloflow.analysis.studies.silo_flat.metrics import (
    FLOW_RATE_BATCHES,
    SLAB_DIAMETERS,
    EscapedParticles,
    flow_table_row,
    silo_flow_metrics,
    steady_rate_estimate,
    vanished_above_outlet,
)

SPACING = 0.004  # m, simple cubic lattice
WIDTH, DEPTH, LAYERS = 0.08, 0.012, 10
CLUMP_MASS = 2.0e-5  # kg
RATE = 6  # clumps discharged per frame
FRAME_INTERVAL = 0.01  # s


def _lattice(layers=LAYERS):
    xs = -WIDTH / 2 + SPACING * (np.arange(round(WIDTH / SPACING)) + 0.5)
    ys = SPACING * (np.arange(round(DEPTH / SPACING)) + 0.5)
    zs = SPACING * (np.arange(layers) + 0.5)
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    # discharge from the top down so that the surface stays level and the remaining fill is a lattice
    return grid[np.lexsort((grid[:, 0], grid[:, 1], -grid[:, 2]))]


def _frames(n_frames, escape_at=None, layers=LAYERS):
    settled = _lattice(layers)
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
    # A constant discharge: every batch slope is the rate, no error. The 28 mm control volume is thinner than two
    # slabs of 4 d = 20 mm: the density's error, and with it those of the figures built on it, are unknown.
    assert metrics.rate_estimate.n == FLOW_RATE_BATCHES and row["mass_flow_rate_batches"] == 10
    assert row["mass_flow_rate_kg_s_error"] == pytest.approx(0.0, abs=1e-12)
    assert row["mass_flow_rate_stderr_kg_s"] == metrics.fit.standard_error  # the old key is kept
    assert row["filling_bulk_density_slabs"] == 1
    for key in ("filling_bulk_density_kg_m3_error", "volumetric_flow_rate_m3_s_error",
                "beverloo_mass_flow_rate_kg_s_error", "beverloo_ratio_error"):
        assert math.isnan(row[key]), key


def test_the_bulk_density_error_is_the_spread_over_slabs_and_carries_into_beverloo():
    # 30 layers: surface at the top centres 118 mm, z_m = 118 - 2 d = 108 mm = 27 a, cut into 5 slabs of
    # 21.6 mm = 5.4 a (at least 4 d = 20 mm) that hold 5, 6, 5, 6, 5 layers of the lattice
    diameter = 0.005
    metrics = silo_flow_metrics(_frames(40, layers=30), WIDTH, DEPTH, outlet_width=0.03, particle_diameter=diameter)
    rho = CLUMP_MASS / SPACING**3
    assert SLAB_DIAMETERS == 4 and metrics.density_estimate.n == 5
    assert metrics.bulk_density.density == pytest.approx(rho, rel=1e-12)
    assert metrics.density_estimate.value == pytest.approx(rho, rel=1e-12)
    error = rho / 5.4 * math.sqrt(0.3) / math.sqrt(5.0)  # std(5, 6, 5, 6, 5) = sqrt(0.3) layers
    assert metrics.bulk_density_error == pytest.approx(error, rel=1e-9)
    row = flow_table_row("sphere2-abc", "sphere2", 600, metrics)
    assert row["filling_bulk_density_kg_m3_error"] == metrics.bulk_density_error
    assert row["filling_bulk_density_slabs"] == 5
    # The flow rate has no error here, so the propagated ones are the density's relative error alone.
    relative = error / rho
    assert row["beverloo_mass_flow_rate_kg_s_error"] == pytest.approx(metrics.beverloo_rate * relative, rel=1e-9)
    assert row["beverloo_ratio_error"] == pytest.approx(metrics.beverloo_ratio * relative, rel=1e-6)
    assert row["volumetric_flow_rate_m3_s_error"] == pytest.approx(metrics.volumetric_flow_rate * relative, rel=1e-6)


def test_the_flow_rate_error_is_the_batch_means_error_of_the_steady_window():
    # slopes 1, 2, 3, 4 kg/s in four batches of three samples of the window t = 0 ... 11 s
    time = np.arange(12.0)
    mass = np.array([0.0, 1.0, 2.0, 10.0, 12.0, 14.0, 30.0, 33.0, 36.0, 50.0, 54.0, 58.0])
    history = DischargeHistory(time=time, discharged_mass=mass)
    fit = steady_flow_rate(time, mass, window=(0.0, 11.0))
    estimate = steady_rate_estimate(history, fit, n_batches=4)
    assert (estimate.value, estimate.n, estimate.method) == (fit.mass_flow_rate, 4, "batch rate")
    assert estimate.std_error == pytest.approx(math.sqrt(5.0 / 3.0) / 2.0, rel=1e-14)  # std(1..4) / sqrt(4)
    # 12 samples hold at most 6 batches of two; a window of 3 samples gives one batch: unknown
    assert steady_rate_estimate(history, fit, n_batches=10).n == 6
    short = steady_flow_rate(time, mass, window=(0.0, 2.0))
    unknown = steady_rate_estimate(history, short)
    assert unknown.n == 1 and math.isnan(unknown.std_error) and unknown.value == short.mass_flow_rate


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
