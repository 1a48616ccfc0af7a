"""The settling criterion: a ratio to the clump's m g d by default, an absolute threshold (J) as an option, one at
most; the blender's own ratio; the threshold in joules the cases hand to the engines and record."""

from __future__ import annotations

import copy
import math

import pytest

from siloflow.model.constants import GRAVITY
from siloflow.model.cases.blender import build_blender_case
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.model.cases.silo_recirculation import build_recirculation_case
from siloflow.engines.config import ConfigError, validate_config

#: The single-sphere clump of the default particle models: radius 1.9 mm, hdpe of 950 kg/m^3.
SPHERE_DIAMETER = 0.0038
SPHERE_MASS = 950.0 * math.pi / 6.0 * SPHERE_DIAMETER**3
#: Its m g d at 1 g (J): 2.7294e-5 kg x 9.81 m/s^2 x 3.8 mm = 1.0175e-6 J.
SPHERE_MGD = SPHERE_MASS * GRAVITY * SPHERE_DIAMETER


@pytest.fixture
def raw(raw_default_config):
    """The default configuration as read, its silo-type cases made of the single-sphere clump."""
    raw = copy.deepcopy(raw_default_config)
    raw["defaults"]["particle_model"] = "sphere"
    return raw


def _settle(raw, section, **keys):
    """Replace the settle criterion of ``section`` (``defaults`` or a case section) by ``keys``."""
    node = raw.setdefault(section, {}).setdefault("settle", {})
    for name in ("kinetic_energy_ratio", "kinetic_energy_threshold"):
        node.pop(name, None)
    node.update(keys)
    return raw


def test_the_energy_scale_is_m_g_d_of_the_clump():
    assert SPHERE_MGD == pytest.approx(1.0174793911773e-6, rel=1e-12)


def test_the_threshold_is_the_ratio_times_m_g_d(raw):
    case = build_silo_case(validate_config(_settle(raw, "silo_flat", kinetic_energy_ratio=2.0e-4)))
    assert case.settle_threshold == pytest.approx(2.0e-4 * SPHERE_MGD, rel=1e-12)
    assert case.settle_criterion.key == "silo_flat.settle.kinetic_energy_ratio"
    summary = case.summary()
    assert summary["settle_threshold_J"] == pytest.approx(2.0e-4 * SPHERE_MGD, rel=1e-12)
    assert summary["settle_kinetic_energy_ratio"] == pytest.approx(2.0e-4, rel=1e-12)
    assert summary["settle_energy_scale_J"] == pytest.approx(SPHERE_MGD, rel=1e-12)
    assert summary["settle_criterion"] == "silo_flat.settle.kinetic_energy_ratio"
    settle = next(stage for stage in case.stages() if stage.kind == "settle")
    assert settle.controls["kinetic_energy_threshold_J"] == case.settle_threshold


def test_the_default_ratio_is_1e_4_of_the_sphere2_clumps_m_g_d(raw_default_config):
    # sphere2: two r = 1.5 mm spheres 0.75 mm apart, V = 2 (4/3) pi r^3 - pi (4r + s)(2r - s)^2 / 12
    r, s = 1.5e-3, 0.75e-3
    volume = 2 * 4 / 3 * math.pi * r**3 - math.pi * (4 * r + s) * (2 * r - s) ** 2 / 12
    mgd = 950.0 * volume * GRAVITY * (6 * volume / math.pi) ** (1 / 3)
    case = build_silo_case(validate_config(raw_default_config))
    assert case.settle_threshold == pytest.approx(1.0e-4 * mgd, rel=1e-12)
    assert mgd == pytest.approx(5.99764e-7, rel=1e-5)


def test_an_absolute_threshold_wins_over_the_ratio_of_defaults(raw):
    # config.yaml gives defaults.settle a ratio; the silo's own absolute threshold replaces it, not joins it
    assert raw["defaults"]["settle"]["kinetic_energy_ratio"] == 1.0e-4
    raw["silo_flat"]["settle"] = {"kinetic_energy_threshold": 3.0e-11}
    config = validate_config(raw)
    case = build_silo_case(config)
    assert case.settle_threshold == 3.0e-11
    assert case.settle_criterion.key == "silo_flat.settle.kinetic_energy_threshold"
    assert case.summary()["settle_kinetic_energy_ratio"] == pytest.approx(3.0e-11 / SPHERE_MGD, rel=1e-12)
    # the other sections keep the ratio of defaults
    recirculation = build_recirculation_case(config, config["silo_recirculation"]["flow_patterns"][0])
    assert recirculation.silo.settle_threshold == pytest.approx(1.0e-4 * SPHERE_MGD, rel=1e-12)


def test_a_null_threshold_in_a_section_keeps_the_ratio_of_defaults(raw):
    _settle(raw, "defaults", kinetic_energy_ratio=3.0e-4)
    raw["silo_flat"]["settle"] = {"kinetic_energy_threshold": None}
    case = build_silo_case(validate_config(raw))
    assert case.settle_threshold == pytest.approx(3.0e-4 * SPHERE_MGD, rel=1e-12)


def test_a_ratio_and_a_threshold_of_equal_energy_define_the_same_run(raw):
    by_ratio = build_silo_case(validate_config(_settle(copy.deepcopy(raw), "silo_flat", kinetic_energy_ratio=1.0e-4)))
    by_energy = build_silo_case(validate_config(
        _settle(copy.deepcopy(raw), "silo_flat", kinetic_energy_threshold=by_ratio.settle_threshold)))
    assert by_ratio.run_id == by_energy.run_id
    looser = build_silo_case(validate_config(_settle(raw, "silo_flat", kinetic_energy_ratio=2.0e-4)))
    assert looser.run_id != by_ratio.run_id


@pytest.mark.parametrize("section", ["defaults", "silo_flat", "silo_recirculation"])
def test_a_ratio_and_an_absolute_threshold_together_are_refused(raw, section):
    _settle(raw, section, kinetic_energy_ratio=1.0e-4, kinetic_energy_threshold=1.0e-12)
    with pytest.raises(ConfigError, match=rf"config keys '{section}.settle.kinetic_energy_ratio' and "
                                          rf"'{section}.settle.kinetic_energy_threshold' are both set"):
        validate_config(raw)


def test_the_recirculating_silo_settles_to_its_sections_ratio(raw):
    config = validate_config(_settle(raw, "silo_recirculation", kinetic_energy_ratio=5.0e-4))
    case = build_recirculation_case(config, config["silo_recirculation"]["flow_patterns"][0])
    assert case.silo.settle_threshold == pytest.approx(5.0e-4 * SPHERE_MGD, rel=1e-12)
    assert case.silo.settle_criterion.key == "silo_recirculation.settle.kinetic_energy_ratio"
    assert case.summary()["settle_threshold_J"] == case.silo.settle_threshold


@pytest.mark.parametrize("factor", [1.0, 4.0])
def test_the_blender_threshold_is_its_ratio_times_m_g_d_at_its_gravity(raw, factor):
    raw["blender"]["settle_kinetic_energy_ratio"] = 2.0e-2
    config = validate_config(raw)
    case = build_blender_case(config, config["blender"]["configurations"][0], factor)
    assert case.silo.settle_threshold == pytest.approx(2.0e-2 * SPHERE_MASS * factor * GRAVITY * SPHERE_DIAMETER,
                                                       rel=1e-12)
    assert case.summary()["settle_kinetic_energy_ratio"] == pytest.approx(2.0e-2, rel=1e-12)
    assert case.silo.settle_criterion.key == "blender.settle_kinetic_energy_ratio"


def test_the_blender_default_is_about_1e_8_joule_for_the_sphere2_clump(raw_default_config):
    config = validate_config(raw_default_config)
    case = build_blender_case(config, config["blender"]["configurations"][0], 1.0)
    assert case.silo.settle_threshold == pytest.approx(1.0e-8, rel=0.03)


def test_the_blenders_threshold_does_not_follow_the_ratio_of_defaults(raw):
    config = validate_config(raw)
    changed = validate_config(_settle(copy.deepcopy(raw), "defaults", kinetic_energy_ratio=3.0e-4))
    configuration = config["blender"]["configurations"][0]
    assert build_blender_case(config, configuration).run_id == build_blender_case(changed, configuration).run_id


def test_the_blenders_old_absolute_key_is_refused_with_the_new_one(raw):
    raw["blender"]["settle_threshold"] = 1.0e-8
    with pytest.raises(ConfigError, match="config key 'blender.settle_threshold' was replaced by "
                                          "'blender.settle_kinetic_energy_ratio'"):
        validate_config(raw)


@pytest.mark.parametrize("key", ["kinetic_energy_ratio", "kinetic_energy_threshold"])
def test_a_settle_criterion_in_the_blenders_settle_is_refused(raw, key):
    raw["blender"]["settle"] = {key: 1.0e-4}
    with pytest.raises(ConfigError, match=rf"config key 'blender.settle.{key}': the blender settles to "
                                          r"blender.settle_kinetic_energy_ratio"):
        validate_config(raw)


def test_a_validated_configuration_validates_again_as_it_is(raw):
    raw["silo_flat"]["settle"] = {"kinetic_energy_threshold": 3.0e-11}
    config = validate_config(raw)
    # the unused keys are null: the silo's ratio beside its threshold, the blender's settle criterion
    assert config["silo_flat"]["settle"]["kinetic_energy_ratio"] is None
    assert config["blender"]["settle"]["kinetic_energy_ratio"] is None
    assert config["blender"]["settle"]["kinetic_energy_threshold"] is None
    assert validate_config(config) == config


def test_a_null_ratio_without_a_threshold_is_refused(raw):
    raw["silo_flat"]["settle"] = {"kinetic_energy_ratio": None}
    with pytest.raises(ConfigError, match="config key 'silo_flat.settle.kinetic_energy_ratio': null needs "
                                          "silo_flat.settle.kinetic_energy_threshold"):
        validate_config(raw)
