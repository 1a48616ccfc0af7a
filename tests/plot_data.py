"""Helpers of the plot unit tests: keep the figures the writers save, so that their plotted data can be checked."""

from __future__ import annotations

from siloflow.analysis.io.plots import save_figure


def saved_figures(monkeypatch, *modules) -> list:
    """The list that each figure saved through ``save_figure`` of ``modules`` is appended to (after it is written)."""
    saved = []

    def keep(figure, path, tight=False):
        saved.append(figure)
        return save_figure(figure, path, tight=tight)

    for module in modules:
        monkeypatch.setattr(module, "save_figure", keep)
    return saved


def legend_texts(axes) -> list[str]:
    """The texts of the legend of ``axes``, in order."""
    return [text.get_text() for text in axes.get_legend().get_texts()]


def lines_with_gid(axes, gid: str) -> list:
    """The lines of ``axes`` whose gid is ``gid``: the series a writer tags by what it is."""
    return [line for line in axes.get_lines() if line.get_gid() == gid]


def assert_legend_outside(figure, axes, *clear_of) -> None:
    """The legend of ``axes`` lies wholly right of its data area and of ``clear_of`` (artists right of it, e.g. a
    secondary axis)."""
    figure.canvas.draw()
    box, data_area = axes.get_legend().get_window_extent(), axes.get_window_extent()
    assert not box.overlaps(data_area)
    assert box.x0 > data_area.x1
    for artist in clear_of:
        assert box.x0 > artist.get_tightbbox().x1
