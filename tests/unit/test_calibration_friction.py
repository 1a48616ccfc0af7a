"""Unit tests for siloflow.calibration.friction and siloflow.calibration.contact_diagnostics on synthetic input with exact answers."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from siloflow.calibration.contact_diagnostics import angular_histogram, mobilised_friction_by_azimuth, mobilised_friction_histogram
from siloflow.calibration.friction import (
    BulkFriction,
    SteadyWindow,
    bulk_friction,
    bulk_friction_of_shear,
    detect_steady_window,
    friction_angle,
    friction_coefficient,
    mean_and_standard_error,
)
from siloflow.calibration.shear_record import bulk_friction_summary

N_SAMPLES = 101


def _ramp(ramp_samples: int, plateau: float = 31.2, n: int = N_SAMPLES):
    """Linear ramp from 0 at sample 0 to the plateau at sample k = ramp_samples, then constant."""
    time = np.linspace(0.0, 1.0, n)
    signal = plateau * np.minimum(np.arange(n) / ramp_samples, 1.0)
    return time, signal


def _unsteadiness_by_polyfit(time, signal, start, n_batches=10):
    """The larger of the drift and the scatter of the window ``start:``, computed independently: explicit batches,
    numpy's polyfit."""
    centres = np.array([batch.mean() for batch in np.array_split(time[start:], n_batches)])
    means = np.array([batch.mean() for batch in np.array_split(signal[start:], n_batches)])
    slope, intercept = np.polyfit(centres, means, 1)
    drift = abs(slope) * (time[-1] - time[start])
    scatter = np.max(np.abs(means - (slope * centres + intercept)))
    return max(drift, scatter) / abs(means.mean())


# --------------------------------------------------------------------------- steady window


def test_steady_window_of_a_linear_signal_is_the_longest_that_drifts_within_the_tolerance():
    # y = 1 + 0.2 t on 101 samples of [0, 1]: the batch means lie on the line, so the window from t_s drifts by
    # 0.2 (1 - t_s) / (1 + 0.2 t_mean). From sample 71 (30 samples, 10 batches of 3, t_mean = 0.855):
    # 0.2 * 0.29 / 1.171 = 4.953 %; from 70 (31 samples, batches of 4, 3, ..., 3 as numpy.array_split cuts them,
    # t_mean = (0.715 + 9 * 0.87) / 10 = 0.8545): 0.2 * 0.30 / 1.1709 = 5.124 % > 5 %.
    time = np.linspace(0.0, 1.0, N_SAMPLES)
    window = detect_steady_window(time, 1.0 + 0.2 * time)
    assert window.i_start == 71
    assert window.t_start == time[71]
    assert (window.i_end, window.t_end) == (N_SAMPLES, 1.0)
    assert window.plateau == pytest.approx(1.171, abs=1e-12)
    # a window of at least 30 % must start at sample 70 or earlier: none is steady
    with pytest.raises(ValueError, match=r"signal: no steady shear: every window of at least 30 % of the 101 samples "
                                         r"after start_after = 0 s drifts or scatters by more than 5 % of its level "
                                         r"\(least: 5.12 % over the last 31 samples\)"):
        detect_steady_window(time, 1.0 + 0.2 * time, min_fraction=0.3)
    # a looser tolerance accepts the whole record: 0.2 / 1.1 = 18.2 %
    assert detect_steady_window(time, 1.0 + 0.2 * time, max_drift=0.19).i_start == 0


def test_steady_window_is_blind_to_fluctuations_shorter_than_a_batch():
    # +-20 % stick-slip of period 10 samples on a level of 10: each batch of 100 samples holds whole periods,
    # so the batch means are 10 and the whole record is steady (a +-5 % band would reject every sample).
    n = 1000
    time = np.linspace(0.0, 1.0, n)
    signal = 10.0 + 2.0 * np.sin(2.0 * np.pi * np.arange(n) / 10.0)
    window = detect_steady_window(time, signal)
    assert window.i_start == 0
    assert window.plateau == pytest.approx(10.0, abs=1e-12)


def test_a_rise_and_a_fall_whose_line_is_level_is_not_steady():
    # a tent from 1 up to 1.5 and back on 101 samples: the whole record's line is level (drift 0) but its batch
    # means lie up to 15 % from it; every shorter window is on the slopes (drift over 5 %)
    time = np.linspace(0.0, 1.0, N_SAMPLES)
    tent = 1.0 + 0.5 * (1.0 - np.abs(2.0 * time - 1.0))
    assert _unsteadiness_by_polyfit(time, tent, 0) > 0.05
    with pytest.raises(ValueError, match="signal: no steady shear"):
        detect_steady_window(time, tent)


def test_after_a_peak_the_steady_window_is_the_residual_plateau():
    # a dense sample: a peak of 1.3 at sample 30, softening linearly to the residual 1 at sample 60, then flat
    time = np.linspace(0.0, 1.0, N_SAMPLES)
    index = np.arange(N_SAMPLES)
    signal = np.interp(index, [0, 30, 60, 100], [0.0, 1.3, 1.0, 1.0])
    window = detect_steady_window(time, signal)
    unsteadiness = [_unsteadiness_by_polyfit(time, signal, start) for start in range(window.i_start + 1)]
    assert unsteadiness[-1] <= 0.05 < min(unsteadiness[:-1])
    assert 45 <= window.i_start <= 60  # the end of the softening, as far as it keeps the window within 5 %
    # a softening spread over several batches biases the window's mean by up to about max_drift / 4
    assert np.mean(signal[window.i_start:]) == pytest.approx(1.0, rel=0.05 / 4)


@pytest.mark.parametrize("ramp_samples", [10, 20, 40, 60])
def test_steady_window_after_a_ramp_is_the_earliest_that_drifts_within_the_tolerance(ramp_samples):
    time, signal = _ramp(ramp_samples)
    window = detect_steady_window(time, signal)
    drifts = [_unsteadiness_by_polyfit(time, signal, start) for start in range(window.i_start + 1)]
    assert drifts[-1] <= 0.05 < min(drifts[:-1])
    # the window takes in at most the ramp's last few samples: its mean is within about max_drift / 5 of the plateau
    assert window.i_start <= ramp_samples
    assert np.mean(signal[window.i_start:]) == pytest.approx(31.2, rel=0.05 / 5)


def test_steady_window_start_after():
    time, signal = _ramp(10)
    window = detect_steady_window(time, signal, start_after=0.5)
    assert window.i_start == 50
    assert window.t_start == time[50]
    assert window.plateau == pytest.approx(31.2, abs=1e-12)


def test_steady_window_growing_signal_raises():
    time = np.linspace(0.0, 1.0, 101)
    with pytest.raises(ValueError, match=r"signal: no steady shear: every window of at least 25 % "):
        detect_steady_window(time, 1.0 + 10.0 * time)


def test_steady_window_min_fraction():
    # Ramp to sample 60: the plateau holds the last 41 of 101 samples (41 %).
    time, signal = _ramp(60)
    assert 50 <= detect_steady_window(time, signal).i_start <= 60
    with pytest.raises(ValueError, match="signal: no steady shear"):
        detect_steady_window(time, signal, min_fraction=0.5)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"max_drift": 0.0}, "max_drift"),
        ({"min_fraction": 1.5}, "min_fraction"),
        ({"n_batches": 2}, "n_batches"),
        ({"n_batches": 2.5}, "n_batches"),
        ({"start_after": 0.85}, r"start_after = 0.85 s leaves 16 samples of signal; at least 20 are needed"),
    ],
)
def test_steady_window_rejects_bad_arguments(kwargs, name):
    time, signal = _ramp(10)
    with pytest.raises(ValueError, match=name):
        detect_steady_window(time, signal, **kwargs)


def test_steady_window_rejects_bad_time_and_zero_signal():
    time, signal = _ramp(10)
    with pytest.raises(ValueError, match="time"):
        detect_steady_window(time[::-1], signal)
    with pytest.raises(ValueError, match="signal"):
        detect_steady_window(time, signal[:-1])
    with pytest.raises(ValueError, match="signal: no steady shear"):
        detect_steady_window(time, np.zeros_like(time))


# --------------------------------------------------------------------------- mean and error


def test_mean_and_error_of_constant():
    assert mean_and_standard_error(np.full(100, 2.5)) == (2.5, 0.0)
    assert mean_and_standard_error(np.full(7, 2.5)) == (2.5, 0.0)


@pytest.mark.parametrize("n", [10, 100, 200])
def test_mean_and_error_alternating(n):
    values = 3.0 + np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    mean, error = mean_and_standard_error(values)
    assert mean == 3.0
    if n < 20:
        # Naive error: s = sqrt(n / (n - 1)), error = s / sqrt(n).
        assert error == pytest.approx(1.0 / math.sqrt(n - 1), rel=1e-14)
    else:
        # Batches of even length average to exactly 3: anti-correlation gives error 0.
        assert error == 0.0


def test_mean_and_error_batch_means_by_hand():
    # 20 values, 10 batches of 2: batch means 0, 1, ..., 9.
    values = np.repeat(np.arange(10.0), 2)
    mean, error = mean_and_standard_error(values)
    assert mean == 4.5
    assert error == pytest.approx(np.std(np.arange(10.0), ddof=1) / math.sqrt(10), rel=1e-14)


def test_bulk_friction_error_is_the_batch_means_error_of_a_series_with_known_batch_means():
    # 20 samples under a constant load of 10 N; shear force in 10 batches of two with means 1, 2, ..., 10 N
    time = np.arange(20.0)
    shear = np.repeat(np.arange(1.0, 11.0), 2) + np.tile([-0.5, 0.5], 10)
    result = bulk_friction(time, shear, np.zeros(20), shear, 8.0, 2.0, window=(0.0, 19.0))
    assert result.coefficient == pytest.approx(0.55, rel=1e-14)
    error = np.std(np.arange(1.0, 11.0), ddof=1) / math.sqrt(10) / 10.0  # of the batch means of F / (F_N + W)
    assert result.standard_error == pytest.approx(error, rel=1e-12)
    assert result.bottom_standard_error == pytest.approx(error, rel=1e-12)
    assert result.angle_standard_error_deg == pytest.approx(math.degrees(error / (1 + 0.55**2)), rel=1e-12)
    summary = bulk_friction_summary(result, "steady")
    assert summary == {
        "bulk_friction": result.coefficient, "bulk_friction_error": result.standard_error,
        "bulk_friction_stderr": result.standard_error, "bulk_friction_angle_deg": result.angle_deg,
        "bulk_friction_angle_deg_error": result.angle_standard_error_deg,
        "bottom_bulk_friction": result.bottom_coefficient, "bottom_bulk_friction_error": result.bottom_standard_error,
        "ring_sides_relative_difference": result.relative_difference, "window_start_s": 0.0, "window_end_s": 19.0,
        "window_samples": 20, "window_method": "steady",
    }


def test_mean_and_error_rejects_short_input():
    with pytest.raises(ValueError, match="values"):
        mean_and_standard_error([1.0])


# --------------------------------------------------------------------------- bulk friction


def _histories(n=201, peak_samples=20):
    """Forces of a dense sample: a peak five times the residual level for ``peak_samples``, then the residual
    plateau; a window that takes in a sample of the peak drifts by more than 5 %, so the steady window is the
    plateau."""
    time = np.linspace(0.0, 2.0, n)
    shape = np.where(np.arange(n) < peak_samples, 5.0, 1.0)
    total = 0.6 * 52.0 * shape
    lid = 0.25 * total
    ring = total - lid
    return time, lid, ring, total


def test_bulk_friction_exact():
    time, lid, ring, total = _histories()
    result = bulk_friction(time, lid, ring, total, 50.0, 2.0)
    assert isinstance(result, BulkFriction)
    assert result.coefficient == pytest.approx(0.6, abs=1e-12)
    assert result.bottom_coefficient == pytest.approx(0.6, abs=1e-12)
    assert result.angle_deg == pytest.approx(math.degrees(math.atan(0.6)), abs=1e-12)
    assert result.bottom_angle_deg == pytest.approx(math.degrees(math.atan(0.6)), abs=1e-12)
    assert result.relative_difference == pytest.approx(0.0, abs=1e-12)
    assert result.standard_error == pytest.approx(0.0, abs=1e-12)
    assert result.normal_load == 52.0
    assert result.shear_force == pytest.approx(31.2, abs=1e-12)
    assert isinstance(result.window, SteadyWindow)
    assert result.window.i_end == time.size
    assert result.window.i_start == 20


def test_bulk_friction_array_loads_and_bottom_difference():
    time, lid, ring, total = _histories()
    normal = np.full(time.size, 50.0)
    weight = np.full(time.size, 2.0)
    result = bulk_friction(time, lid, ring, 0.9 * total, normal, weight)
    assert result.coefficient == pytest.approx(0.6, abs=1e-12)
    assert result.bottom_coefficient == pytest.approx(0.54, abs=1e-12)
    assert result.relative_difference == pytest.approx(0.1, abs=1e-12)


def test_bulk_friction_explicit_windows():
    time, lid, ring, total = _histories()
    by_times = bulk_friction(time, lid, ring, total, 50.0, 2.0, window=(1.0, 2.0))
    assert by_times.window.i_start == 100
    assert by_times.window.i_end == 201
    assert by_times.coefficient == pytest.approx(0.6, abs=1e-12)
    # A window including the peak raises the mean: the given window is used as is.
    given = SteadyWindow(t_start=0.0, t_end=0.2, i_start=0, i_end=21, plateau=31.2)
    peak = bulk_friction(time, lid, ring, total, 50.0, 2.0, window=given)
    assert peak.window is given
    assert peak.coefficient == pytest.approx(0.6 * (20 * 5.0 + 1.0) / 21, abs=1e-12)  # 20 peak samples, 1 residual


def test_bulk_friction_standard_error_from_fluctuations():
    # Plateau alternating 31.2 +- 1 (period 2): batch means are exact, error 0; a block pattern is not.
    time, lid, ring, total = _histories()
    fluctuating = total + np.where(np.arange(time.size) % 2 == 0, 1.0, -1.0) * (np.arange(time.size) >= 20)
    result = bulk_friction(time, fluctuating, np.zeros_like(time), total, 50.0, 2.0, window=(1.0, 1.995))
    assert result.coefficient == pytest.approx(0.6, abs=1e-12)
    assert result.standard_error == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    "name, change",
    [
        ("lid_force", {"lid_force": np.zeros(5)}),
        ("bottom_force", {"bottom_force": np.full(201, np.nan)}),
        ("normal_force", {"normal_force": -2.0}),
        ("weight_above", {"weight_above": np.zeros(3)}),
        ("window", {"window": (1.0, 0.5)}),
    ],
)
def test_bulk_friction_rejects_bad_input(name, change):
    time, lid, ring, total = _histories()
    arguments = dict(
        time=time, lid_force=lid, ring_force=ring, bottom_force=total, normal_force=50.0, weight_above=2.0
    )
    arguments.update(change)
    with pytest.raises(ValueError, match=name):
        bulk_friction(**arguments)


def test_friction_angle_and_coefficient():
    assert friction_angle(1.0) == pytest.approx(45.0, abs=1e-12)
    assert friction_angle(0.0) == 0.0
    assert friction_coefficient(45.0) == pytest.approx(1.0, abs=1e-12)
    angles = friction_angle(np.array([0.2, 0.6]))
    np.testing.assert_allclose(friction_coefficient(angles), [0.2, 0.6], rtol=1e-14)
    with pytest.raises(ValueError, match="mu"):
        friction_angle(-0.1)
    with pytest.raises(ValueError, match="angle_deg"):
        friction_coefficient(90.0)


# --------------------------------------------------------------------------- diagnostics


def test_mobilised_friction_histogram_by_hand():
    normal = np.array([[0, 0, 2.0], [0, 0, 1.0], [0, 0, 4.0], [0, 0, 1.0], [0, 0, 0.0]])
    tangential = np.array([[0.2, 0, 0], [0, 0.25, 0], [1.2, 1.6, 0], [0.7, 0, 0], [1.0, 0, 0]])
    # ratios: 0.1, 0.25, 0.5, 0.7; the unloaded contact is left out
    edges, counts = mobilised_friction_histogram(normal, tangential, bins=4, range=(0.0, 0.8))
    np.testing.assert_allclose(edges, [0.0, 0.2, 0.4, 0.6, 0.8])
    assert counts.tolist() == [1, 1, 1, 1]

    edges, counts = mobilised_friction_histogram(normal, tangential, bins=[0.0, 0.3, 1.0])
    assert counts.tolist() == [2, 2]

    # default range: (0, max ratio), the maximum in the last bin
    edges, counts = mobilised_friction_histogram(normal, tangential, bins=7)
    assert edges[0] == 0.0 and edges[-1] == pytest.approx(0.7)
    assert counts.sum() == 4 and counts[-1] == 1


def test_mobilised_friction_histogram_rejects_mismatch():
    with pytest.raises(ValueError, match="normal_force_vectors"):
        mobilised_friction_histogram(np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="tangential_force_vectors"):
        mobilised_friction_histogram(np.zeros((3, 3)), np.zeros((3, 2)))


def test_angular_histogram_axis_y_by_hand():
    vectors = np.array(
        [
            [1.0, 5.0, 0.0],   # +x: 0 -> sector 0
            [0.0, 0.0, 2.0],   # +z: pi/2 -> sector 1 (on an edge: the sector starting there)
            [-1.0, 0.0, 0.0],  # -x: pi -> sector 2
            [0.0, -3.0, -1.0],  # -z: 3 pi/2 -> sector 3
            [1.0, 0.0, 1.0],   # pi/4 -> sector 0
            [0.0, 7.0, 0.0],   # along y: no direction, left out
        ]
    )
    edges, counts = angular_histogram(vectors, axis="y", bins=4)
    np.testing.assert_allclose(edges, [0.0, math.pi / 2, math.pi, 1.5 * math.pi, 2 * math.pi])
    assert counts.tolist() == [2, 1, 1, 1]


def test_angular_histogram_other_axes_and_weights():
    vectors = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]])
    _, counts_x = angular_histogram(vectors, axis="x", bins=4)  # (y, z): 0, pi/2, 0
    assert counts_x.tolist() == [2, 1, 0, 0]
    _, counts_z = angular_histogram(vectors, axis="z", bins=8)  # (x, y): pi/2, none, pi/4
    assert counts_z.tolist() == [0, 1, 1, 0, 0, 0, 0, 0]
    edges, weighted = angular_histogram(vectors, axis="x", bins=4, weights=[2.0, 3.0, 0.5])
    assert weighted.tolist() == [2.5, 3.0, 0.0, 0.0]
    assert edges.size == 5
    edges, counts = angular_histogram(vectors)
    assert edges.size == 37 and counts.size == 36


def test_angular_histogram_rejects_bad_arguments():
    with pytest.raises(ValueError, match="axis"):
        angular_histogram(np.zeros((2, 3)), axis="w")
    with pytest.raises(ValueError, match="vectors"):
        angular_histogram(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="bins"):
        angular_histogram(np.zeros((2, 3)), bins=0)
    with pytest.raises(ValueError, match="weights"):
        angular_histogram(np.zeros((2, 3)), weights=[1.0])


def test_bulk_friction_of_shear_uses_the_plateau_or_the_second_half():
    time = np.linspace(0.0, 1.0, 201)
    load = 52.0
    plateau = np.where(time < 0.2, 0.6 * load * time / 0.2, 0.6 * load)
    signals = SimpleNamespace(time=time, lid_force=0.5 * plateau, ring_force=0.5 * plateau, bottom_force=plateau,
                              normal_force=50.0, weight_above=2.0)
    friction, method = bulk_friction_of_shear(signals)
    assert method == "steady"
    # the window may take in the ramp's last samples, as far as they keep its drift within 5 %
    assert friction.coefficient == pytest.approx(0.6, rel=0.05 / 5)
    assert 0.1 <= friction.window.t_start <= 0.2

    growing = 10.0 * time  # never settles: the mean of the second half is 10 * 0.75
    signals = SimpleNamespace(time=time, lid_force=growing, ring_force=0.0 * time, bottom_force=growing,
                              normal_force=50.0, weight_above=0.0)
    friction, method = bulk_friction_of_shear(signals)
    assert method == "second half"
    assert friction.coefficient == pytest.approx(7.5 / 50.0, abs=1e-12)
    assert friction.window.t_start == pytest.approx(0.5)


def test_mobilised_friction_by_azimuth_exact_sectors():
    points = [[1.0, 0.0, 0.0], [1.0, 0.1, 0.0], [-1.0, 0.01, 0.0], [0.0, 1.0, 0.0]]
    normal = [[-2.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    tangential = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.5], [0.0, 1.0, 0.0], [0.0, 3.0, 0.0]]
    edges, ratio, counts = mobilised_friction_by_azimuth(points, normal, tangential, bins=4)
    np.testing.assert_allclose(edges, [-np.pi, -np.pi / 2, 0.0, np.pi / 2, np.pi])
    # sector [0, pi/2): contacts at azimuth 0 and 0.0997 rad with ratios 0.5 and 0.5; the zero-load one is dropped
    np.testing.assert_array_equal(counts, [0, 0, 2, 1])
    np.testing.assert_allclose(ratio, [0.0, 0.0, 0.5, 0.25])
