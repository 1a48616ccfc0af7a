"""Unit tests for siloflow.analysis.numerics.profiles, .kinematic and .janssen on synthetic profiles with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.grid import Fields, Grid
from siloflow.analysis.numerics.coarse_graining import coarse_grain
from siloflow.analysis.numerics.field_ops import depth_average
from siloflow.analysis.numerics.janssen import janssen_characteristic_depth, janssen_coefficient, janssen_vertical_stress
from siloflow.analysis.numerics.kinematic import (
    KinematicFit,
    fit_kinematic_constant,
    kinematic_horizontal_velocity,
    kinematic_velocity,
)
from siloflow.analysis.numerics.profiles import (
    FlowChannelBoundary,
    ProfileErrors,
    flow_channel_boundary,
    profile_errors,
    profile_flow_rate,
    velocity_profile,
)

W, T = 0.15, 0.04  # silo width and depth [m]
A_CENTRE = 0.2  # centreline speed [m/s]
B_KIN = 0.002  # kinematic constant [m]
SILO_GRID = Grid.covering((-W / 2, 0.0, 0.0), (W / 2, T, 0.18))


def analytic_v_z(x, z):
    return -A_CENTRE * np.exp(-(x**2) / (4 * B_KIN * z))


# --------------------------------------------------------------------------- velocity_profile


def plane_fields(grid: Grid, v_x, v_z) -> Fields:
    velocity = np.zeros(grid.shape + (3,))
    velocity[..., 0] = v_x
    velocity[..., 2] = v_z
    density = np.full(grid.shape, 600.0)
    return Fields(grid=grid, density=density, momentum_density=density[..., None] * velocity, velocity=velocity,
                  kinetic_stress=np.zeros(grid.shape + (3, 3)), mask=np.ones(grid.shape, bool))


def test_velocity_profile_interpolates_linearly_between_rows():
    grid = Grid(origin=(-W / 2, 0.0, 0.0), spacing=(0.006, T, 0.006), shape=(25, 1, 30))
    xs, _, zs = np.meshgrid(grid.x, grid.y, grid.z, indexing="ij")
    fields = plane_fields(grid, v_x=xs * zs, v_z=-1.0 - 2.0 * zs + xs)  # linear in z at fixed x
    at_row = velocity_profile(fields, grid.z[3])
    np.testing.assert_allclose(at_row.v_z, -1.0 - 2.0 * grid.z[3] + grid.x, rtol=1e-14)
    between = velocity_profile(fields, 0.020)  # between the rows at 15 and 21 mm
    assert between.z == 0.020
    np.testing.assert_allclose(between.v_z, -1.0 - 2.0 * 0.020 + grid.x, rtol=1e-13)
    np.testing.assert_allclose(between.v_x, grid.x * 0.020, rtol=1e-13, atol=1e-16)
    nearest = velocity_profile(fields, 0.020, method="nearest")
    assert nearest.z == pytest.approx(0.021)
    # The same from plain arrays.
    plain = velocity_profile((grid.x, grid.z, fields.velocity[:, 0, :, 0], fields.velocity[:, 0, :, 2]), 0.020)
    np.testing.assert_allclose(plain.v_z, between.v_z, rtol=1e-15)


def test_velocity_profile_rejects_bad_input():
    grid = Grid(origin=(-W / 2, 0.0, 0.0), spacing=(0.006, T, 0.006), shape=(25, 1, 30))
    fields = plane_fields(grid, 0.0, -1.0)
    with pytest.raises(ValueError, match="z_value"):
        velocity_profile(fields, 0.001)  # below the first row (3 mm)
    with pytest.raises(ValueError, match="layer"):
        velocity_profile(plane_fields(SILO_GRID, 0.0, -1.0), 0.05)
    with pytest.raises(ValueError, match="method"):
        velocity_profile(fields, 0.05, method="cubic")


# --------------------------------------------------------------------------- flow channel boundary


@pytest.mark.parametrize("z", [0.04, 0.08, 0.12])
def test_flow_channel_boundary_of_the_analytic_profile_on_grid_nodes(z):
    x = SILO_GRID.x
    boundary = flow_channel_boundary(x, analytic_v_z(x, z))
    expected = np.sqrt(-4 * B_KIN * z * np.log(boundary.fractions))
    np.testing.assert_allclose(boundary.fractions, [0.01, 0.05, 0.10])
    cell = SILO_GRID.spacing[0]
    finite = np.isfinite(boundary.right)
    assert finite.any()
    np.testing.assert_allclose(boundary.right[finite], expected[finite], rtol=0, atol=cell)
    np.testing.assert_allclose(boundary.left[finite], -expected[finite], rtol=0, atol=cell)
    # Where the analytic boundary lies beyond the outermost node, none is reported.
    assert np.all(expected[~finite] > x[-1])


def test_flow_channel_boundary_interpolates_linearly_and_reports_an_open_side():
    x = np.array([-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0])
    v = -np.array([0.5, 0.5, 6.0, 10.0, 4.0, 0.0, 0.0])
    boundary = flow_channel_boundary(x, v, fractions=[0.5, 0.02])
    # Right: 10 -> 4 between 0 and 1, then 4 -> 0 between 1 and 2: 50 % (5) at (10 - 5) / (10 - 4) = 5/6;
    # 2 % (0.2) at 1 + (4 - 0.2) / 4 = 1.95.
    np.testing.assert_allclose(boundary.right, [5.0 / 6.0, 1.95], rtol=1e-14)
    # Left: 50 % at -(1 + (6 - 5) / 5.5) = -1.1818...; 2 % never reached (0.5 > 0.2): NaN.
    assert boundary.left[0] == pytest.approx(-(1 + 1 / 5.5), rel=1e-14)
    assert math.isnan(boundary.left[1])
    assert boundary.centreline_speed == 10.0
    assert isinstance(boundary, FlowChannelBoundary)
    assert boundary.width[0] == pytest.approx(5.0 / 6.0 + 1 + 1 / 5.5, rel=1e-14)


def test_flow_channel_boundary_can_subtract_the_wall_velocity():
    x = SILO_GRID.x
    z = 0.02  # the Gaussian is negligible (exp(-32.4) ~ 1e-14) at the outermost nodes, x = 72 mm
    wall = -0.03
    plain = flow_channel_boundary(x, analytic_v_z(x, z))
    shifted = flow_channel_boundary(x, analytic_v_z(x, z) + wall, subtract_wall_velocity=True)
    assert shifted.wall_velocity == pytest.approx(wall, rel=1e-9)
    np.testing.assert_allclose(shifted.right, plain.right, rtol=1e-9)
    np.testing.assert_allclose(shifted.left, plain.left, rtol=1e-9)


def test_flow_channel_boundary_validation():
    x = np.linspace(-1, 1, 5)
    with pytest.raises(ValueError, match="fractions"):
        flow_channel_boundary(x, -np.ones(5), fractions=[1.5])
    with pytest.raises(ValueError, match="x"):
        flow_channel_boundary(x[::-1], -np.ones(5))
    with pytest.raises(ValueError, match="centreline"):
        flow_channel_boundary(x, np.zeros(5))


# --------------------------------------------------------------------------- kinematic model


@pytest.mark.parametrize("z", [0.04, 0.08, 0.12])
def test_fit_recovers_the_kinematic_constant_from_exact_samples(z):
    x = SILO_GRID.x
    fit = fit_kinematic_constant(x, analytic_v_z(x, z), z)
    assert isinstance(fit, KinematicFit)
    assert fit.B == pytest.approx(B_KIN, rel=1e-8)
    assert fit.A == pytest.approx(-A_CENTRE, rel=1e-8)
    assert fit.rms_residual < 1e-10


@pytest.fixture(scope="module")
def coarse_grained_kinematic_flow():
    """Particles on a 2 mm lattice filling the silo, moving with the kinematic-model field."""
    a = 0.002
    axes = [lo + (np.arange(round((hi - lo) / a)) + 0.5) * a
            for lo, hi in zip(SILO_GRID.lower, SILO_GRID.upper)]
    positions = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    x, z = positions[:, 0], positions[:, 2]
    v_z = analytic_v_z(x, z)
    velocities = np.zeros_like(positions)
    velocities[:, 2] = v_z
    width = 0.0045
    fields = coarse_grain(positions, 2e-6, velocities, SILO_GRID, width)
    return depth_average(fields), width


@pytest.mark.parametrize("z", [0.081, 0.123])  # node rows (3 + 6 k mm): no interpolation in z
def test_coarse_grained_gaussian_flow_gives_back_B_and_the_boundary(coarse_grained_kinematic_flow, z):
    averaged, width = coarse_grained_kinematic_flow
    profile = velocity_profile(averaged, z)
    fit = fit_kinematic_constant(profile.x, profile.v_z, z, kernel_width=width)
    assert fit.B == pytest.approx(B_KIN, rel=0.01)
    # Without the kernel correction the smoothing widens the profile: B is biased high.
    raw = fit_kinematic_constant(profile.x, profile.v_z, z)
    assert raw.B > fit.B
    boundary = flow_channel_boundary(profile.x, profile.v_z)
    expected = np.sqrt(-4 * B_KIN * z * np.log(boundary.fractions))
    cell = SILO_GRID.spacing[0]
    np.testing.assert_allclose(boundary.right, expected, rtol=0, atol=cell)
    np.testing.assert_allclose(boundary.left, -expected, rtol=0, atol=cell)


def test_kinematic_horizontal_velocity_is_minus_B_times_the_gradient():
    # Central differences are exact for a quadratic: v_z = c x^2 -> dv/dx = 2 c x.
    x = np.linspace(-0.075, 0.075, 26)
    c = -3.0
    u = kinematic_horizontal_velocity(x, c * x**2, B_KIN)
    np.testing.assert_allclose(u[1:-1], -B_KIN * 2 * c * x[1:-1], rtol=1e-12, atol=1e-17)
    # For the Gaussian profile u points to the axis above the outlet (x u < 0).
    z = 0.08
    fine = np.linspace(-0.075, 0.075, 3001)
    v = kinematic_velocity(fine, z, -A_CENTRE, B_KIN)
    u = kinematic_horizontal_velocity(fine, v, B_KIN)
    exact = -B_KIN * v * (-2 * fine / (4 * B_KIN * z))
    np.testing.assert_allclose(u[1:-1], exact[1:-1], rtol=0, atol=1e-5 * A_CENTRE)
    assert np.all(fine[1:-1] * u[1:-1] <= 0.0)


def test_kinematic_validation():
    with pytest.raises(ValueError, match="z"):
        fit_kinematic_constant([-1, 0, 1], [-0.1, -1, -0.1], 0.0)
    with pytest.raises(ValueError, match="kernel_width"):
        fit_kinematic_constant([-1, 0, 1], [-0.1, -1, -0.1], 1.0, kernel_width=10.0)
    with pytest.raises(ValueError, match="B"):
        kinematic_horizontal_velocity([0, 1], [0, 1], -1.0)


# --------------------------------------------------------------------------- flow rate


def test_profile_flow_rate_of_a_parabola():
    # v_z = -V (1 - (2x/W)^2) over [-W/2, W/2]: integral of v_z dx = -(2/3) V W, so the
    # (downward, positive) mass flow rate is +(2/3) rho V W T.
    V, rho = 0.1, 667.0
    exact = 2.0 / 3.0 * rho * V * W * T
    x = np.linspace(-W / 2, W / 2, 2001)
    rate = profile_flow_rate(x, -V * (1 - (2 * x / W) ** 2), rho, T)
    # Trapezoid error for a parabola: (b - a) h^2 f'' / 12 with f'' = 8 V / W^2 -> rho T W h^2 (8 V / W^2) / 12.
    h = W / 2000
    assert rate == pytest.approx(exact - rho * T * W * h**2 * 8 * V / W**2 / 12, rel=1e-12)
    assert rate > 0.0
    # Cell-centred nodes with the walls as bounds: the midpoint rule, error -(b - a) h^2 f'' / 24.
    nodes = SILO_GRID.x
    h = SILO_GRID.spacing[0]
    rate = profile_flow_rate(nodes, -V * (1 - (2 * nodes / W) ** 2), rho, T, bounds=(-W / 2, W / 2))
    assert rate == pytest.approx(exact + rho * T * W * h**2 * 8 * V / W**2 / 24, rel=1e-12)
    assert profile_flow_rate(nodes, V * np.ones_like(nodes), rho, T, bounds=(-W / 2, W / 2)) == pytest.approx(
        -rho * T * W * V, rel=1e-12
    )
    with pytest.raises(ValueError, match="bounds"):
        profile_flow_rate(nodes, -np.ones_like(nodes), rho, T, bounds=(-0.01, 0.01))
    with pytest.raises(ValueError, match="bulk_density"):
        profile_flow_rate(nodes, -np.ones_like(nodes), 0.0, T)


# --------------------------------------------------------------------------- Janssen


def test_janssen_matches_a_hand_calculation():
    # phi = 30 deg: sin = 1/2, K = (1 - 1/2) / (1 + 1/2) = 1/3.
    # W = 0.15 m, T = 0.04 m, mu_sw = 0.2, mu_fw = 0.25:
    #   T mu_sw + W mu_fw = 0.008 + 0.0375 = 0.0455 m
    #   z_c = W T / (2 K * 0.0455) = 0.006 / (0.0303333...) = 18/91 = 0.197802198 m
    # gamma = rho_b g = 667 * 9.81 = 6543.27 N/m3; gamma z_c = 1294.273187 Pa
    # h = 0.2 m: exp(-0.2 / 0.197802) = exp(-1.0111111) = 0.363814517
    #   sigma_v = 1294.273187 * (1 - 0.363814517) = 823.397813 Pa
    assert janssen_coefficient(30.0) == pytest.approx(1.0 / 3.0, rel=1e-14)
    z_c = janssen_characteristic_depth(W, T, 0.2, 0.25, 30.0)
    assert z_c == pytest.approx(18.0 / 91.0, rel=1e-13)
    stress = janssen_vertical_stress(0.2, 667.0, W, T, 0.2, 0.25, 30.0)
    assert stress == pytest.approx(823.397813, rel=1e-8)


def test_janssen_limits():
    h = np.array([0.0, 1e-6, 10.0])
    stress = janssen_vertical_stress(h, 667.0, W, T, 0.2, 0.25, 30.0)
    gamma = 667.0 * 9.81
    assert stress[0] == 0.0
    assert stress[1] == pytest.approx(gamma * 1e-6, rel=1e-5)  # hydrostatic near the surface
    assert stress[2] == pytest.approx(gamma * 18.0 / 91.0, rel=1e-12)  # saturates at gamma z_c
    # No wall friction: hydrostatic everywhere.
    assert janssen_vertical_stress(0.3, 667.0, W, T, 0.0, 0.0, 30.0) == pytest.approx(gamma * 0.3, rel=1e-14)
    with pytest.raises(ValueError, match="depth_below_surface"):
        janssen_vertical_stress(-0.1, 667.0, W, T, 0.2, 0.25, 30.0)
    with pytest.raises(ValueError, match="internal_friction_angle_deg"):
        janssen_vertical_stress(0.1, 667.0, W, T, 0.2, 0.25, 95.0)
    with pytest.raises(ValueError, match="wall_friction_front"):
        janssen_vertical_stress(0.1, 667.0, W, T, 0.2, -0.25, 30.0)


# --------------------------------------------------------------------------- comparison


def test_profile_errors_by_hand():
    errors = profile_errors([1.0, 2.0, 3.0], [1.0, 2.0, 4.0], uncertainty=0.5)
    assert isinstance(errors, ProfileErrors)
    # mean |s - m| = 1/3, mean |m| = 7/3 -> 100 / 7 %.
    assert errors.mean_error_percent == pytest.approx(100.0 / 7.0, rel=1e-14)
    assert errors.rms_error == pytest.approx(math.sqrt(1.0 / 3.0), rel=1e-14)
    assert errors.max_abs_error == 1.0
    assert errors.n_points == 3
    assert errors.fraction_within_uncertainty == pytest.approx(2.0 / 3.0)
    assert errors.normalised_rms == pytest.approx(math.sqrt(4.0 / 3.0), rel=1e-14)
    plain = profile_errors([-1.0, -2.0], [-1.0, -2.0])
    assert plain.mean_error_percent == 0.0 and plain.fraction_within_uncertainty is None
    with pytest.raises(ValueError, match="measured"):
        profile_errors([1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="uncertainty"):
        profile_errors([1.0], [1.0], uncertainty=0.0)
