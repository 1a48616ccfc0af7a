"""Unit tests for siloflow.analysis.numerics.pathlines: virtual tracers through velocity fields with exact residence times."""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.analysis.numerics.pathlines import (
    EXITED,
    HAVE_NUMBA,
    NOT_EXITED,
    OUTSIDE,
    PathlineResult,
    integrate_pathlines,
    interpolate_velocity,
    time_levels,
)
from siloflow.analysis.numerics.rtd import rtd_from_exit_times
from siloflow.analysis.numerics.tracer_seeds import lattice_seeds
from tests.bench.bench_pathlines import integrate_with_scipy, max_relative_difference

BACKENDS = ["numba", "numpy"] if HAVE_NUMBA else ["numpy"]
METHODS = ["rk2", "euler"]

# a 6 x 5 x 12 lattice of 0.1 x 0.08 x 0.05 m cells from (-0.3, 0, 0): box up to (0.3, 0.4, 0.6)
ORIGIN = (-0.3, 0.0, 0.0)
SPACING = (0.1, 0.08, 0.05)
SHAPE = (6, 5, 12)


def node_axes(shape=SHAPE, origin=ORIGIN, spacing=SPACING):
    return [origin[a] + (np.arange(shape[a]) + 0.5) * spacing[a] for a in range(3)]


def uniform_series(velocity, n_times=1, shape=SHAPE):
    return np.broadcast_to(np.asarray(velocity, float), (n_times,) + tuple(shape) + (3,)).copy()


# --------------------------------------------------------------------------- exact residence times


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("method", METHODS)
def test_uniform_downward_field_gives_exact_residence_time(backend, method):
    speed = 0.37
    seeds = lattice_seeds((-0.25, 0.05, 0.1), (0.25, 0.35, 0.55), count=(3, 2, 5))
    outlet = 0.02
    result = integrate_pathlines(
        seeds, 1.234, uniform_series((0.0, 0.0, -speed), n_times=3), [0.0, 1.0, 2.0], ORIGIN, SPACING,
        dt=0.0123, outlet_z=outlet, max_time=5.0, method=method, backend=backend,
    )
    assert isinstance(result, PathlineResult)
    expected = (seeds[:, 2] - outlet) / speed
    np.testing.assert_allclose(result.residence_time, expected, rtol=1e-12, atol=0)
    np.testing.assert_allclose(result.exit_time, 1.234 + expected, rtol=1e-12)
    np.testing.assert_array_equal(result.status, EXITED)
    np.testing.assert_allclose(result.exit_position[:, :2], seeds[:, :2], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(result.exit_position[:, 2], outlet)
    np.testing.assert_array_equal(result.n_steps, np.ceil(expected / 0.0123 - 1e-9).astype(int))
    assert result.fraction_exited == 1.0 and result.tracer_steps == result.n_steps.sum()


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("shape", [SHAPE, (6, 1, 12)])  # also a one-cell-thick (planar) grid
def test_linear_shear_gives_exact_residence_time(backend, method, shape):
    v0, a = 0.2, 0.5  # v_z = -(v0 + a x): 0.05 m/s at x = -0.3, 0.35 m/s at x = 0.3
    spacing = (SPACING[0], 0.4 / shape[1], SPACING[2])
    x, y, z = np.meshgrid(*node_axes(shape, ORIGIN, spacing), indexing="ij")
    field = np.zeros(shape + (3,))
    field[..., 2] = -v0 - a * x
    # seeds within the hull of the nodes in x (-0.25 to 0.25), where trilinear interpolation is exact
    seeds = lattice_seeds((-0.25, 0.04, 0.3), (0.25, 0.36, 0.5), count=(6, 3, 3))
    result = integrate_pathlines(seeds, 0.0, field[None], [0.0], ORIGIN, spacing, dt=0.01, outlet_z=0.0,
                                 max_time=20.0, method=method, backend=backend)
    expected = seeds[:, 2] / (v0 + a * seeds[:, 0])
    np.testing.assert_allclose(result.residence_time, expected, rtol=1e-12, atol=0)
    np.testing.assert_allclose(result.exit_position[:, 0], seeds[:, 0], rtol=0, atol=1e-15)


@pytest.mark.parametrize("backend", BACKENDS)
def test_field_switching_linearly_in_time_gives_the_analytic_crossing(backend):
    v1, v2 = 0.1, 0.4
    ta, tb = 0.25, 0.5  # the speed ramps from v1 to v2 between ta and tb (instants on the step grid)
    series = np.stack([uniform_series((0, 0, -v))[0] for v in (v1, v1, v2, v2)])
    times = [0.0, ta, tb, 10.0]
    seeds = np.array([[0.0, 0.2, z] for z in (0.25, 0.3, 0.45, 0.58)])
    result = integrate_pathlines(seeds, 0.0, series, times, ORIGIN, SPACING, dt=1.0 / 64, outlet_z=0.0,
                                 max_time=5.0, method="rk2", backend=backend)
    z_tb = seeds[:, 2] - v1 * ta - 0.5 * (v1 + v2) * (tb - ta)  # all still above the outlet at tb
    assert np.all(z_tb > 0.0)
    expected = tb + z_tb / v2
    np.testing.assert_allclose(result.residence_time, expected, rtol=1e-12, atol=0)
    # Euler is first order: its error halves with the step
    errors = []
    for dt in (1.0 / 64, 1.0 / 128):
        euler = integrate_pathlines(seeds, 0.0, series, times, ORIGIN, SPACING, dt=dt, outlet_z=0.0,
                                    max_time=5.0, method="euler", backend=backend)
        errors.append(np.max(np.abs(euler.residence_time - expected)))
    assert errors[0] > 1e-4
    assert errors[1] == pytest.approx(errors[0] / 2, rel=0.05)


@pytest.mark.parametrize("backend", BACKENDS)
def test_release_before_the_first_field_and_after_the_last_holds_the_end_fields(backend):
    series = np.stack([uniform_series((0, 0, -v))[0] for v in (0.2, 0.4)])
    seeds = np.array([[0.0, 0.2, 0.3]])
    # released at t0 = -1 with fields at 0 and 0.5: 0.2 m/s until 0, then a ramp to 0.4 m/s at 0.5
    early = integrate_pathlines(seeds, -1.0, series, [0.0, 0.5], ORIGIN, SPACING, dt=1.0 / 32, outlet_z=0.0,
                                max_time=5.0, backend=backend)
    z_at_0 = 0.3 - 0.2
    # 0.1 m left at t = 0: the ramp covers 0.15 m by t = 0.5, so it crosses during the ramp:
    # 0.1 = 0.2 s + 0.2 s^2 (speed 0.2 + 0.4 s) -> s = (-0.2 + sqrt(0.04 + 0.08)) / 0.4
    s = (-0.2 + np.sqrt(0.04 + 4 * 0.2 * z_at_0)) / (2 * 0.2)
    # the crossing inside a ramp is interpolated linearly within the step: second order in dt
    assert early.residence_time[0] == pytest.approx(1.0 + s, abs=(1.0 / 32) ** 2)
    late = integrate_pathlines(seeds, 3.0, series, [0.0, 0.5], ORIGIN, SPACING, dt=0.01, outlet_z=0.0,
                               max_time=5.0, backend=backend)
    assert late.residence_time[0] == pytest.approx(0.3 / 0.4, rel=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
def test_tracers_outside_or_never_exiting_get_nan(backend):
    field = uniform_series((0.0, 0.0, -0.1), n_times=3)
    field[2, ..., 2] = 0.0  # 0.1 m/s down until t = 1, then slowing linearly to rest at t = 2
    seeds = np.array(
        [
            [0.0, 0.2, 0.05],  # exits at 0.5 s
            [0.0, 0.2, 0.5],  # moves 0.1 + 0.05 m, then rests at z = 0.35: never exits
            [0.5, 0.2, 0.3],  # outside the box in x
            [0.0, 0.2, 0.7],  # above the box
            [0.0, 0.2, 0.0],  # on the outlet plane
        ]
    )
    result = integrate_pathlines(seeds, 0.0, field, [0.0, 1.0, 2.0], ORIGIN, SPACING, dt=0.01, outlet_z=0.0,
                                 max_time=10.0, backend=backend, record_every=10)
    assert result.residence_time[0] == pytest.approx(0.5, rel=1e-12)
    assert np.all(np.isnan(result.residence_time[1:]))
    assert np.all(np.isnan(result.exit_position[1:]))
    np.testing.assert_array_equal(result.status, [EXITED, NOT_EXITED, OUTSIDE, OUTSIDE, OUTSIDE])
    np.testing.assert_array_equal(result.n_steps, [50, 1000, 0, 0, 0])
    assert result.fraction_exited == pytest.approx(0.2)
    # history: seeds first, NaN after the exit and for the seeds outside
    assert result.history.shape == (101, 5, 3)
    np.testing.assert_allclose(result.history_time, np.arange(101) * 0.1, rtol=1e-15)
    np.testing.assert_array_equal(result.history[0, :2], seeds[:2])
    assert np.all(np.isnan(result.history[:, 2:]))
    assert np.all(np.isfinite(result.history[:5, 0])) and np.all(np.isnan(result.history[5:, 0]))
    assert result.history[1, 0, 2] == pytest.approx(0.04, rel=1e-12)
    assert np.all(np.isfinite(result.history[:, 1]))


@pytest.mark.parametrize("backend", BACKENDS)
def test_exit_after_max_time_is_not_counted(backend):
    seeds = np.array([[0.0, 0.2, 0.3], [0.0, 0.2, 0.1]])
    result = integrate_pathlines(seeds, 0.0, uniform_series((0, 0, -0.1)), [0.0], ORIGIN, SPACING, dt=0.3,
                                 outlet_z=0.0, max_time=2.0, backend=backend)
    # the first would cross at 3 s; the second at 1 s
    np.testing.assert_array_equal(result.status, [NOT_EXITED, EXITED])
    assert np.isnan(result.residence_time[0]) and result.residence_time[1] == pytest.approx(1.0, rel=1e-12)
    assert result.n_steps[0] == 7  # ceil(2.0 / 0.3)
    assert result.history is None and result.history_time is None


def test_residence_times_feed_the_rtd():
    speed = 0.25
    seeds = lattice_seeds((-0.25, 0.04, 0.2), (0.25, 0.36, 0.4), count=(2, 2, 10))
    result = integrate_pathlines(np.vstack([seeds, [[1.0, 1.0, 1.0]]]), 0.0, uniform_series((0, 0, -speed)),
                                 [0.0], ORIGIN, SPACING, dt=0.01, outlet_z=0.0, max_time=5.0)
    rtd = rtd_from_exit_times(result.residence_time, bins=10)
    assert rtd.n_exited == 40 and rtd.n_total == 41
    assert rtd.t_first == pytest.approx(0.21 / speed, rel=1e-12)
    assert rtd.t_last == pytest.approx(0.39 / speed, rel=1e-12)
    assert rtd.t_mean == pytest.approx(0.3 / speed, rel=1e-12)


# --------------------------------------------------------------------------- backends and the scipy peer


def smooth_series(n_times=3):
    x, y, z = np.meshgrid(*node_axes(), indexing="ij")
    series = np.empty((n_times,) + SHAPE + (3,))
    for level in range(n_times):
        scale = 1.0 + 0.3 * level
        series[level, ..., 0] = -0.2 * x * np.exp(-z / 0.2) * scale
        series[level, ..., 1] = 0.03 * np.sin(np.pi * y / 0.4) * np.cos(3 * x)
        series[level, ..., 2] = -scale * (0.05 + 0.3 * np.exp(-(x**2) / (2 * 0.1**2)))
    return series


@pytest.mark.parametrize("method", METHODS)
def test_backends_and_the_scipy_peer_agree(method):
    series = smooth_series()
    times = [0.0, 0.7, 1.5]
    seeds = lattice_seeds((-0.4, 0.01, 0.35), (0.4, 0.39, 0.59), count=(9, 4, 3))  # x = +-0.356 outside the box
    kwargs = dict(velocities=series, times=times, origin=ORIGIN, spacing=SPACING, dt=0.01, outlet_z=0.0,
                  max_time=6.0, method=method)
    results = {backend: integrate_pathlines(seeds, 0.1, **kwargs, backend=backend, record_every=7)
               for backend in BACKENDS}
    reference = results["numpy"]
    assert np.any(reference.status == OUTSIDE) and np.any(reference.status == EXITED)
    for result in results.values():
        np.testing.assert_array_equal(result.status, reference.status)
        np.testing.assert_array_equal(result.n_steps, reference.n_steps)
        np.testing.assert_allclose(result.residence_time, reference.residence_time, rtol=1e-12, equal_nan=True)
        np.testing.assert_allclose(result.exit_position, reference.exit_position, rtol=1e-12, atol=1e-14,
                                   equal_nan=True)
        np.testing.assert_allclose(result.history, reference.history, rtol=1e-12, atol=1e-14, equal_nan=True)
        np.testing.assert_array_equal(result.history_time, reference.history_time)
    residence, status, steps = integrate_with_scipy(seeds, 0.1, **kwargs)
    np.testing.assert_array_equal(status, reference.status)
    assert steps == reference.tracer_steps
    assert max_relative_difference(reference.residence_time, residence) <= 1e-9


# --------------------------------------------------------------------------- interpolation


def test_interpolation_at_nodes_between_them_clamped_and_in_time():
    series = smooth_series(2)
    axes = node_axes()
    node = np.array([[axes[0][2], axes[1][3], axes[2][4]]])
    np.testing.assert_allclose(interpolate_velocity(node, 0.0, series, [0.0, 1.0], ORIGIN, SPACING)[0],
                               series[0, 2, 3, 4], rtol=1e-14)
    # halfway in time: the mean of the two levels
    np.testing.assert_allclose(interpolate_velocity(node, 0.5, series, [0.0, 1.0], ORIGIN, SPACING)[0],
                               0.5 * (series[0, 2, 3, 4] + series[1, 2, 3, 4]), rtol=1e-14)
    # midway between two nodes in x: the mean of the two
    mid = node + [[0.05, 0.0, 0.0]]
    np.testing.assert_allclose(interpolate_velocity(mid, 0.0, series, [0.0, 1.0], ORIGIN, SPACING)[0],
                               0.5 * (series[0, 2, 3, 4] + series[0, 3, 3, 4]), rtol=1e-14)
    # beyond the last node (and beyond the box) the boundary node's value holds
    corner = np.array([[10.0, -10.0, 5.0]])
    np.testing.assert_allclose(interpolate_velocity(corner, 7.0, series, [0.0, 1.0], ORIGIN, SPACING)[0],
                               series[1, -1, 0, -1], rtol=1e-14)


def test_time_levels():
    k, w = time_levels([0.0, 1.0, 3.0], [-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0])
    np.testing.assert_array_equal(k, [0, 0, 0, 1, 1, 2, 2])
    np.testing.assert_allclose(w, [0.0, 0.0, 0.5, 0.0, 0.5, 0.0, 0.0])
    k, w = time_levels([2.0], [0.0, 5.0])
    np.testing.assert_array_equal(k, [0, 0])
    np.testing.assert_array_equal(w, [0.0, 0.0])


# --------------------------------------------------------------------------- seeds


def test_lattice_seeds():
    seeds = lattice_seeds((0.0, 0.0, 1.0), (1.0, 0.5, 1.0), count=(4, 2, 1))
    assert seeds.shape == (8, 3)
    np.testing.assert_allclose(np.unique(seeds[:, 0]), [0.125, 0.375, 0.625, 0.875])
    np.testing.assert_allclose(np.unique(seeds[:, 1]), [0.125, 0.375])
    np.testing.assert_array_equal(seeds[:, 2], 1.0)
    np.testing.assert_allclose(seeds[1], [0.125, 0.375, 1.0])  # z fastest, then y, x slowest
    by_spacing = lattice_seeds((0.0, 0.0, 1.0), (1.0, 0.5, 1.0), spacing=0.25)
    np.testing.assert_allclose(by_spacing, seeds)
    cube = lattice_seeds((0.0, 0.0, 0.0), (0.2, 0.1, 0.4), count=1000)
    assert cube.shape[0] == 10 * 5 * 20
    assert lattice_seeds((0, 0, 0), (0, 0, 0), count=5).shape == (1, 3)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(count=None, spacing=None), "count"),
        (dict(count=10, spacing=0.1), "count"),
        (dict(count=0), "count"),
        (dict(count=(2, 2)), "count"),
        (dict(count=(2, 0, 1)), "count"),
        (dict(spacing=0.0), "spacing"),
        (dict(count=2.5), "count"),
    ],
)
def test_lattice_seeds_rejects_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        lattice_seeds((0, 0, 0), (1, 1, 1), **kwargs)
    with pytest.raises(ValueError, match="region_upper"):
        lattice_seeds((0, 0, 0), (1, -1, 1), count=2)


# --------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    "change, match",
    [
        (dict(seeds=np.zeros((2, 2))), "seeds"),
        (dict(seeds=[[0.0, 0.0, np.nan]]), "seeds"),
        (dict(velocities=np.zeros((1, 2, 2, 2))), "velocities"),
        (dict(velocities=np.full((1, 2, 2, 2, 3), np.inf)), "velocities"),
        (dict(times=[0.0, 1.0]), "times"),
        (dict(velocities=np.zeros((2, 2, 2, 2, 3)), times=[1.0, 1.0]), "times"),
        (dict(origin=(0.0, 0.0)), "origin"),
        (dict(spacing=(0.1, 0.0, 0.1)), "spacing"),
        (dict(dt=0.0), "dt"),
        (dict(max_time=-1.0), "max_time"),
        (dict(outlet_z=np.nan), "outlet_z"),
        (dict(t0=np.inf), "t0"),
        (dict(method="rk4"), "method"),
        (dict(record_every=-1), "record_every"),
        (dict(backend="cuda"), "backend"),
    ],
)
def test_integrate_pathlines_rejects_bad_input(change, match):
    kwargs = dict(seeds=[[0.1, 0.1, 0.1]], t0=0.0, velocities=np.zeros((1, 2, 2, 2, 3)), times=[0.0],
                  origin=(0.0, 0.0, 0.0), spacing=(0.1, 0.1, 0.1), dt=0.01, outlet_z=0.0, max_time=1.0)
    kwargs.update(change)
    with pytest.raises(ValueError, match=match):
        integrate_pathlines(**kwargs)


def test_no_seeds():
    result = integrate_pathlines(np.empty((0, 3)), 0.0, np.zeros((1, 2, 2, 2, 3)), [0.0], (0, 0, 0), 0.1,
                                 dt=0.01, outlet_z=0.0, max_time=1.0)
    assert result.residence_time.shape == (0,) and result.fraction_exited == 0.0 and result.tracer_steps == 0
