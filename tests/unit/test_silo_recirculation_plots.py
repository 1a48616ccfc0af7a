"""Unit tests for siloflow.analysis.studies.silo_recirculation.plots and .rtd_plots: PNGs are written (under tmp_path only)
and the plotted data are the input, as each writer's docstring promises."""

from __future__ import annotations

import matplotlib.patches
import numpy as np
import pytest
from matplotlib.collections import PathCollection, PolyCollection
from matplotlib.colors import to_hex
from matplotlib.path import Path as MplPath

import siloflow.analysis.studies.silo_recirculation.plots as plots
from siloflow.analysis.io.plot_style import PALETTE
import siloflow.analysis.studies.silo_recirculation.rtd_plots as rtd_plots
import siloflow.analysis.studies.silo_recirculation.vrr_summary_plot as vrr_summary_plot
from tests.plot_data import saved_figures
from siloflow.analysis.studies.silo_recirculation.plots import (
    plot_coloured_snapshots,
    plot_outlet_concentration,
    plot_paths_comparison,
    plot_vrr_versus_recirculations,
)
from siloflow.analysis.studies.silo_recirculation.vrr_summary_plot import plot_vrr_summary, vrr_replicate_curves
from siloflow.analysis.studies.silo_recirculation.rtd_plots import (
    plot_lti_comparison,
    plot_recirculation_model,
    plot_residence_time_comparison,
    plot_rtd_comparison,
    plot_vrr_versus_period,
)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
WIDTH, OUTLET, TOP, CHANNEL = 0.2, 0.02, 0.3, 0.08


def _assert_png(target, returned):
    assert returned == target
    data = target.read_bytes()
    assert data.startswith(PNG_SIGNATURE)
    assert 5_000 < len(data) < 5_000_000
    assert sorted(p.name for p in target.parent.iterdir()) == [target.name], "temporary files left behind"


@pytest.fixture
def figures(monkeypatch):
    """The figures the writers save, kept (after they are written) so that their plotted data can be checked."""
    return saved_figures(monkeypatch, plots, rtd_plots, vrr_summary_plot)


def _only_axes(figures):
    (figure,) = figures
    (axes,) = figure.axes
    return axes


def _line(axes, label):
    (line,) = [line for line in axes.get_lines() if line.get_label() == label]
    return line


def _lines_with_gid(axes, gid):
    return [line for line in axes.get_lines() if line.get_gid() == gid]


def _pieces(line) -> int:
    """Separate pieces matplotlib draws for a line: NaN samples split it (one MOVETO per piece)."""
    return sum(code == MplPath.MOVETO for _, code in line.get_path().cleaned(remove_nans=True).iter_segments())


def _horizontal_lines(axes) -> list[float]:
    """The y of every horizontal reference line (axhline), in drawing order."""
    return [line.get_ydata()[0] for line in axes.get_lines()
            if line.get_transform() != axes.transData and list(line.get_xdata()) == [0, 1]]


def _concentration_curves():
    nr = np.linspace(0.0, 4.0, 81)
    return [("DEM", nr, 0.5 + 0.5 * np.exp(-nr) * np.cos(6 * nr)), ("model", nr, 0.5 + 0.4 * np.exp(-1.5 * nr))]


def _rtd_curves():
    t = np.linspace(0.05, 9.95, 100)
    return [("DEM", t, np.exp(-t / 2.0) / 2.0, 2.0), ("mixer", t, np.exp(-t / 3.0) / 3.0, 3.0)]


def _snapshot(nr, n=300, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.uniform(-0.5 * WIDTH, 0.5 * WIDTH, n)
    z = rng.uniform(0.0, TOP, n)
    return (nr, x, z, z > 0.5 * TOP)


def _paths():
    z = np.linspace(TOP, 0.0, 50)
    track = np.column_stack([0.05 * z / TOP, z])
    broken = track.copy()
    broken[20] = np.nan
    line = np.column_stack([0.04 * z / TOP, z])
    return [track, broken], [line]


# ---------------------------------------------------------------------------------------- outlet concentration


@pytest.mark.parametrize("tolerance", [0.10, 0.05])
def test_plot_outlet_concentration_draws_each_curve_and_the_band(tmp_path, figures, tolerance):
    target = tmp_path / "plots" / "outlet.png"
    _assert_png(target, plot_outlet_concentration(_concentration_curves(), 0.4, target, "outlet", tolerance=tolerance))
    axes = _only_axes(figures)
    for label, nr, c in _concentration_curves():
        line = _line(axes, label)
        np.testing.assert_array_equal(line.get_xdata(), nr)
        np.testing.assert_array_equal(line.get_ydata(), c)
        assert _pieces(line) == 1
    assert _horizontal_lines(axes) == [0.4]  # the blue fraction
    (band,) = [patch for patch in axes.patches if isinstance(patch, matplotlib.patches.Rectangle)]
    np.testing.assert_allclose([band.get_y(), band.get_y() + band.get_height()],
                               [0.4 * (1 - tolerance), 0.4 * (1 + tolerance)], rtol=1e-12)
    assert axes.get_title() == "outlet"


def test_plot_outlet_concentration_nan_is_a_gap(tmp_path, figures):
    label, nr, c = _concentration_curves()[0]
    c = c.copy()
    c[10:15] = np.nan
    target = tmp_path / "outlet.png"
    _assert_png(target, plot_outlet_concentration([(label, nr, c)], 0.5, target, "gaps"))
    line = _line(_only_axes(figures), label)
    # every sample is handed to matplotlib, NaN included (not dropped, not bridged), so the line breaks in two
    np.testing.assert_array_equal(line.get_xdata(), nr)
    np.testing.assert_array_equal(line.get_ydata(), c)
    assert _pieces(line) == 2


def test_plot_outlet_concentration_rejects_bad_input(tmp_path):
    nr = np.linspace(0, 1, 5)
    with pytest.raises(ValueError, match="curves"):
        plot_outlet_concentration([], 0.5, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] y"):
        plot_outlet_concentration([("a", nr, nr[:-1])], 0.5, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="blue_fraction"):
        plot_outlet_concentration([("a", nr, nr)], 0.0, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="tolerance"):
        plot_outlet_concentration([("a", nr, nr)], 0.5, tmp_path / "a.png", "t", tolerance=-0.1)
    assert not (tmp_path / "a.png").exists()


# ---------------------------------------------------------------------------------------- VRR vs recirculations


def _at_ceiling(axes) -> list[tuple[list, list]]:
    """(x, y) of the open markers of VRRs at the counting-noise ceiling, one entry per curve that has some."""
    return [(list(line.get_xdata()), list(line.get_ydata())) for line in _lines_with_gid(axes, "at_ceiling")]


@pytest.mark.parametrize("noise_limit", [None, 250.0])
def test_plot_vrr_versus_recirculations_draws_the_ceiling_and_marks_vrrs_near_it(tmp_path, figures, noise_limit):
    nr = np.arange(1.0, 6.0)
    curves = [("DEM", nr, 3.0 ** nr), ("model", nr, 2.0 ** nr)]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "VRR", noise_limit=noise_limit))
    axes = _only_axes(figures)
    assert axes.get_yscale() == "log"
    for label, x, y in curves:
        np.testing.assert_array_equal(_line(axes, label).get_xdata(), x)
        np.testing.assert_array_equal(_line(axes, label).get_ydata(), y)
    if noise_limit is None:
        assert _horizontal_lines(axes) == [1.0]
        assert _at_ceiling(axes) == []
    else:
        assert _horizontal_lines(axes) == [1.0, 250.0]
        assert [line.get_ydata()[0] for line in _lines_with_gid(axes, "ceiling")] == [250.0]
        # 3^5 = 243 >= 250 / 2 is marked; 3^4 = 81 and every 2^k are not
        assert _at_ceiling(axes) == [([5.0], [243.0])]
        assert "within x2 of the ceiling: lower bound" in [text.get_text() for text in axes.get_legend().get_texts()]


def test_plot_vrr_versus_recirculations_skips_non_finite(tmp_path, figures):
    nr = np.arange(1.0, 6.0)
    curves = [("mixed", nr, np.array([2.0, np.nan, 8.0, np.inf, -1.0])),
              ("all bad", nr, np.full(5, np.nan))]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "non-finite", noise_limit=10.0))
    axes = _only_axes(figures)
    mixed = _line(axes, "mixed")
    np.testing.assert_array_equal(mixed.get_xdata(), [1.0, 3.0])  # NaN, inf and -1 are not on the line
    np.testing.assert_array_equal(mixed.get_ydata(), [2.0, 8.0])
    empty = _line(axes, "all bad (no finite VRR)")
    assert np.size(empty.get_xdata()) == 0 and np.size(empty.get_ydata()) == 0
    (infinite,) = _lines_with_gid(axes, "infinite")  # inf: a triangle at the top of the axes, at Nr = 4
    np.testing.assert_array_equal(infinite.get_xdata(), [4.0])
    np.testing.assert_array_equal(infinite.get_ydata(), [0.97])
    assert infinite.get_color() == mixed.get_color()
    assert _at_ceiling(axes) == [([3.0], [8.0])]  # 8 >= 10 / 2; 2 is not


def test_plot_vrr_versus_recirculations_uses_each_curves_own_ceiling(tmp_path, figures):
    nr = np.array([1.0, 2.0])
    curves = [("run a", nr, [10.0, 30.0], 40.0), ("run b", nr, [10.0, 30.0], 100.0), ("run c", nr, [10.0, 30.0]),
              ("run d", nr, [10.0, 30.0], None)]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "ceilings"))
    axes = _only_axes(figures)
    assert [line.get_ydata()[0] for line in _lines_with_gid(axes, "ceiling")] == [40.0, 100.0]
    assert _at_ceiling(axes) == [([2.0], [30.0])]  # run a only: 30 >= 40 / 2 but < 100 / 2; c and d have none
    (marker,) = _lines_with_gid(axes, "at_ceiling")
    assert marker.get_markerfacecolor() == "white" and marker.get_markeredgecolor() == _line(axes, "run a").get_color()
    # the markers take no colour from the cycle: the curves keep the default colours in order
    assert [to_hex(_line(axes, f"run {name}").get_color()) for name in "abcd"] == [
        "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"]
    figures.clear()
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "ceilings", noise_limit=60.0, factor=4.0))
    # factor 4: 30 >= 100 / 4 and 60 / 4 too; 10 >= 40 / 4 as well
    assert _at_ceiling(_only_axes(figures)) == [([1.0, 2.0], [10.0, 30.0]), ([2.0], [30.0]), ([2.0], [30.0]),
                                                ([2.0], [30.0])]


def _error_bars(axes) -> list[list[tuple[float, float, float]]]:
    """(x, lower end, upper end) of every error bar, one list per curve that has bars."""
    return [[(float(x0), float(y0), float(y1)) for ((x0, y0), (_, y1)) in collection.get_segments()]
            for collection in axes.collections if collection.get_gid() == "vrr_error"]


def test_plot_vrr_versus_recirculations_draws_one_standard_error_bars(tmp_path, figures):
    nr = np.array([0.5, 1.5, 2.5, 3.5])
    curves = [("run a", nr, [2.0, 8.0, np.nan, np.inf], 100.0, [0.5, 2.0, 1.0, np.nan]),
              ("run b", nr, [3.0, 6.0, 9.0, 12.0], None, [np.nan, 1.5, 3.0, 9.0]),
              ("run c", nr, [4.0, 5.0, 6.0, 7.0])]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "errors", noise_limit=50.0))
    axes = _only_axes(figures)
    # the plotted line is still the data
    np.testing.assert_array_equal(_line(axes, "run a").get_xdata(), [0.5, 1.5])
    np.testing.assert_array_equal(_line(axes, "run a").get_ydata(), [2.0, 8.0])
    np.testing.assert_array_equal(_line(axes, "run b").get_ydata(), [3.0, 6.0, 9.0, 12.0])
    # +- one error around each drawn VRR; none where the VRR (NaN, inf) or the error (NaN) is missing, none for
    # run c; the bar of 12 +- 9 keeps its lower end at 3
    assert _error_bars(axes) == [[(0.5, 1.5, 2.5), (1.5, 6.0, 10.0)],
                                 [(1.5, 4.5, 7.5), (2.5, 6.0, 12.0), (3.5, 3.0, 21.0)]]
    bars = [collection for collection in axes.collections if collection.get_gid() == "vrr_error"]
    assert [to_hex(bar.get_colors()[0]) for bar in bars] == [to_hex(_line(axes, f"run {name}").get_color())
                                                             for name in "ab"]
    # the bars take no colour from the cycle and add nothing to the legend
    assert [to_hex(_line(axes, f"run {name}").get_color()) for name in "abc"] == ["#1f77b4", "#ff7f0e", "#2ca02c"]
    assert [text.get_text() for text in axes.get_legend().get_texts()][-3:] == ["run a", "run b", "run c"]


def test_plot_vrr_versus_recirculations_rejects_bad_input(tmp_path):
    nr = np.arange(1.0, 4.0)
    with pytest.raises(ValueError, match="curves"):
        plot_vrr_versus_recirculations([], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] x"):
        plot_vrr_versus_recirculations([("a", [1.0, np.nan, 3.0], nr)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="noise_limit"):
        plot_vrr_versus_recirculations([("a", nr, nr)], tmp_path / "a.png", "t", noise_limit=0.0)
    with pytest.raises(ValueError, match=r"curves\[0\] must be a tuple of 3 items"):
        plot_vrr_versus_recirculations([("a", nr)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] must be a tuple of 3 items"):
        plot_vrr_versus_recirculations([("a", nr, nr, 5.0, nr, 1)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] error must be a 1-D array of the same length"):
        plot_vrr_versus_recirculations([("a", nr, nr, 5.0, 1.0)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] error must hold standard errors >= 0"):
        plot_vrr_versus_recirculations([("a", nr, nr, None, [0.1, -0.1, 0.1])], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] error must hold standard errors >= 0"):
        plot_vrr_versus_recirculations([("a", nr, nr, None, [0.1, np.inf, 0.1])], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[1\] ceiling must be a finite number > 0"):
        plot_vrr_versus_recirculations([("a", nr, nr), ("b", nr, nr, 0.0)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="factor must be a finite number >= 1"):
        plot_vrr_versus_recirculations([("a", nr, nr)], tmp_path / "a.png", "t", factor=0.5)
    assert not (tmp_path / "a.png").exists()


# ---------------------------------------------------------------------------------------- VRR summary

SUMMARY_NR = np.array([0.5, 1.5, 2.5, 3.5])
#: internal flow blue13: three seeds, mean [3, 5, 9, 18] and sample standard deviation [1, 1, 1, 2]
INTERNAL_BLUE13 = np.array([[2.0, 4.0, 8.0, 16.0], [3.0, 5.0, 9.0, 18.0], [4.0, 6.0, 10.0, 20.0]])
STUDY_B4 = [{"id": "B4", "flow_pattern": "internal_flow", "at": 4.0, "low": 8.0, "high": 13.0},
            {"id": "B4", "flow_pattern": "semi_mass_flow", "at": 4.0, "low": 4.0, "high": 6.0}]


def _summary_curves():
    """2 flow patterns x 2 layouts: internal flow with 3 seeds, semi-mass flow with 1; four ceilings, one None."""
    return [
        {"flow_pattern": "internal_flow", "layout": "blue13", "recirculations": SUMMARY_NR, "vrr": INTERNAL_BLUE13,
         "ceiling": 500.0},
        {"flow_pattern": "internal_flow", "layout": "blue4", "recirculations": SUMMARY_NR,
         "vrr": 2.0 * INTERNAL_BLUE13, "ceiling": 300.0},
        {"flow_pattern": "semi_mass_flow", "layout": "blue13", "recirculations": SUMMARY_NR,
         "vrr": [[1.5, 2.5, 3.5, 4.5]], "ceiling": None},
        {"flow_pattern": "semi_mass_flow", "layout": "blue4", "recirculations": SUMMARY_NR,
         "vrr": [[1.2, 2.2, 3.2, 4.2]], "ceiling": 800.0},
    ]


def _bands(axes) -> list:
    return [collection for collection in axes.collections if collection.get_gid() == "vrr_band"]


def test_plot_vrr_summary_draws_one_mean_per_pattern_and_layout_with_a_band_for_replicates(tmp_path, figures):
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_summary(_summary_curves(), target, "VRR summary", findings=STUDY_B4))
    axes = _only_axes(figures)
    assert axes.get_yscale() == "log"
    means = _lines_with_gid(axes, "vrr_mean")
    assert len(means) == 2 * 2  # n_patterns x n_layouts, not x seeds
    internal, semi = to_hex(PALETTE[0]), to_hex(PALETTE[1])
    assert [to_hex(line.get_color()) for line in means] == [internal, internal, semi, semi]
    assert [line.get_linestyle() for line in means] == ["-", "--", "-", "--"]  # one style per layout, in each pattern
    assert [line.get_marker() for line in means] == ["o", "s", "o", "s"]
    np.testing.assert_allclose(means[0].get_ydata(), [3.0, 5.0, 9.0, 18.0], rtol=1e-12)
    np.testing.assert_array_equal(means[0].get_xdata(), SUMMARY_NR)
    np.testing.assert_array_equal(means[2].get_ydata(), [1.5, 2.5, 3.5, 4.5])  # one seed: the seed itself
    # a band for each replicated curve (internal flow) only, mean +- the standard error of the mean
    bands = _bands(axes)
    assert len(bands) == 2 and all(isinstance(band, PolyCollection) for band in bands)
    assert [to_hex(band.get_facecolor()[0][:3]) for band in bands] == [internal, internal]
    assert bands[0].get_alpha() == pytest.approx(0.2)
    vertices = bands[0].get_paths()[0].vertices
    at_three_and_a_half = sorted(vertices[np.isclose(vertices[:, 0], 3.5), 1])
    sem = 2.0 / np.sqrt(3.0)
    np.testing.assert_allclose([at_three_and_a_half[0], at_three_and_a_half[-1]], [18.0 - sem, 18.0 + sem],
                               rtol=1e-12)


def test_plot_vrr_summary_draws_the_lowest_ceiling_once_with_a_direct_label(tmp_path, figures):
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_summary(_summary_curves(), target, "VRR summary"))
    axes = _only_axes(figures)
    (ceiling,) = _lines_with_gid(axes, "ceiling")
    assert list(ceiling.get_ydata()) == [300.0, 300.0]
    assert ceiling.get_linestyle() == "--"
    assert _horizontal_lines(axes) == [300.0]
    (label,) = [text for text in axes.texts if text.get_gid() == "ceiling_label"]
    assert label.get_text() == "counting-noise ceiling"
    assert label.get_position() == (0.99, 300.0) and label.get_horizontalalignment() == "right"
    legend = [text.get_text() for text in axes.get_legend().get_texts()]
    assert not any("ceiling" in text for text in legend)


def test_plot_vrr_summary_legend_has_each_pattern_layout_and_finding_once_outside_the_data(tmp_path, figures):
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_summary(_summary_curves(), target, "VRR summary", findings=STUDY_B4))
    (figure,) = figures
    axes = _only_axes(figures)
    legend = axes.get_legend()
    assert [text.get_text() for text in legend.get_texts()] == [
        "internal flow", "semi mass flow", "layout blue13", "layout blue4", "study B4: internal flow 8-13",
        "study B4: semi mass flow 4-6"]  # n_patterns + n_layouts + n_findings
    figure.canvas.draw()
    box, data_area = legend.get_window_extent(), axes.get_window_extent()
    assert not box.overlaps(data_area)
    assert box.x0 > data_area.x1
    assert axes.get_xlabel() == "number of recirculations Nr [-]"
    assert axes.get_ylabel() == "variance reduction ratio VRR [-]"
    assert axes.get_title() == "VRR summary"


def test_plot_vrr_summary_draws_each_finding_as_a_bar_at_its_nr_in_its_patterns_colour(tmp_path, figures):
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_summary(_summary_curves(), target, "VRR summary", findings=STUDY_B4))
    axes = _only_axes(figures)
    bars = [collection for collection in axes.collections if collection.get_gid() == "finding B4"]
    segments = [[tuple(map(float, point)) for point in bar.get_segments()[0]] for bar in bars]
    np.testing.assert_allclose(segments, [[(4.0, 8.0), (4.0, 13.0)], [(4.0, 4.0), (4.0, 6.0)]], rtol=1e-12)
    assert [to_hex(bar.get_colors()[0]) for bar in bars] == [to_hex(PALETTE[0]), to_hex(PALETTE[1])]


def test_plot_vrr_summary_skips_what_a_log_axis_cannot_show_and_colours_a_finding_without_curve(tmp_path, figures):
    curves = [{"flow_pattern": "internal_flow", "layout": "blue13", "recirculations": [1.0, 2.0, 3.0],
               "vrr": [[2.0, np.nan, np.inf], [4.0, 6.0, -1.0]]}]
    findings = [{"id": "B4", "flow_pattern": "semi_mass_flow", "at": 4.0, "low": 4.0, "high": 6.0}]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_summary(curves, target, "gaps", findings=findings))
    axes = _only_axes(figures)
    (mean,) = _lines_with_gid(axes, "vrr_mean")
    # Nr 1: both seeds; Nr 2: the one finite seed; Nr 3: none left (inf and -1 have no place on a log axis): a gap
    np.testing.assert_array_equal(mean.get_ydata(), [3.0, 6.0, np.nan])
    assert _lines_with_gid(axes, "ceiling") == []
    (bar,) = [collection for collection in axes.collections if collection.get_gid() == "finding B4"]
    assert to_hex(bar.get_colors()[0]) == to_hex(PALETTE[1])  # the next colour after the curves' flow pattern
    assert [text.get_text() for text in axes.get_legend().get_texts()] == [
        "internal flow", "layout blue13", "study B4: semi mass flow 4-6"]


def test_plot_vrr_summary_rejects_bad_input(tmp_path):
    target = tmp_path / "a.png"
    good = _summary_curves()[0]
    with pytest.raises(ValueError, match="curves must not be empty"):
        plot_vrr_summary([], target, "t")
    with pytest.raises(ValueError, match=r"curves\[0\] vrr must be a 2-D array"):
        plot_vrr_summary([{**good, "vrr": [1.0, 2.0, 3.0, 4.0]}], target, "t")
    with pytest.raises(ValueError, match=r"curves\[0\] vrr must have as many columns as curves\[0\] recirculations"):
        plot_vrr_summary([{**good, "vrr": INTERNAL_BLUE13[:, :3]}], target, "t")
    with pytest.raises(ValueError, match=r"curves\[0\] recirculations must contain only finite numbers"):
        plot_vrr_summary([{**good, "recirculations": [0.5, np.nan, 2.5, 3.5]}], target, "t")
    with pytest.raises(ValueError, match=r"curves\[1\] ceiling must be a finite number > 0"):
        plot_vrr_summary([good, {**good, "layout": "blue4", "ceiling": 0.0}], target, "t")
    with pytest.raises(ValueError, match=r"curves\[1\]: flow pattern 'internal_flow' with layout 'blue13' appears"):
        plot_vrr_summary([good, good], target, "t")
    with pytest.raises(ValueError, match=r"curves\[0\] lacks vrr"):
        plot_vrr_summary([{key: value for key, value in good.items() if key != "vrr"}], target, "t")
    with pytest.raises(ValueError, match=r"findings\[0\] high must be >= low"):
        plot_vrr_summary([good], target, "t", findings=[{**STUDY_B4[0], "low": 13.0, "high": 8.0}])
    with pytest.raises(ValueError, match=r"findings\[1\] low must be a finite number > 0"):
        plot_vrr_summary([good], target, "t", findings=[STUDY_B4[0], {**STUDY_B4[1], "low": 0.0}])
    assert not target.exists()


def test_vrr_replicate_curves_groups_seeds_by_pattern_and_layout():
    rows = [{"flow_pattern": "internal_flow", "layout": "blue13"}, {"flow_pattern": "internal_flow", "layout": "blue4"},
            {"flow_pattern": "internal_flow", "layout": "blue13"},
            {"flow_pattern": "semi_mass_flow", "layout": "blue13"}]
    nr = [0.5, 1.5, 2.5, 3.5]
    errors = [np.nan] * 4
    curves = [("internal_flow blue13", nr, [2.0, 4.0, 8.0, 16.0], 500.0, errors),
              ("internal_flow blue4", nr, [1.0, 2.0, 3.0, 4.0], 500.0, errors),
              # another seed run for fewer windows, on another grid: its log VRR is interpolated onto the first's
              ("internal_flow blue13", [1.0, 2.0, 3.0], [2.0, 8.0, 32.0], 300.0, [np.nan] * 3),
              ("semi_mass_flow blue13", nr, [1.5, np.nan, 3.5, 4.5], None, errors)]
    grouped = vrr_replicate_curves(rows, curves)
    assert [(curve["flow_pattern"], curve["layout"], curve["ceiling"]) for curve in grouped] == [
        ("internal_flow", "blue13", 300.0), ("internal_flow", "blue4", 500.0), ("semi_mass_flow", "blue13", None)]
    blue13 = grouped[0]
    np.testing.assert_array_equal(blue13["recirculations"], nr)
    assert blue13["vrr"].shape == (2, 4)
    np.testing.assert_array_equal(blue13["vrr"][0], [2.0, 4.0, 8.0, 16.0])
    # halfway between 2 and 8 in log space is 4, between 8 and 32 is 16; no value outside the seed's own Nr range
    np.testing.assert_allclose(blue13["vrr"][1], [np.nan, 4.0, 16.0, np.nan], rtol=1e-12)
    np.testing.assert_array_equal(grouped[2]["vrr"], [[1.5, np.nan, 3.5, 4.5]])
    with pytest.raises(ValueError, match="rows and curves must be of the same length"):
        vrr_replicate_curves(rows, curves[:3])
    assert [curve["discharge"] for curve in grouped] == [None, None, None]  # no run discharged after recirculating


def test_vrr_replicate_curves_keeps_each_seeds_discharge_after_the_recirculations():
    rows = [{"flow_pattern": "internal_flow", "layout": "blue13", "final_discharge_recirculations": 4.1,
             "final_discharge_vrr": 9.0},
            {"flow_pattern": "internal_flow", "layout": "blue13", "final_discharge_recirculations": 3.9,
             "final_discharge_vrr": 11.0},
            {"flow_pattern": "semi_mass_flow", "layout": "blue13", "final_discharge_recirculations": np.nan,
             "final_discharge_vrr": np.nan}]
    nr = [0.5, 1.5]
    curves = [(f"{row['flow_pattern']} blue13", nr, [2.0, 4.0], 500.0, [np.nan] * 2) for row in rows]
    internal, semi = vrr_replicate_curves(rows, curves)
    np.testing.assert_array_equal(internal["discharge"]["recirculations"], [4.1, 3.9])
    np.testing.assert_array_equal(internal["discharge"]["vrr"], [9.0, 11.0])
    assert semi["discharge"] is None


def test_plot_vrr_summary_draws_the_discharge_after_the_recirculations_beside_b4(tmp_path, figures):
    curves = [{"flow_pattern": "internal_flow", "layout": "blue13", "recirculations": [0.5, 1.5],
               "vrr": [[2.0, 4.0], [2.0, 6.0]], "ceiling": 400.0,
               "discharge": {"recirculations": [4.1, 3.9], "vrr": [9.0, 11.0]}},
              {"flow_pattern": "semi_mass_flow", "layout": "blue13", "recirculations": [0.5, 1.5],
               "vrr": [[1.5, 2.0]], "ceiling": 400.0, "discharge": {"recirculations": [4.2], "vrr": [5.0]}}]
    findings = [{"id": "B4", "flow_pattern": "internal_flow", "at": 4.0, "low": 8.0, "high": 13.0},
                {"id": "B4", "flow_pattern": "semi_mass_flow", "at": 4.0, "low": 4.0, "high": 6.0}]
    plot_vrr_summary(curves, tmp_path / "vrr.png", "VRR", findings=findings)
    (figure,) = figures
    axes = figure.axes[0]
    points = [line for line in axes.get_lines() if line.get_gid() == "vrr_discharge"]
    # one open marker per curve at the seeds' mean Nr and VRR, in its pattern's colour
    assert [(list(line.get_xdata()), list(line.get_ydata())) for line in points] == [([4.0], [10.0]), ([4.2], [5.0])]
    assert [line.get_markerfacecolor() for line in points] == ["white", "white"]
    assert to_hex(points[0].get_color()) == to_hex(PALETTE[0]) and to_hex(points[1].get_color()) == to_hex(PALETTE[1])
    # the standard error of the mean of two seeds, 9 and 11: sqrt(2) / sqrt(2) = 1; none for one seed
    (bar,) = [c for c in axes.collections if c.get_gid() == "vrr_discharge_error"]
    np.testing.assert_allclose(bar.get_segments()[0][:, 1], [9.0, 11.0], rtol=1e-12)
    texts = [text.get_text() for text in axes.get_legend().get_texts()]
    assert "discharge after the recirculations" in texts
    assert "study B4: internal flow 8-13" in texts and "study B4: semi mass flow 4-6" in texts


# ---------------------------------------------------------------------------------------- snapshots


def _panels(figures):
    (figure,) = figures
    return [axes for axes in figure.axes if axes.get_visible()]


def _scatter_points(axes) -> list[np.ndarray]:
    """Offsets of the scatters of a panel, in drawing order (white batch, then blue)."""
    return [np.asarray(c.get_offsets()) for c in axes.collections if isinstance(c, PathCollection)]


@pytest.mark.parametrize("count", [1, 3, 6])
def test_plot_coloured_snapshots_one_panel_per_snapshot_coloured_by_batch(tmp_path, figures, count):
    snapshots = [_snapshot(0.5 * k, seed=k) for k in range(count)]
    target = tmp_path / "snapshots.png"
    _assert_png(target, plot_coloured_snapshots(snapshots, WIDTH, OUTLET, TOP, CHANNEL, target, "blend"))
    panels = _panels(figures)
    assert len(panels) == count
    columns = min(count, 4)  # rows of up to four panels, the spare ones hidden
    assert len(figures[0].axes) == columns * -(-count // columns)
    for axes, (nr, x, z, blue) in zip(panels, snapshots):
        assert axes.get_title() == f"Nr = {nr:g}"
        white, coloured = _scatter_points(axes)
        np.testing.assert_array_equal(white, np.column_stack([1e3 * x[~blue], 1e3 * z[~blue]]))  # drawn in mm
        np.testing.assert_array_equal(coloured, np.column_stack([1e3 * x[blue], 1e3 * z[blue]]))
        assert axes.get_xlim() == pytest.approx((-0.55e3 * WIDTH, 0.55e3 * WIDTH))


def test_plot_coloured_snapshots_empty_snapshot_allowed(tmp_path, figures):
    target = tmp_path / "snapshots.png"
    empty = (0.0, np.empty(0), np.empty(0), np.empty(0, dtype=bool))
    _assert_png(target, plot_coloured_snapshots([empty, _snapshot(1.0)], WIDTH, OUTLET, TOP, CHANNEL, target, "t"))
    first, second = _panels(figures)
    assert [points.size for points in _scatter_points(first)] == [0, 0]
    assert sum(len(points) for points in _scatter_points(second)) == 300


def test_plot_coloured_snapshots_rejects_bad_input(tmp_path):
    nr, x, z, blue = _snapshot(0.5)
    target = tmp_path / "a.png"
    with pytest.raises(ValueError, match="snapshots"):
        plot_coloured_snapshots([], WIDTH, OUTLET, TOP, CHANNEL, target, "t")
    with pytest.raises(ValueError, match=r"snapshots\[0\]"):
        plot_coloured_snapshots([(nr, x, z, blue[:-1])], WIDTH, OUTLET, TOP, CHANNEL, target, "t")
    with pytest.raises(ValueError, match="channel_length"):
        plot_coloured_snapshots([(nr, x, z, blue)], WIDTH, OUTLET, TOP, 0.0, target, "t")
    with pytest.raises(ValueError, match="width"):
        plot_coloured_snapshots([(nr, x, z, blue)], -WIDTH, OUTLET, TOP, CHANNEL, target, "t")
    assert not target.exists()


# ---------------------------------------------------------------------------------------- RTD comparison


@pytest.mark.parametrize("dimensionless", [True, False])
def test_plot_rtd_comparison_draws_steps_of_each_rtd(tmp_path, figures, dimensionless):
    target = tmp_path / "rtd.png"
    _assert_png(target, plot_rtd_comparison(_rtd_curves(), target, "RTD", dimensionless=dimensionless))
    axes = _only_axes(figures)
    for label, t, e, t_mean in _rtd_curves():
        line = _line(axes, f"{label} (t_m = {t_mean:.3g} s)")
        assert line.get_drawstyle() == "steps-mid"
        # E(theta) = t_m E(t) against theta = t / t_m, or E(t) against t
        np.testing.assert_array_equal(line.get_xdata(), t / t_mean if dimensionless else t)
        np.testing.assert_array_equal(line.get_ydata(), t_mean * e if dimensionless else e)
    assert axes.get_xlim()[0] == 0.0 and axes.get_ylim()[0] == 0.0


def test_plot_rtd_comparison_rejects_bad_input(tmp_path):
    t = np.linspace(0.1, 1.0, 10)
    with pytest.raises(ValueError, match="curves"):
        plot_rtd_comparison([], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] E"):
        plot_rtd_comparison([("a", t, t[:5], 1.0)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[1\] t_mean"):
        plot_rtd_comparison([("a", t, t, 1.0), ("b", t, t, np.nan)], tmp_path / "a.png", "t")


# ---------------------------------------------------------------------------------------- LTI comparison


def test_plot_lti_comparison_draws_every_series_in_its_style(tmp_path, figures):
    time = np.linspace(0.0, 20.0, 201)
    series = [
        ("square input", (np.sin(time) > 0).astype(float), "input"),
        ("DEM", 0.5 + 0.2 * np.sin(time - 1.0), "direct"),
        ("RTD convolution", 0.5 + 0.18 * np.sin(time - 1.1), "predicted"),
        ("first pass only", 0.5 + 0.3 * np.sin(time - 0.5), "first pass"),
        ("other", np.full(time.size, 0.45), "whatever"),
    ]
    target = tmp_path / "lti.png"
    _assert_png(target, plot_lti_comparison(time, series, target, "LTI", blue_fraction=0.5, x_label="Nr [-]"))
    axes = _only_axes(figures)
    expected_styles = {"input": "-", "direct": "-", "predicted": "--", "first pass": ":", "whatever": "-"}
    for label, concentration, style in series:
        line = _line(axes, f"{label} ({style})")
        np.testing.assert_array_equal(line.get_xdata(), time)
        np.testing.assert_array_equal(line.get_ydata(), concentration)
        assert line.get_linestyle() == expected_styles[style]
    assert _line(axes, "square input (input)").get_color() == "0.5"
    assert _horizontal_lines(axes) == [0.5]
    assert axes.get_xlabel() == "Nr [-]"


def test_plot_lti_comparison_rejects_bad_input(tmp_path):
    time = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match="series"):
        plot_lti_comparison(time, [], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="time"):
        plot_lti_comparison([], [("a", [], "direct")], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"series\[0\] concentration"):
        plot_lti_comparison(time, [("a", time[:3], "direct")], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="blue_fraction"):
        plot_lti_comparison(time, [("a", time, "direct")], tmp_path / "a.png", "t", blue_fraction=-1.0)


# ---------------------------------------------------------------------------------------- VRR vs period


def test_plot_vrr_versus_period_draws_the_finite_points_log_log(tmp_path, figures):
    fraction = np.logspace(-1, 1, 9)
    curves = [("DEM", 1.0 + (2 * np.pi / fraction) ** 2), ("mixer", np.r_[np.nan, 1.0 + (2 * np.pi / fraction[1:]) ** 2])]
    target = tmp_path / "vrr_period.png"
    _assert_png(target, plot_vrr_versus_period(fraction, curves, target, "VRR(T)"))
    axes = _only_axes(figures)
    assert (axes.get_xscale(), axes.get_yscale()) == ("log", "log")
    np.testing.assert_array_equal(_line(axes, "DEM").get_xdata(), fraction)
    np.testing.assert_array_equal(_line(axes, "DEM").get_ydata(), curves[0][1])
    np.testing.assert_array_equal(_line(axes, "mixer").get_xdata(), fraction[1:])  # the NaN point is skipped
    np.testing.assert_array_equal(_line(axes, "mixer").get_ydata(), curves[1][1][1:])
    assert _horizontal_lines(axes) == [1.0]


def test_plot_vrr_versus_period_rejects_bad_input(tmp_path):
    fraction = np.array([0.5, 1.0, 2.0])
    with pytest.raises(ValueError, match="period_fraction"):
        plot_vrr_versus_period(np.array([0.0, 1.0, 2.0]), [("a", fraction)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="curves"):
        plot_vrr_versus_period(fraction, [], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] VRR"):
        plot_vrr_versus_period(fraction, [("a", fraction[:2])], tmp_path / "a.png", "t")


# ---------------------------------------------------------------------------------------- recirculation model


@pytest.mark.parametrize("homogenised_after", [2.3, float("nan")])
def test_plot_recirculation_model_draws_the_model_and_when_it_is_homogenised(tmp_path, figures, homogenised_after):
    passes = np.linspace(0.0, 5.0, 251)
    concentration = 0.5 + 0.5 * np.exp(-passes) * np.cos(2 * np.pi * passes)
    target = tmp_path / "recirculation.png"
    returned = plot_recirculation_model(passes, concentration, 0.5, homogenised_after, target, "recirculation")
    _assert_png(target, returned)
    axes = _only_axes(figures)
    model = _line(axes, "LTI model, recirculated")
    np.testing.assert_array_equal(model.get_xdata(), passes)
    np.testing.assert_array_equal(model.get_ydata(), concentration)
    (band,) = [patch for patch in axes.patches if isinstance(patch, matplotlib.patches.Rectangle)]
    np.testing.assert_allclose([band.get_y(), band.get_y() + band.get_height()], [0.45, 0.55], rtol=1e-12)
    marks = [line for line in axes.get_lines() if line.get_label().startswith("within band after")]
    texts = [text.get_text() for text in axes.texts]
    if np.isnan(homogenised_after):
        assert marks == [] and texts == ["not within band"]
    else:
        (mark,) = marks
        assert list(mark.get_xdata()) == [2.3, 2.3] and mark.get_label() == "within band after Nr = 2.3"
        assert texts == []


def test_plot_recirculation_model_rejects_bad_input(tmp_path):
    passes = np.linspace(0.0, 2.0, 11)
    with pytest.raises(ValueError, match="concentration"):
        plot_recirculation_model(passes, passes[:4], 0.5, 1.0, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="time_in_passes"):
        plot_recirculation_model([], [], 0.5, 1.0, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="homogenised_after"):
        plot_recirculation_model(passes, passes, 0.5, float("inf"), tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="tolerance"):
        plot_recirculation_model(passes, passes, 0.5, 1.0, tmp_path / "a.png", "t", tolerance=0.0)


# ---------------------------------------------------------------------------------------- paths


def _path_lines(axes, linestyle):
    """The drawn tracks (solid) or pathlines (dashed): lines of that style with data, not the legend proxies."""
    return [line for line in axes.get_lines()
            if line.get_linestyle() == linestyle and np.size(line.get_xdata()) and line.get_label().startswith("_")
            and line.get_color() != "black"]


def test_plot_paths_comparison_draws_tracks_solid_and_pathlines_dashed_in_mm(tmp_path, figures):
    tracks, lines = _paths()
    target = tmp_path / "paths.png"
    _assert_png(target, plot_paths_comparison(tracks, lines, WIDTH, OUTLET, TOP, target, "paths"))
    axes = _only_axes(figures)
    drawn_tracks, drawn_lines = _path_lines(axes, "-"), _path_lines(axes, "--")
    assert len(drawn_tracks) == 2 and len(drawn_lines) == 1
    for line, expected in zip(drawn_tracks + drawn_lines, tracks + lines):
        np.testing.assert_array_equal(line.get_xdata(), 1e3 * expected[:, 0])
        np.testing.assert_array_equal(line.get_ydata(), 1e3 * expected[:, 1])
    assert [_pieces(line) for line in drawn_tracks] == [1, 2]  # the NaN row breaks the second track
    legend = [text.get_text() for text in axes.get_legend().get_texts()]
    assert legend == ["DEM particle tracks (2)", "pathlines (1)"]


def test_plot_paths_comparison_one_list_may_be_empty(tmp_path, figures):
    tracks, _ = _paths()
    target = tmp_path / "paths.png"
    _assert_png(target, plot_paths_comparison(tracks, [], WIDTH, OUTLET, TOP, target, "tracks only"))
    axes = _only_axes(figures)
    assert len(_path_lines(axes, "-")) == 2 and _path_lines(axes, "--") == []
    assert [text.get_text() for text in axes.get_legend().get_texts()] == ["DEM particle tracks (2)", "pathlines (0)"]


def test_plot_paths_comparison_rejects_bad_input(tmp_path):
    tracks, lines = _paths()
    with pytest.raises(ValueError, match="particle_paths and pathlines"):
        plot_paths_comparison([], [], WIDTH, OUTLET, TOP, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"pathlines\[0\]"):
        plot_paths_comparison(tracks, [np.zeros((5, 3))], WIDTH, OUTLET, TOP, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="outlet_width"):
        plot_paths_comparison(tracks, lines, WIDTH, 0.0, TOP, tmp_path / "a.png", "t")


# ---------------------------------------------------------------------------------------- residence times


def test_plot_residence_time_comparison_draws_histograms_and_cumulative_fractions(tmp_path, figures):
    rng = np.random.default_rng(1)
    dem = rng.exponential(2.0, 400)
    dem[:7] = np.nan
    samples = [("DEM", dem), ("pathlines", 1.0 + rng.gamma(4.0, 0.5, 300)), ("single", np.array([3.0]))]
    target = tmp_path / "residence.png"
    _assert_png(target, plot_residence_time_comparison(samples, target, "residence times"))
    (figure,) = figures
    left, right = figure.axes
    labels = ["DEM (n = 393, 7 NaN ignored)", "pathlines (n = 300)", "single (n = 1)"]
    assert [text.get_text() for text in left.get_legend().get_texts()] == labels
    for label, (_, times) in zip(labels, samples):
        finite = np.sort(times[np.isfinite(times)])
        cumulative = _line(right, label)  # F(t): steps from 0 up to 1 at the sorted finite times
        assert cumulative.get_drawstyle() == "steps-post"
        np.testing.assert_array_equal(cumulative.get_xdata(), np.r_[finite[0], finite])
        np.testing.assert_array_equal(cumulative.get_ydata(), np.r_[0.0, np.arange(1, finite.size + 1) / finite.size])
    histograms = [patch for patch in left.patches if patch.get_label() in labels]
    assert [patch.get_label() for patch in histograms] == labels  # one step histogram per sample


def test_plot_residence_time_comparison_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError, match="samples"):
        plot_residence_time_comparison([], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"samples\[1\]"):
        plot_residence_time_comparison([("a", [1.0, 2.0]), ("b", [np.nan, np.nan])], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"samples\[0\]"):
        plot_residence_time_comparison([("a", [1.0, np.inf])], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"samples\[0\]"):
        plot_residence_time_comparison([("a", np.ones((2, 2)))], tmp_path / "a.png", "t")
    assert not (tmp_path / "a.png").exists()
