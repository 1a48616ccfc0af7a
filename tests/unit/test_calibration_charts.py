"""Unit tests for calibration.charts (files under tmp_path only)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from calibration.charts import plot_calibration_chart, plot_polar_histogram
from calibration.contact_diagnostics import angular_histogram
from calibration.inversion import CalibrationCurve

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


@pytest.mark.parametrize("target, tolerance", [(30.0, 1.0), (30.0, None), (None, None)])
def test_plot_calibration_chart_writes_png(tmp_path, target, tolerance):
    path = tmp_path / "plots" / "chart.png"
    returned = plot_calibration_chart(_curves(), path, "sphere2, internal friction", target, tolerance)
    assert returned == path
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(path.parent, "chart.png")


def test_plot_calibration_chart_mixed_shapes_and_materials(tmp_path):
    particle = [0.0, 0.5, 1.0]
    curves = [
        CalibrationCurve("sphere", "wall", 0.0, particle, [0.05, 0.2, 0.3], wall_material="aluminium"),
        CalibrationCurve("sphere4", "wall", 0.1, particle, [0.1, 0.25, 0.35], [0.01, np.nan, 0.02], "perspex"),
    ]
    path = tmp_path / "wall.png"
    plot_calibration_chart(curves, path, "wall friction", target_angle_deg=9.5, tolerance_deg=1.0)
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(tmp_path, "wall.png")


def test_plot_calibration_chart_rejects_empty_and_keeps_old_file(tmp_path):
    path = tmp_path / "chart.png"
    path.write_bytes(b"old")
    with pytest.raises(ValueError, match="curves"):
        plot_calibration_chart([], path, "empty")
    with pytest.raises(ValueError, match="tolerance_deg"):
        plot_calibration_chart(_curves(), path, "bad", 30.0, -1.0)
    assert path.read_bytes() == b"old"
    _only_file(tmp_path, "chart.png")


def test_plot_polar_histogram_writes_png(tmp_path):
    rng = np.random.default_rng(7)
    edges, counts = angular_histogram(rng.normal(size=(500, 3)), axis="y", bins=36)
    path = tmp_path / "polar" / "omega.png"
    returned = plot_polar_histogram(edges, counts, path, "angular velocity direction")
    assert returned == path
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(path.parent, "omega.png")


def test_plot_polar_histogram_rejects_mismatch(tmp_path):
    edges = np.linspace(0.0, 2.0 * math.pi, 5)
    with pytest.raises(ValueError, match="counts"):
        plot_polar_histogram(edges, [1, 2, 3], tmp_path / "x.png", "bad")
    with pytest.raises(ValueError, match="edges_rad"):
        plot_polar_histogram(edges[::-1], [1, 2, 3, 4], tmp_path / "x.png", "bad")
    assert list(tmp_path.iterdir()) == []
