"""Calibrated parameters flow into the silo configuration."""

import pytest

from siloflow.calibration.parameters import apply_calibrated_parameters
from siloflow.engines.config import validate_config
from siloflow.model.cases.silo_flat import build_silo_case

PARAMETERS = {
    "shape": "sphere4",
    "rolling_friction": 0.05,
    "particle_particle": {"sliding_friction": 0.42, "lower": 0.38, "upper": 0.47},
    "particle_wall": {"aluminium": {"sliding_friction": 0.15, "lower": 0.12, "upper": 0.18}},
}


def _contact(config, a, b):
    return next(c for c in config["contacts"] if sorted(c["materials"]) == sorted([a, b]))


def test_calibrated_values_replace_the_configured_ones():
    config = validate_config({})
    calibrated = apply_calibrated_parameters(config, PARAMETERS, "hdpe")
    assert calibrated["silo_flat"]["particle_model"] == "sphere4"
    assert _contact(calibrated, "hdpe", "hdpe")["sliding_friction"] == 0.42
    assert _contact(calibrated, "hdpe", "hdpe")["rolling_friction"] == 0.05
    assert _contact(calibrated, "hdpe", "aluminium")["sliding_friction"] == 0.15
    # perspex was not calibrated: configured sliding friction, calibrated rolling friction
    assert _contact(calibrated, "hdpe", "perspex")["sliding_friction"] == 0.2
    assert _contact(calibrated, "hdpe", "perspex")["rolling_friction"] == 0.05
    # the lid is a calibration device, never part of a silo
    assert _contact(calibrated, "hdpe", "lid") == _contact(config, "hdpe", "lid")
    # the input is untouched and the result defines a different run
    assert _contact(config, "hdpe", "hdpe")["sliding_friction"] == 0.35
    assert build_silo_case(calibrated).run_id != build_silo_case(config).run_id
    assert build_silo_case(calibrated).run_id.startswith("sphere4-")


def test_parameters_without_internal_result_are_refused():
    with pytest.raises(ValueError, match="the calibration chose no particle-particle friction"):
        apply_calibrated_parameters(validate_config({}), {"shape": "sphere2", "rolling_friction": 0.1}, "hdpe")
