"""Unit tests for siloflow.analysis.io.plot_style: the style is applied only inside its context, the palette is
colour-blind safe and given out deterministically, and a legend placed outside stays off the data."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_hex

from siloflow.analysis.io.plot_style import (
    BAND_ALPHA,
    LABEL_SIZE,
    LEGEND_SIZE,
    LINE_STYLES,
    LINE_WIDTH,
    MARKER_SIZE,
    MARKERS,
    PALETTE,
    REFERENCE_COLOUR,
    STYLE,
    TICK_SIZE,
    StudyNote,
    StudyValue,
    colour_of,
    draw_reference_band,
    draw_reference_value,
    draw_study_value,
    journal_style,
    legend_outside,
    note_study,
    study_findings,
    study_label,
)

OKABE_ITO = ["#000000", "#e69f00", "#56b4e9", "#009e73", "#f0e442", "#0072b2", "#d55e00", "#cc79a7"]


def test_the_constants_are_the_journal_sizes_and_the_okabe_ito_palette():
    assert (LABEL_SIZE, TICK_SIZE, LEGEND_SIZE, LINE_WIDTH, MARKER_SIZE) == (9, 8, 8, 1.3, 4.5)
    assert [to_hex(colour) for colour in PALETTE] == OKABE_ITO
    assert len(set(LINE_STYLES)) == len(LINE_STYLES) >= 4
    assert len(set(MARKERS)) == len(MARKERS) >= 4


def test_journal_style_applies_its_settings_inside_and_restores_rcparams_after():
    before = dict(matplotlib.rcParams)
    with journal_style():
        assert matplotlib.rcParams["axes.labelsize"] == LABEL_SIZE
        assert matplotlib.rcParams["xtick.labelsize"] == TICK_SIZE
        assert matplotlib.rcParams["ytick.labelsize"] == TICK_SIZE
        assert matplotlib.rcParams["legend.fontsize"] == LEGEND_SIZE
        assert matplotlib.rcParams["lines.linewidth"] == LINE_WIDTH
        assert matplotlib.rcParams["lines.markersize"] == MARKER_SIZE
        assert [to_hex(c) for c in matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]] == OKABE_ITO
    assert dict(matplotlib.rcParams) == before


def test_journal_style_restores_rcparams_when_the_drawing_fails():
    before = dict(matplotlib.rcParams)
    with pytest.raises(RuntimeError, match="drawing failed"):
        with journal_style():
            raise RuntimeError("drawing failed")
    assert dict(matplotlib.rcParams) == before


def test_importing_the_style_changes_no_rcparam():
    # every key of STYLE but the palette differs from matplotlib's defaults somewhere; none is set globally
    assert any(matplotlib.rcParams[key] != value for key, value in STYLE.items())
    assert [to_hex(c) for c in matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]] != OKABE_ITO


def test_colour_of_is_deterministic_distinct_and_in_order():
    names = ["internal_flow", "semi_mass_flow", "internal_flow", "mass_flow"]
    colours = colour_of(names)
    assert colours == {"internal_flow": PALETTE[0], "semi_mass_flow": PALETTE[1], "mass_flow": PALETTE[2]}
    assert colour_of(iter(names)) == colours  # the same names in the same order: the same colours
    assert len(set(colour_of(f"pattern {k}" for k in range(len(PALETTE))).values())) == len(PALETTE)
    assert colour_of([]) == {}


def test_colour_of_refuses_more_names_than_colours():
    with pytest.raises(ValueError, match="names: 9 distinct names, but the palette has 8 colours"):
        colour_of(f"pattern {k}" for k in range(9))


def test_legend_outside_puts_the_legend_right_of_the_data_area():
    with journal_style():
        figure, axes = plt.subplots(figsize=(6.5, 3.5))
        try:
            figure.subplots_adjust(right=0.6)
            axes.plot([0, 1], [0, 1], label="a line")
            axes.plot([0, 1], [1, 0], label="another line")
            legend = legend_outside(axes, title="lines")
            assert legend is axes.get_legend()
            assert legend.get_title().get_text() == "lines"  # keyword arguments reach the legend
            assert [text.get_text() for text in legend.get_texts()] == ["a line", "another line"]
            assert legend.get_texts()[0].get_fontsize() == LEGEND_SIZE
            figure.canvas.draw()
            box, data_area = legend.get_window_extent(), axes.get_window_extent()
            assert box.x0 > data_area.x1  # wholly right of the axes
            assert box.y1 == pytest.approx(data_area.y1, abs=1.0)  # aligned with the axes' top
        finally:
            plt.close(figure)


def test_legend_outside_clear_of_stands_right_of_a_secondary_axis():
    with journal_style():
        figure, axes = plt.subplots(figsize=(6.5, 3.5))
        try:
            figure.subplots_adjust(right=0.55)
            axes.plot([0, 1], [10, 40], label="a line")
            secondary = axes.secondary_yaxis("right", functions=(lambda d: d / 100.0, lambda c: 100.0 * c))
            secondary.set_ylabel("coefficient [-]")
            legend = legend_outside(axes, clear_of=[secondary])
            figure.canvas.draw()
            box = legend.get_window_extent()
            assert box.x0 > secondary.get_tightbbox().x1 > axes.get_window_extent().x1
            assert not box.overlaps(axes.get_window_extent())
        finally:
            plt.close(figure)


# ---------------------------------------------------------------------------------------- the study's findings


def test_study_values_and_notes_are_labelled_with_the_finding_id():
    assert study_label("C2", "~0.54") == "study (C2): ~0.54"
    assert StudyValue("C2", 0.54).label == "study (C2): ~0.54"
    assert StudyValue("C7", 30, unit="deg").label == "study (C7): ~30 deg"
    assert StudyValue("M1", 0.16, series="exterior", approximate=False).label == "study (M1): exterior 0.16"
    assert StudyNote("S5", "B decreases with height").label == "study (S5): B decreases with height"


def test_study_values_and_notes_refuse_what_cannot_be_drawn():
    with pytest.raises(ValueError, match="id must be a non-empty finding id"):
        StudyValue("", 0.5)
    with pytest.raises(ValueError, match="C2: value must be a finite number"):
        StudyValue("C2", float("nan"))
    with pytest.raises(ValueError, match=r"C2: band must be \(low, high\) with low <= high"):
        StudyValue("C2", 0.5, band=(0.6, 0.4))
    with pytest.raises(ValueError, match=r"C2: band must be \(low, high\)"):
        StudyValue("C2", 0.5, band=(0.4,))
    with pytest.raises(ValueError, match="S5: text must be a non-empty string"):
        StudyNote("S5", "")
    assert study_findings(None, StudyNote) == []
    with pytest.raises(ValueError, match=r"findings\[1\] must be a StudyNote, got StudyValue"):
        study_findings([StudyNote("S5", "x"), StudyValue("S5", 1.0)], StudyNote)


def test_reference_values_and_bands_are_drawn_once_across_the_axes():
    with journal_style():
        figure, axes = plt.subplots()
        try:
            axes.plot([0.0, 1.0], [0.0, 1.0])
            line = draw_reference_value(axes, 0.4, "target", gid="target")
            band = draw_reference_band(axes, 0.3, 0.5, gid="target")
            vertical = draw_reference_value(axes, 0.7, vertical=True)
            assert list(line.get_ydata()) == [0.4, 0.4] and line.get_label() == "target"
            assert (line.get_linestyle(), to_hex(line.get_color()), line.get_gid()) == (
                ":", to_hex(REFERENCE_COLOUR), "target")
            assert (band.get_y(), band.get_y() + band.get_height()) == pytest.approx((0.3, 0.5))
            assert band.get_alpha() == BAND_ALPHA and band.get_label() == "_nolegend_"
            assert list(vertical.get_xdata()) == [0.7, 0.7]
            assert [text.get_text() for text in axes.legend().get_texts()] == ["target"]
        finally:
            plt.close(figure)


def test_draw_study_value_converts_to_the_axis_unit_across_the_axes_or_over_spans():
    study = StudyValue("C2", 0.5, band=(0.4, 0.6), series="sphere2")
    with journal_style():
        figure, axes = plt.subplots()
        try:
            band, line = draw_study_value(axes, study, colour=PALETTE[1], convert=lambda mu: 100.0 * mu)
            assert list(line.get_ydata()) == [50.0, 50.0] and line.get_label() == "study (C2): sphere2 ~0.5"
            assert (band.get_y(), band.get_y() + band.get_height()) == pytest.approx((40.0, 60.0))
            assert {band.get_gid(), line.get_gid()} == {"finding C2"}
            assert to_hex(line.get_color()) == to_hex(PALETTE[1])
            artists = draw_study_value(axes, StudyValue("M1", 2.0), spans=[(1.0, 2.0), (-2.0, -1.0)],
                                       label="study (M1): ~2 of mean")
            assert len(artists) == 2  # no band: one segment per span
            assert artists[-1].get_label() == "study (M1): ~2 of mean" and list(artists[-1].get_xdata()) == [1.0, 2.0]
            assert artists[0].get_label() == "_nolegend_" and list(artists[0].get_xdata()) == [-2.0, -1.0]
            assert [text.get_text() for text in axes.legend().get_texts()] == [
                "study (C2): sphere2 ~0.5", "study (M1): ~2 of mean"]
        finally:
            plt.close(figure)


def test_note_study_is_a_legend_entry_without_data():
    with journal_style():
        figure, axes = plt.subplots()
        try:
            axes.plot([0.0, 1.0], [2.0, 3.0], label="data")
            limits = axes.dataLim.frozen()
            handle = note_study(axes, StudyNote("S5", "B decreases with height"))
            assert handle.get_gid() == "finding S5" and np.size(handle.get_xdata()) == 0
            assert np.allclose(axes.dataLim.get_points(), limits.get_points())  # moves no axis limit
            assert [text.get_text() for text in axes.legend().get_texts()] == [
                "data", "study (S5): B decreases with height"]
        finally:
            plt.close(figure)
