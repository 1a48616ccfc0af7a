"""Unit tests for analysis.studies.silo_recirculation.plots and .rtd_plots (files under tmp_path only)."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.studies.silo_recirculation.plots import (
    plot_coloured_snapshots,
    plot_outlet_concentration,
    plot_paths_comparison,
    plot_vrr_versus_recirculations,
)
from analysis.studies.silo_recirculation.rtd_plots import (
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
def test_plot_outlet_concentration_writes_png(tmp_path, tolerance):
    target = tmp_path / "plots" / "outlet.png"
    _assert_png(target, plot_outlet_concentration(_concentration_curves(), 0.5, target, "outlet", tolerance=tolerance))


def test_plot_outlet_concentration_nan_is_a_gap(tmp_path):
    label, nr, c = _concentration_curves()[0]
    c = c.copy()
    c[10:15] = np.nan
    target = tmp_path / "outlet.png"
    _assert_png(target, plot_outlet_concentration([(label, nr, c)], 0.5, target, "gaps"))


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


@pytest.mark.parametrize("noise_limit", [None, 250.0])
def test_plot_vrr_versus_recirculations_writes_png(tmp_path, noise_limit):
    nr = np.arange(1.0, 6.0)
    curves = [("DEM", nr, 3.0 ** nr), ("model", nr, 2.0 ** nr)]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "VRR", noise_limit=noise_limit))


def test_plot_vrr_versus_recirculations_skips_non_finite(tmp_path):
    nr = np.arange(1.0, 6.0)
    curves = [("mixed", nr, np.array([2.0, np.nan, 8.0, np.inf, -1.0])),
              ("all bad", nr, np.full(5, np.nan))]
    target = tmp_path / "vrr.png"
    _assert_png(target, plot_vrr_versus_recirculations(curves, target, "non-finite", noise_limit=10.0))


def test_plot_vrr_versus_recirculations_rejects_bad_input(tmp_path):
    nr = np.arange(1.0, 4.0)
    with pytest.raises(ValueError, match="curves"):
        plot_vrr_versus_recirculations([], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] x"):
        plot_vrr_versus_recirculations([("a", [1.0, np.nan, 3.0], nr)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="noise_limit"):
        plot_vrr_versus_recirculations([("a", nr, nr)], tmp_path / "a.png", "t", noise_limit=0.0)
    with pytest.raises(ValueError, match=r"curves\[0\]"):
        plot_vrr_versus_recirculations([("a", nr)], tmp_path / "a.png", "t")


# ---------------------------------------------------------------------------------------- snapshots


@pytest.mark.parametrize("count", [1, 3, 6])
def test_plot_coloured_snapshots_writes_png(tmp_path, count):
    snapshots = [_snapshot(0.5 * k, seed=k) for k in range(count)]
    target = tmp_path / "snapshots.png"
    _assert_png(target, plot_coloured_snapshots(snapshots, WIDTH, OUTLET, TOP, CHANNEL, target, "blend"))


def test_plot_coloured_snapshots_empty_snapshot_allowed(tmp_path):
    target = tmp_path / "snapshots.png"
    empty = (0.0, np.empty(0), np.empty(0), np.empty(0, dtype=bool))
    _assert_png(target, plot_coloured_snapshots([empty, _snapshot(1.0)], WIDTH, OUTLET, TOP, CHANNEL, target, "t"))


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
def test_plot_rtd_comparison_writes_png(tmp_path, dimensionless):
    target = tmp_path / "rtd.png"
    _assert_png(target, plot_rtd_comparison(_rtd_curves(), target, "RTD", dimensionless=dimensionless))


def test_plot_rtd_comparison_rejects_bad_input(tmp_path):
    t = np.linspace(0.1, 1.0, 10)
    with pytest.raises(ValueError, match="curves"):
        plot_rtd_comparison([], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[0\] E"):
        plot_rtd_comparison([("a", t, t[:5], 1.0)], tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"curves\[1\] t_mean"):
        plot_rtd_comparison([("a", t, t, 1.0), ("b", t, t, np.nan)], tmp_path / "a.png", "t")


# ---------------------------------------------------------------------------------------- LTI comparison


def test_plot_lti_comparison_writes_png(tmp_path):
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


def test_plot_vrr_versus_period_writes_png(tmp_path):
    fraction = np.logspace(-1, 1, 9)
    curves = [("DEM", 1.0 + (2 * np.pi / fraction) ** 2), ("mixer", np.r_[np.nan, 1.0 + (2 * np.pi / fraction[1:]) ** 2])]
    target = tmp_path / "vrr_period.png"
    _assert_png(target, plot_vrr_versus_period(fraction, curves, target, "VRR(T)"))


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
def test_plot_recirculation_model_writes_png(tmp_path, homogenised_after):
    passes = np.linspace(0.0, 5.0, 251)
    concentration = 0.5 + 0.5 * np.exp(-passes) * np.cos(2 * np.pi * passes)
    target = tmp_path / "recirculation.png"
    returned = plot_recirculation_model(passes, concentration, 0.5, homogenised_after, target, "recirculation")
    _assert_png(target, returned)


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


def test_plot_paths_comparison_writes_png(tmp_path):
    tracks, lines = _paths()
    target = tmp_path / "paths.png"
    _assert_png(target, plot_paths_comparison(tracks, lines, WIDTH, OUTLET, TOP, target, "paths"))


def test_plot_paths_comparison_one_list_may_be_empty(tmp_path):
    tracks, _ = _paths()
    target = tmp_path / "paths.png"
    _assert_png(target, plot_paths_comparison(tracks, [], WIDTH, OUTLET, TOP, target, "tracks only"))


def test_plot_paths_comparison_rejects_bad_input(tmp_path):
    tracks, lines = _paths()
    with pytest.raises(ValueError, match="particle_paths and pathlines"):
        plot_paths_comparison([], [], WIDTH, OUTLET, TOP, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match=r"pathlines\[0\]"):
        plot_paths_comparison(tracks, [np.zeros((5, 3))], WIDTH, OUTLET, TOP, tmp_path / "a.png", "t")
    with pytest.raises(ValueError, match="outlet_width"):
        plot_paths_comparison(tracks, lines, WIDTH, 0.0, TOP, tmp_path / "a.png", "t")


# ---------------------------------------------------------------------------------------- residence times


def test_plot_residence_time_comparison_writes_png(tmp_path):
    rng = np.random.default_rng(1)
    dem = rng.exponential(2.0, 400)
    dem[:7] = np.nan
    samples = [("DEM", dem), ("pathlines", 1.0 + rng.gamma(4.0, 0.5, 300)), ("single", np.array([3.0]))]
    target = tmp_path / "residence.png"
    _assert_png(target, plot_residence_time_comparison(samples, target, "residence times"))


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
