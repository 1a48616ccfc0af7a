"""Unit tests for siloflow.analysis.io.plot_style: the style is applied only inside its context, the palette is
colour-blind safe and given out deterministically, and a legend placed outside stays off the data."""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import pytest
from matplotlib.colors import to_hex

from siloflow.analysis.io.plot_style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    LINE_STYLES,
    LINE_WIDTH,
    MARKER_SIZE,
    MARKERS,
    PALETTE,
    STYLE,
    TICK_SIZE,
    colour_of,
    journal_style,
    legend_outside,
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
