"""Unit tests for siloflow.calibration.charts: the PNG is written and the plotted data are the input (files under tmp_path
only)."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_hex

from siloflow.analysis.io.plot_style import PALETTE, REFERENCE_COLOUR, StudyNote
from siloflow.analysis.studies.validation.figure_findings import study_value
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.calibration.charts import plot_calibration_chart, plot_force_history, plot_lid_comparison, plot_polar_histogram
from siloflow.calibration.contact_diagnostics import angular_histogram
from siloflow.calibration.friction import BulkFriction, SteadyWindow
from siloflow.calibration.inversion import CalibrationCurve, curves_from_table
from siloflow.calibration.shear import ShearSignals
from tests.plot_data import assert_legend_outside, legend_texts

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _only_file(folder, name):
    assert sorted(p.name for p in folder.iterdir()) == [name], "temporary files left behind"


def _curves():
    particle = np.linspace(0.0, 1.0, 11)
    return [
        CalibrationCurve(
            shape="sphere2",
            test="internal",
            rolling_friction=rolling,
            particle_friction=particle,
            bulk_friction=0.2 + rolling + 0.4 * np.minimum(particle, 0.6),
            bulk_standard_error=np.full(particle.size, 0.01) if rolling > 0 else None,
        )
        for rolling in (0.1, 0.0, 0.05)
    ]


def _curve_containers(axes):
    """{legend label: errorbar container} of the chart's curves."""
    return {container.get_label(): container for container in axes.containers}


def _error_segments(container):
    """The (x, y - err, y + err) of each error bar of an errorbar container (none where the error is NaN)."""
    (bars,) = container.lines[2]
    return np.array([[segment[0, 0], segment[0, 1], segment[1, 1]] for segment in bars.get_segments()
                     if len(segment)])


@pytest.mark.parametrize("target, tolerance", [(30.0, 1.0), (30.0, None), (None, None)])
def test_plot_calibration_chart_draws_each_curve_in_degrees_with_its_error_and_the_target(tmp_path, target, tolerance):
    path = tmp_path / "plots" / "chart.png"
    figure = plot_calibration_chart(_curves(), path, "sphere2, internal friction", target, tolerance)
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(path.parent, "chart.png")
    assert not plt.fignum_exists(figure.number), "the writer closes its figure"
    axes = figure.axes[0]
    assert (axes.get_title(), axes.get_xlabel(), axes.get_ylabel()) == (
        "sphere2, internal friction", "particle-particle sliding friction coefficient [-]", "bulk friction angle [deg]")
    assert [a.get_ylabel() for a in figure.axes[0].child_axes] == ["bulk friction coefficient [-]"]

    particle = np.linspace(0.0, 1.0, 11)
    curves = _curve_containers(axes)
    assert list(curves) == ["mu_r = 0", "mu_r = 0.05", "mu_r = 0.1"]  # sorted by rolling friction
    for rolling in (0.0, 0.05, 0.1):
        bulk = 0.2 + rolling + 0.4 * np.minimum(particle, 0.6)
        container = curves[f"mu_r = {rolling:g}"]
        np.testing.assert_allclose(container.lines[0].get_xydata(),
                                   np.column_stack([particle, np.degrees(np.arctan(bulk))]), rtol=1e-14)
        if rolling == 0.0:
            assert not container.has_yerr  # no standard error given
        else:
            error = np.degrees(0.01 / (1.0 + bulk**2))
            np.testing.assert_allclose(_error_segments(container), np.column_stack(
                [particle, np.degrees(np.arctan(bulk)) - error, np.degrees(np.arctan(bulk)) + error]), rtol=1e-14)

    bands = [patch for patch in axes.patches if patch.get_label().startswith("target")]
    target_lines = [line for line in axes.get_lines() if line.get_gid() == "target"]
    if target is None:
        assert bands == [] and target_lines == []
    else:
        (line,) = target_lines  # drawn once, dashed
        assert line.get_linestyle() == "--"
        np.testing.assert_array_equal(line.get_ydata(), [30.0, 30.0])
        if tolerance is None:
            assert bands == [] and line.get_label() == "target 30 deg"
        else:
            (band,) = bands
            assert band.get_label() == "target 30 ± 1 deg"
            assert (band.get_y(), band.get_y() + band.get_height()) == (29.0, 31.0)
    plt.close(figure)


def test_plot_calibration_chart_draws_the_bulk_friction_errors_of_the_calibration_table(tmp_path):
    # rows as the calibration table holds them (strings), each with its batch-means error bulk_friction_error
    rows = [{"shape": "sphere2", "test": "wall", "wall_material": "aluminium", "rolling_friction": "0.1",
             "particle_friction": str(p), "bulk_friction": str(mu), "bulk_friction_error": str(e),
             "bulk_friction_stderr": str(e)}
            for p, mu, e in ((0.1, 0.1, 0.002), (0.3, 0.3, 0.004), (0.5, 0.4, 0.006))]
    path = tmp_path / "chart.png"
    figure = plot_calibration_chart(curves_from_table(rows), path, "sphere2, aluminium wall friction", 9.5, 1.0)
    (container,) = _curve_containers(figure.axes[0]).values()
    mu, error = np.array([0.1, 0.3, 0.4]), np.array([0.002, 0.004, 0.006])
    angle, angle_error = np.degrees(np.arctan(mu)), np.degrees(error / (1.0 + mu**2))
    np.testing.assert_allclose(_error_segments(container),
                               np.column_stack([[0.1, 0.3, 0.5], angle - angle_error, angle + angle_error]), rtol=1e-14)
    plt.close(figure)


def test_plot_calibration_chart_mixed_shapes_and_materials(tmp_path):
    particle = [0.0, 0.5, 1.0]
    curves = [
        CalibrationCurve("sphere", "wall", 0.0, particle, [0.05, 0.2, 0.3], wall_material="aluminium"),
        CalibrationCurve("sphere4", "wall", 0.1, particle, [0.1, 0.25, 0.35], [0.01, np.nan, 0.02], "perspex"),
    ]
    path = tmp_path / "wall.png"
    figure = plot_calibration_chart(curves, path, "wall friction", target_angle_deg=9.5, tolerance_deg=1.0)
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(tmp_path, "wall.png")
    axes = figure.axes[0]
    assert axes.get_xlabel() == "particle-wall sliding friction coefficient [-]"
    containers = _curve_containers(axes)
    assert list(containers) == ["sphere, aluminium, mu_r = 0", "sphere4, perspex, mu_r = 0.1"]
    np.testing.assert_allclose(containers["sphere, aluminium, mu_r = 0"].lines[0].get_ydata(),
                               np.degrees(np.arctan([0.05, 0.2, 0.3])), rtol=1e-14)
    bars = _error_segments(containers["sphere4, perspex, mu_r = 0.1"])
    angles = np.degrees(np.arctan([0.1, 0.25, 0.35]))
    errors = np.degrees(np.array([0.01, np.nan, 0.02]) / (1.0 + np.array([0.1, 0.25, 0.35]) ** 2))
    drawn = np.isfinite(errors)  # the NaN error of the middle point draws no bar
    np.testing.assert_allclose(bars, np.column_stack([particle, angles - errors, angles + errors])[drawn], rtol=1e-14)
    (band,) = [patch for patch in axes.patches if patch.get_label().startswith("target")]
    assert (band.get_y(), band.get_height()) == (8.5, 2.0)
    plt.close(figure)


def test_plot_calibration_chart_rejects_empty_and_keeps_old_file(tmp_path):
    path = tmp_path / "chart.png"
    path.write_bytes(b"old")
    with pytest.raises(ValueError, match="curves"):
        plot_calibration_chart([], path, "empty")
    with pytest.raises(ValueError, match="tolerance_deg"):
        plot_calibration_chart(_curves(), path, "bad", 30.0, -1.0)
    assert path.read_bytes() == b"old"
    _only_file(tmp_path, "chart.png")


def _finding_artists(axes, finding_id):
    """The lines and bands drawn for a finding (``gid="finding <id>"``)."""
    gid = f"finding {finding_id}"
    return ([line for line in axes.get_lines() if line.get_gid() == gid],
            [patch for patch in axes.patches if patch.get_gid() == gid])





#: C2's plateau of the two-sphere clump with its band (+- 10 %), C7's measured internal friction angle.
C2_SPHERE2 = study_value(PARTS["C2.sphere2"], band=(0.486, 0.594), series="sphere2")
C7_INTERNAL = study_value(PARTS["C7.internal"])


def test_plot_calibration_chart_in_the_journal_style_one_colour_per_shape_one_style_per_rolling_friction(tmp_path):
    figure = plot_calibration_chart(_curves(), tmp_path / "chart.png", "sphere2, internal friction", 30.0, 1.0)
    axes = figure.axes[0]
    curves = [container for container in axes.containers if not container.get_label().startswith("_")]
    assert len(curves) == 3  # one series per curve, nothing else drawn as data
    data_lines = [container.lines[0] for container in curves]
    assert {to_hex(line.get_color()) for line in data_lines} == {to_hex(PALETTE[1])}  # sphere2's colour
    assert [line.get_linestyle() for line in data_lines] == ["-", "--", "-."]
    assert [line.get_marker() for line in data_lines] == ["o", "s", "^"]
    assert axes.xaxis.label.get_fontsize() == 9 and axes.title.get_fontsize() == 9
    # the curves first, then the target; no finding unless asked for
    assert legend_texts(axes) == ["mu_r = 0", "mu_r = 0.05", "mu_r = 0.1", "target 30 ± 1 deg"]
    assert not any("study" in text for text in legend_texts(axes))
    assert [line for line in axes.get_lines() if (line.get_gid() or "").startswith("finding")] == []
    assert "[deg]" in axes.get_ylabel() and "[-]" in axes.get_xlabel()
    assert_legend_outside(figure, axes, *axes.child_axes)


def test_plot_calibration_chart_draws_each_finding_once_at_its_angle_labelled_with_its_id(tmp_path):
    figure = plot_calibration_chart(_curves(), tmp_path / "chart.png", "sphere2, internal friction", 30.0, 1.0,
                                    findings=[C2_SPHERE2, C7_INTERNAL, StudyNote("C1", "finite at zero friction")])
    axes = figure.axes[0]
    assert len([container for container in axes.containers if not container.get_label().startswith("_")]) == 3
    assert legend_texts(axes) == ["mu_r = 0", "mu_r = 0.05", "mu_r = 0.1", "target 30 ± 1 deg",
                                   "study (C2): sphere2 ~0.54", "study (C7): ~30 deg",
                                   "study (C1): finite at zero friction"]
    # C2: a coefficient, drawn at its angle atan(0.54) [deg] with its band, in the colour of its shape
    (line,), (band,) = _finding_artists(axes, "C2")
    np.testing.assert_allclose(line.get_ydata(), [math.degrees(math.atan(0.54))] * 2, rtol=1e-12)
    assert line.get_linestyle() == ":" and to_hex(line.get_color()) == to_hex(PALETTE[1])
    np.testing.assert_allclose([band.get_y(), band.get_y() + band.get_height()],
                               np.degrees(np.arctan([0.486, 0.594])), rtol=1e-12)
    # C7: an angle, drawn as it is, in the reference grey (no series), with no band
    (line,), bands = _finding_artists(axes, "C7")
    np.testing.assert_array_equal(line.get_ydata(), [30.0, 30.0])
    assert bands == [] and to_hex(line.get_color()) == to_hex(REFERENCE_COLOUR)
    (note,), _ = _finding_artists(axes, "C1")
    assert np.size(note.get_xdata()) == 0  # a legend entry only: no data
    assert_legend_outside(figure, axes, *axes.child_axes)


def test_plot_calibration_chart_refuses_a_finding_it_cannot_draw(tmp_path):
    path = tmp_path / "chart.png"
    with pytest.raises(ValueError, match=r"findings\[0\] \(S2\) must be a bulk friction coefficient"):
        plot_calibration_chart(_curves(), path, "t", findings=[study_value(PARTS["S2"])])
    with pytest.raises(ValueError, match=r"findings\[1\] must be a StudyValue or StudyNote, got tuple"):
        plot_calibration_chart(_curves(), path, "t", findings=[C2_SPHERE2, ("C2", 0.54)])
    assert not path.exists()


def _sectors(figure):
    """(start angle, width, height) of each bar of a rose diagram."""
    (axes,) = figure.axes
    return np.array([[bar.get_x(), bar.get_width(), bar.get_height()] for bar in axes.patches])


def test_plot_polar_histogram_draws_one_sector_per_bin(tmp_path):
    edges = np.array([0.0, 0.5, 1.5, 2.0 * math.pi])
    path = tmp_path / "polar" / "friction.png"
    figure = plot_polar_histogram(edges, [3, 0, 1.5], path, "friction direction")
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(path.parent, "friction.png")
    assert not plt.fignum_exists(figure.number)
    assert figure.axes[0].name == "polar" and figure.axes[0].get_title() == "friction direction"
    np.testing.assert_allclose(_sectors(figure), [[0.0, 0.5, 3.0], [0.5, 1.0, 0.0], [1.5, 2.0 * math.pi - 1.5, 1.5]],
                               rtol=1e-15)
    plt.close(figure)


def test_plot_polar_histogram_of_an_angular_histogram(tmp_path):
    rng = np.random.default_rng(7)
    edges, counts = angular_histogram(rng.normal(size=(500, 3)), axis="y", bins=36)
    path = tmp_path / "polar" / "omega.png"
    figure = plot_polar_histogram(edges, counts, path, "angular velocity direction")
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(path.parent, "omega.png")
    np.testing.assert_allclose(_sectors(figure), np.column_stack([edges[:-1], np.diff(edges), counts]), rtol=1e-15)
    assert _sectors(figure)[:, 2].sum() == 500
    plt.close(figure)


def test_plot_polar_histogram_rejects_mismatch(tmp_path):
    edges = np.linspace(0.0, 2.0 * math.pi, 5)
    with pytest.raises(ValueError, match="counts"):
        plot_polar_histogram(edges, [1, 2, 3], tmp_path / "x.png", "bad")
    with pytest.raises(ValueError, match="edges_rad"):
        plot_polar_histogram(edges[::-1], [1, 2, 3, 4], tmp_path / "x.png", "bad")
    assert list(tmp_path.iterdir()) == []


def test_plot_force_history_draws_the_shear_and_normal_forces_and_the_window(tmp_path):
    time = np.linspace(0.0, 2.0, 5)
    signals = ShearSignals(time=time, lid_force=np.array([0.0, 1.0, 2.0, 2.0, 2.0]),
                           ring_force=np.array([0.0, 0.5, 1.0, 1.0, 1.0]),
                           bottom_force=np.array([0.0, 1.4, 2.9, 3.0, 2.8]),
                           normal_force=np.full(5, 5.0), weight_above=np.full(5, 1.0))
    friction = BulkFriction(coefficient=0.5, standard_error=0.01, bottom_coefficient=0.48,
                            bottom_standard_error=0.02, angle_deg=26.565, bottom_angle_deg=25.64,
                            window=SteadyWindow(t_start=1.0, t_end=2.0, i_start=2, i_end=5, plateau=3.0),
                            relative_difference=0.04, shear_force=3.0, normal_load=6.0)
    path = tmp_path / "force.png"
    figure = plot_force_history(signals, friction, path, "internal, mu = 0.3")
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(tmp_path, "force.png")
    assert not plt.fignum_exists(figure.number)
    (axes,) = figure.axes
    assert (axes.get_title(), axes.get_xlabel(), axes.get_ylabel()) == ("internal, mu = 0.3", "time [s]", "force [N]")
    lines = {line.get_label(): line.get_xydata() for line in axes.get_lines()}
    np.testing.assert_array_equal(lines["lid + shear ring"], np.column_stack([time, [0.0, 1.5, 3.0, 3.0, 3.0]]))
    np.testing.assert_array_equal(lines["bottom ring / plate"], np.column_stack([time, [0.0, 1.4, 2.9, 3.0, 2.8]]))
    np.testing.assert_array_equal(lines["normal force + weight above"], np.column_stack([time, np.full(5, 6.0)]))
    (window,) = [patch for patch in axes.patches if patch.get_label() == "averaging window"]
    assert (window.get_x(), window.get_width()) == (1.0, 1.0)
    assert [text.get_text() for text in axes.texts] == ["mu_bulk = 0.500 +- 0.010 (26.6 deg)\nbottom side: 0.480"]
    plt.close(figure)


def test_plot_lid_comparison_draws_both_lids_per_shape_and_rolling_friction(tmp_path):
    rows = [{"shape": "sphere2", "rolling_friction": 0.1, "particle_friction": mu, "bulk_friction_rigid_lid": rigid,
             "bulk_friction_servo_lid": servo}
            for mu, rigid, servo in ((0.2, 0.40, 0.42), (0.5, 0.55, 0.60))]
    rows.insert(1, {"shape": "sphere", "rolling_friction": 0.0, "particle_friction": 0.3,
                    "bulk_friction_rigid_lid": 0.3, "bulk_friction_servo_lid": 0.35})
    path = tmp_path / "lids.png"
    figure = plot_lid_comparison(rows, path, "lids")
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    (axes,) = figure.axes
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("particle-particle sliding friction coefficient [-]",
                                                      "bulk friction coefficient [-]")
    lines = {line.get_label(): line.get_xydata().tolist() for line in axes.get_lines()}
    assert lines == {
        "sphere, mu_r = 0: rigid lid": [[0.3, 0.3]],
        "sphere, mu_r = 0: servo lid": [[0.3, 0.35]],
        "sphere2, mu_r = 0.1: rigid lid": [[0.2, 0.40], [0.5, 0.55]],
        "sphere2, mu_r = 0.1: servo lid": [[0.2, 0.42], [0.5, 0.60]],
    }
    assert [line.get_label() for line in axes.get_lines()][0] == "sphere, mu_r = 0: rigid lid"  # sorted groups
    plt.close(figure)
