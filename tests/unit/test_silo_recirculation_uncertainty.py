"""Unit tests for the standard errors of the recirculation study's figures (siloflow.analysis.studies.silo_recirculation.vrr):
the mean residence time from Little's law and the VRR per recirculation, on hand-built series with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from siloflow.analysis.studies.silo_recirculation.vrr import (
    RecirculationVRR,
    littles_law,
    vrr_by_recirculation,
    vrr_standard_error,
)

NAN = math.nan

# --------------------------------------------------------------------------- Little's law

# 20 frames at t = 0 ... 19 s, cut into 2 batches of 10. The holdup is 4 in the first batch and 6 in the second
# (batch means 4 and 6: mean 5, standard error sqrt(2) / sqrt(2) = 1). One crossing at each of t = 0 ... 9 s and
# three at each of t = 10 ... 19 s: counted up to each frame, the cumulative crossings rise by 1 per second in the
# first batch and by 3 in the second, so the batch rates are 1 and 3 per s, standard error 1 per s. The 40
# crossings in [0, 19] s give the throughput 40 / 19 per s and t_res = 5 x 19 / 40 = 2.375 s.
FRAMES = np.arange(20.0)
HOLDUP = np.r_[np.full(10, 4.0), np.full(10, 6.0)]
EXITS = np.r_[np.arange(10.0), np.repeat(np.arange(10.0, 20.0), 3)]


def test_littles_law_gives_batch_errors_and_propagates_them_to_the_residence_time():
    little = littles_law(FRAMES, HOLDUP, EXITS[::-1], 0.0, 19.0, n_batches=2)  # crossings in any order
    assert (little.holdup.value, little.holdup.std_error) == (5.0, 1.0)
    assert (little.holdup.method, little.holdup.n, little.holdup.dof) == ("batch means", 2, 1.0)
    assert little.throughput.value == 40.0 / 19.0
    assert little.throughput.std_error == pytest.approx(1.0, rel=1e-14)
    assert little.throughput.method == "batch rate"
    assert little.residence_time.value == 2.375
    # relative errors 1 / 5 and 1 / (40 / 19) = 19 / 40 in quadrature
    expected = 2.375 * math.sqrt(0.2**2 + (19.0 / 40.0) ** 2)
    assert little.residence_time.std_error == pytest.approx(expected, rel=1e-14)


def test_littles_law_of_a_constant_holdup_is_the_throughputs_relative_error():
    little = littles_law(FRAMES, np.full(20, 5.0), EXITS, 0.0, 19.0, n_batches=2)
    assert little.holdup.std_error == 0.0
    assert little.residence_time.std_error == pytest.approx(2.375 * 19.0 / 40.0, rel=1e-14)


def test_littles_law_with_too_few_frames_for_its_batches_has_unknown_errors():
    # 20 frames cannot give 11 batches of two frames each: the values stand, the errors are unknown (not zero)
    little = littles_law(FRAMES, HOLDUP, EXITS, 0.0, 19.0, n_batches=11)
    assert (little.holdup.value, little.residence_time.value) == (5.0, 2.375)
    assert all(math.isnan(e.std_error) for e in (little.holdup, little.throughput, little.residence_time))


def test_littles_law_ignores_nan_crossings_and_those_outside_the_window():
    exits = np.r_[EXITS, NAN, -1.0, 25.0]
    little = littles_law(FRAMES, HOLDUP, exits, 0.0, 19.0, n_batches=2)
    assert little.throughput.value == 40.0 / 19.0
    assert little.throughput.std_error == pytest.approx(1.0, rel=1e-14)


@pytest.mark.parametrize("frames, n_batches, message", [
    (FRAMES[:-1], 2, "frame_times must have the shape of n_in_silo"),
    (FRAMES[::-1], 2, "frame_times must be strictly increasing"),
    (FRAMES, 1, "n_batches must be an integer >= 2"),
])
def test_littles_law_rejects_bad_input(frames, n_batches, message):
    with pytest.raises(ValueError, match=message):
        littles_law(frames, HOLDUP, EXITS, 0.0, 19.0, n_batches=n_batches)


# --------------------------------------------------------------------------- VRR


def test_relative_error_of_the_sample_variance_is_that_of_the_chi_square():
    # the assumption behind vrr_standard_error: (N - 1) s^2 / sigma^2 is chi^2 with N - 1 degrees of freedom
    for n in (2, 5, 20):
        assert stats.chi2(n - 1).std() / (n - 1) == pytest.approx(math.sqrt(2.0 / (n - 1)), rel=1e-14)


def test_vrr_standard_error_values():
    assert vrr_standard_error(4.5, 9) == 2.25  # sqrt(2 / 8) = 1/2
    assert vrr_standard_error(6.0, 3) == 6.0  # sqrt(2 / 2) = 1
    np.testing.assert_equal(
        vrr_standard_error([4.0, NAN, np.inf, 4.0, 4.0, 0.0], [2, 5, 5, 1, 0, 9]),
        [4.0 * math.sqrt(2.0), NAN, NAN, NAN, NAN, 0.0],  # NaN: no VRR, no variance left, fewer than 2 windows
    )
    np.testing.assert_equal(vrr_standard_error([4.5, 9.0], 9), [2.25, 4.5])  # one window count for all


@pytest.mark.parametrize("vrr, n_windows, message", [
    (-1.0, 5, "vrr must be >= 0"),
    (1.0, 2.5, "n_windows must hold integers >= 0"),
    (1.0, -2, "n_windows must hold integers >= 0"),
    (1.0, NAN, "n_windows must hold integers >= 0"),
    ([1.0, 2.0], [2, 3, 4], "vrr and n_windows must broadcast together"),
])
def test_vrr_standard_error_rejects_bad_input(vrr, n_windows, message):
    with pytest.raises(ValueError, match=message):
        vrr_standard_error(vrr, n_windows)


def test_vrr_error_of_a_hand_built_outlet_series():
    # t_res = 9 s, windows of 1 s from t_open = 0, blue fraction 1/2 (input variance 1/4).
    # Recirculation 1: 9 windows 1/4, 3/4 (four times) and 1/2: variance 1/18, VRR 4.5, error sqrt(2/8) 4.5 = 2.25.
    # Recirculation 2: 3 windows 1/4, 1/2, 3/4: variance 1/24, VRR 6, error sqrt(2/2) 6 = 6.
    # Recirculation 3: one window: no VRR, no error.
    centres = np.r_[np.arange(9) + 0.5, [9.5, 10.5, 11.5], [18.5]]
    concentration = np.r_[[0.25, 0.75] * 4, [0.5], [0.25, 0.5, 0.75], [0.5]]
    vrr = vrr_by_recirculation(centres, concentration, 0.0, 9.0, 0.5, 3)
    assert isinstance(vrr, RecirculationVRR)
    np.testing.assert_array_equal(vrr.n_windows, [9, 3, 1])
    np.testing.assert_allclose(vrr.vrr[:2], [4.5, 6.0], rtol=1e-14)
    np.testing.assert_allclose(vrr.vrr_error[:2], [2.25, 6.0], rtol=1e-14)
    assert math.isnan(vrr.vrr[2]) and math.isnan(vrr.vrr_error[2])
