"""Unit tests for the flat-bottom silo plots (siloflow.analysis.studies.silo_flat.plots): each writes its PNG and the figure
it returns shows the synthetic input, scaled to the axes' units (files under tmp_path only).

The discharge plot is tested in test_plots_tables.py.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_hex

from siloflow.analysis.io.plot_style import PALETTE, StudyNote, StudyValue
from siloflow.analysis.numerics.force_chains import ForceChainSegments
from siloflow.analysis.numerics.flow import DischargeHistory, FlowRateFit
from siloflow.analysis.studies.silo_flat.field_comparisons import SeedKinematic, SeedProfiles
from siloflow.analysis.studies.silo_flat.fields import JanssenComparison, ProfileAnalysis, ProfileUncertainty
from siloflow.analysis.studies.silo_flat.measured import MeasuredProfile, compare_with_measurement
from siloflow.analysis.studies.silo_flat.plots import (
    plot_centreline_velocity,
    plot_discharge,
    plot_force_chains,
    plot_janssen,
    plot_kinematic_constant,
    plot_kinematic_horizontal_velocity,
    plot_measured_comparison,
    plot_parametric_study,
    plot_posterior_draws,
    plot_profiles_over_silo,
    plot_seed_profiles,
    plot_velocity_contour,
)
from tests.plot_data import assert_legend_outside, legend_texts, lines_with_gid

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
X = np.array([-0.02, -0.01, 0.0, 0.01, 0.02])
HEIGHTS = np.array([0.01, 0.03])


@pytest.fixture
def written(tmp_path):
    """Check that a writer left exactly its PNG and closed its figure; close it for good."""
    figures = []

    def check(figure, path):
        assert path.read_bytes().startswith(PNG_SIGNATURE)
        assert sorted(p.name for p in path.parent.iterdir()) == [path.name], "temporary files left behind"
        assert not plt.fignum_exists(figure.number), "the writer closes its figure"
        figures.append(figure)
        return figure

    yield check
    for figure in figures:
        plt.close(figure)


def _profiles():
    v_z = np.array([[-0.02, -0.06, -0.1, -0.06, -0.02], [-0.01, -0.03, -0.05, -0.03, -0.01]])
    return ProfileAnalysis(
        heights=HEIGHTS, x=X, v_z=v_z, v_x=np.array([[0.01, 0.02, 0.0, -0.02, -0.01], [0.0, 0.01, 0.0, -0.01, 0.0]]),
        fcb_fractions=(0.05, 0.1), fcb_left=np.array([[-0.02, -0.015], [-0.018, -0.012]]),
        fcb_right=np.array([[0.02, 0.015], [0.018, 0.012]]), kinematic_B=np.array([0.002, 0.003]),
        kinematic_u=np.array([[0.012, 0.018, 0.0, -0.018, -0.012], [0.003, 0.009, 0.0, -0.009, -0.003]]))


def _uncertainty():
    return ProfileUncertainty(
        kinematic_B_error=np.array([0.0002, np.nan]), fcb_left_error=np.array([[0.001, 0.0015], [0.002, 0.0025]]),
        fcb_right_error=np.array([[0.003, 0.0035], [0.004, np.nan]]), batches=np.array([10, 1]), n_batches=10,
        boundary_resolution=0.0005)


def _bars(container):
    """The ((x0, y0), (x1, y1)) ends of each bar of an errorbar container; empty where the error is NaN."""
    (bars,) = container.lines[2]
    return [np.asarray(segment) for segment in bars.get_segments()]


def _outline(width_mm, outlet_mm, top_mm):
    half, slot = width_mm / 2, outlet_mm / 2
    return [[[-half, top_mm], [-half, 0.0], [-slot, 0.0]], [[half, top_mm], [half, 0.0], [slot, 0.0]]]


def test_plot_profiles_over_silo_draws_each_profile_at_its_height_with_the_boundary(tmp_path, written):
    path = tmp_path / "profiles.png"
    figure = written(plot_profiles_over_silo(_profiles(), 0.05, 0.01, 0.04, path, "profiles"), path)
    (axes,) = figure.axes
    assert (axes.get_title(), axes.get_xlabel(), axes.get_ylabel()) == ("profiles", "x [mm]", "z [mm]")
    lines = axes.get_lines()
    np.testing.assert_allclose([line.get_xydata() for line in lines[:2]], _outline(50.0, 10.0, 40.0))
    scale = 0.8 * 0.02 / 0.1  # 80 % of the height spacing for the fastest profile
    for i, z in enumerate(HEIGHTS):
        guide, profile, boundary = lines[2 + 3 * i: 5 + 3 * i]
        np.testing.assert_allclose(guide.get_ydata(), [1e3 * z] * 2)
        np.testing.assert_allclose(profile.get_xydata(),
                                   np.column_stack([1e3 * X, 1e3 * (z + scale * _profiles().v_z[i])]), rtol=1e-14)
        left, right = _profiles().fcb_left[i, -1], _profiles().fcb_right[i, -1]
        np.testing.assert_allclose(boundary.get_xydata(), [[1e3 * left, 1e3 * z], [1e3 * right, 1e3 * z]])
    assert [line.get_label() for line in lines[-2:]] == ["FCB at 10 % of centreline v_z",
                                                         f"v_z (1 mm = {1e-3 / scale:.3g} m/s)"]
    assert axes.containers == []  # no uncertainty given: no error bars


def test_plot_profiles_over_silo_draws_the_boundary_error_bars_in_mm(tmp_path, written):
    path = tmp_path / "profiles.png"
    figure = written(plot_profiles_over_silo(_profiles(), 0.05, 0.01, 0.04, path, "profiles",
                                             uncertainty=_uncertainty()), path)
    (axes,) = figure.axes
    # outline, per height guide, profile and boundary, then the legend's two entries; the bars' caps come on top
    assert len(axes.get_lines()) == 2 + 3 * len(HEIGHTS) + 2 + 2 * len(HEIGHTS)
    containers = axes.containers
    assert len(containers) == len(HEIGHTS)
    for i, (z, container) in enumerate(zip(HEIGHTS, containers)):
        assert container.has_xerr and not container.has_yerr
        left, right = 1e3 * _profiles().fcb_left[i, -1], 1e3 * _profiles().fcb_right[i, -1]
        left_error = 1e3 * _uncertainty().fcb_left_error[i, -1]  # 1.5 and 2.5 mm
        left_bar, right_bar = _bars(container)
        np.testing.assert_allclose(left_bar, [[left - left_error, 1e3 * z], [left + left_error, 1e3 * z]], rtol=1e-14)
        if i == 0:  # 3.5 mm
            np.testing.assert_allclose(right_bar, [[right - 3.5, 1e3 * z], [right + 3.5, 1e3 * z]], rtol=1e-14)
        else:
            assert right_bar.size == 0  # unknown error: no bar


def test_plot_velocity_contour_fills_from_the_slowest_velocity_to_zero(tmp_path, written):
    z = np.array([0.0, 0.02, 0.04])
    v_z = np.array([[-0.01, -0.005, 0.0], [-0.2, -0.1, -0.05], [-0.01, -0.005, 0.0]])  # (nx, nz)
    path = tmp_path / "contour.png"
    figure = written(plot_velocity_contour(X[1:4], z, v_z, 0.05, 0.01, path, "v_z"), path)
    axes, colorbar = figure.axes
    filled = axes.collections[0]
    np.testing.assert_allclose(filled.levels, np.linspace(-0.2, 0.0, 21))
    np.testing.assert_allclose(axes.dataLim.get_points(), [[-25.0, 0.0], [25.0, 40.0]])  # the outline spans all
    assert colorbar.get_ylabel() == "v_z [m/s]"
    np.testing.assert_allclose([line.get_xydata() for line in axes.get_lines()], _outline(50.0, 10.0, 40.0))


def test_plot_kinematic_constant_draws_b_against_height_in_mm(tmp_path, written):
    path = tmp_path / "B.png"
    figure = written(plot_kinematic_constant(HEIGHTS, [0.002, 0.0031], path, "B"), path)
    (axes,) = figure.axes
    (line,) = axes.get_lines()
    np.testing.assert_allclose(line.get_xydata(), [[2.0, 10.0], [3.1, 30.0]])
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("B [mm]", "z [mm]")
    assert axes.containers == []


def test_plot_kinematic_constant_draws_the_standard_error_of_b_as_horizontal_bars(tmp_path, written):
    path = tmp_path / "B.png"
    figure = written(plot_kinematic_constant(HEIGHTS, [0.002, 0.0031], path, "B", B_error=[0.0002, np.nan]), path)
    (axes,) = figure.axes
    (container,) = axes.containers
    assert container.has_xerr and not container.has_yerr and container.get_label() == "± standard error"
    first, second = _bars(container)
    np.testing.assert_allclose(first, [[1.8, 10.0], [2.2, 10.0]], rtol=1e-14)
    assert second.size == 0  # unknown error: no bar


def _janssen():
    return JanssenComparison(depth_below_surface=np.array([0.005, 0.015]), simulated=np.array([40.0, 95.0]),
                             janssen=np.array([38.0, 100.0]), surface_height=0.05, height=np.array([0.045, 0.035]),
                             simulated_error=np.array([4.0, 6.0]), hydrostatic=np.array([45.0, 135.0]),
                             hydrostatic_error=np.array([0.5, 1.5]), bin_pairs=2)


def test_plot_janssen_draws_the_dem_stress_with_its_error_janssen_and_hydrostatic_against_depth(tmp_path, written):
    path = tmp_path / "janssen.png"
    figure = written(plot_janssen(_janssen(), path, "stress"), path)
    (axes,) = figure.axes
    lines = {line.get_label(): line.get_xydata() for line in axes.get_lines()}
    np.testing.assert_allclose(lines["Janssen"], [[38.0, 5.0], [100.0, 15.0]])
    np.testing.assert_allclose(lines["hydrostatic rho_b g h"], [[45.0, 5.0], [135.0, 15.0]])
    (container,) = axes.containers  # the DEM points and their bars: one series
    assert container.get_label() == "DEM (contact stress) ± standard error"
    assert container.has_xerr and not container.has_yerr
    np.testing.assert_allclose(container.lines[0].get_xydata(), [[40.0, 5.0], [95.0, 15.0]])
    np.testing.assert_allclose(_bars(container), [[[36.0, 5.0], [44.0, 5.0]], [[89.0, 15.0], [101.0, 15.0]]],
                               rtol=1e-14)
    assert axes.yaxis_inverted()  # depth grows downwards
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("vertical stress [Pa]", "depth below surface [mm]")


# --------------------------------------------------------------------------- the record's figures in the journal style

S1 = StudyNote("S1", "DEM in good agreement")
S5 = StudyNote("S5", "B decreases with height")






def test_plot_profiles_over_silo_one_colour_for_the_profiles_one_for_the_boundary_legend_outside(tmp_path, written):
    path = tmp_path / "profiles.png"
    figure = written(plot_profiles_over_silo(_profiles(), 0.05, 0.01, 0.04, path, "profiles",
                                             uncertainty=_uncertainty()), path)
    (axes,) = figure.axes
    profiles, boundaries = lines_with_gid(axes, "profile"), lines_with_gid(axes, "fcb")
    assert len(profiles) == len(boundaries) == len(HEIGHTS)  # one profile and one boundary pair per height
    assert {to_hex(line.get_color()) for line in profiles} == {to_hex(PALETTE[5])}
    assert {to_hex(line.get_color()) for line in boundaries} == {to_hex(PALETTE[6])}
    assert legend_texts(axes) == ["FCB at 10 % of centreline v_z", "v_z (1 mm = 0.00625 m/s)"]
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("x [mm]", "z [mm]")
    assert_legend_outside(figure, axes)


def test_plot_kinematic_constant_draws_the_expected_trend_of_the_study_only_when_asked(tmp_path, written):
    path = tmp_path / "plain" / "B.png"
    figure = written(plot_kinematic_constant(HEIGHTS, [0.002, 0.0031], path, "B", B_error=[0.0002, np.nan]), path)
    (axes,) = figure.axes
    assert len(lines_with_gid(axes, "kinematic_B")) == 1 and len(axes.containers) == 1  # B, its error bars
    assert legend_texts(axes) == ["DEM kinematic constant B", "± standard error"]
    assert lines_with_gid(axes, "finding S5") == []
    assert_legend_outside(figure, axes)

    path = tmp_path / "study" / "B.png"
    figure = written(plot_kinematic_constant(HEIGHTS, [0.002, 0.0031], path, "B", B_error=[0.0002, np.nan],
                                             findings=[S5]), path)
    (axes,) = figure.axes
    (line,) = lines_with_gid(axes, "kinematic_B")
    np.testing.assert_allclose(line.get_xydata(), [[2.0, 10.0], [3.1, 30.0]])
    assert len(axes.containers) == 1
    assert legend_texts(axes) == ["DEM kinematic constant B", "± standard error",
                                   "study (S5): B decreases with height"]
    (note,) = lines_with_gid(axes, "finding S5")
    assert np.size(note.get_xdata()) == 0  # an annotation: no data, no mark
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("B [mm]", "z [mm]")
    assert_legend_outside(figure, axes)


def test_plot_janssen_names_the_janssen_curve_with_the_study_finding_only_when_asked(tmp_path, written):
    path = tmp_path / "plain" / "janssen.png"
    figure = written(plot_janssen(_janssen(), path, "stress"), path)
    (axes,) = figure.axes
    assert legend_texts(axes) == ["DEM (contact stress) ± standard error", "Janssen", "hydrostatic rho_b g h"]
    assert not any("S1" in text for text in legend_texts(axes))
    assert_legend_outside(figure, axes)

    path = tmp_path / "study" / "janssen.png"
    figure = written(plot_janssen(_janssen(), path, "stress", findings=[S1]), path)
    (axes,) = figure.axes
    # the DEM, Janssen and hydrostatic: three series, Janssen's drawn once
    assert [len(lines_with_gid(axes, gid)) for gid in ("dem_stress", "janssen", "hydrostatic")] == [1, 1, 1]
    assert len(axes.containers) == 1
    assert legend_texts(axes) == ["DEM (contact stress) ± standard error",
                                   "Janssen, study (S1): DEM in good agreement", "hydrostatic rho_b g h"]
    (janssen,) = lines_with_gid(axes, "janssen")
    np.testing.assert_allclose(janssen.get_xydata(), [[38.0, 5.0], [100.0, 15.0]])
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("vertical stress [Pa]", "depth below surface [mm]")
    assert_legend_outside(figure, axes)


def test_silo_figures_refuse_a_finding_they_cannot_draw(tmp_path):
    path = tmp_path / "x.png"
    with pytest.raises(ValueError, match=r"findings\[0\] must be a StudyNote, got StudyValue"):
        plot_kinematic_constant(HEIGHTS, [0.002, 0.0031], path, "B", findings=[StudyValue("S5", 1.0)])
    with pytest.raises(ValueError, match=r"findings\[0\] must be a StudyNote, got str"):
        plot_janssen(_janssen(), path, "stress", findings=["S1"])
    assert not path.exists()


def test_plot_centreline_velocity_draws_one_history_per_height(tmp_path, written):
    times = np.array([0.0, 0.1, 0.2])
    velocities = np.array([[0.0, 0.0], [-0.1, -0.05], [-0.12, -0.06]])
    path = tmp_path / "centreline.png"
    figure = written(plot_centreline_velocity(times, HEIGHTS, velocities, path, "axis"), path)
    (axes,) = figure.axes
    lines = {line.get_label(): line.get_xydata() for line in axes.get_lines()}
    assert list(lines) == ["z = 10 mm", "z = 30 mm"]
    np.testing.assert_array_equal(lines["z = 10 mm"], np.column_stack([times, velocities[:, 0]]))
    np.testing.assert_array_equal(lines["z = 30 mm"], np.column_stack([times, velocities[:, 1]]))


def test_plot_force_chains_draws_each_branch_in_the_x_z_plane_coloured_by_force(tmp_path, written):
    segments = ForceChainSegments(start=np.array([[0.0, 0.001, 0.01], [0.01, -0.001, 0.02]]),
                                  end=np.array([[0.002, 0.001, 0.012], [0.012, 0.0, 0.021]]),
                                  normal_force=np.array([0.5, 3.0]), cap=2.0)
    path = tmp_path / "chains.png"
    figure = written(plot_force_chains(segments, 0.05, 0.01, 0.04, path, "chains"), path)
    axes, colorbar = figure.axes
    (chains,) = axes.collections
    np.testing.assert_allclose(chains.get_segments(), [[[0.0, 10.0], [2.0, 12.0]], [[10.0, 20.0], [12.0, 21.0]]])
    np.testing.assert_array_equal(chains.get_array(), [0.5, 3.0])
    assert chains.get_clim() == (0.0, 2.0)
    assert colorbar.get_ylabel() == "normal force [N] (capped at 2 N)"


def test_plot_measured_comparison_draws_measured_points_and_the_interpolated_dem_profile(tmp_path, written):
    x = np.array([-0.01, 0.0, 0.01])
    with_error = MeasuredProfile(z=0.02, window="0-1 s", x=x, v_z=np.array([-0.05, -0.1, -0.05]), v_x=np.zeros(3),
                                 uncertainty=np.array([0.01, 0.02, 0.01]))
    without = MeasuredProfile(z=0.04, window="1-2 s", x=x, v_z=np.array([-0.02, -0.04, -0.02]), v_x=np.zeros(3),
                              uncertainty=None)
    simulated = np.array([-0.04, -0.06, -0.1, -0.06, -0.04])
    comparisons = [compare_with_measurement(X, simulated, with_error), compare_with_measurement(X, simulated, without)]
    path = tmp_path / "measured.png"
    figure = written(plot_measured_comparison(comparisons, path, "DEM vs PIV"), path)
    top, bottom = figure.axes
    (bars,) = top.containers
    np.testing.assert_allclose(bars.lines[0].get_xydata(), [[-10.0, -0.05], [0.0, -0.1], [10.0, -0.05]])
    np.testing.assert_allclose([segment[:, 1] for segment in bars.lines[2][0].get_segments()],
                               [[-0.06, -0.04], [-0.12, -0.08], [-0.06, -0.04]])
    for axes, comparison in ((top, comparisons[0]), (bottom, comparisons[1])):
        lines = {line.get_label(): line.get_xydata() for line in axes.get_lines()}
        np.testing.assert_allclose(lines["DEM"], [[-10.0, -0.06], [0.0, -0.1], [10.0, -0.06]])
        errors = comparison.errors
        assert axes.get_title().endswith(f"mean error {errors.mean_error_percent:.1f} %, RMS {errors.rms_error:.3g} m/s")
    np.testing.assert_allclose({line.get_label(): line for line in bottom.get_lines()}["measured"].get_xydata(),
                               [[-10.0, -0.02], [0.0, -0.04], [10.0, -0.02]])
    assert top.get_title().startswith("z = 20 mm, 0-1 s:") and bottom.get_xlabel() == "x [mm]"


def test_plot_parametric_study_draws_the_profiles_and_a_bar_per_run(tmp_path, written):
    profiles = [np.array([-0.02, -0.06, -0.1, -0.06, -0.02]), np.array([-0.01, -0.05, -0.12, -0.05, -0.01])]
    path = tmp_path / "study.png"
    figure = written(plot_parametric_study(X, profiles, ["base", "rough"], [0.12, 0.1], 0.03, path, "friction"), path)
    left, right = figure.axes
    lines = {line.get_label(): line.get_xydata() for line in left.get_lines()}
    np.testing.assert_allclose(lines["base"], np.column_stack([1e3 * X, profiles[0]]))
    np.testing.assert_allclose(lines["rough"], np.column_stack([1e3 * X, profiles[1]]))
    assert left.get_ylabel() == "v_z at z = 30 mm [m/s]"
    assert [bar.get_height() for bar in right.patches] == [0.12, 0.1]
    assert [label.get_text() for label in right.get_xticklabels()] == ["base", "rough"]


def test_plot_kinematic_horizontal_velocity_draws_dem_and_model_per_height(tmp_path, written):
    profiles = _profiles()
    path = tmp_path / "u.png"
    figure = written(plot_kinematic_horizontal_velocity(profiles, path, "u"), path)
    assert len(figure.axes) == 2
    for i, axes in enumerate(figure.axes):
        dem, model = axes.get_lines()
        np.testing.assert_allclose(dem.get_xydata(), np.column_stack([1e3 * X, profiles.v_x[i]]))
        np.testing.assert_allclose(model.get_xydata(), np.column_stack([1e3 * X, profiles.kinematic_u[i]]))
        assert axes.get_ylabel() == f"z = {1e3 * HEIGHTS[i]:g} mm\n[m/s]"
    assert [line.get_label() for line in figure.axes[0].get_lines()] == ["DEM v_x", "kinematic u = -B dv_z/dx"]


def test_plot_discharge_states_the_given_flow_rate_error_in_its_legend(tmp_path, written):
    history = DischargeHistory(time=np.array([0.0, 0.1, 0.2, 0.3]), discharged_mass=np.array([0.0, 0.01, 0.02, 0.03]))
    fit = FlowRateFit(mass_flow_rate=0.1, standard_error=1e-6, t_start=0.1, t_end=0.3, n_points=3, intercept=0.0)
    path = tmp_path / "discharge.png"
    figure = written(plot_discharge(history, fit, None, path, "discharge", rate_error=0.0021), path)
    labels = [line.get_label() for line in figure.axes[0].get_lines()]
    assert "fit: 0.1 ± 0.0021 kg/s" in labels  # the batch-means error, not the fit's 1e-06


def test_plot_posterior_draws_marks_each_run_with_its_error_and_the_calibration_band(tmp_path, written):
    rows = [{"label": label, "mass_flow_rate_kg_s": flow, "mass_flow_rate_kg_s_error": 0.01,
             "base_vertical_stress_Pa": stress, "base_vertical_stress_Pa_error": 2.0}
            for label, flow, stress in (("posterior mean", 0.11, 240.0), ("draw 0", 0.1, 230.0), ("draw 1", 0.13, 250.0))]
    spread = [{"figure": "mass_flow_rate_kg_s", "unit": "kg/s", "posterior_mean": 0.11, "calibration_sd": 0.02},
              {"figure": "base_vertical_stress_Pa", "unit": "Pa", "posterior_mean": 240.0, "calibration_sd": float("nan")}]
    path = tmp_path / "draws.png"
    figure = written(plot_posterior_draws(rows, spread, path, "draws"), path)
    flow, stress = figure.axes
    np.testing.assert_allclose(flow.get_lines()[0].get_xydata(), [[0, 0.11], [1, 0.1], [2, 0.13]])
    assert [label.get_text() for label in flow.get_xticklabels()] == ["posterior mean", "draw 0", "draw 1"]
    assert flow.get_ylabel() == "mass flow rate kg s [kg/s]"
    band = flow.patches[0]
    assert band.get_y() == pytest.approx(0.09) and band.get_y() + band.get_height() == pytest.approx(0.13)
    assert not stress.patches  # no calibration band without a spread


def _seeds(seeds=3):
    v_z = np.array([[-0.02, -0.06, -0.1, -0.06, -0.02], [-0.01, -0.03, -0.05, -0.03, -0.01]])
    error = np.full(v_z.shape, 0.004 if seeds > 1 else np.nan)
    profiles = SeedProfiles(heights=HEIGHTS, x=X, v_z=v_z, v_z_error=error, seeds=seeds)
    kinematic = SeedKinematic(heights=HEIGHTS, B=np.array([0.002, 0.0031]), B_error=np.array([0.0002, np.nan]),
                              seeds=np.array([seeds, seeds]))
    return profiles, kinematic


def test_plot_seed_profiles_draws_the_seeds_mean_per_height_with_its_band_and_b_with_the_study(tmp_path, written):
    path = tmp_path / "profiles.png"
    figure = written(plot_seed_profiles(*_seeds(), path, "silo", findings=[S5]), path)
    left, right = figure.axes
    for z, row in zip(("10", "30"), _seeds()[0].v_z):
        (line,) = lines_with_gid(left, f"v_z z={z}")
        np.testing.assert_allclose(line.get_xydata(), np.column_stack([1e3 * X, row]), rtol=1e-14)
        (band,) = [c for c in left.collections if c.get_gid() == f"v_z band z={z}"]
        edges = band.get_paths()[0].vertices
        np.testing.assert_allclose([edges[:, 1].min(), edges[:, 1].max()], [row.min() - 0.004, row.max() + 0.004])
    colours = {to_hex(line.get_color()) for line in left.get_lines()}
    assert len(colours) == 2  # one colour per height
    (b_line,) = lines_with_gid(right, "kinematic_B")
    np.testing.assert_allclose(b_line.get_xydata(), [[2.0, 10.0], [3.1, 30.0]], rtol=1e-14)
    assert (left.get_xlabel(), left.get_ylabel(), right.get_xlabel(), right.get_ylabel()) == (
        "x [mm]", "v_z [m/s]", "B [mm]", "z [mm]")
    assert right.get_xscale() == "linear"  # B within a factor 10
    assert legend_texts(right) == ["z = 10 mm", "z = 30 mm", "± standard error of 3 seeds' mean",
                                   "B, seeds' mean ± error", "study (S5): B decreases with height"]
    assert left.get_legend() is None
    assert_legend_outside(figure, right)
    figure.canvas.draw()
    assert not right.get_legend().get_window_extent().overlaps(left.get_window_extent())


def test_plot_seed_profiles_of_one_seed_draws_no_band_and_spans_of_b_go_on_a_log_axis(tmp_path, written):
    profiles, kinematic = _seeds(seeds=1)
    kinematic = SeedKinematic(heights=HEIGHTS, B=np.array([0.002, 0.09]), B_error=np.array([0.0002, 0.2]),
                              seeds=np.array([1, 1]))
    path = tmp_path / "profiles.png"
    figure = written(plot_seed_profiles(profiles, kinematic, path, "silo"), path)
    left, right = figure.axes
    assert [c for c in left.collections if str(c.get_gid()).startswith("v_z band")] == []
    assert legend_texts(right) == ["z = 10 mm", "z = 30 mm", "B, seeds' mean ± error"]
    assert right.get_xscale() == "log"
    (container,) = right.containers
    # the lower bar of an error larger than B stops short of zero, the upper one is the error
    lower, upper = container.lines[2][0].get_segments()[1][:, 0]
    assert lower == pytest.approx(0.09e3 - 0.999 * 0.09e3) and upper == pytest.approx(0.29e3)
