"""Unit tests for siloflow.analysis.studies.blender.plots: PNGs are written and the plotted data are the input (files under
tmp_path)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.colors import to_hex

import siloflow.analysis.studies.blender.plots as blender_plots
from siloflow.analysis.io.plot_style import PALETTE, StudyNote, StudyValue
from siloflow.analysis.studies.validation.figure_findings import study_note, study_value
from siloflow.analysis.studies.validation.findings import PARTS
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
from tests.plot_data import assert_legend_outside, legend_texts, lines_with_gid, saved_figures
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






#: M1 at the diverging insert's outlet: each passage over the cross-section mean (exterior with a +- 10 % band).
M1 = [study_value(PARTS["M1.exterior"], band=(0.144, 0.176), series="exterior"),
      study_value(PARTS["M1.interior"], series="interior"), study_value(PARTS["M1.tube"], series="tube")]
M2 = study_note(PARTS["M2.outlet_order"])


def test_plot_passage_distributions_one_colour_per_passage_one_legend_outside_no_finding_unless_asked(
        tmp_path, figures):
    inlet = passage_velocities(shear_field(), 0.6, PASSAGES)
    outlet = passage_velocities(uniform_field(), 0.2, {"interior": (0.0, 0.05), "exterior": (0.06, 0.1)})
    target = tmp_path / "passages.png"
    assert_png(target, plot_passage_distributions(inlet, outlet, target, "passages"))
    (figure,) = figures
    left, right = figure.axes
    # per panel: the profile and each passage's mean on both sides of the axis
    assert [len(lines_with_gid(axes, "profile")) for axes in (left, right)] == [1, 1]
    assert [len(lines_with_gid(axes, "passage_mean")) for axes in (left, right)] == [2 * 3, 2 * 2]
    tube, interior, exterior = (to_hex(colour) for colour in PALETTE[:3])  # the same in every configuration
    assert [to_hex(line.get_color()) for line in lines_with_gid(left, "passage_mean")[::2]] == [tube, interior, exterior]
    assert [to_hex(line.get_color()) for line in lines_with_gid(right, "passage_mean")[::2]] == [interior, exterior]
    assert left.get_legend() is None  # one legend for both panels
    assert legend_texts(right) == [
        "v_z profile", f"tube: inlet {inlet.mean_v_z['tube']:.3g}, outlet n/a m/s",
        f"interior: inlet {inlet.mean_v_z['interior']:.3g}, outlet {outlet.mean_v_z['interior']:.3g} m/s",
        f"exterior: inlet {inlet.mean_v_z['exterior']:.3g}, outlet {outlet.mean_v_z['exterior']:.3g} m/s"]
    assert not any("study" in text for text in legend_texts(right))
    assert (left.get_ylabel(), left.get_xlabel(), right.get_xlabel()) == ("v_z [m/s]", "x [mm]", "x [mm]")
    assert_legend_outside(figure, right)


def test_plot_passage_distributions_draws_m1_over_each_outlet_passage_and_m2_as_a_note(tmp_path, figures):
    inlet = passage_velocities(shear_field(), 0.6, PASSAGES)
    outlet = passage_velocities(shear_field(0.1, 5.0), 0.2, PASSAGES)
    target = tmp_path / "passages.png"
    assert_png(target, plot_passage_distributions(inlet, outlet, target, "passages", findings=M1 + [M2]))
    (figure,) = figures
    left, right = figure.axes
    assert [len(lines_with_gid(axes, "passage_mean")) for axes in (left, right)] == [2 * 3, 2 * 3]  # data unchanged
    assert lines_with_gid(left, "finding M1") == []  # the findings are the outlet's
    # one dotted segment at the finding's fraction of the outlet's cross-section mean on each side of each passage
    lines = lines_with_gid(right, "finding M1")
    assert len(lines) == 2 * 3 and {line.get_linestyle() for line in lines} == {":"}
    mean = outlet.profile.cross_section_mean
    for line, (name, ratio) in zip(lines[::2], (("exterior", 0.16), ("interior", 1.49), ("tube", 1.79))):
        np.testing.assert_allclose(line.get_ydata(), [ratio * mean] * 2, rtol=1e-12)
        lo, hi = PASSAGES[name]
        np.testing.assert_allclose(sorted(np.abs(line.get_xdata())), [1e3 * lo, 1e3 * hi], rtol=1e-12)
        assert to_hex(line.get_color()) == to_hex(PALETTE[("tube", "interior", "exterior").index(name)])
    bands = [collection for collection in right.collections if collection.get_gid() == "finding M1"]
    assert len(bands) == 2  # the exterior's band, on both sides
    texts = legend_texts(right)
    assert texts[4:] == ["study (M1): exterior ~0.16 of mean", "study (M1): interior ~1.49 of mean",
                         "study (M1): tube ~1.79 of mean",
                         "study (M2): tube > interior annulus > exterior annulus"]
    assert_legend_outside(figure, right)


def test_plot_passage_distributions_refuses_a_finding_it_cannot_draw(tmp_path):
    inlet = passage_velocities(shear_field(), 0.6, PASSAGES)
    target = tmp_path / "passages.png"
    with pytest.raises(ValueError, match=r"findings\[0\] \(M1\) must be a velocity over the cross-section mean"):
        plot_passage_distributions(inlet, inlet, target, "t", findings=[StudyValue("M1", 0.16, series="annulus")])
    with pytest.raises(ValueError, match=r"findings\[0\] \(M1\) must be"):
        plot_passage_distributions(inlet, inlet, target, "t",
                                   findings=[StudyValue("M1", 0.16, unit="m/s", series="exterior")])
    with pytest.raises(ValueError, match=r"findings\[0\] must be a StudyValue or StudyNote"):
        plot_passage_distributions(inlet, inlet, target, "t", findings=[0.16])
    assert not target.exists()


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


def _gravity_runs():
    """The converging insert at 4, 1 and 9 g (the 9 g run off the square-root scaling), the straight one at 1 g."""
    t1 = np.linspace(0.0, 3.0, 31)
    v1 = -0.2 * (1.0 - np.exp(-t1))
    return t1, v1, [("converging", 4.0, t1 / 2.0, 2.0 * v1), ("converging", 1.0, t1, v1),
                    ("converging", 9.0, t1 / 3.0, 2.7 * v1), ("straight", 1.0, t1, 0.8 * v1)]


def test_plot_gravity_scaling_one_colour_per_configuration_one_style_per_factor_no_finding_unless_asked(
        tmp_path, figures):
    _, _, runs = _gravity_runs()
    target = tmp_path / "gravity.png"
    assert_png(target, plot_gravity_scaling(runs, target, "gravity", quantity="mean v_z"))
    axes = figures[0].axes[0]
    lines = lines_with_gid(axes, "run")
    assert len(lines) == 4 and len(axes.get_lines()) == 4  # one series per run, nothing else
    converging, straight = to_hex(PALETTE[0]), to_hex(PALETTE[1])
    assert [to_hex(line.get_color()) for line in lines] == [converging, converging, converging, straight]
    assert [line.get_linestyle() for line in lines] == ["--", "-", "-.", "-"]  # 1, 4, 9 g: the factor's style
    assert legend_texts(axes) == ["converging (4 g)", "converging (1 g)", "converging (9 g)", "straight (1 g)"]
    assert lines_with_gid(axes, "finding M4") == []
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("t sqrt(g_run / g) [s]", "mean v_z / sqrt(g_run / g) [m/s]")
    assert_legend_outside(figures[0], axes)


def test_plot_gravity_scaling_draws_the_square_root_scaling_once_labelled_m4(tmp_path, figures):
    t1, v1, runs = _gravity_runs()
    target = tmp_path / "gravity.png"
    m4 = StudyNote("M4", "v scales with sqrt(g)")
    assert_png(target, plot_gravity_scaling(runs, target, "gravity", findings=[m4]))
    axes = figures[0].axes[0]
    assert len(lines_with_gid(axes, "run")) == 4
    # the curve each configuration's runs lie on under the scaling (its 1 g run's), under the runs, one legend entry
    scalings = lines_with_gid(axes, "finding M4")
    assert len(scalings) == 2 and axes.get_lines()[:2] == scalings
    for scaling, factor in zip(scalings, (1.0, 0.8)):
        np.testing.assert_allclose(scaling.get_xdata(), t1, rtol=1e-12)
        np.testing.assert_allclose(scaling.get_ydata(), factor * v1, rtol=1e-12)
    assert legend_texts(axes) == ["study (M4): v scales with sqrt(g)", "converging (4 g)", "converging (1 g)",
                                   "converging (9 g)", "straight (1 g)"]
    assert_legend_outside(figures[0], axes)
    with pytest.raises(ValueError, match=r"findings\[0\] must be a StudyNote, got StudyValue"):
        plot_gravity_scaling(runs, tmp_path / "bad.png", "gravity", findings=[StudyValue("M4", 0.5)])


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
