"""Unit tests for siloflow.analysis.studies.blender.plots: PNGs are written and the plotted data are the input (files under
tmp_path)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import siloflow.analysis.studies.blender.plots as blender_plots
import siloflow.analysis.studies.silo_recirculation.rtd_plots as rtd_plots
from siloflow.analysis.studies.blender.comparison import comparison_table
from siloflow.analysis.studies.blender.modes import continuous_mode, discontinuous_mode
from siloflow.analysis.studies.blender.profiles import flow_channel_boundary_over_height, passage_velocities, profiles_over_time
from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.tracers import layer_rtd, tracer_pathlines
from siloflow.analysis.studies.blender.plots import (
    plot_channel_boundary,
    plot_configuration_comparison,
    plot_continuous_mode,
    plot_discontinuous_mode,
    plot_gravity_scaling,
    plot_passage_distributions,
    plot_profiles_over_time,
    plot_rtd_theta,
    plot_tracer_pathlines,
)
from tests.plot_data import saved_figures
from test_blender_analysis import PASSAGES, X_FULL, Z_ROWS, channel_field, metrics, shear_field, uniform_field

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def figures(monkeypatch):
    """The figures the writers save (kept so that their line data can be checked)."""
    return saved_figures(monkeypatch, blender_plots, rtd_plots)


def assert_png(target, returned):
    assert returned == target
    data = target.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and len(data) > 5_000
    assert sorted(p.name for p in target.parent.iterdir()) == [target.name], "temporary files left behind"


def data_lines(axes):
    """Lines with at least 2 points that are not reference lines in axes coordinates."""
    return [line for line in axes.get_lines() if np.size(line.get_xdata()) >= 2
            and line.get_transform() == axes.transData]


# --------------------------------------------------------------------------- profiles


def test_plot_profiles_over_time(tmp_path, figures):
    fields = [shear_field(0.2, 3.0), shear_field(0.4, 1.0)]
    profiles = profiles_over_time(fields, [1.0, 5.0], [0.2, 0.5, 0.9], passages=PASSAGES)
    target = tmp_path / "profiles.png"
    assert_png(target, plot_profiles_over_time(profiles, target, "profiles"))
    (figure,) = figures
    panels = [axes for axes in figure.axes if axes.get_visible()]
    assert len(panels) == 3
    for h, axes in enumerate(panels):
        lines = [line for line in axes.get_lines() if line.get_label().startswith("t = ")]
        assert len(lines) == 2
        for w, line in enumerate(lines):
            np.testing.assert_array_equal(line.get_xdata(), 1e3 * X_FULL)
            np.testing.assert_array_equal(line.get_ydata(), profiles.normalised[w, h])


def test_plot_passage_distributions(tmp_path, figures):
    inlet = passage_velocities(shear_field(), 0.6, PASSAGES)
    outlet = passage_velocities(uniform_field(), 0.2, {"interior": (0.0, 0.05), "exterior": (0.06, 0.1)})
    target = tmp_path / "passages.png"
    assert_png(target, plot_passage_distributions(inlet, outlet, target, "passages"))
    left, right = figures[0].axes
    for axes, result in ((left, inlet), (right, outlet)):
        profile_line = next(line for line in axes.get_lines() if line.get_label() == "v_z")
        np.testing.assert_array_equal(profile_line.get_xdata(), 1e3 * X_FULL)
        np.testing.assert_array_equal(profile_line.get_ydata(), result.profile.v_z)
        for name, (lo, hi) in result.passages.items():
            segment = next(line for line in axes.get_lines() if line.get_label().startswith(f"{name}:"))
            np.testing.assert_allclose(segment.get_xdata(), [1e3 * lo, 1e3 * hi])
            np.testing.assert_array_equal(segment.get_ydata(), [result.mean_v_z[name]] * 2)


def test_plot_channel_boundary(tmp_path, figures):
    field = channel_field()
    boundary = flow_channel_boundary_over_height(field, 0.1)
    target = tmp_path / "fcb.png"
    assert_png(target, plot_channel_boundary(field, boundary, target, "FCB"))
    axes = figures[0].axes[0]
    mesh = axes.collections[0]
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).reshape(Z_ROWS.size, X_FULL.size), np.abs(field.v_z).T)
    lines = data_lines(axes)
    np.testing.assert_allclose(lines[0].get_xdata(), 1e3 * boundary.left)
    np.testing.assert_allclose(lines[1].get_xdata(), 1e3 * boundary.right)
    np.testing.assert_allclose(lines[1].get_ydata(), 1e3 * Z_ROWS)
    np.testing.assert_allclose(lines[3].get_xdata(), 1e3 * boundary.wall_x)


# --------------------------------------------------------------------------- tracers and RTD


def test_plot_tracer_pathlines(tmp_path, figures):
    x = X_FULL[10:]
    shape = (x.size, Z_ROWS.size)
    v_z = np.full(shape, -0.5)
    v_z[-2:] = 0.0  # one tracer stalls
    field = BlenderField(x=x, z=Z_ROWS, v_x=np.zeros(shape), v_z=v_z, solid_fraction=np.ones(shape))
    result = tracer_pathlines(field, 0.5, max_time=2.0, spacing=0.03)
    target = tmp_path / "pathlines.png"
    assert_png(target, plot_tracer_pathlines(result, target, "pathlines"))
    left, right = figures[0].axes
    paths = data_lines(left)[: len(result.paths)]
    assert len(result.paths) == 4 and len(paths) == 4
    for line, points in zip(paths, result.paths):
        np.testing.assert_array_equal(line.get_xdata(), 1e3 * points[:, 0])
        np.testing.assert_array_equal(line.get_ydata(), 1e3 * points[:, 1])
    assert paths[-1].get_linestyle() == ":"  # did not exit
    (times,) = right.get_lines()
    np.testing.assert_array_equal(times.get_xdata(), 1e3 * result.release_x[:3])
    np.testing.assert_array_equal(times.get_ydata(), result.residence_time[:3])
    assert "1 not out" in times.get_label()


def test_plot_rtd_theta(tmp_path, figures):
    uniform = layer_rtd(uniform_field(), 0.3, 0.5, max_time=5.0, tracer_spacing=0.025, bins=8)
    shear = layer_rtd(shear_field(), 0.3, 0.5, max_time=10.0, tracer_spacing=0.025, bins=12)
    target = tmp_path / "rtd.png"
    assert_png(target, plot_rtd_theta({"uniform": uniform, "shear": shear.rtd}, target, "RTD"))
    lines = [line for line in figures[0].axes[0].get_lines() if "t_m" in line.get_label()]
    assert len(lines) == 2
    for line, rtd in zip(lines, (uniform.rtd, shear.rtd)):
        np.testing.assert_allclose(line.get_xdata(), rtd.time / rtd.t_mean, rtol=1e-15)
        np.testing.assert_allclose(line.get_ydata(), rtd.E * rtd.t_mean, rtol=1e-15)


def test_plot_discontinuous_mode(tmp_path, figures):
    result = discontinuous_mode(uniform_field(), 1.0, max_time=5.0, passes=3, window=0.1, tracer_spacing=0.05)
    target = tmp_path / "discontinuous.png"
    assert_png(target, plot_discontinuous_mode(result, target, "two-layer fill"))
    line = next(line for line in figures[0].axes[0].get_lines() if line.get_label() == "LTI model, recirculated")
    np.testing.assert_array_equal(line.get_xdata(), result.time_in_passes)
    np.testing.assert_array_equal(line.get_ydata(), result.concentration)


def test_plot_continuous_mode(tmp_path, figures):
    fractions = np.array([0.5, 2.0 / 3.0, 1.0, 2.0, 4.0]) / 1.5
    two_peaks = continuous_mode([1.0, 2.0], 2.0**-6, fractions)
    plug = continuous_mode([1.5], 2.0**-6, fractions)
    target = tmp_path / "continuous.png"
    assert_png(target, plot_continuous_mode({"two peaks": two_peaks, "plug": plug}, target, "continuous"))
    left, right = figures[0].axes
    vrr_lines = [line for line in left.get_lines() if line.get_label() in ("two peaks", "plug")]
    keep = np.isfinite(two_peaks.vrr) & (two_peaks.vrr > 0)
    np.testing.assert_array_equal(vrr_lines[0].get_xdata(), fractions[keep])
    np.testing.assert_array_equal(vrr_lines[0].get_ydata(), two_peaks.vrr[keep])
    np.testing.assert_array_equal(vrr_lines[1].get_ydata(), plug.vrr)
    cov_lines = right.get_lines()
    np.testing.assert_array_equal(cov_lines[1].get_xdata(), fractions)
    np.testing.assert_array_equal(cov_lines[1].get_ydata(), plug.cov_out)


# --------------------------------------------------------------------------- gravity and comparison


def test_plot_gravity_scaling_collapses_runs(tmp_path, figures):
    t1 = np.linspace(0.0, 3.0, 31)
    v1 = -0.2 * (1.0 - np.exp(-t1))
    runs = [("1 g", 1.0, t1, v1), ("4 g", 4.0, t1 / 2.0, 2.0 * v1)]
    target = tmp_path / "gravity.png"
    assert_png(target, plot_gravity_scaling(runs, target, "gravity"))
    one, four = figures[0].axes[0].get_lines()
    for line in (one, four):
        np.testing.assert_array_equal(line.get_xdata(), t1)
        np.testing.assert_array_equal(line.get_ydata(), v1)


def test_plot_configuration_comparison(tmp_path, figures):
    rows = comparison_table([metrics("diverging", 2.0, 5.0), metrics("straight", 3.0, 4.0, 12.0),
                             metrics("converging", math.nan, 1.0)])
    columns = ["recirculations_to_homogenise", "vrr_at_0.5_tm"]
    target = tmp_path / "comparison.png"
    assert_png(target, plot_configuration_comparison(rows, columns, target, "configurations", best="diverging"))
    first, second = figures[0].axes
    np.testing.assert_array_equal([bar.get_height() for bar in first.patches], [2.0, 3.0, 0.0])
    assert not first.patches[2].get_visible()  # NaN: never homogenised
    np.testing.assert_array_equal([bar.get_height() for bar in second.patches], [5.0, 4.0, 1.0])
    assert second.patches[0].get_linewidth() == 2.0


def test_plot_configuration_comparison_draws_one_standard_error_where_known(tmp_path, figures):
    rows = [{"configuration": "a", "flow": 3.0, "flow_error": 0.5, "vrr_at_1_tm": 10.0},
            {"configuration": "b", "flow": 2.0, "flow_error": math.nan, "vrr_at_1_tm": 12.0},
            {"configuration": "c", "flow": 1.0, "flow_error": 0.25, "vrr_at_1_tm": 14.0}]
    target = tmp_path / "comparison.png"
    plot_configuration_comparison(rows, ["flow", "vrr_at_1_tm"], target, "errors")
    flow, vrr = figures[0].axes
    (bars,) = flow.containers[1:]  # after the bars: one error-bar set, for a and c only
    segments = bars.lines[2][0].get_segments()
    np.testing.assert_allclose([segment[:, 1] for segment in segments], [[2.5, 3.5], [0.75, 1.25]])
    np.testing.assert_allclose([segment[0, 0] for segment in segments], [0.0, 2.0])
    assert len(vrr.containers) == 1  # no error column: bars only


# --------------------------------------------------------------------------- bad input


def test_plot_writers_reject_bad_input(tmp_path):
    target = tmp_path / "bad.png"
    field = uniform_field()
    passages = passage_velocities(field, 0.5, PASSAGES)
    with pytest.raises(ValueError, match="profiles must be a ProfilesOverTime"):
        plot_profiles_over_time(field, target, "t")
    with pytest.raises(ValueError, match="outlet must be a PassageVelocities"):
        plot_passage_distributions(passages, None, target, "t")
    other_rows = BlenderField(x=X_FULL, z=Z_ROWS[:5], v_x=np.zeros((21, 5)), v_z=-np.ones((21, 5)),
                              solid_fraction=np.ones((21, 5)))
    with pytest.raises(ValueError, match="rows"):
        plot_channel_boundary(field, flow_channel_boundary_over_height(other_rows, 0.1), target, "t")
    with pytest.raises(ValueError, match="pathlines must be"):
        plot_tracer_pathlines(passages, target, "t")
    with pytest.raises(ValueError, match="rtds"):
        plot_rtd_theta({}, target, "t")
    with pytest.raises(ValueError, match=r"rtds\['a'\] must be a RTD"):
        plot_rtd_theta({"a": 1.0}, target, "t")
    with pytest.raises(ValueError, match="result must be a DiscontinuousMode"):
        plot_discontinuous_mode(passages, target, "t")
    with pytest.raises(ValueError, match="results must be a mapping"):
        plot_continuous_mode([1.0], target, "t")
    t = np.linspace(0.0, 1.0, 5)
    with pytest.raises(ValueError, match="gravity_factor"):
        plot_gravity_scaling([("a", 0.0, t, t)], target, "t")
    with pytest.raises(ValueError, match=r"runs\[0\] velocity"):
        plot_gravity_scaling([("a", 1.0, t, t[:-1])], target, "t")
    with pytest.raises(ValueError, match="runs"):
        plot_gravity_scaling([], target, "t")
    rows = comparison_table([metrics("a", 1.0, 2.0)])
    with pytest.raises(ValueError, match="no column"):
        plot_configuration_comparison(rows, ["flow"], target, "t")
    with pytest.raises(ValueError, match="best"):
        plot_configuration_comparison(rows, ["rtd_mean_s"], target, "t", best="b")
    with pytest.raises(ValueError, match="columns"):
        plot_configuration_comparison(rows, [], target, "t")
    assert not target.exists()
