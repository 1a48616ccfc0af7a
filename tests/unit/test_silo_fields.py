"""Silo field analysis (fields, field_study, field_comparisons) on synthetic input with exact answers."""

from __future__ import annotations

import json
import math
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import OptimizeWarning

from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.model.contacts import ContactFrame
from siloflow.model.frames import ClumpFrame
from siloflow.model.constants import GRAVITY
from siloflow.analysis.numerics.field_ops import depth_average
from siloflow.analysis.numerics.grid import Fields, Grid
from siloflow.analysis.numerics.profiles import flow_channel_boundary, velocity_profile
from siloflow.analysis.numerics.janssen import janssen_vertical_stress
from siloflow.analysis.studies.silo_flat.field_comparisons import (
    MEASURED_PLANES,
    compare_with_measurements,
    comparison_plane,
    measured_comparison_rows,
    parametric_profiles,
    seed_janssen,
    seed_kinematic,
    seed_profiles,
    parametric_rows,
)
from siloflow.analysis.studies.silo_flat.field_clock import WINDOW_CONFIGURED, WINDOW_STEADY, averaging_window
from siloflow.analysis.studies.silo_flat.field_study import (
    COVERED_DENSITY_FRACTION,
    FIELD_BATCHES,
    SURFACE_COLUMN_DIAMETERS,
    SiloDimensions,
    SiloFieldOptions,
    analyse_silo_fields,
    boundary_rows,
    centreline_rows,
    field_summary,
    fill_surface_heights,
    force_chain_cap,
    instantaneous_profile_rows,
    janssen_rows,
    kinematic_rows,
    profile_heights_inside,
    profile_rows,
    vtk_series,
)
from siloflow.analysis.studies.silo_flat.fields import (
    FieldSettings,
    JanssenComparison,
    ProfileAnalysis,
    ProfileUncertainty,
    analyse_profiles,
    centreline_velocity,
    clump_fields,
    compare_janssen,
    mirror_bin_error,
    profile_mass_flow_rate,
    profile_uncertainty,
    silo_grid,
)
from siloflow.analysis.studies.silo_flat.measured import MeasuredProfile


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
    np.testing.assert_allclose(comparison.height, surface - comparison.depth_below_surface, rtol=1e-12)
    np.testing.assert_allclose(comparison.hydrostatic, 667.0 * GRAVITY * comparison.depth_below_surface, rtol=1e-12)
    # no bin width, no bulk density error: both errors unknown
    assert comparison.bin_pairs == 0
    assert np.all(np.isnan(comparison.simulated_error)) and np.all(np.isnan(comparison.hydrostatic_error))


def test_a_fill_too_shallow_for_the_kernel_is_refused_with_both_heights():
    grid = silo_grid(0.04, 0.012, 0.03, (0.006, 0.004, 0.006))
    stress = np.zeros(grid.shape + (3, 3))
    with pytest.raises(ValueError, match=r"kernel's reach \(0\.0135 m\).*surface \(0\.025 m\).*above 0\.027 m"):
        compare_janssen(stress, grid, 0.025, 600.0, 0.04, 0.012, 0.0, 0.0, 30.0, margin=0.0135)


def test_janssen_error_is_the_difference_of_mirror_bins_and_hydrostatic_carries_the_density_error():
    grid = silo_grid(0.08, 0.012, 0.06, (0.01, 0.004, 0.006))  # 8 columns of 10 mm, 10 rows
    # sigma_zz = c_i (k + 1) in column i, row k: the mirror bins of two columns have means (2, 5) on the left and
    # (1, 4) on the right, from the walls inwards: differences 1 and 1
    column_factor = np.array([2.0, 2.0, 5.0, 5.0, 4.0, 4.0, 1.0, 1.0])
    stress = np.zeros(grid.shape + (3, 3))
    stress[..., 2, 2] = column_factor[:, None, None] * (np.arange(grid.shape[2]) + 1.0)[None, None, :]
    comparison = compare_janssen(stress, grid, 0.06, 600.0, 0.08, 0.012, 0.0, 0.0, 30.0, margin=0.0,
                                 bin_width=0.02, bulk_density_error=12.0)
    assert comparison.bin_pairs == 2
    rows = np.arange(grid.shape[2]) + 1.0
    np.testing.assert_allclose(comparison.simulated, 3.0 * rows, rtol=1e-14)
    # sqrt(1^2 + 1^2) / (2 x 2 bins per side)
    np.testing.assert_allclose(comparison.simulated_error, rows * math.sqrt(2.0) / 4.0, rtol=1e-14)
    np.testing.assert_allclose(comparison.hydrostatic, 600.0 * GRAVITY * comparison.depth_below_surface, rtol=1e-14)
    np.testing.assert_allclose(comparison.hydrostatic_error, 12.0 * GRAVITY * comparison.depth_below_surface,
                               rtol=1e-14)
    # the symmetric shape of a profile is not noise: a symmetric stress has no error
    symmetric = stress.copy()
    symmetric[..., 2, 2] = np.array([1.0, 2.0, 5.0, 9.0, 9.0, 5.0, 2.0, 1.0])[:, None, None]
    assert np.all(compare_janssen(symmetric, grid, 0.06, 600.0, 0.08, 0.012, 0.0, 0.0, 30.0,
                                  bin_width=0.02).simulated_error == 0.0)
    # bins wider than half the silo: none
    wide = compare_janssen(stress, grid, 0.06, 600.0, 0.08, 0.012, 0.0, 0.0, 30.0, bin_width=0.05)
    assert wide.bin_pairs == 0 and np.all(np.isnan(wide.simulated_error))


def test_mirror_bin_error_of_an_odd_profile_with_unequal_bins_by_hand():
    # 7 values: halves [1, 2, 6] and, from the right wall, [3, 2, 4]; the middle value 100 is left out.
    # One pair: d = 3 - 3 = 0. Two pairs, bins of 2 and 1 (numpy.array_split): d = 1.5 - 2.5 = -1 and 6 - 4 = 2
    values = [1.0, 2.0, 6.0, 100.0, 4.0, 2.0, 3.0]
    assert mirror_bin_error(values, 1) == 0.0
    assert mirror_bin_error(values, 2) == pytest.approx(math.sqrt(5.0) / 4.0, rel=1e-14)
    assert math.isnan(mirror_bin_error(values, 0)) and math.isnan(mirror_bin_error(values, 4))


# --------------------------------------------------------------------------- the study of one run (field_study)


def _clumps(position, velocity, mass, time=0.0, step=0):
    position = np.asarray(position, dtype=float)
    n = len(position)
    return ClumpFrame(time=time, step=step, clump_id=np.arange(1, n + 1), position=position,
                      velocity=np.broadcast_to(np.asarray(velocity, dtype=float), (n, 3)), mass=np.full(n, mass),
                      n_spheres=np.full(n, 2))


# --------------------------------------------------------------------------- errors of B(z) and the boundary


PROFILE_GRID = Grid(origin=(-0.075, 0.0, 0.0), spacing=(0.002, 0.012, 0.01), shape=(75, 1, 6))  # z = 5 ... 55 mm


def _gaussian_frame(B, density_above=1.0, A=0.2):
    """One-layer fields of density 1 (``density_above`` from z = 30 mm up) whose v_z is the kinematic model's
    Gaussian -A exp(-x^2 / (4 B z)) at every node row."""
    x, z = PROFILE_GRID.x[:, None], PROFILE_GRID.z[None, :]
    density = np.where(z < 0.03, 1.0, density_above) * np.ones_like(x)
    momentum = np.zeros(PROFILE_GRID.shape + (3,))
    momentum[:, 0, :, 2] = density * -A * np.exp(-x**2 / (4.0 * B * z))
    return Fields.from_moments(PROFILE_GRID, density[:, None, :], momentum, np.zeros(PROFILE_GRID.shape + (3, 3)))


def test_profile_uncertainty_is_the_spread_of_batch_fits_over_the_batches_that_cover_each_height():
    heights = (0.015, 0.045)  # node rows: the profiles are exact Gaussians there
    # Frames at t = 0 ... 6; the window (0.5, 6) holds six, cut into five batches of one frame, the oldest
    # (B = 50 mm) left out. The last has density 0.3 above 30 mm: its fill no longer covers 45 mm.
    b_values = (0.002, 0.05, 0.001, 0.002, 0.003, 0.004, 0.010)
    series = [_gaussian_frame(b, density_above=0.3 if k == 6 else 1.0) for k, b in enumerate(b_values)]
    times = np.arange(7.0)
    uncertainty = profile_uncertainty(series, times, (0.5, 6.0), heights, (0.1,), covered_density=0.5,
                                      n_batches=5)
    assert uncertainty.n_batches == 5
    np.testing.assert_array_equal(uncertainty.batches, [5, 4])
    low = np.array([0.001, 0.002, 0.003, 0.004, 0.010])
    expected_b = [np.std(low, ddof=1) / math.sqrt(5), math.sqrt(5.0 / 3.0) / 2.0 * 1e-3]  # 1,2,3,4 mm at 45 mm
    np.testing.assert_allclose(uncertainty.kinematic_B_error, expected_b, rtol=1e-6)
    resolution = 0.002 / math.sqrt(12.0)
    assert uncertainty.boundary_resolution == pytest.approx(resolution, rel=1e-14)
    for i, (z, used) in enumerate(zip(heights, (slice(2, 7), slice(2, 6)))):
        bounds = [flow_channel_boundary(PROFILE_GRID.x, velocity_profile(f, z).v_z, (0.1,))
                  for f in series[used]]
        for side, errors in (("left", uncertainty.fcb_left_error), ("right", uncertainty.fcb_right_error)):
            positions = np.array([getattr(b, side)[0] for b in bounds])
            spread = np.std(positions, ddof=1) / math.sqrt(positions.size)
            assert errors[i, 0] == pytest.approx(math.hypot(spread, resolution), rel=1e-12)


def test_flow_pattern_index_is_wall_over_centreline_velocity_with_its_batch_error():
    # Gaussian v_z = -A exp(-x^2 / (4 B z)): the outermost nodes are x = -0.075 and x = +0.073 (75 nodes, 2 mm)
    x = PROFILE_GRID.x
    z = 0.015
    series = [_gaussian_frame(b) for b in (0.002, 0.05, 0.1)]
    expected = [0.5 * (math.exp(-x[0]**2 / (4 * b * z)) + math.exp(-x[-1]**2 / (4 * b * z))) for b in (0.002, 0.05, 0.1)]
    for frame, index in zip(series, expected):
        analysis = analyse_profiles(frame, (z,), (0.1,))
        assert analysis.flow_pattern_index[0] == pytest.approx(index, rel=1e-12)
    # plug flow: 1; no flow on the axis: unknown
    assert analyse_profiles(_gaussian_frame(1e6), (z,), (0.1,)).flow_pattern_index[0] == pytest.approx(1.0, abs=1e-4)
    assert np.isnan(analyse_profiles(_gaussian_frame(0.002, A=0.0), (z,), (0.1,)).flow_pattern_index[0])
    # three batches of one frame each (window holds t = 1, 2, 3)
    uncertainty = profile_uncertainty([_gaussian_frame(0.01)] + series, np.arange(4.0), (0.5, 3.5), (z,), (0.1,),
                                      covered_density=0.5, n_batches=3)
    assert uncertainty.flow_pattern_index_error[0] == pytest.approx(np.std(expected, ddof=1) / math.sqrt(3), rel=1e-10)


def test_profile_uncertainty_of_a_window_with_one_frame_is_unknown():
    series = [_gaussian_frame(0.002), _gaussian_frame(0.003)]
    uncertainty = profile_uncertainty(series, np.array([0.0, 1.0]), (0.5, 1.5), (0.015,), (0.1,), 0.5)
    assert uncertainty.n_batches == 0 and uncertainty.batches.tolist() == [0]
    assert np.isnan(uncertainty.kinematic_B_error).all() and np.isnan(uncertainty.fcb_right_error).all()
    with pytest.raises(ValueError, match="covered_density"):
        profile_uncertainty(series, np.array([0.0, 1.0]), (0.5, 1.5), (0.015,), (0.1,), 0.0)
    with pytest.raises(ValueError, match="n_batches"):
        profile_uncertainty(series, np.array([0.0, 1.0]), (0.5, 1.5), (0.015,), (0.1,), 0.5, n_batches=1)


def test_fill_surface_is_the_highest_particle_top_per_column_of_four_diameters():
    radius = 0.001
    frame = _lattice_frame(0.06, 0.012, 0.06, 0.002, 1e-5, (0.0, 0.0, 0.0))
    # A step in the fill: nothing above z = 0.04 on the left half.
    keep = ~((frame.position[:, 0] < 0.0) & (frame.position[:, 2] > 0.04))
    stepped = _clumps(frame.position[keep], (0.0, 0.0, 0.0), 1e-5)
    surface = fill_surface_heights(stepped, radius, 0.06)
    # int(0.06 / (4 * 0.002)) = 7 columns of 8.57 mm; columns 0-2 lie left of the axis, column 3 straddles it.
    assert surface.shape == (7,)
    np.testing.assert_allclose(surface, [0.04, 0.04, 0.04, 0.06, 0.06, 0.06, 0.06], rtol=1e-12)
    assert SURFACE_COLUMN_DIAMETERS == 4


def test_profile_heights_inside_the_fill_keep_their_order():
    grid = silo_grid(0.06, 0.012, 0.06, (0.006, 0.004, 0.006))  # nodes z = 3, 9, ..., 57 mm
    requested = [0.002, 0.02, 0.05, 0.052, 0.04]
    assert profile_heights_inside(requested, grid, 0.06, 0.006) == [0.02, 0.05, 0.04]  # up to 57 - 6 mm
    assert profile_heights_inside(requested, grid, 0.03, 0.006) == [0.02]  # up to 30 - 6 mm
    with pytest.raises(ValueError, match="profile_heights"):
        profile_heights_inside(requested, grid, 0.005, 0.006)


def test_force_chain_cap_is_fifty_particle_weights_at_the_simulated_gravity():
    assert GRAVITY == 9.81  # the decks' g, not scipy's 9.80665
    assert force_chain_cap(2e-5) == pytest.approx(50 * 2e-5 * 9.81, rel=1e-15)
    assert force_chain_cap(2e-5, gravity=1.0) == pytest.approx(1e-3, rel=1e-15)


def test_vtk_series_takes_every_nth_frame_named_by_step():
    series = vtk_series((100, 200, 300, 400, 500), np.array([0.0, 0.1, 0.2, 0.3, 0.4]), 2)
    assert series == [(0, 0.0, "fields_100.vti"), (2, 0.2, "fields_300.vti"), (4, 0.4, "fields_500.vti")]
    assert [name for _, _, name in vtk_series((7,), [0.0], 5)] == ["fields_7.vti"]


FIELD_SECTION = {
    "spacing": [0.006, 0.004, 0.006], "kernel": "gaussian", "width_radii": 3.0, "cutoff": 3.0,
    "profile_heights": [0.03, 0.04, 0.06], "fcb_fractions": [0.1], "subtract_wall_velocity": False,
    "average_window": None, "vtk_every": 2,
    "janssen": {"internal_friction_angle_deg": 30.0, "side_wall_friction_angle_deg": 0.0,
                "front_wall_friction_angle_deg": 0.0},
    "force_chain_slice": 0.004, "measured_profiles": None, "measured_plane": "front_wall",
}
#: What of a silo case the field study reads (:meth:`SiloDimensions.from_case`), with round numbers.
CASE = SimpleNamespace(width=0.06, depth=0.012, outlet_width=0.02,
                       particle=SimpleNamespace(equivalent_diameter=0.002, mass=1e-5))


def test_settings_and_dimensions_from_the_config_section_and_the_silo_case():
    options = SiloFieldOptions.from_config(FIELD_SECTION)
    assert options.spacing == (0.006, 0.004, 0.006) and options.profile_heights == (0.03, 0.04, 0.06)
    assert options.average_window is None and options.vtk_every == 2 and options.force_chain_slice == 0.004
    assert options.internal_friction_angle_deg == 30.0 and options.side_wall_friction_angle_deg == 0.0
    assert SiloFieldOptions.from_config({**FIELD_SECTION, "average_window": [0.2, 0.8]}).average_window == (0.2, 0.8)
    settings = options.field_settings(0.001)
    assert settings == FieldSettings((0.006, 0.004, 0.006), "gaussian", 0.003, 3.0)
    silo = SiloDimensions.from_case(CASE)
    assert silo == SiloDimensions(width=0.06, depth=0.012, outlet_width=0.02, particle_radius=0.001, clump_mass=1e-5)


def test_dimensions_of_a_built_silo_case_are_the_numbers_of_its_case_json(tiny_config):
    # the analysis once read these from deck/case.json: the typed case must give them unchanged
    case = build_silo_case(tiny_config)
    summary = json.loads(json.dumps(case.summary(), default=float))
    silo = SiloDimensions.from_case(case)
    assert (silo.width, silo.depth, silo.outlet_width) == (0.08, 0.012, 0.024)
    assert silo == SiloDimensions(width=summary["width_m"], depth=summary["depth_m"],
                                  outlet_width=summary["outlet_width_m"],
                                  particle_radius=0.5 * summary["equivalent_diameter_m"],
                                  clump_mass=summary["clump_mass_kg"])


SPEEDS = (0.1, 0.2, 0.4)  # downward speed of the whole lattice in each frame (m/s)
STEADY_WINDOW = (0.005, 0.03)  # holds the second and third frame (s)
BULK_DENSITY = 600.0
SPACING = 0.002  # lattice spacing (m); one clump of 1e-5 kg per 8e-9 m3
FORCES = (1e-3, 2e-3, 1.0)  # normal forces of the three vertical contacts (N)


@pytest.fixture(scope="module")
def lattice_study():
    frames = []
    for index, speed in enumerate(SPEEDS):
        frame = _lattice_frame(0.06, 0.012, 0.06, SPACING, 1e-5, (0.0, 0.0, -speed))
        frames.append(_clumps(frame.position, frame.velocity, 1e-5, time=1.0 + 0.01 * index, step=1000 + 10 * index))
    # Two contacts in the mid-depth slice (|y - 6 mm| <= 2 mm) and one outside it, all vertical, 2 mm long, with
    # the upper sphere pushing the lower one down.
    lower = np.array([[0.0, 0.006, 0.03], [0.01, 0.007, 0.03], [-0.01, 0.001, 0.03]])
    upper = lower + [0.0, 0.0, SPACING]
    force = np.array([[0.0, 0.0, -f] for f in FORCES])
    contacts = ContactFrame(step=1000, position_i=lower, position_j=upper, id_i=np.arange(3), id_j=np.arange(3, 6),
                            force=force)
    with warnings.catch_warnings():
        # A flat profile gives the kinematic fit no curvature to fit (scipy warns; B is not asserted here).
        warnings.simplefilter("ignore", OptimizeWarning)
        study = analyse_silo_fields(frames, contacts, SiloDimensions.from_case(CASE),
                                    SiloFieldOptions.from_config(FIELD_SECTION), STEADY_WINDOW, BULK_DENSITY)
    return frames, contacts, study


def test_silo_field_study_of_a_uniformly_sinking_lattice(lattice_study):
    frames, contacts, study = lattice_study
    assert (FIELD_BATCHES, COVERED_DENSITY_FRACTION) == (10, 0.5)
    # The window holds two frames: two batches of one, the fill (1250 kg/m3 > 0.5 x 600) covers both heights
    assert study.uncertainty.n_batches == 2 and study.uncertainty.batches.tolist() == [2, 2]
    # A uniform flow has no boundary inside the silo: unknown, not zero
    assert np.isnan(study.uncertainty.fcb_left_error).all() and np.isnan(study.uncertainty.fcb_right_error).all()
    rho = 1e-5 / SPACING**3
    np.testing.assert_allclose(study.surface, 0.06, rtol=1e-12)  # top lattice row 59 mm + radius 1 mm
    assert study.top == pytest.approx(0.06, rel=1e-12)
    assert study.grid.shape == (10, 3, 10) and study.settings.width == pytest.approx(0.003, rel=1e-15)
    assert study.steps == (1000, 1010, 1020)
    np.testing.assert_allclose(study.times, [0.0, 0.01, 0.02], rtol=0, atol=1e-12)
    assert study.window == STEADY_WINDOW
    assert study.heights == [0.03, 0.04]  # 60 mm lies above 57 - 6 mm
    inside = rho * 0.06 * 0.012 * 0.06
    assert study.averaged.total_mass == pytest.approx(inside, rel=1e-12)
    # Averaged over the second and third frame: 0.3 m/s down everywhere in the fill.
    mean_speed = 0.5 * (SPEEDS[1] + SPEEDS[2])
    np.testing.assert_allclose(study.profiles.v_z, -mean_speed, rtol=1e-12)
    np.testing.assert_allclose(study.front.v_z, -mean_speed, rtol=1e-12)
    np.testing.assert_allclose(study.centreline, -np.array([SPEEDS, SPEEDS]).T, rtol=1e-12)
    # At 30 mm, midway between two lattice planes, the kernel's ripple over the lattice cancels.
    assert study.profile_rate == pytest.approx(rho * 0.06 * 0.012 * mean_speed, rel=1e-9)
    # Trapezoid rule between the outermost nodes: W - dx of the width.
    assert study.bulk_rate == pytest.approx(BULK_DENSITY * 0.012 * mean_speed * (0.06 - 0.006), rel=1e-12)


def test_silo_field_study_contact_stress_janssen_and_force_chains(lattice_study):
    frames, contacts, study = lattice_study
    # Virial: the contact stress integrates to sum f l over the contacts (compression positive).
    total = study.stress[..., 2, 2].sum() * study.grid.cell_volume
    assert total == pytest.approx(SPACING * sum(FORCES), rel=1e-12)
    janssen = study.janssen
    assert janssen.surface_height == pytest.approx(0.06, rel=1e-12)
    # Rows more than 3 widths (9 mm) from floor and surface: z = 15, 21, ..., 45 mm.
    np.testing.assert_allclose(janssen.depth_below_surface, 0.06 - np.arange(0.015, 0.046, 0.006), rtol=1e-12)
    # No wall friction: Janssen's stress is the hydrostatic rho_b g h.
    np.testing.assert_allclose(janssen.janssen, BULK_DENSITY * GRAVITY * janssen.depth_below_surface, rtol=1e-12)
    rows = (study.grid.z > 0.012) & (study.grid.z < 0.048)  # the rows z = 15 ... 45 mm
    np.testing.assert_array_equal(janssen.simulated, study.stress[..., 2, 2].mean(axis=(0, 1))[rows])
    # Bins as wide as the kernel's support, 2 x 3 widths = 18 mm: one pair over the 5 columns (30 mm) of each half
    assert janssen.bin_pairs == 1
    columns = study.stress[..., 2, 2].mean(axis=1)[:, rows]
    np.testing.assert_allclose(janssen.simulated_error, [mirror_bin_error(c, 1) for c in columns.T], rtol=1e-14)
    np.testing.assert_allclose(janssen.hydrostatic, BULK_DENSITY * GRAVITY * janssen.depth_below_surface, rtol=1e-14)
    assert np.isnan(janssen.hydrostatic_error).all()  # the study was given no bulk density error
    cap = 50 * 1e-5 * GRAVITY
    assert study.segments.cap == pytest.approx(cap, rel=1e-15)
    np.testing.assert_allclose(study.segments.normal_force, [FORCES[0], FORCES[1]], rtol=1e-12)  # 1 N is outside
    np.testing.assert_array_equal(study.segments.start, contacts.position_i[:2])
    assert study.n_contacts == 3


def test_the_averaging_window_is_the_configured_times_else_the_steady_window():
    assert averaging_window([0.5, 0.7], (0.31, 1.24)) == ((0.5, 0.7), WINDOW_CONFIGURED)
    assert averaging_window(None, (0.31, 1.24)) == ((0.31, 1.24), WINDOW_STEADY)
    assert (WINDOW_CONFIGURED, WINDOW_STEADY) == ("silo_flat.fields.average_window", "silo_flat.steady_window")
    for bad in ((0.7, 0.5), (-0.1, 0.5), (0.5,)):
        with pytest.raises(ValueError, match="averaging window"):
            averaging_window(bad, (0.31, 1.24))


def test_a_configured_window_in_seconds_after_opening_picks_its_frames(lattice_study):
    frames, contacts, steady = lattice_study
    options = SiloFieldOptions.from_config({**FIELD_SECTION, "average_window": [0.0, 0.01]})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", OptimizeWarning)
        study = analyse_silo_fields(frames, None, SiloDimensions.from_case(CASE), options, STEADY_WINDOW,
                                    BULK_DENSITY)
    # the frames at 0 and 0.01 s after opening, not the steady window's at 0.01 and 0.02 s; the second frame's time,
    # 1.01 - 1.0, lies a round-off above the window's end and still counts
    assert study.times[1] > 0.01
    assert study.window == (0.0, 0.01) and study.window_source == WINDOW_CONFIGURED
    np.testing.assert_allclose(study.profiles.v_z, -0.5 * (SPEEDS[0] + SPEEDS[1]), rtol=1e-12)
    summary = field_summary(study, outflow_rate=2.0)
    assert summary["average_window_s"] == [0.0, 0.01]
    assert summary["average_window_source"] == "silo_flat.fields.average_window"
    assert steady.window_source == WINDOW_STEADY
    assert field_summary(steady, outflow_rate=2.0)["average_window_source"] == "silo_flat.steady_window"


def test_silo_field_study_needs_a_frame():
    with pytest.raises(ValueError, match="frames"):
        analyse_silo_fields([], None, SiloDimensions.from_case(CASE),
                            SiloFieldOptions.from_config(FIELD_SECTION), STEADY_WINDOW, BULK_DENSITY)


def _profile_analysis():
    return ProfileAnalysis(
        heights=np.array([0.02, 0.04]), x=np.array([-0.01, 0.0, 0.01]),
        v_z=np.array([[-1.0, -2.0, -3.0], [-4.0, -5.0, -6.0]]), v_x=np.array([[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]),
        fcb_fractions=(0.05, 0.1), fcb_left=np.array([[-0.01, -0.009], [-0.008, -0.007]]),
        fcb_right=np.array([[0.01, 0.009], [0.008, 0.007]]), kinematic_B=np.array([0.002, np.nan]),
        kinematic_u=np.array([[7.0, 8.0, 9.0], [10.0, 11.0, 12.0]]))


def test_table_rows_lay_out_the_profiles_boundaries_and_kinematic_constant():
    profiles = _profile_analysis()
    front = ProfileAnalysis(**{**profiles.__dict__, "v_z": -profiles.v_z, "v_x": -profiles.v_x})
    rows = profile_rows(profiles, front)
    assert len(rows) == 6
    assert rows[4] == {"z_m": 0.04, "x_m": 0.0, "v_z_m_s": -5.0, "v_x_m_s": 0.5, "u_kinematic_m_s": 11.0,
                       "v_z_front_wall_m_s": 5.0, "v_x_front_wall_m_s": -0.5}
    uncertainty = ProfileUncertainty(
        kinematic_B_error=np.array([0.0001, np.nan]), fcb_left_error=np.array([[1e-3, 2e-3], [3e-3, 4e-3]]),
        fcb_right_error=np.array([[5e-3, 6e-3], [7e-3, 8e-3]]), batches=np.array([10, 3]), n_batches=10,
        boundary_resolution=0.001)
    boundaries = boundary_rows(profiles, uncertainty)
    assert [(r["z_m"], r["fraction"]) for r in boundaries] == [(0.02, 0.05), (0.02, 0.1), (0.04, 0.05), (0.04, 0.1)]
    assert boundaries[2] == {"z_m": 0.04, "fraction": 0.05, "x_left_m": -0.008, "x_left_m_error": 3e-3,
                             "x_right_m": 0.008, "x_right_m_error": 7e-3, "batches": 3}
    kinematic = kinematic_rows(profiles, uncertainty)
    assert kinematic[0] == {"z_m": 0.02, "B_m": 0.002, "B_m_error": 0.0001, "batches": 10}
    assert kinematic[1]["z_m"] == 0.04 and kinematic[1]["batches"] == 3
    assert math.isnan(kinematic[1]["B_m"]) and math.isnan(kinematic[1]["B_m_error"])


def test_table_rows_of_the_centreline_and_janssen():
    centre = np.array([[-0.1, -0.2], [-0.3, -0.4], [-0.5, -0.6]])
    rows = centreline_rows([0.0, 0.01, 0.02], [0.02, 0.045], centre)
    assert rows[1] == {"time_s": 0.01, "v_z_at_20mm_m_s": -0.3, "v_z_at_45mm_m_s": -0.4}
    assert len(rows) == 3
    comparison = JanssenComparison(np.array([0.01, 0.02]), np.array([50.0, 90.0]), np.array([55.0, 100.0]), 0.06,
                                   height=np.array([0.05, 0.04]), simulated_error=np.array([2.0, 3.0]),
                                   hydrostatic=np.array([60.0, 120.0]), hydrostatic_error=np.array([0.5, 1.0]),
                                   bin_pairs=2)
    assert janssen_rows(comparison) == [
        {"depth_below_surface_m": 0.01, "z_m": 0.05, "sigma_v_dem_Pa": 50.0, "sigma_v_dem_Pa_error": 2.0,
         "sigma_v_janssen_Pa": 55.0, "hydrostatic_pa": 60.0, "hydrostatic_pa_error": 0.5},
        {"depth_below_surface_m": 0.02, "z_m": 0.04, "sigma_v_dem_Pa": 90.0, "sigma_v_dem_Pa_error": 3.0,
         "sigma_v_janssen_Pa": 100.0, "hydrostatic_pa": 120.0, "hydrostatic_pa_error": 1.0},
    ]


def test_instantaneous_rows_and_summary_of_the_lattice_study(lattice_study):
    _, _, study = lattice_study
    rows = instantaneous_profile_rows(study.times, study.depth_series, study.heights)
    assert len(rows) == len(SPEEDS) * len(study.heights) * study.grid.shape[0]
    for row in rows:
        frame = int(round(row["time_s"] / 0.01))
        assert row["v_z_m_s"] == pytest.approx(-SPEEDS[frame], rel=1e-12)
        assert row["v_x_m_s"] == pytest.approx(0.0, abs=1e-12)
    assert [r["x_m"] for r in rows[:10]] == list(study.grid.x)
    summary = field_summary(study, outflow_rate=2.0)
    assert summary["grid_shape"] == [10, 3, 10] and summary["kernel"] == "gaussian"
    assert summary["kernel_width_m"] == study.settings.width and summary["average_window_s"] == list(STEADY_WINDOW)
    assert summary["profile_heights_m"] == [0.03, 0.04] and summary["profile_flow_height_m"] == 0.03
    assert summary["profile_over_outflow"] == study.profile_rate / 2.0
    assert summary["outflow_mass_flow_rate_kg_s"] == 2.0
    assert summary["profile_bulk_density_mass_flow_rate_kg_s"] == study.bulk_rate
    assert list(summary["kinematic_B_m"]) == ["0.03", "0.04"]
    assert summary["kinematic_B_m_error"] == {"0.03": study.uncertainty.kinematic_B_error[0],
                                              "0.04": study.uncertainty.kinematic_B_error[1]}
    assert summary["error_batches"] == 2 and summary["janssen_error_bin_pairs"] == 1
    assert summary["surface_height_m"] == study.top and summary["contacts"] == 3


# --------------------------------------------------------------------------- comparisons (field_comparisons)


def _linear_fields(grid, slope, offset):
    """Fields of unit density whose v_z = offset + slope * x everywhere, v_x = 0."""
    density = np.ones(grid.shape)
    momentum = np.zeros(grid.shape + (3,))
    momentum[..., 2] = offset + slope * grid.node_positions()[..., 0]
    return Fields.from_moments(grid, density, momentum, np.zeros(grid.shape + (3, 3)))


def test_comparison_plane_is_the_front_wall_layer_or_the_depth_average():
    grid = silo_grid(0.06, 0.012, 0.06, (0.006, 0.004, 0.006))
    fields = _linear_fields(grid, -1.0, -0.1)
    front = comparison_plane(fields, "front_wall")
    assert front.grid.shape == (10, 1, 10) and front.grid.y[0] == pytest.approx(0.002, rel=1e-12)
    averaged = comparison_plane(fields, "depth_average")
    assert averaged.grid.shape == (10, 1, 10) and averaged.grid.y[0] == pytest.approx(0.006, rel=1e-12)
    with pytest.raises(ValueError, match="plane"):
        comparison_plane(fields, "back_wall")
    assert MEASURED_PLANES == ("front_wall", "depth_average")


def test_a_measurement_of_the_simulated_linear_profile_has_no_error():
    grid = silo_grid(0.06, 0.012, 0.06, (0.006, 0.004, 0.006))
    plane = comparison_plane(_linear_fields(grid, -2.0, -0.1), "depth_average")
    x = np.array([-0.02, 0.0, 0.015])
    exact = MeasuredProfile(z=0.03, window="a", x=x, v_z=-0.1 - 2.0 * x, v_x=np.zeros(3), uncertainty=None)
    shifted = MeasuredProfile(z=0.021, window="b", x=x, v_z=-0.1 - 2.0 * x + 0.01, v_x=np.zeros(3),
                              uncertainty=np.full(3, 0.02))
    comparisons = compare_with_measurements(plane, [exact, shifted])
    np.testing.assert_allclose(comparisons[0].simulated_v_z, exact.v_z, rtol=1e-12)
    assert comparisons[0].errors.rms_error == pytest.approx(0.0, abs=1e-15)
    assert comparisons[1].errors.rms_error == pytest.approx(0.01, rel=1e-9)
    rows = measured_comparison_rows(comparisons)
    assert [r["z_m"] for r in rows] == [0.03, 0.021] and [r["window"] for r in rows] == ["a", "b"]
    assert rows[1]["n_points"] == 3 and rows[1]["max_abs_error_m_s"] == pytest.approx(0.01, rel=1e-9)
    assert rows[1]["fraction_within_uncertainty"] == 1.0


def test_parametric_profiles_at_the_highest_height_every_run_covers():
    tall = silo_grid(0.06, 0.012, 0.06, (0.006, 0.004, 0.006))  # nodes up to 57 mm
    short = silo_grid(0.06, 0.012, 0.048, (0.004, 0.004, 0.006))  # nodes up to 45 mm, 4 mm across
    runs = [depth_average(_linear_fields(tall, -1.0, -0.1)), depth_average(_linear_fields(short, -2.0, -0.2))]
    profiles = parametric_profiles(runs, 0.05)
    assert profiles.height == pytest.approx(0.039, rel=1e-12)  # the short run's second-highest row
    assert parametric_profiles(runs, 0.02).height == 0.02
    np.testing.assert_allclose(profiles.x, tall.x, rtol=1e-12)
    np.testing.assert_allclose(profiles.v_z[1], -0.2 - 2.0 * tall.x, rtol=1e-12)  # interpolated onto the tall x
    # the first flow.json predates the errors (the ratio's is null, JSON's NaN); the second has them all
    flows = [{"mass_flow_rate_kg_s": 0.1, "mass_flow_rate_stderr_kg_s": 0.001, "beverloo_ratio": 1.5,
              "beverloo_ratio_error": None, "filling_bulk_density_kg_m3": 600.0},
             {"mass_flow_rate_kg_s": 0.2, "mass_flow_rate_kg_s_error": 0.004, "mass_flow_rate_stderr_kg_s": 0.002,
              "beverloo_ratio": 1.4, "beverloo_ratio_error": 0.03, "filling_bulk_density_kg_m3": 610.0,
              "filling_bulk_density_kg_m3_error": 5.0}]
    rows = parametric_rows("friction", ["mu=0", "mu=1"], ["r0", "r1"], flows, profiles)
    assert rows[1] == {"study": "friction", "label": "mu=1", "run_id": "r1", "profile_height_m": profiles.height,
                       "mass_flow_rate_kg_s": 0.2, "mass_flow_rate_kg_s_error": 0.004,
                       "mass_flow_rate_stderr_kg_s": 0.002, "beverloo_ratio": 1.4, "beverloo_ratio_error": 0.03,
                       "filling_bulk_density_kg_m3": 610.0, "filling_bulk_density_kg_m3_error": 5.0,
                       "centreline_v_z_m_s": pytest.approx(-0.2, rel=1e-12)}
    assert rows[0]["centreline_v_z_m_s"] == pytest.approx(-0.1, rel=1e-12)
    assert all(math.isnan(rows[0][key]) for key in
               ("mass_flow_rate_kg_s_error", "beverloo_ratio_error", "filling_bulk_density_kg_m3_error"))
    with pytest.raises(ValueError, match="at least one"):
        parametric_profiles([], 0.05)
    with pytest.raises(ValueError, match=r"one node layer in y .* got \[3\]"):
        parametric_profiles([_linear_fields(tall, -1.0, -0.1)], 0.05)


def test_seed_profiles_are_the_seeds_mean_with_the_standard_error_of_that_mean():
    grid = silo_grid(0.06, 0.012, 0.06, (0.006, 0.004, 0.006))
    other = silo_grid(0.06, 0.012, 0.06, (0.004, 0.004, 0.006))  # another x spacing: put on the first seed's nodes
    seeds = [depth_average(_linear_fields(grid, -1.0, -0.1)), depth_average(_linear_fields(other, -1.0, -0.3))]
    profiles = seed_profiles(seeds, [0.02, 0.04])
    assert profiles.seeds == 2 and profiles.v_z.shape == (2, grid.shape[0])
    np.testing.assert_allclose(profiles.x, grid.x, rtol=1e-12)
    # v_z = offset - x: the mean offset -0.2; two seeds 0.2 apart have a standard deviation 0.2 / sqrt(2) and a
    # standard error of their mean 0.1
    np.testing.assert_allclose(profiles.v_z, np.tile(-0.2 - grid.x, (2, 1)), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(profiles.v_z_error, 0.1, rtol=1e-12)
    alone = seed_profiles(seeds[:1], [0.02])
    np.testing.assert_allclose(alone.v_z[0], -0.1 - grid.x, rtol=1e-12, atol=1e-15)
    assert alone.seeds == 1 and np.all(np.isnan(alone.v_z_error))
    with pytest.raises(ValueError, match=r"profile heights \[0.08\] m lie outside"):
        seed_profiles(seeds, [0.02, 0.08])
    with pytest.raises(ValueError, match="at least one profile height"):
        seed_profiles(seeds, [])
    with pytest.raises(ValueError, match="at least one"):
        seed_profiles([], [0.02])


def test_seed_kinematic_is_the_mean_of_the_seeds_that_fitted_a_b_with_its_replicate_error():
    first = [{"z_m": 0.02, "B_m": 0.004, "B_m_error": 0.0001}, {"z_m": 0.04, "B_m": 0.006, "B_m_error": 0.003},
             {"z_m": 0.08, "B_m": None, "B_m_error": None}]
    second = [{"z_m": 0.02, "B_m": 0.006, "B_m_error": 0.0001}, {"z_m": 0.04, "B_m": 0.008, "B_m_error": 0.003},
              {"z_m": 0.08, "B_m": 0.01, "B_m_error": 0.002}]
    kinematic = seed_kinematic([first, second])
    np.testing.assert_allclose(kinematic.heights, [0.02, 0.04, 0.08])
    np.testing.assert_allclose(kinematic.B, [0.005, 0.007, 0.01], rtol=1e-12)
    # 20 mm: the seeds' standard error 0.001 exceeds the within-run sqrt(2) 1e-4 / 2; 40 mm: the within-run
    # sqrt(2) * 0.003 / 2 exceeds the seeds' 0.001; 80 mm: one seed, its own error
    np.testing.assert_allclose(kinematic.B_error, [0.001, math.sqrt(2) * 0.0015, 0.002], rtol=1e-12)
    assert kinematic.seeds.tolist() == [2, 2, 1]
    none = seed_kinematic([[{"z_m": 0.02, "B_m": None, "B_m_error": None}]])
    assert math.isnan(none.B[0]) and math.isnan(none.B_error[0]) and none.seeds.tolist() == [0]
    with pytest.raises(ValueError, match="different heights"):
        seed_kinematic([first, second[:2]])
    with pytest.raises(ValueError, match="at least one"):
        seed_kinematic([])


def test_seed_janssen_combines_the_seeds_stresses_row_by_row_as_the_rows_do():
    def table(depth_top, dem, dem_error):
        return [{"depth_below_surface_m": depth_top + 0.006 * k, "z_m": 0.021 - 0.006 * k, "sigma_v_dem_Pa": value,
                 "sigma_v_dem_Pa_error": dem_error, "sigma_v_janssen_Pa": 100.0 + k, "hydrostatic_pa": 120.0 + k,
                 "hydrostatic_pa_error": 1.0} for k, value in enumerate(dem)]
    first, second = table(0.27, [800.0, 820.0], 2.0), table(0.29, [840.0, 830.0], 2.0)
    comparison = seed_janssen([first, second])
    np.testing.assert_allclose(comparison.height, [0.021, 0.015])
    np.testing.assert_allclose(comparison.depth_below_surface, [0.28, 0.286], rtol=1e-12)
    assert comparison.surface_height == pytest.approx(0.301, rel=1e-12)
    np.testing.assert_allclose(comparison.simulated, [820.0, 825.0], rtol=1e-12)
    # the seeds' standard errors, 20 and 5 Pa, are larger than the within-run sqrt(2) * 2 / 2 Pa: they are the errors
    np.testing.assert_allclose(comparison.simulated_error, [20.0, 5.0], rtol=1e-12)
    np.testing.assert_allclose(comparison.janssen, [100.0, 101.0])
    np.testing.assert_allclose(comparison.hydrostatic, [120.0, 121.0])
    np.testing.assert_allclose(comparison.hydrostatic_error, math.sqrt(2.0) / 2.0, rtol=1e-12)
    assert comparison.bin_pairs == 0
    with pytest.raises(ValueError, match="different heights"):
        seed_janssen([first, second[:1]])
    with pytest.raises(ValueError, match="at least one"):
        seed_janssen([])
