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
