"""Measured-profile files and their comparison with simulated profiles."""

import numpy as np
import pytest

from siloflow.analysis.studies.silo_flat.measured import (
    MeasurementFormatError,
    compare_with_measurement,
    parse_measured_profiles,
    read_measured_profiles,
)

TEXT = """# PIV at the front wall
z_m,x_m,window,v_z_m_s,v_x_m_s,uncertainty_m_s
0.12,0.01,0.5-0.7,-0.030,0.001,0.002
0.12,-0.01,0.5-0.7,-0.030,-0.001,0.002
0.12,0.0,0.5-0.7,-0.040,0.0,0.002
0.04,0.0,0.5-0.7,-0.080,0.0,
"""


def test_profiles_are_grouped_by_height_and_window_and_sorted():
    low, high = parse_measured_profiles(TEXT)
    assert (low.z, high.z) == (0.04, 0.12)
    np.testing.assert_array_equal(high.x, [-0.01, 0.0, 0.01])
    np.testing.assert_array_equal(high.v_z, [-0.030, -0.040, -0.030])
    np.testing.assert_array_equal(high.uncertainty, [0.002, 0.002, 0.002])
    assert low.uncertainty is None


def test_comparison_of_an_exact_simulation_has_zero_error():
    _, high = parse_measured_profiles(TEXT)
    x = np.linspace(-0.02, 0.02, 41)
    v_z = -0.04 + np.abs(x)  # linear: -0.03 at x = +-0.01, exact under interpolation
    comparison = compare_with_measurement(x, v_z, high)
    np.testing.assert_allclose(comparison.simulated_v_z, high.v_z, atol=1e-15)
    assert comparison.errors.rms_error == pytest.approx(0.0, abs=1e-15)
    assert comparison.errors.fraction_within_uncertainty == 1.0


def test_a_uniform_offset_gives_its_error():
    _, high = parse_measured_profiles(TEXT)
    x = np.linspace(-0.02, 0.02, 41)
    comparison = compare_with_measurement(x, -0.04 + np.abs(x) + 0.001, high)
    assert comparison.errors.rms_error == pytest.approx(0.001, rel=1e-9)
    assert comparison.errors.mean_error_percent == pytest.approx(100 * 0.001 / (0.1 / 3), rel=1e-9)


def test_bad_files_name_the_file_and_line(tmp_path):
    path = tmp_path / "piv.csv"
    path.write_text(TEXT.replace("-0.040", "fast"))
    with pytest.raises(MeasurementFormatError, match=rf"{path}: line 5, column v_z_m_s is not a number$"):
        read_measured_profiles(path)
    path.write_text("z_m,x_m\n0.1,0.0\n")
    with pytest.raises(MeasurementFormatError, match="missing column"):
        read_measured_profiles(path)


def test_measurements_beyond_the_simulated_width_are_refused():
    _, high = parse_measured_profiles(TEXT)
    with pytest.raises(ValueError, match="beyond the simulated profile"):
        compare_with_measurement(np.linspace(-0.005, 0.005, 5), np.zeros(5), high)
