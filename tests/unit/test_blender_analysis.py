"""Unit tests for the blender analysis (steady field, profiles, tracers, modes, gravity, comparison): exact answers on
uniform, linear and closed-form cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.grid import Fields, Grid
from siloflow.analysis.numerics.replicates import combine_replicates
from siloflow.analysis.studies.blender.comparison import BlenderMetrics, best_blender, comparison_table
from siloflow.analysis.studies.blender.gravity import gravity_normalised_time, gravity_normalised_velocity, gravity_scaling
from siloflow.analysis.studies.blender.modes import continuous_mode, discontinuous_mode
from siloflow.analysis.studies.blender.profiles import (
    flow_channel_boundary_over_height,
    height_profile,
    passage_velocities,
    profiles_over_time,
)
from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.tracers import layer_rtd, tabulated_rtd, tracer_layer, tracer_pathlines, virtual_tracer_rtd

SPEED = 0.5  # m/s, downward
DX = 0.01
DZ = 0.05
X_FULL = np.round(np.arange(-10, 11) * DX, 12)  # 21 bins centred on the axis, -0.1 ... 0.1 m
Z_ROWS = (np.arange(22) + 0.5) * DZ  # 0.025 ... 1.075 m; the grid box is [0, 1.1] m
PASSAGES = {"tube": (0.0, 0.025), "interior": (0.035, 0.065), "exterior": (0.075, 0.1)}


def uniform_field(speed=SPEED, x=X_FULL, z=Z_ROWS, solid_fraction=0.6) -> BlenderField:
    shape = (x.size, z.size)
    return BlenderField(x=x, z=z, v_x=np.zeros(shape), v_z=np.full(shape, -speed),
                        solid_fraction=np.full(shape, solid_fraction))


def shear_field(a=0.2, c=3.0, x=X_FULL, z=Z_ROWS, solid_fraction=None) -> BlenderField:
    """v_z(x) = -(a + c |x|), the same at every height; v_x = 0."""
    shape = (x.size, z.size)
    v_z = np.repeat(-(a + c * np.abs(x))[:, None], z.size, axis=1)
    fraction = np.ones(shape) if solid_fraction is None else solid_fraction
    return BlenderField(x=x, z=z, v_x=np.zeros(shape), v_z=v_z, solid_fraction=fraction)


# --------------------------------------------------------------------------- field


def test_field_keeps_velocities_of_occupied_bins_only_and_is_read_only():
    fraction = np.full((X_FULL.size, Z_ROWS.size), 0.6)
    fraction[0, :] = np.nan  # inside a wall
    fraction[1, :] = 0.0
    v_z = np.full(fraction.shape, -SPEED)
    v_z[0, :] = np.nan  # no velocity where no particles: allowed
    field = BlenderField(x=X_FULL, z=Z_ROWS, v_x=np.zeros(fraction.shape), v_z=v_z, solid_fraction=fraction)
    assert np.all(np.isnan(field.v_z[:2])) and np.all(field.v_z[2:] == -SPEED)
    np.testing.assert_array_equal(field.solid_fraction[:2], 0.0)
    np.testing.assert_array_equal(field.occupied[:2], False)
    assert field.bin_size() == pytest.approx((DX, DZ), rel=1e-12)
    with pytest.raises(ValueError):
        field.v_z[5, 5] = 0.0


@pytest.mark.parametrize(
    "change, match",
    [
        (dict(x=X_FULL[::-1]), "x must be"),
        (dict(v_z=np.zeros((3, 3))), "v_z must have shape"),
        (dict(solid_fraction=-np.ones((21, 22))), "solid_fraction must be >= 0"),
        (dict(v_x=np.full((21, 22), np.nan)), "v_x must be finite in every occupied bin"),
    ],
)
def test_field_rejects_bad_input(change, match):
    arguments = dict(x=X_FULL, z=Z_ROWS, v_x=np.zeros((21, 22)), v_z=np.zeros((21, 22)),
                     solid_fraction=np.ones((21, 22)))
    arguments.update(change)
    with pytest.raises(ValueError, match=match):
        BlenderField(**arguments)


def test_field_from_depth_averaged_fields():
    grid = Grid(origin=(-0.105, 0.0, 0.0), spacing=(DX, 0.04, DZ), shape=(21, 1, 22))
    density = np.full((21, 1, 22), 900.0)
    density[:, :, -1] = 0.0
    velocity = np.zeros((21, 1, 22, 3))
    velocity[..., 2] = np.where(density > 0, -SPEED, 0.0)
    fields = Fields(grid=grid, density=density, momentum_density=density[..., None] * velocity, velocity=velocity,
                    kinetic_stress=np.zeros((21, 1, 22, 3, 3)), mask=density > 0)
    field = BlenderField.from_fields(fields, particle_density=1500.0)
    np.testing.assert_allclose(field.solid_fraction[:, :-1], 0.6, rtol=1e-15)
    np.testing.assert_allclose(field.x, X_FULL, atol=1e-15)
    np.testing.assert_allclose(field.z, Z_ROWS, atol=1e-15)
    np.testing.assert_array_equal(field.v_z[:, :-1], -SPEED)
    assert np.all(np.isnan(field.v_z[:, -1])) and np.all(field.solid_fraction[:, -1] == 0.0)
    with pytest.raises(ValueError, match="Fields"):
        BlenderField.from_fields("not fields", 1500.0)
    with pytest.raises(ValueError, match="particle_density"):
        BlenderField.from_fields(fields, 0.0)


def test_field_from_a_planar_field_like_object():
    class Planar:
        x, z = X_FULL[10:], Z_ROWS
        v_x = np.zeros((11, 22))
        v_z = np.full((11, 22), -SPEED)
        solid_fraction = np.full((11, 22), 0.55)

    field = BlenderField.from_planar(Planar())
    np.testing.assert_array_equal(field.solid_fraction, 0.55)
    np.testing.assert_array_equal(field.v_z, -SPEED)
    with pytest.raises(ValueError, match="solid_fraction"):
        BlenderField.from_planar(object())


# --------------------------------------------------------------------------- 1. profiles


def test_uniform_field_normalised_profile_is_one_everywhere():
    profile = height_profile(uniform_field(), 0.31)  # between rows
    assert profile.cross_section_mean == pytest.approx(-SPEED, rel=1e-14)
    np.testing.assert_allclose(profile.normalised, 1.0, rtol=1e-14)
    assert profile.is_open.all() and profile.z == 0.31


def test_profile_with_passages_excludes_wall_bins():
    profile = height_profile(shear_field(), 0.5, PASSAGES)
    distance = np.abs(X_FULL)
    walls = (distance > 0.025) & (distance < 0.035) | (distance > 0.065) & (distance < 0.075)
    np.testing.assert_array_equal(profile.is_open, ~walls)
    assert np.all(np.isnan(profile.normalised[walls]))
    open_v = -(0.2 + 3.0 * distance[~walls])
    assert profile.cross_section_mean == pytest.approx(open_v.mean(), rel=1e-13)
    np.testing.assert_allclose(profile.normalised[~walls], open_v / open_v.mean(), rtol=1e-13)


def test_profile_is_linear_between_rows_and_takes_the_occupied_row_alone():
    shape = (X_FULL.size, Z_ROWS.size)
    v_z = -(0.1 + 2.0 * np.broadcast_to(Z_ROWS, shape))  # linear in z
    fraction = np.ones(shape)
    fraction[:, -1] = 0.0  # the top row is empty
    field = BlenderField(x=X_FULL, z=Z_ROWS, v_x=np.zeros(shape), v_z=v_z, solid_fraction=fraction)
    np.testing.assert_allclose(height_profile(field, 0.337).v_z, -(0.1 + 2.0 * 0.337), rtol=1e-13)
    np.testing.assert_allclose(height_profile(field, 1.06).v_z, -(0.1 + 2.0 * Z_ROWS[-2]), rtol=1e-13)
    with pytest.raises(ValueError, match="no open bin"):
        height_profile(field, Z_ROWS[-1])
    with pytest.raises(ValueError, match="outside the node rows"):
        height_profile(field, 2.0)


def test_profiles_over_time_normalise_each_window():
    fields = [uniform_field(0.4), uniform_field(0.8)]
    result = profiles_over_time(fields, [1.0, 3.0], [0.2, 0.6], passages=[PASSAGES, None])
    np.testing.assert_array_equal(result.window_time, [1.0, 3.0])
    np.testing.assert_allclose(result.cross_section_mean, [[-0.4, -0.4], [-0.8, -0.8]], rtol=1e-14)
    np.testing.assert_allclose(result.normalised[:, 1], 1.0, rtol=1e-14)
    open_bins = np.isfinite(result.normalised[0, 0])
    np.testing.assert_allclose(result.normalised[:, 0][:, open_bins], 1.0, rtol=1e-14)
    assert np.count_nonzero(open_bins) == 17  # 21 bins less two wall bins on each side
    with pytest.raises(ValueError, match="window_time"):
        profiles_over_time(fields, [1.0], [0.2])
    with pytest.raises(ValueError, match="passages"):
        profiles_over_time(fields, [1.0, 2.0], [0.2], passages=[PASSAGES, PASSAGES])
    with pytest.raises(ValueError, match="same x bins"):
        profiles_over_time([uniform_field(), uniform_field(x=X_FULL + 0.001)], [1.0, 2.0], [0.2])


# --------------------------------------------------------------------------- 2. passage velocities


def test_uniform_field_passage_means_are_the_velocity():
    result = passage_velocities(uniform_field(), 0.9, PASSAGES)
    assert result.mean_v_z == pytest.approx({"tube": -SPEED, "interior": -SPEED, "exterior": -SPEED}, rel=1e-14)
    assert result.n_bins == {"tube": 5, "interior": 6, "exterior": 6}  # mirrored halves included


def test_linear_shear_passage_mean_is_the_midpoint_value():
    a, c = 0.2, 3.0
    passages = {"interior": (0.015, 0.055), "exterior": (0.06, 0.1), "narrow": (0.041, 0.049)}
    result = passage_velocities(shear_field(a, c), 0.4, passages)
    assert result.mean_v_z["interior"] == pytest.approx(-(a + c * 0.035), rel=1e-13)
    assert result.mean_v_z["exterior"] == pytest.approx(-(a + c * 0.08), rel=1e-13)
    assert result.n_bins["interior"] == 8 and math.isnan(result.mean_v_z["narrow"]) and result.n_bins["narrow"] == 0
    np.testing.assert_allclose(result.profile.v_z, -(a + c * np.abs(X_FULL)), rtol=1e-13)


@pytest.mark.parametrize(
    "passages, match",
    [({}, "non-empty mapping"), ({"a": (0.05, 0.01)}, "x_lo < x_hi"), ({"a": (-0.1, 0.0)}, "0 <= x_lo"),
     ({"a": (0.0,)}, "two numbers"), ([(0.0, 0.1)], "mapping")],
)
def test_passage_velocities_rejects_bad_passages(passages, match):
    with pytest.raises(ValueError, match=match):
        passage_velocities(uniform_field(), 0.5, passages)


# --------------------------------------------------------------------------- 3. flow channel boundary


def channel_field(x=X_FULL, wall=0.1):
    """v_z = -(0.1 + (wall - |x|)) inside the wall: v' = v_z - v_wall = -(wall - |x|) falls linearly to 0."""
    shape = (x.size, Z_ROWS.size)
    v_z = np.repeat(-(0.1 + (wall - np.abs(x)))[:, None], Z_ROWS.size, axis=1)
    return BlenderField(x=x, z=Z_ROWS, v_x=np.zeros(shape), v_z=v_z, solid_fraction=np.ones(shape))


@pytest.mark.parametrize("x", [X_FULL, X_FULL[10:]], ids=["both halves", "right half mirrored"])
def test_flow_channel_boundary_at_known_crossing(x):
    result = flow_channel_boundary_over_height(channel_field(x), 0.1)
    np.testing.assert_allclose(result.x_boundary, 0.09, rtol=1e-12)  # |v'| = 0.1 |v'(0)| at |x| = 0.9 wall
    np.testing.assert_allclose(result.right, 0.09, rtol=1e-12)
    np.testing.assert_allclose(result.left, -0.09, rtol=1e-12)
    np.testing.assert_allclose(result.wall_velocity, -0.1, rtol=1e-12)
    np.testing.assert_allclose(result.centreline_speed, 0.1, rtol=1e-12)
    assert not result.reaches_wall.any() and result.fraction == 0.1


def test_flow_channel_boundary_with_a_wall_per_row_and_fraction():
    walls = np.where(Z_ROWS < 0.5, 0.05, 0.1)
    result = flow_channel_boundary_over_height(channel_field(), walls, fraction=0.2)
    # below 0.5 m: v_wall = v(0.05) = -0.15, v' = -(0.05 - |x|), |v'| = 0.2 |v'(0)| at |x| = 0.04
    np.testing.assert_allclose(result.x_boundary, np.where(Z_ROWS < 0.5, 0.04, 0.08), rtol=1e-12)
    np.testing.assert_allclose(result.wall_velocity, np.where(Z_ROWS < 0.5, -0.15, -0.1), rtol=1e-12)
    np.testing.assert_array_equal(result.wall_x, walls)


def test_plug_flow_channel_fills_the_width_and_empty_rows_are_nan():
    fraction = np.full((X_FULL.size, Z_ROWS.size), 0.6)
    fraction[:, -3:] = 0.0  # above the fill
    field = BlenderField(x=X_FULL, z=Z_ROWS, v_x=np.zeros(fraction.shape), v_z=np.full(fraction.shape, -SPEED),
                         solid_fraction=fraction)
    result = flow_channel_boundary_over_height(field, 0.1)
    np.testing.assert_array_equal(result.x_boundary[:-3], 0.1)
    assert result.reaches_wall[:-3].all() and not result.reaches_wall[-3:].any()
    assert np.all(np.isnan(result.x_boundary[-3:]))


@pytest.mark.parametrize(
    "wall_x, fraction, match",
    [(0.0, 0.1, "wall_x"), (np.ones(3), 0.1, "wall_x"), (0.1, 1.0, "fraction"), (0.1, 0.0, "fraction")],
)
def test_flow_channel_boundary_rejects_bad_input(wall_x, fraction, match):
    with pytest.raises(ValueError, match=match):
        flow_channel_boundary_over_height(uniform_field(), wall_x, fraction)


# --------------------------------------------------------------------------- 4. pathlines


def test_uniform_field_pathlines_take_height_over_speed():
    release = 0.8
    result = tracer_pathlines(uniform_field(), release, max_time=5.0, spacing=0.015, dt=0.0037)
    np.testing.assert_allclose(result.release_x, np.arange(-6, 7) * 0.015, atol=1e-15)  # within +-0.1 m
    np.testing.assert_allclose(result.residence_time, release / SPEED, rtol=0, atol=1e-9)
    assert result.n_not_exited == 0
    for x0, path in zip(result.release_x, result.paths):
        np.testing.assert_allclose(path[0], [x0, release], atol=1e-12)
        np.testing.assert_allclose(path[-1], [x0, 0.0], atol=1e-12)
        np.testing.assert_allclose(path[:, 0], x0, atol=1e-12)


def test_linear_shear_residence_time_across_the_width():
    a, c, release = 0.2, 3.0, 1.0
    result = tracer_pathlines(shear_field(a, c), release, max_time=10.0, spacing=0.015, dt=0.002, record_every=7)
    np.testing.assert_allclose(result.residence_time, release / (a + c * np.abs(result.release_x)), rtol=1e-12)


def test_half_field_releases_from_the_axis_and_stalled_tracers_are_counted():
    x = X_FULL[10:]
    shape = (x.size, Z_ROWS.size)
    v_z = np.full(shape, -SPEED)
    v_z[-2:] = 0.0  # a dead zone next to the wall
    field = BlenderField(x=x, z=Z_ROWS, v_x=np.zeros(shape), v_z=v_z, solid_fraction=np.ones(shape))
    result = tracer_pathlines(field, 0.5, max_time=2.0, spacing=0.03)
    np.testing.assert_allclose(result.release_x, [0.0, 0.03, 0.06, 0.09], atol=1e-15)
    np.testing.assert_allclose(result.residence_time[:3], 1.0, atol=1e-9)
    assert np.isnan(result.residence_time[3]) and result.n_not_exited == 1
    assert np.all(np.isfinite(result.paths[3])) and result.paths[3].shape[0] > 1


def test_tracer_pathlines_rejects_bad_input():
    with pytest.raises(ValueError, match="max_time"):
        tracer_pathlines(uniform_field(), 0.5, max_time=0.0)
    with pytest.raises(ValueError, match="spacing"):
        tracer_pathlines(uniform_field(), 0.5, max_time=1.0, spacing=-0.01)
    with pytest.raises(ValueError, match="record_every"):
        tracer_pathlines(uniform_field(), 0.5, max_time=1.0, record_every=0)
    with pytest.raises(ValueError, match="field.x"):
        tracer_pathlines(uniform_field(x=np.array([-0.1, 0.0, 0.05])), 0.5, max_time=1.0)
    with pytest.raises(ValueError, match="field must be a BlenderField"):
        tracer_pathlines(None, 0.5, max_time=1.0)


# --------------------------------------------------------------------------- 5. RTD of a layer


def test_uniform_layer_gives_a_uniform_rtd():
    h1, h2, spacing = 0.3, 0.5, 0.025
    n_rows = 8
    edges = np.linspace(h1 / SPEED, h2 / SPEED, n_rows + 1)
    result = layer_rtd(uniform_field(), h1, h2, max_time=5.0, tracer_spacing=spacing, bins=edges)
    np.testing.assert_allclose(result.rtd.E, SPEED / (h2 - h1), rtol=1e-12)
    assert result.rtd.t_mean == pytest.approx((h1 + h2) / (2 * SPEED), rel=1e-12)
    assert result.rtd.t_first == pytest.approx((h1 + spacing / 2) / SPEED, rel=1e-9)
    assert result.rtd.t_last == pytest.approx((h2 - spacing / 2) / SPEED, rel=1e-9)
    assert result.rtd.n_total == result.release_x.size == n_rows * 8  # round(0.21 m / 0.025 m) = 8 columns
    assert result.n_not_exited == 0 and result.rtd.fraction_exited == 1.0
    assert result.spread == pytest.approx(math.sqrt(result.rtd.variance) / result.rtd.t_mean)


def test_layer_rtd_weights_tracers_by_solid_fraction():
    a, c = 0.2, 3.0
    fraction = np.repeat((1.0 + 10.0 * np.abs(X_FULL))[:, None], Z_ROWS.size, axis=1)
    field = shear_field(a, c, solid_fraction=fraction)
    result = layer_rtd(field, 0.2, 0.4, max_time=10.0, tracer_spacing=0.02, bins=10)
    weight = 1.0 + 10.0 * np.abs(np.round(result.release_x / DX) * DX)  # solid fraction of the bin each one starts in
    np.testing.assert_array_equal(result.weights, weight)
    tau = result.release_z / (a + c * np.abs(result.release_x))
    assert result.rtd.t_mean == pytest.approx(np.sum(weight * tau) / np.sum(weight), rel=1e-9)
    assert np.sum(result.rtd.E * result.rtd.widths) == pytest.approx(1.0, rel=1e-12)


def test_layer_rtd_counts_tracers_that_never_exit():
    shape = (X_FULL.size, Z_ROWS.size)
    v_z = np.full(shape, -SPEED)
    v_z[:5] = 0.0  # stagnant left wall zone (occupied, not moving)
    field = BlenderField(x=X_FULL, z=Z_ROWS, v_x=np.zeros(shape), v_z=v_z, solid_fraction=np.ones(shape))
    result = layer_rtd(field, 0.3, 0.5, max_time=3.0, tracer_spacing=0.025)
    stalled = result.release_x < -0.05
    assert result.n_not_exited == np.count_nonzero(stalled) > 0
    assert result.rtd.n_total == result.release_x.size
    assert result.rtd.n_exited == result.release_x.size - result.n_not_exited
    assert np.sum(result.rtd.E * result.rtd.widths) == pytest.approx(result.rtd.fraction_exited, rel=1e-12)


def test_tracer_layer_holds_the_volume_fraction():
    assert tracer_layer(uniform_field(), 1.0, 0.1) == pytest.approx((0.9, 1.0), rel=1e-12)
    with_channel = uniform_field(z=Z_ROWS - 0.035)  # the lowest row spans [-0.035, 0.015] m
    assert tracer_layer(with_channel, 1.0, 0.99) == pytest.approx((0.01, 1.0), rel=1e-12)
    fraction = np.ones((X_FULL.size, Z_ROWS.size))
    fraction[:10, Z_ROWS < 0.4] = 0.0  # below 0.4 m only 11 of the 21 columns hold material
    field = BlenderField(x=X_FULL, z=Z_ROWS, v_x=np.zeros(fraction.shape), v_z=-fraction, solid_fraction=fraction)
    filled = 11 * DX * 0.4 + 21 * DX * 0.6
    bottom, top = tracer_layer(field, 1.0, 0.9)
    assert top == 1.0
    # the layer reaches below 0.4 m: 0.1 filled is left over, in the 11-column part
    assert bottom == pytest.approx(0.1 * filled / (11 * DX), rel=1e-12)


def test_virtual_tracer_rtd_uses_the_top_tenth_of_the_fill():
    result = virtual_tracer_rtd(uniform_field(), 1.0, max_time=5.0, tracer_spacing=0.025)
    assert (result.layer_bottom, result.layer_top) == pytest.approx((0.9, 1.0), rel=1e-12)
    assert result.rtd.t_mean == pytest.approx(0.95 / SPEED, rel=1e-12)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda f: layer_rtd(f, 0.5, 0.3, 5.0), "z_bottom < z_top"),
        (lambda f: layer_rtd(f, 0.3, 1.5, 5.0), "above the grid"),
        (lambda f: layer_rtd(f, 0.3, 0.5, 0.1), "no virtual tracer"),
        (lambda f: tracer_layer(f, 2.0, 0.1), "above the grid"),
        (lambda f: tracer_layer(f, 1.0, 1.5), "volume_fraction"),
        (lambda f: virtual_tracer_rtd(f, 1.0, 5.0, tracer_fraction=0.0), "tracer_fraction"),
    ],
)
def test_layer_rtd_rejects_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call(uniform_field())


def test_tabulated_rtd_puts_residence_times_on_their_sample():
    time, E = tabulated_rtd([1.0, 2.0, np.nan, 2.0], 0.25, weights=[2.0, 1.0, 0.5, 0.5])
    np.testing.assert_array_equal(time, np.arange(10) * 0.25)
    expected = np.zeros(10)
    expected[4], expected[8] = 2.0 / 4.0 / 0.25, 1.5 / 4.0 / 0.25
    np.testing.assert_allclose(E, expected, rtol=1e-14)
    with pytest.raises(ValueError, match="weights"):
        tabulated_rtd([1.0, 2.0], 0.25, weights=[1.0, 0.0])


# --------------------------------------------------------------------------- 6. discontinuous mode


def test_two_layer_plug_flow_first_pass_is_a_step_and_tracer_is_conserved():
    fill, spacing, window = 1.0, 0.05, 0.1  # a lattice row leaves in each window
    result = discontinuous_mode(uniform_field(), fill, max_time=5.0, passes=3, tracer_fraction=0.2,
                                window=window, tracer_spacing=spacing)
    t_m = fill / SPEED
    assert result.mean_residence_time == pytest.approx(t_m, rel=1e-12)
    assert result.tracer_fraction == pytest.approx(0.2, rel=1e-12)
    assert result.tracer_bottom == pytest.approx(0.8, rel=1e-12)
    step = (result.window_start >= 0.8 * t_m - 1e-9) & (result.window_start < t_m - 1e-9)
    np.testing.assert_allclose(result.first_pass, np.where(step, 1.0, 0.0), atol=1e-12)  # the top 20 % leaves last
    assert result.first_pass.size == 60
    # recirculated: the same step once per pass, so every pass carries 0.2 of tracer on average
    expected = np.tile(np.where(np.arange(20) >= 16, 1.0, 0.0), 3)
    np.testing.assert_allclose(result.concentration, expected, atol=1e-12)
    np.testing.assert_allclose(result.pass_mean, [0.2, 0.2, 0.2], rtol=1e-12)
    assert math.isnan(result.homogenised_after)  # plug flow never blends
    np.testing.assert_allclose(result.time_in_passes, result.window_start / result.mean_residence_time)
    assert result.n_not_exited == 0 and result.n_entry_not_exited == 0


def test_discontinuous_mode_first_pass_carries_the_tracer_share():
    result = discontinuous_mode(shear_field(), 1.0, max_time=20.0, passes=6, window=0.02, tracer_spacing=0.02)
    # sum(c_first) window = (tracer weight) t_m / (fill weight) when every tracer exits
    assert np.sum(result.first_pass) * result.window == pytest.approx(
        result.tracer_fraction * result.mean_residence_time, rel=1e-12)
    assert result.concentration.min() >= 0.0
    late = result.pass_mean[-1]
    assert abs(late - result.tracer_fraction) < 0.1 * result.tracer_fraction  # shear flow blends the layers
    assert np.isfinite(result.homogenised_after)


@pytest.mark.parametrize(
    "kwargs, match",
    [(dict(passes=0), "passes"), (dict(tracer_fraction=1.0), "tracer_fraction"), (dict(tolerance=0.0), "tolerance"),
     (dict(window=5.0), "window")],
)
def test_discontinuous_mode_rejects_bad_input(kwargs, match):
    arguments = dict(max_time=5.0, tracer_spacing=0.05)
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=match):
        discontinuous_mode(uniform_field(), 1.0, **arguments)


# --------------------------------------------------------------------------- 7. continuous mode


def test_two_peak_rtd_resonates_with_the_peak_spacing():
    a, b, step = 1.0, 2.0, 2.0**-6  # E = (delta(t - a) + delta(t - b)) / 2, t_m = 1.5 s
    periods = np.array([0.5, 2.0 / 3.0, 1.0, 2.0, 4.0])  # seconds
    result = continuous_mode([a, b], step, periods / 1.5, mean=0.5, amplitude=0.5)
    # output = cos(pi (b - a) / P) sin(...): VRR = 1 / cos^2(pi (b - a) / P)
    assert result.vrr[[0, 2]] == pytest.approx([1.0, 1.0], rel=1e-9)
    assert result.vrr[4] == pytest.approx(2.0, rel=1e-9)
    assert result.vrr[1] > 1e20 and result.vrr[3] > 1e20
    assert result.cov_in == pytest.approx(1.0 / math.sqrt(2.0), rel=1e-15)
    assert result.cov_out[4] == pytest.approx(0.5, rel=1e-9)
    np.testing.assert_allclose(result.resonant_periods_over_tm, [1.0 / 1.5])
    assert result.weakest_damping_period_over_tm in (periods[0] / 1.5, periods[2] / 1.5)
    assert result.vrr_at(4.0 / 1.5) == pytest.approx(2.0, rel=1e-9)
    np.testing.assert_allclose(result.vrr_table.period, periods, rtol=1e-12)
    with pytest.raises(ValueError, match="was not computed"):
        result.vrr_at(0.3)


def test_plug_flow_does_not_damp_a_sine():
    result = continuous_mode([1.0, 1.0, 1.0], 2.0**-5, [0.25, 0.5, 1.0])
    np.testing.assert_allclose(result.vrr, 1.0, rtol=1e-9)
    np.testing.assert_allclose(result.cov_out, result.cov_in, rtol=1e-9)


@pytest.mark.parametrize(
    "kwargs, match",
    [(dict(residence_time=[np.nan]), "no tracer exited"), (dict(periods_over_tm=[1.0, 0.5]), "strictly increasing"),
     (dict(periods_over_tm=[]), "periods_over_tm"), (dict(mean=0.0), "mean"), (dict(step=0.0), "step")],
)
def test_continuous_mode_rejects_bad_input(kwargs, match):
    arguments = dict(residence_time=[1.0, 2.0], step=0.01, periods_over_tm=[0.5, 1.0])
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=match):
        continuous_mode(**arguments)


# --------------------------------------------------------------------------- 8. gravity scaling


def test_gravity_normalisation_collapses_a_faster_run_exactly():
    t1 = np.linspace(0.0, 3.0, 31)
    v1 = -0.2 * (1.0 - np.exp(-t1))
    t4, v4 = t1 / 2.0, v1 * 2.0  # the same run at 4 g: twice as fast
    np.testing.assert_array_equal(gravity_normalised_time(t4, 4.0), t1)
    np.testing.assert_array_equal(gravity_normalised_velocity(v4, 4.0), v1)
    np.testing.assert_array_equal(gravity_normalised_velocity([np.nan, -1.0], 1.0), [np.nan, -1.0])
    with pytest.raises(ValueError, match="gravity_factor"):
        gravity_normalised_time(t1, 0.0)
    with pytest.raises(ValueError, match="velocity"):
        gravity_normalised_velocity([np.inf], 4.0)


def test_gravity_scaling_rows_and_verdicts():
    factors = [1.0, 5.0, 50.0]
    flow = [0.3, 0.3 * math.sqrt(5.0), 0.3 * math.sqrt(50.0) * 1.02]
    wall_velocity = [0.01, 0.01, 0.01]
    result = gravity_scaling(factors, {"mass_flow_rate_kg_s": flow, "wall_v_z_m_s": wall_velocity}, tolerance=0.05)
    assert result.scales == {"mass_flow_rate_kg_s": True, "wall_v_z_m_s": False}
    assert len(result.rows) == 6
    assert list(result.rows[0]) == ["quantity", "gravity_factor", "value", "ratio_to_1g", "expected_ratio",
                                    "relative_deviation", "scales"]
    last = result.rows[2]
    assert last["ratio_to_1g"] == pytest.approx(math.sqrt(50.0) * 1.02, rel=1e-14)
    assert last["expected_ratio"] == pytest.approx(math.sqrt(50.0), rel=1e-15)
    assert last["relative_deviation"] == pytest.approx(0.02, rel=1e-12) and last["scales"] is True
    assert result.rows[4]["relative_deviation"] == pytest.approx(1.0 / math.sqrt(5.0) - 1.0, rel=1e-14)


@pytest.mark.parametrize(
    "factors, quantities, match",
    [([2.0, 5.0], {"q": [1.0, 2.0]}, "factor 1"), ([1.0, 1.0], {"q": [1.0, 1.0]}, "distinct"),
     ([1.0, 4.0], {"q": [1.0]}, "one per factor"), ([1.0, 4.0], {"q": [0.0, 1.0]}, "is 0 at factor 1"),
     ([1.0, 4.0], {}, "non-empty mapping")],
)
def test_gravity_scaling_rejects_bad_input(factors, quantities, match):
    with pytest.raises(ValueError, match=match):
        gravity_scaling(factors, quantities)


# --------------------------------------------------------------------------- 9. comparison


def metrics(name, recirculations, vrr_short, vrr_long=10.0):
    return BlenderMetrics(name=name, mass_flow_rate=0.5, exterior_v_z=-0.01, interior_v_z=-0.02, tube_v_z=-0.03,
                          rtd_mean=20.0, rtd_spread=0.3, ts_over_td=0.2, recirculations_to_homogenise=recirculations,
                          vrr_by_period={2.0: vrr_long, 0.5: vrr_short})


def test_comparison_table_has_a_stable_column_order():
    rows = comparison_table([metrics("diverging", 2.0, 5.0), metrics("straight", 3.0, 4.0, 12.0)])
    assert list(rows[0]) == [
        "configuration", "mass_flow_rate_kg_s", "mass_flow_rate_kg_s_error", "exterior_v_z_m_s",
        "exterior_v_z_m_s_error", "interior_v_z_m_s", "interior_v_z_m_s_error", "tube_v_z_m_s", "tube_v_z_m_s_error",
        "rtd_mean_s", "rtd_mean_s_error", "rtd_spread", "rtd_spread_error", "ts_over_td", "ts_over_td_error",
        "recirculations_to_homogenise", "recirculations_to_homogenise_error", "vrr_at_0.5_tm", "vrr_at_0.5_tm_error",
        "vrr_at_2_tm", "vrr_at_2_tm_error",
    ]
    assert rows[1]["configuration"] == "straight" and rows[1]["vrr_at_2_tm"] == 12.0
    assert rows[0]["recirculations_to_homogenise"] == 2.0 and rows[0]["tube_v_z_m_s"] == -0.03
    # errors not given are unknown, and without a ceiling there are no ceiling columns
    assert all(math.isnan(rows[0][key]) for key in rows[0] if key.endswith("_error"))


def test_best_blender_fewest_recirculations_then_highest_vrr_at_shortest_period():
    assert best_blender([metrics("a", 3.0, 9.0), metrics("b", 2.0, 1.0), metrics("c", math.nan, 99.0)]) == "b"
    assert best_blender([metrics("a", 2.0, 3.0, 100.0), metrics("b", 2.0, 4.0, 1.0)]) == "b"
    assert best_blender([metrics("a", math.nan, 3.0), metrics("b", math.nan, 4.0)]) == "b"
    assert best_blender([metrics("a", 2.0, 4.0), metrics("b", 2.0, 4.0)]) == "a"


def test_replicates_keep_a_row_each_and_rank_by_their_mean():
    # seeds of "a" homogenise after 1 and 4 recirculations (mean 2.5): "b" with 2 is better than the best seed
    replicated = [metrics("a", 1.0, 9.0), metrics("b", 2.0, 1.0), metrics("a", 4.0, 9.0)]
    rows = comparison_table(replicated)
    assert [row["configuration"] for row in rows] == ["a", "b", "a"]
    assert [row["recirculations_to_homogenise"] for row in rows] == [1.0, 2.0, 4.0]
    combined = combine_replicates(rows, ["configuration"])
    assert [row["configuration"] for row in combined] == ["a", "b"]
    assert combined[0]["recirculations_to_homogenise"] == 2.5 and combined[0]["replicates"] == 2
    assert best_blender(replicated) == "b"
    # equal means: VRR means break the tie (a: (3 + 5) / 2 = 4 > b: 3.5)
    assert best_blender([metrics("a", 2.0, 3.0), metrics("b", 2.0, 3.5), metrics("a", 2.0, 5.0)]) == "a"
    # a seed that never homogenises sends its configuration behind every one that does
    assert best_blender([metrics("a", 1.0, 9.0), metrics("a", math.nan, 9.0), metrics("b", 5.0, 1.0)]) == "b"


def test_comparison_rejects_inconsistent_metrics():
    other = BlenderMetrics(name="b", mass_flow_rate=0.5, exterior_v_z=0.0, interior_v_z=0.0, tube_v_z=0.0,
                           rtd_mean=1.0, rtd_spread=0.1, ts_over_td=0.5, recirculations_to_homogenise=1.0,
                           vrr_by_period={1.0: 2.0})
    with pytest.raises(ValueError, match="VRR periods"):
        comparison_table([metrics("a", 1.0, 2.0), other])
    with pytest.raises(ValueError, match="BlenderMetrics"):
        comparison_table([])
