"""Unit tests for siloflow.calibration.inversion on synthetic charts with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from siloflow.calibration.inversion_errors import interpolation_error, inversion_error
from siloflow.calibration.inversion import (
    CalibrationCurve,
    Inversion,
    UnreachableTarget,
    curves_from_table,
    invert_calibration,
    invert_curve,
)

PARTICLE = np.linspace(0.0, 1.0, 11)


def _deg(mu: float) -> float:
    return math.degrees(math.atan(mu))


def _linear_curve(test="internal", material=None, rolling=0.1, shape="sphere2", offset=0.2, slope=0.5):
    return CalibrationCurve(
        shape=shape,
        test=test,
        rolling_friction=rolling,
        particle_friction=PARTICLE,
        bulk_friction=offset + slope * PARTICLE,
        wall_material=material,
    )


def _plateau_curve():
    return CalibrationCurve(
        shape="sphere2",
        test="internal",
        rolling_friction=0.05,
        particle_friction=[0.0, 0.2, 0.4, 0.6, 0.8, 1.0],
        bulk_friction=[0.3, 0.4, 0.5, 0.55, 0.55, 0.54],
    )


# --------------------------------------------------------------------------- invert_curve


def test_invert_monotone_chart_exact():
    target = _deg(0.45)
    inversion = invert_curve(_linear_curve(), target, tolerance_deg=1.0)
    assert isinstance(inversion, Inversion)
    assert inversion.particle_friction == pytest.approx(0.5, abs=1e-12)

    # Band edges by hand: linear interpolation in angle between the bracketing chart points.
    def angle(p):
        return _deg(0.2 + 0.5 * p)

    low_angle, high_angle = target - 1.0, target + 1.0
    assert angle(0.4) < low_angle < angle(0.5) < high_angle < angle(0.6)
    lower = 0.4 + 0.1 * (low_angle - angle(0.4)) / (angle(0.5) - angle(0.4))
    upper = 0.5 + 0.1 * (high_angle - angle(0.5)) / (angle(0.6) - angle(0.5))
    assert inversion.lower == pytest.approx(lower, abs=1e-12)
    assert inversion.upper == pytest.approx(upper, abs=1e-12)
    assert inversion.band_clipped is False
    assert inversion.plateau_particle_friction is None
    assert inversion.reachable_range_deg == pytest.approx((_deg(0.2), _deg(0.7)), abs=1e-12)
    assert (inversion.shape, inversion.test, inversion.rolling_friction) == ("sphere2", "internal", 0.1)
    assert inversion.target_angle_deg == target and inversion.tolerance_deg == 1.0


def test_inversion_error_propagates_the_angle_errors_through_the_local_slope():
    angles, particle, errors = [10.0, 20.0, 30.0], [0.0, 0.5, 1.0], [0.3, 0.4, 0.5]  # slope 20 deg per unit
    # midway in the first segment: sqrt(0.15^2 + 0.2^2) / 20 = 0.25 / 20
    assert inversion_error(angles, particle, errors, 15.0) == pytest.approx(0.0125, rel=1e-14)
    assert inversion_error(angles, particle, errors, 20.0) == pytest.approx(0.02, rel=1e-14)  # a point: its own error
    assert inversion_error(angles, particle, errors, 30.0) == pytest.approx(0.025, rel=1e-14)  # the last point
    # an unknown error counts only where it has weight
    assert inversion_error(angles, particle, [0.3, math.nan, 0.5], 10.0) == pytest.approx(0.015, rel=1e-14)
    assert math.isnan(inversion_error(angles, particle, [0.3, math.nan, 0.5], 15.0))
    assert math.isnan(inversion_error(angles, particle, None, 15.0))
    assert math.isnan(inversion_error([10.0], [0.5], [0.3], 10.0))


def test_invert_curve_error_of_a_chart_with_bulk_friction_errors():
    curve = CalibrationCurve(shape="sphere2", test="internal", rolling_friction=0.1, particle_friction=PARTICLE,
                             bulk_friction=0.2 + 0.5 * PARTICLE, bulk_standard_error=np.full(PARTICLE.size, 0.01))
    target = _deg(0.475)  # between the points p = 0.5 (mu 0.45) and p = 0.6 (mu 0.5)
    inversion = invert_curve(curve, target, tolerance_deg=1.0)
    low, high = _deg(0.45), _deg(0.5)
    t = (target - low) / (high - low)
    error_low, error_high = math.degrees(0.01 / (1 + 0.45**2)), math.degrees(0.01 / (1 + 0.5**2))
    expected = math.hypot((1 - t) * error_low, t * error_high) / ((high - low) / 0.1)
    assert inversion.standard_error == pytest.approx(expected, rel=1e-10)
    np.testing.assert_allclose(curve.bulk_angle_standard_error_deg,
                               np.degrees(0.01 / (1 + curve.bulk_friction**2)), rtol=1e-15)
    result = invert_calibration([curve], {"internal": target}, shape="sphere2", rolling_friction=0.1)
    # the chart's bend adds its interpolation error in quadrature
    assert result["particle_particle"]["sliding_friction_error"] == pytest.approx(
        math.hypot(inversion.standard_error, inversion.interpolation_error), rel=1e-12)
    assert yaml.safe_load(yaml.safe_dump(result)) == result
    assert math.isnan(invert_curve(_linear_curve(), target).standard_error)  # no errors on the chart


def test_invert_reproduces_chart_points():
    curve = _linear_curve()
    for p, mu in zip(curve.particle_friction, curve.bulk_friction):
        assert invert_curve(curve, _deg(mu), 0.0).particle_friction == pytest.approx(p, abs=1e-12)


def test_invert_plateau_uses_monotone_part():
    curve = _plateau_curve()
    inversion = invert_curve(curve, _deg(0.45), tolerance_deg=1.0)
    # between p = 0.2 (0.4) and 0.4 (0.5), linear in angle
    expected = 0.2 + 0.2 * (_deg(0.45) - _deg(0.4)) / (_deg(0.5) - _deg(0.4))
    assert inversion.particle_friction == pytest.approx(expected, abs=1e-12)
    assert inversion.plateau_particle_friction == 0.6
    assert inversion.reachable_range_deg == pytest.approx((_deg(0.3), _deg(0.55)), abs=1e-12)

    # Target reachable, upper band edge beyond the first maximum: clipped to p = 0.6.
    near_top = invert_curve(curve, _deg(0.55) - 0.5, tolerance_deg=1.0)
    assert near_top.band_clipped is True
    assert near_top.upper == 0.6
    assert near_top.lower < near_top.particle_friction < 0.6

    # Lower band edge below the chart: clipped to p = 0.
    near_bottom = invert_curve(curve, _deg(0.3) + 0.5, tolerance_deg=1.0)
    assert near_bottom.band_clipped is True
    assert near_bottom.lower == 0.0


def test_unreachable_target_message_names_range():
    curve = _plateau_curve()
    expected = (
        "internal friction angle 30.0 deg is unreachable for sphere2 with rolling friction 0.05: "
        "the chart reaches 16.7-28.8 deg (bulk friction stops growing above particle friction 0.6)"
    )
    with pytest.raises(UnreachableTarget) as raised:
        invert_curve(curve, 30.0)
    assert str(raised.value) == expected
    assert isinstance(raised.value, ValueError)

    with pytest.raises(UnreachableTarget, match=r"aluminium wall friction angle 5\.0 deg .* reaches 11\.3-35\.0 deg$"):
        invert_curve(_linear_curve("wall", "aluminium"), 5.0)


def test_invert_curve_rejects_bad_arguments():
    with pytest.raises(ValueError, match="target_angle_deg"):
        invert_curve(_linear_curve(), float("nan"))
    with pytest.raises(ValueError, match="tolerance_deg"):
        invert_curve(_linear_curve(), 25.0, tolerance_deg=-1.0)
    with pytest.raises(ValueError, match="curve"):
        invert_curve({"shape": "sphere"}, 25.0)


@pytest.mark.parametrize(
    "change, name",
    [
        ({"test": "shear"}, "test"),
        ({"particle_friction": [0.0, 0.2, 0.1]}, "particle_friction"),
        ({"bulk_friction": [0.1, 0.2]}, "bulk_friction"),
        ({"bulk_standard_error": [0.1]}, "bulk_standard_error"),
        ({"rolling_friction": -0.1}, "rolling_friction"),
        ({"wall_material": "perspex"}, "wall_material"),
        ({"shape": ""}, "shape"),
    ],
)
def test_calibration_curve_validation(change, name):
    arguments = dict(
        shape="sphere", test="internal", rolling_friction=0.0, particle_friction=[0.0, 0.1, 0.2],
        bulk_friction=[0.2, 0.3, 0.4],
    )
    arguments.update(change)
    with pytest.raises(ValueError, match=name):
        CalibrationCurve(**arguments)


def test_calibration_curve_normalises_empty_material():
    curve = CalibrationCurve("sphere", "internal", 0, [0.1], [0.3], wall_material="")
    assert curve.wall_material is None
    assert isinstance(curve.particle_friction, np.ndarray)
    assert curve.rolling_friction == 0.0


# --------------------------------------------------------------------------- invert_calibration


def _chart_set():
    return [
        _linear_curve("internal", None, rolling=0.1),
        _linear_curve("wall", "aluminium", rolling=0.1, offset=0.05, slope=0.5),
        _linear_curve("wall", "perspex", rolling=0.1, offset=0.1, slope=0.5),
        _linear_curve("internal", None, rolling=0.05, offset=0.1),  # other rolling friction
        _linear_curve("internal", None, rolling=0.1, shape="sphere4", offset=0.3),  # other shape
    ]


def test_invert_calibration_dict():
    targets = {"internal": _deg(0.45), "aluminium": _deg(0.30), "perspex": _deg(0.35)}
    result = invert_calibration(_chart_set(), targets, tolerance_deg=1.0, shape="sphere2", rolling_friction=0.1)
    assert set(result) == {"shape", "rolling_friction", "tolerance_deg", "particle_particle", "particle_wall", "targets_deg"}
    assert result["shape"] == "sphere2" and result["rolling_friction"] == 0.1 and result["tolerance_deg"] == 1.0
    assert result["particle_particle"]["sliding_friction"] == pytest.approx(0.5, abs=1e-12)
    assert result["particle_wall"]["aluminium"]["sliding_friction"] == pytest.approx(0.5, abs=1e-12)
    assert result["particle_wall"]["perspex"]["sliding_friction"] == pytest.approx(0.5, abs=1e-12)
    assert set(result["particle_wall"]["perspex"]) == {"sliding_friction", "sliding_friction_error", "lower", "upper",
                                                       "band_clipped"}
    assert result["particle_particle"]["sliding_friction_error"] is None  # the chart has no errors: YAML null
    assert result["targets_deg"] == targets
    expected_band = invert_curve(_linear_curve(), _deg(0.45), 1.0)
    assert result["particle_particle"]["lower"] == expected_band.lower
    assert result["particle_particle"]["upper"] == expected_band.upper
    # plain types only: safe_dump accepts it and round-trips
    assert yaml.safe_load(yaml.safe_dump(result)) == result


def test_invert_calibration_missing_curve():
    curves = _chart_set()[:2]
    with pytest.raises(ValueError, match=r"no wall friction on perspex curve for shape sphere2 with rolling friction 0\.1"):
        invert_calibration(curves, {"internal": 24.0, "perspex": 11.0}, shape="sphere2", rolling_friction=0.1)
    with pytest.raises(ValueError, match=r"no internal friction curve for shape sphere with rolling friction 0\.1"):
        invert_calibration(curves, {"internal": 24.0}, shape="sphere", rolling_friction=0.1)


def test_invert_calibration_unreachable_propagates():
    with pytest.raises(UnreachableTarget, match="perspex wall friction angle 40.0 deg"):
        invert_calibration(_chart_set(), {"perspex": 40.0}, shape="sphere2", rolling_friction=0.1)


# --------------------------------------------------------------------------- curves_from_table


def test_curves_from_table_groups_and_sorts():
    rows = [
        {"shape": "sphere2", "test": "wall", "wall_material": "perspex", "rolling_friction": "0.1",
         "particle_friction": "0.5", "bulk_friction": "0.3", "bulk_friction_stderr": "0.01"},
        {"shape": "sphere2", "test": "internal", "wall_material": "", "rolling_friction": "0.1",
         "particle_friction": "0.2", "bulk_friction": "0.5", "bulk_friction_stderr": ""},
        {"shape": "sphere", "test": "internal", "wall_material": float("nan"), "rolling_friction": 0.0,
         "particle_friction": 0.3, "bulk_friction": 0.45, "bulk_friction_stderr": 0.02},
        {"shape": "sphere2", "test": "internal", "wall_material": None, "rolling_friction": 0.1,
         "particle_friction": 0.1, "bulk_friction": 0.4},
        {"shape": "sphere2", "test": "wall", "wall_material": "aluminium", "rolling_friction": 0.1,
         "particle_friction": 0.5, "bulk_friction": 0.25, "bulk_friction_stderr": 0.01},
        {"shape": "sphere2", "test": "wall", "wall_material": "perspex", "rolling_friction": 0.1,
         "particle_friction": 0.2, "bulk_friction": 0.2, "bulk_friction_stderr": None},
        {"shape": "sphere2", "test": "internal", "wall_material": "", "rolling_friction": 0.05,
         "particle_friction": 0.1, "bulk_friction": 0.35},
        {"shape": "sphere", "test": "internal", "wall_material": "", "rolling_friction": 0.0,
         "particle_friction": 0.1, "bulk_friction": 0.3, "bulk_friction_stderr": 0.01},
    ]
    curves = curves_from_table(rows)
    keys = [(c.shape, c.test, c.wall_material, c.rolling_friction) for c in curves]
    assert keys == [
        ("sphere", "internal", None, 0.0),
        ("sphere2", "internal", None, 0.05),
        ("sphere2", "internal", None, 0.1),
        ("sphere2", "wall", "aluminium", 0.1),
        ("sphere2", "wall", "perspex", 0.1),
    ]
    sphere = curves[0]
    np.testing.assert_array_equal(sphere.particle_friction, [0.1, 0.3])
    np.testing.assert_array_equal(sphere.bulk_friction, [0.3, 0.45])
    np.testing.assert_array_equal(sphere.bulk_standard_error, [0.01, 0.02])
    internal = curves[2]
    np.testing.assert_array_equal(internal.particle_friction, [0.1, 0.2])
    np.testing.assert_array_equal(internal.bulk_friction, [0.4, 0.5])
    assert internal.bulk_standard_error is None
    perspex = curves[4]
    np.testing.assert_array_equal(perspex.particle_friction, [0.2, 0.5])
    np.testing.assert_array_equal(perspex.bulk_standard_error, [np.nan, 0.01])


def test_curves_from_table_reads_the_error_under_its_current_name_first():
    row = {"shape": "sphere", "test": "internal", "wall_material": "", "rolling_friction": 0.0, "bulk_friction": 0.3}
    (curve,) = curves_from_table([
        dict(row, particle_friction=0.1, bulk_friction_error="0.02", bulk_friction_stderr="0.5"),
        dict(row, particle_friction=0.2, bulk_friction_stderr="0.03"),  # an older row: only the old name
        dict(row, particle_friction=0.3, bulk_friction_error=""),
    ])
    np.testing.assert_array_equal(curve.bulk_standard_error, [0.02, 0.03, np.nan])


def test_curves_from_table_errors():
    row = {"shape": "sphere", "test": "internal", "wall_material": "", "rolling_friction": 0.0,
           "particle_friction": 0.1, "bulk_friction": 0.3}
    with pytest.raises(ValueError, match="particle friction 0.1"):
        curves_from_table([row, dict(row)])
    with pytest.raises(ValueError, match=r"rows\[0\] lacks the key 'bulk_friction'"):
        curves_from_table([{k: v for k, v in row.items() if k != "bulk_friction"}])
    with pytest.raises(ValueError, match=r"rows\[0\]: bulk_friction"):
        curves_from_table([dict(row, bulk_friction="abc")])
    with pytest.raises(ValueError, match=r"rows\[0\]: test"):
        curves_from_table([dict(row, test="shear")])


def test_unreachable_targets_can_be_recorded_instead_of_raised():
    particle = np.array([0.0, 0.5, 1.0])
    curves = [
        CalibrationCurve("sphere2", "internal", 0.1, particle, 0.2 + 0.5 * particle),
        CalibrationCurve("sphere2", "wall", 0.1, particle, 0.1 + 0.2 * particle, wall_material="aluminium"),
    ]
    target = math.degrees(math.atan(0.45))
    result = invert_calibration(curves, {"internal": target, "aluminium": 45.0}, 0.5, shape="sphere2",
                                rolling_friction=0.1, record_unreachable=True)
    assert result["particle_particle"]["sliding_friction"] == pytest.approx(0.5, abs=1e-12)
    assert "aluminium" not in result["particle_wall"]
    assert "45.0 deg is unreachable" in result["unreachable"]["aluminium"]


def test_interpolation_error_is_zero_on_a_straight_chart_and_the_parabola_gap_where_it_bends():
    # p = 0.1, 0.3, 0.5 at 10, 20, 40 deg: target 15 deg in the first segment, third point 40 deg.
    angles, particle = [10.0, 20.0, 40.0], [0.1, 0.3, 0.5]
    line = 0.2  # halfway along the first segment
    coefficients = np.polyfit(angles, particle, 2)
    assert interpolation_error(angles, particle, 15.0) == pytest.approx(abs(np.polyval(coefficients, 15.0) - line),
                                                                        rel=1e-12)
    # by hand: the parabola through the three points is p(x) = a x^2 + b x + c with a = -1/3000, b = 0.03,
    # c = -1/6; at 15 deg it gives 0.208333, 1/120 above the line
    assert interpolation_error(angles, particle, 15.0) == pytest.approx(1.0 / 120.0, rel=1e-9)
    assert interpolation_error(angles, particle, 20.0) == pytest.approx(0.0, abs=1e-12)  # a chart point
    assert interpolation_error([10.0, 20.0, 30.0], [0.1, 0.2, 0.3], 15.0) == pytest.approx(0.0, abs=1e-12)
    assert math.isnan(interpolation_error([10.0, 20.0], [0.1, 0.3], 15.0))  # two points cannot show a bend
