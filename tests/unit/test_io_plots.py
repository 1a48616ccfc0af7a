"""Unit tests for analysis.io.plots, what every plot writer shares: the silo outline it draws, the atomic PNG
writer and the argument checks (files under tmp_path only)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from analysis.io.plots import (
    finite_abscissa,
    matching_ordinate,
    non_empty_list,
    positive_finite_points,
    save_png,
    silo_outline,
    tuple_entry,
)

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


def test_save_png_writes_the_figure_atomically_and_returns_the_path(tmp_path):
    figure, axes = plt.subplots(figsize=(2.0, 1.0))
    try:
        axes.plot([0.0, 1.0], [0.0, 1.0])
        target = tmp_path / "plots" / "line.png"
        assert save_png(figure, target) == target
        data = target.read_bytes()
        assert data.startswith(PNG_SIGNATURE)
        assert int.from_bytes(data[16:20], "big") == 300 and int.from_bytes(data[20:24], "big") == 150  # 150 dpi
        assert [p.name for p in target.parent.iterdir()] == ["line.png"], "temporary files left behind"
    finally:
        plt.close(figure)


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
