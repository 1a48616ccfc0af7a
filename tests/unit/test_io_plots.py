"""Unit tests for siloflow.analysis.io.plots, what every plot writer shares: the silo outline it draws, the atomic figure
writer (PNG, PDF, SVG, the formats of plots.format) and the argument checks (files under tmp_path only); and that the
workflow names its plots in the configured format."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import numpy as np
import pytest

from siloflow.analysis.io.plots import (
    PLOT_FORMATS,
    finite_abscissa,
    matching_ordinate,
    non_empty_list,
    plot_format,
    positive_finite_points,
    save_figure,
    silo_outline,
    tuple_entry,
)
from siloflow.engines.config import load_schema
from tests.repo import REPO_ROOT

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_silo_outline_draws_the_walls_and_the_floor_up_to_the_slot():
    figure, axes = plt.subplots()
    try:
        silo_outline(axes, width=200.0, outlet_width=30.0, top=500.0)
        left, right = axes.get_lines()
        np.testing.assert_array_equal(left.get_xydata(), [[-100.0, 500.0], [-100.0, 0.0], [-15.0, 0.0]])
        np.testing.assert_array_equal(right.get_xydata(), [[100.0, 500.0], [100.0, 0.0], [15.0, 0.0]])
        assert left.get_color() == right.get_color() == "black"
    finally:
        plt.close(figure)


def test_save_figure_writes_a_png_at_150_dpi_atomically_and_returns_the_path(tmp_path):
    figure, axes = plt.subplots(figsize=(2.0, 1.0))
    try:
        axes.plot([0.0, 1.0], [0.0, 1.0])
        target = tmp_path / "plots" / "line.png"
        assert save_figure(figure, target) == target
        data = target.read_bytes()
        assert data.startswith(PNG_SIGNATURE)
        assert int.from_bytes(data[16:20], "big") == 300 and int.from_bytes(data[20:24], "big") == 150  # 150 dpi
        assert [p.name for p in target.parent.iterdir()] == ["line.png"], "temporary files left behind"
    finally:
        plt.close(figure)


@pytest.mark.parametrize("suffix, signature", [("pdf", b"%PDF-"), ("svg", b"<?xml")])
def test_save_figure_writes_a_vector_file_in_the_format_of_its_suffix(tmp_path, suffix, signature):
    figure, axes = plt.subplots(figsize=(2.0, 1.0))
    try:
        axes.plot([0.0, 1.0], [0.0, 1.0])
        axes.set_title("Q [kg/s]")
        target = tmp_path / f"line.{suffix}"
        assert save_figure(figure, target, tight=True) == target
        data = target.read_bytes()
        assert data.startswith(signature)
        if suffix == "svg":
            assert b"<svg" in data[:1000]
        else:
            # the text's font embedded as a TrueType font program (FontFile2), not as matplotlib's default Type 3
            assert b"/Subtype /Type3" not in data and b"/FontFile2" in data
        assert [p.name for p in tmp_path.iterdir()] == [target.name], "temporary files left behind"
    finally:
        plt.close(figure)


@pytest.mark.parametrize("name", ["line.jpg", "line", "line.png.tmp"])
def test_save_figure_refuses_a_suffix_of_no_plot_format_and_writes_nothing(tmp_path, name):
    figure, axes = plt.subplots(figsize=(2.0, 1.0))
    try:
        with pytest.raises(ValueError, match=r"a plot is written as \.png, \.pdf, \.svg"):
            save_figure(figure, tmp_path / name)
        assert list(tmp_path.iterdir()) == []
    finally:
        plt.close(figure)
    assert plot_format("a/b.PDF") == "pdf"


def test_the_writer_takes_every_format_the_configuration_offers():
    offered = load_schema()["properties"]["plots"]["properties"]["format"]
    assert offered["enum"] == list(PLOT_FORMATS) and offered["default"] == "png"


def test_the_workflow_names_every_plot_in_the_configured_format():
    """The rules and their scripts give a plot's suffix as plots.format says (plot_file in common.smk, the rule's
    plot_format parameter), never as a literal."""
    files = [REPO_ROOT / "Snakefile", *sorted((REPO_ROOT / "siloflow" / "workflow" / "rules").glob("*.smk")),
             *sorted((REPO_ROOT / "siloflow" / "workflow" / "scripts").glob("*.py"))]
    literal = re.compile(r"\.(?:%s)[\"']" % "|".join(PLOT_FORMATS))
    found = [f"{path.relative_to(REPO_ROOT)}:{number}" for path in files
             for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if literal.search(line)]
    assert not found, f"plot suffixes given as literals: {found}"


def test_argument_checks_name_the_argument():
    assert non_empty_list("runs", (1, 2)) == [1, 2]
    with pytest.raises(ValueError, match="runs must not be empty"):
        non_empty_list("runs", [])
    assert tuple_entry("runs", 0, ["a", 1.0], 2) == ("a", 1.0)
    with pytest.raises(ValueError, match=r"runs\[3\] must be a tuple of 2 items"):
        tuple_entry("runs", 3, 5.0, 2)
    np.testing.assert_array_equal(finite_abscissa("time", [0, 1]), [0.0, 1.0])
    with pytest.raises(ValueError, match="time must not be empty"):
        finite_abscissa("time", [])
    np.testing.assert_array_equal(matching_ordinate("v", [1.0, np.nan], 2, "time"), [1.0, np.nan])
    with pytest.raises(ValueError, match=r"v must be a 1-D array of the same length as time \(3\)"):
        matching_ordinate("v", [1.0, 2.0], 3, "time")
    x, y = positive_finite_points(np.array([0.0, 1.0, 2.0, np.nan, 4.0]), np.array([1.0, 0.0, np.inf, 1.0, 2.0]))
    np.testing.assert_array_equal(x, [0.0, 4.0])
    np.testing.assert_array_equal(y, [1.0, 2.0])
