"""Unit tests for siloflow.analysis.numerics.flow on synthetic input with exact answers (no engine)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.flow import (
    BulkDensity,
    DischargeHistory,
    FlowRateFit,
    beverloo_mass_flow_rate,
    column_surface_heights,
    discharged_mass_history,
    filling_bulk_density,
    mass_in_silo,
    slab_bulk_density,
    steady_flow_rate,
    volumetric_flow_rate,
)
from siloflow.model.cases.particles import clump_volume, equivalent_diameter

# --------------------------------------------------------------------------- Beverloo


def test_beverloo_matches_formula_by_hand():
    # B0 - k d = 0.04 - 1.5 * 0.004 = 0.034 m
    expected = 0.58 * 667.0 * math.sqrt(9.81) * 0.04 * 0.034**1.5
    rate = beverloo_mass_flow_rate(667.0, 0.04, 0.04, 0.004)
    assert rate == pytest.approx(expected, rel=1e-14)


def test_beverloo_exact_with_simple_numbers():
    # C = 1, rho = 1, g = 4, L = 2, B0 - k d = 4 - 2 * 0.5 * ... -> choose B0 - k d = 4: 1 * 1 * 2 * 2 * 8 = 32
    rate = beverloo_mass_flow_rate(
        bulk_density=1.0,
        outlet_width=5.0,
        outlet_length=2.0,
        particle_diameter=0.5,
        discharge_coefficient=1.0,
        shape_coefficient=2.0,
        gravity=4.0,
    )
    assert rate == 32.0


def test_beverloo_outlet_too_small():
    with pytest.raises(ValueError, match=r"outlet too small for particles: B0 - k d = -0\.002 m"):
        beverloo_mass_flow_rate(667.0, 0.004, 0.04, 0.004)


@pytest.mark.parametrize(
    "name, kwargs",
    [
        ("bulk_density", {"bulk_density": -1.0}),
        ("outlet_width", {"outlet_width": 0.0}),
        ("outlet_length", {"outlet_length": float("nan")}),
        ("particle_diameter", {"particle_diameter": float("inf")}),
        ("gravity", {"gravity": 0.0}),
    ],
)
def test_beverloo_rejects_bad_arguments_by_name(name, kwargs):
    arguments = dict(bulk_density=667.0, outlet_width=0.04, outlet_length=0.04, particle_diameter=0.004)
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=name):
        beverloo_mass_flow_rate(**arguments)


def test_volumetric_flow_rate():
    assert volumetric_flow_rate(2.0, 500.0) == 0.004
    with pytest.raises(ValueError, match="bulk_density"):
        volumetric_flow_rate(2.0, 0.0)


# --------------------------------------------------------------------------- surface and bulk density


def test_column_surface_heights_per_column_with_empty_column():
    width = 4.0  # columns [-2,-1), [-1,0), [0,1), [1,2]
    x = np.array([-1.5, -1.2, 0.5, 2.0, 5.0])  # x = 2.0 is on the wall -> last column; 5.0 outside
    z = np.array([1.0, 3.0, 2.0, 0.5, 100.0])
    radius = np.array([0.1, 0.2, 0.3, 0.4, 0.5])
    heights = column_surface_heights(x, z, radius, width, 4)
    assert heights[0] == pytest.approx(3.2)
    assert math.isnan(heights[1])
    assert heights[2] == pytest.approx(2.3)
    assert heights[3] == pytest.approx(0.9)


def test_column_surface_heights_scalar_radius_and_bad_columns():
    heights = column_surface_heights([-0.5, 0.5], [1.0, 2.0], 0.25, 2.0, 2)
    np.testing.assert_array_equal(heights, [1.25, 2.25])
    with pytest.raises(ValueError, match="n_columns"):
        column_surface_heights([0.0], [0.0], 0.1, 1.0, 0)


def _cubic_lattice(spacing, nx, ny, nz):
    """Centres of a simple cubic lattice filling [-nx a/2, nx a/2] x [0, ny a] x [0, nz a]."""
    ix, iy, iz = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    x = (ix.ravel() + 0.5) * spacing - 0.5 * nx * spacing
    y = (iy.ravel() + 0.5) * spacing
    z = (iz.ravel() + 0.5) * spacing
    return np.column_stack([x, y, z])


def test_filling_bulk_density_cubic_lattice_is_exact():
    # Dyadic numbers keep every operation exact in floating point.
    spacing, clump_mass = 0.25, 0.5
    nx, ny, nz = 8, 4, 12
    positions = _cubic_lattice(spacing, nx, ny, nz)
    # Surface = top centre + a/2 = nz a = 3.0; margin 2a -> z_m = 2.5 = 10 a, below layer 10.
    result = filling_bulk_density(
        positions, clump_mass, width=nx * spacing, depth=ny * spacing,
        surface_margin=2 * spacing, n_columns=4, radius=spacing / 2,
    )
    assert isinstance(result, BulkDensity)
    assert result.measured_height == 10 * spacing
    assert result.mass == nx * ny * 10 * clump_mass
    assert result.volume == (nx * spacing) * (ny * spacing) * (10 * spacing)
    assert result.density == clump_mass / spacing**3  # 32 kg/m3 exactly


def test_filling_bulk_density_lattice_realistic_numbers():
    spacing, clump_mass = 0.004, 2.0e-5
    nx, ny, nz = 10, 5, 30
    positions = _cubic_lattice(spacing, nx, ny, nz)
    result = filling_bulk_density(
        positions, np.full(len(positions), clump_mass), width=nx * spacing, depth=ny * spacing,
        surface_margin=3 * spacing, n_columns=5, radius=spacing / 2,
    )
    assert result.measured_height == pytest.approx(27 * spacing, rel=1e-12)
    assert result.density == pytest.approx(clump_mass / spacing**3, rel=1e-12)


def test_filling_bulk_density_excludes_central_heap():
    spacing, clump_mass = 0.25, 0.5
    nx, ny, nz = 8, 4, 12
    positions = _cubic_lattice(spacing, nx, ny, nz)
    # A heap on the middle half of the width: extra layers that must not count.
    heap = _cubic_lattice(spacing, nx // 2, ny, 4)
    heap[:, 2] += nz * spacing
    all_positions = np.vstack([positions, heap])
    result = filling_bulk_density(
        all_positions, clump_mass, width=nx * spacing, depth=ny * spacing,
        surface_margin=2 * spacing, n_columns=4, radius=spacing / 2,
    )
    assert result.measured_height == 10 * spacing
    assert result.density == clump_mass / spacing**3


def test_filling_bulk_density_errors():
    positions = _cubic_lattice(0.25, 8, 4, 4)
    with pytest.raises(ValueError, match="surface_margin"):
        filling_bulk_density(positions, 0.5, 2.0, 1.0, surface_margin=5.0, n_columns=4, radius=0.125)
    with pytest.raises(ValueError, match="n_columns"):
        filling_bulk_density(positions, 0.5, 2.0, 1.0, surface_margin=0.1, n_columns=16, radius=0.125)
    with pytest.raises(ValueError, match="clump_position"):
        filling_bulk_density(positions[:, :2], 0.5, 2.0, 1.0, surface_margin=0.1)
    with pytest.raises(ValueError, match="clump_mass"):
        filling_bulk_density(positions, np.ones(3), 2.0, 1.0, surface_margin=0.1)


def test_slab_bulk_density_of_slabs_with_known_masses():
    # area 0.5 m2, z_m = 4 m, slabs of 1 m: masses 0.5, 1, 1.5, 2 kg give densities 1, 2, 3, 4 kg/m3
    z = np.array([0.5, 1.0, 1.5, 2.2, 2.7, 3.9, -0.1, 4.0])  # 1.0 lies on an edge: the slab above
    mass = np.array([0.5, 0.25, 0.75, 0.75, 0.75, 2.0, 9.0, 9.0])  # the last two lie outside [0, 4)
    estimate = slab_bulk_density(z, mass, area=0.5, measured_height=4.0, slab_thickness=1.0)
    assert (estimate.value, estimate.n, estimate.method, estimate.dof) == (2.5, 4, "slab spread", 3.0)
    assert estimate.std_error == pytest.approx(math.sqrt(5.0 / 3.0) / 2.0, rel=1e-14)  # std(1..4) / sqrt(4)


def test_slab_bulk_density_of_a_lattice_with_whole_layers_per_slab_has_no_spread():
    spacing, clump_mass = 0.25, 0.5
    positions = _cubic_lattice(spacing, 8, 4, 12)
    # z_m = 10 a in slabs of at least 2 a: 5 slabs of two layers each
    estimate = slab_bulk_density(positions[:, 2], clump_mass, 2.0 * 1.0, 10 * spacing, 2 * spacing)
    assert (estimate.value, estimate.std_error, estimate.n) == (clump_mass / spacing**3, 0.0, 5)


def test_slab_bulk_density_of_a_layer_thinner_than_two_slabs_has_an_unknown_error():
    estimate = slab_bulk_density([0.1, 0.2], 1.0, area=1.0, measured_height=1.0, slab_thickness=0.6)
    assert (estimate.value, estimate.n) == (2.0, 1) and math.isnan(estimate.std_error)
    with pytest.raises(ValueError, match="slab_thickness"):
        slab_bulk_density([0.1], 1.0, area=1.0, measured_height=1.0, slab_thickness=0.0)
    with pytest.raises(ValueError, match="clump_mass"):
        slab_bulk_density([0.1, 0.2], [1.0], area=1.0, measured_height=1.0, slab_thickness=0.5)


# --------------------------------------------------------------------------- mass and history


def test_mass_in_silo_counts_at_or_above_plane():
    z = np.array([-0.01, 0.0, 0.02, 0.5])
    mass = np.array([1.0, 2.0, 4.0, 8.0])
    assert mass_in_silo(z, mass) == 14.0
    assert mass_in_silo(z, 0.5) == 1.5
    assert mass_in_silo(z, mass, outlet_plane=0.1) == 8.0


def test_discharged_mass_history():
    history = discharged_mass_history([2.0, 2.5, 3.0], [10.0, 9.0, 7.5])
    assert isinstance(history, DischargeHistory)
    np.testing.assert_array_equal(history.time, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(history.discharged_mass, [0.0, 1.0, 2.5])


def test_discharged_mass_history_validation():
    with pytest.raises(ValueError, match="equal lengths"):
        discharged_mass_history([0.0, 1.0], [1.0])
    with pytest.raises(ValueError, match="increasing"):
        discharged_mass_history([0.0, 1.0, 1.0], [3.0, 2.0, 1.0])


# --------------------------------------------------------------------------- steady flow rate


def _synthetic_discharge(rate=2.5, t_delay=0.1, t_end=1.0, n=201):
    """Quadratic start-up, then exactly m = rate (t - t_delay), then saturation at the end."""
    time = np.linspace(0.0, t_end, n)
    t_linear = 2.0 * t_delay  # a parabola from (0, 0) with slope `rate` meets the line here
    mass = np.where(time < t_linear, rate * time**2 / (4.0 * t_delay), rate * (time - t_delay))
    m_final = rate * (0.8 * t_end - t_delay)
    mass = np.minimum(mass, m_final)  # the silo empties: the curve flattens
    return time, mass


def test_steady_flow_rate_linear_history_is_exact():
    time, mass = _synthetic_discharge()
    fit = steady_flow_rate(time, mass)
    assert isinstance(fit, FlowRateFit)
    assert fit.mass_flow_rate == pytest.approx(2.5, abs=1e-12)
    assert fit.intercept == pytest.approx(-0.25, abs=1e-12)
    assert fit.standard_error < 1e-12
    # Window from 20 % to 80 % of the final mass, both inside the linear part.
    m_final = mass[-1]
    assert fit.t_start == time[np.argmax(mass >= 0.2 * m_final)]
    assert fit.t_end == time[np.argmax(mass >= 0.8 * m_final)]
    assert fit.t_start > 0.2 and fit.t_end < 0.8
    assert fit.n_points == np.count_nonzero((time >= fit.t_start) & (time <= fit.t_end))


def test_steady_flow_rate_explicit_window():
    time, mass = _synthetic_discharge()
    fit = steady_flow_rate(time, mass, window=(0.3, 0.6))
    assert fit.mass_flow_rate == pytest.approx(2.5, abs=1e-12)
    assert (fit.t_start, fit.t_end) == (0.3, 0.6)
    assert fit.n_points == 61


def test_steady_flow_rate_full_history_is_biased_so_window_matters():
    time, mass = _synthetic_discharge()
    fit = steady_flow_rate(time, mass, fraction_window=(0.0, 1.0))
    assert abs(fit.mass_flow_rate - 2.5) > 0.05


def test_steady_flow_rate_noisy_within_standard_error():
    rng = np.random.default_rng(12345)
    time = np.linspace(0.0, 2.0, 401)
    true_rate, noise = 1.7, 0.01
    mass = true_rate * time + rng.normal(0.0, noise, time.size)
    fit = steady_flow_rate(time, mass, window=(0.0, 2.0))
    # Theoretical standard error of an OLS slope: sigma / sqrt(sum (t - mean t)^2).
    expected_se = noise / math.sqrt(np.sum((time - time.mean()) ** 2))
    assert fit.standard_error == pytest.approx(expected_se, rel=0.15)
    assert abs(fit.mass_flow_rate - true_rate) < 4.0 * fit.standard_error


def test_steady_flow_rate_too_few_points_names_window():
    time, mass = _synthetic_discharge(n=201)
    # Samples every 0.005 s: only 0.3 and 0.305 fall in the window.
    with pytest.raises(ValueError, match=r"window = \(0\.2975, 0\.3075\) s holds 2 samples"):
        steady_flow_rate(time, mass, window=(0.2975, 0.3075))
    coarse_time = np.array([0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="fraction_window"):
        steady_flow_rate(coarse_time, np.array([0.0, 1.0, 2.0]))


def test_steady_flow_rate_validation():
    with pytest.raises(ValueError, match="equal lengths"):
        steady_flow_rate([0.0, 1.0, 2.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="fraction_window"):
        steady_flow_rate([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], fraction_window=(0.8, 0.2))
    with pytest.raises(ValueError, match="window"):
        steady_flow_rate([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], window=(2.0, 1.0))


# --------------------------------------------------------------------------- clump volume


def test_clump_volume_one_sphere():
    assert clump_volume([[1.0, 2.0, 3.0]], [2.0]) == pytest.approx(32.0 / 3.0 * math.pi, rel=1e-15)


def test_clump_volume_two_equal_spheres_lens_by_hand():
    # r = 1, d = 1: lens = pi (4 + 1)(2 - 1)^2 / 12 = 5 pi / 12; union = 8 pi / 3 - 5 pi / 12 = 9 pi / 4.
    volume = clump_volume([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], [1.0, 1.0])
    assert volume == pytest.approx(9.0 * math.pi / 4.0, rel=1e-14)


def test_clump_volume_two_touching_and_disjoint_spheres_sum():
    sphere = 4.0 / 3.0 * math.pi
    assert clump_volume([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [1.0, 1.0]) == pytest.approx(2 * sphere, rel=1e-15)
    assert clump_volume([[0.0, 0.0, 0.0], [0.0, 5.0, 0.0]], [1.0, 2.0]) == pytest.approx(9 * sphere, rel=1e-15)
    # Three disjoint spheres take the exact sum too.
    three = clump_volume([[0, 0, 0], [3, 0, 0], [0, 3, 0]], [1.0, 1.0, 1.0])
    assert three == pytest.approx(3 * sphere, rel=1e-15)


def test_clump_volume_sphere_inside_sphere():
    assert clump_volume([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]], [1.0, 0.5]) == pytest.approx(4.0 / 3.0 * math.pi)


def test_clump_volume_unequal_lens_matches_cap_formula():
    # Two caps: cap height h_i = (r_j - r_i + d)(r_j + r_i - d) / (2 d), cap volume pi h^2 (3 r - h) / 3.
    r1, r2, d = 1.0, 0.6, 1.2
    h1 = (r2 - r1 + d) * (r2 + r1 - d) / (2 * d)
    h2 = (r1 - r2 + d) * (r1 + r2 - d) / (2 * d)
    lens = math.pi * h1**2 * (3 * r1 - h1) / 3 + math.pi * h2**2 * (3 * r2 - h2) / 3
    expected = 4.0 / 3.0 * math.pi * (r1**3 + r2**3) - lens
    volume = clump_volume([[0.0, 0.0, 0.0], [d, 0.0, 0.0]], [r1, r2])
    assert volume == pytest.approx(expected, rel=1e-13)


@pytest.mark.parametrize(
    "second_centre",
    [(0.0, 0.0, 0.75e-3), (0.3e-3, -0.5e-3, 0.4e-3), (2.0e-3, 0.0, 0.0)],
)
def test_clump_volume_numerical_matches_two_sphere_closed_form(second_centre):
    # The sphere2 pellet of the study: 3 mm spheres 0.75 mm apart, and other placements.
    centres = np.array([[0.0, 0.0, 0.0], second_centre])
    radii = np.array([1.5e-3, 1.5e-3])
    exact = clump_volume(centres, radii)
    numerical = clump_volume(centres, radii, method="grid")
    assert numerical == pytest.approx(exact, rel=1e-3)


def test_clump_volume_numerical_three_spheres_in_a_row():
    # Neighbours overlap, the outer two do not: inclusion-exclusion is exact with pair lenses only.
    r, d = 1.0, 1.5
    lens = math.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    expected = 3 * 4.0 / 3.0 * math.pi * r**3 - 2 * lens
    volume = clump_volume([[0, 0, 0], [d, 0, 0], [2 * d, 0, 0]], [r, r, r])
    assert volume == pytest.approx(expected, rel=1e-3)


def test_clump_volume_tetrahedron_is_between_bounds_and_deterministic():
    spacing, r = 0.75e-3, 1.5e-3
    vertices = spacing / math.sqrt(8.0) * np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    volume = clump_volume(vertices, np.full(4, r))
    one_sphere = 4.0 / 3.0 * math.pi * r**3
    assert one_sphere < volume < 4 * one_sphere
    assert volume == clump_volume(vertices, np.full(4, r))


def test_clump_volume_validation():
    with pytest.raises(ValueError, match="sphere_radii"):
        clump_volume([[0.0, 0.0, 0.0]], [-1.0])
    with pytest.raises(ValueError, match="sphere_positions"):
        clump_volume([[0.0, 0.0]], [1.0])
    with pytest.raises(ValueError, match="resolution"):
        clump_volume([[0.0, 0.0, 0.0]], [1.0], resolution=2)


def test_equivalent_diameter():
    assert equivalent_diameter(math.pi / 6.0) == pytest.approx(1.0, rel=1e-15)
    assert equivalent_diameter(4.0 / 3.0 * math.pi * 0.0019**3) == pytest.approx(0.0038, rel=1e-14)
    with pytest.raises(ValueError, match="volume"):
        equivalent_diameter(0.0)
