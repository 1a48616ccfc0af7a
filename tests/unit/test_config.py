"""Configuration validation: defaults filled, one clear message naming the key for bad input."""

from __future__ import annotations

import copy

import pytest
import yaml

from siloflow.model.cases import cases_of
from siloflow.model.cases.silo_flat import build_silo_case
from snakemake.utils import update_config

from siloflow.engines.config import ConfigError, load_config, load_config_file, load_schema, validate_config
from siloflow.engines.config_reference import keys_lacking_description_or_default
from siloflow.engines.interface import CaseNotSupported, engine_for
from tests.repo import REPO_ROOT


def test_every_schema_key_has_description_and_default():
    # the main schema with every case kind's fragment; the rule is defined once, where the reference page is made
    assert keys_lacking_description_or_default(load_schema()) == []


def test_empty_config_gets_every_default():
    config = validate_config({})
    assert config["engine"] == {"kind": "liggghts", "mpi_ranks": 1, "mpirun": "mpirun",
                                "liggghts": {"executable": "liggghts"},
                                "yade": {"python": "/usr/bin/python3", "threads": 1}}
    assert config["silo_flat"]["width"] == 0.15
    assert config["silo_flat"]["settle"]["kinetic_energy_ratio"] == 1e-4
    assert config["silo_flat"]["settle"]["kinetic_energy_threshold"] is None
    assert config["blender"]["settle_kinetic_energy_ratio"] == 1.7e-2
    assert config["silo_flat"]["beverloo"] == {
        "discharge_coefficient": 0.58,
        "shape_coefficient": 1.5,
        "particle_diameter": None,
    }
    assert set(config["particle_models"]) == {"sphere", "sphere2", "sphere4"}


def test_validation_does_not_modify_its_input(raw_default_config):
    before = copy.deepcopy(raw_default_config)
    validate_config(raw_default_config)
    assert raw_default_config == before


def test_default_and_thesis_configs_are_valid():
    for name in ("config/config.yaml", "config/thesis.yaml"):
        config = load_config(REPO_ROOT / name)
        assert config["silo_flat"]["particle_model"] == "sphere2"


def _with(raw, path, value):
    config = copy.deepcopy(raw)
    node = config
    for key in path[:-1]:
        node = node.setdefault(key, {})
    node[path[-1]] = value
    return config


@pytest.mark.parametrize(
    "path, value, expected",
    [
        (("silo_flat", "width"), "wide", "config key 'silo_flat.width': 'wide' is not of type 'number'"),
        (("silo_flat", "outlet_width"), -0.04, "config key 'silo_flat.outlet_width': -0.04 is less than or equal to the minimum of 0"),
        (("engine", "mpi_ranks"), 1.5, "config key 'engine.mpi_ranks': 1.5 is not of type 'integer'"),
        (("silo_flat", "particle_model"), "sphere3", "config key 'silo_flat.particle_model': unknown particle model 'sphere3'; defined: sphere, sphere2, sphere4"),
        (("silo_flat", "wall_materials", "side"), "steel", "config key 'silo_flat.wall_materials.side': unknown material 'steel'"),
        (("silo_flat", "widht"), 0.1, "config key 'silo_flat.widht' is not a siloflow setting: did you mean "
                                       "'silo_flat.width'? the keys here are beverloo, depth, discharge_time"),
        (("silo_recirculation", "lti", "input_csv"), "in.csv", "config key 'silo_recirculation.lti.input_csv' is not a "
         "siloflow setting: the keys here are passes, period_fractions, tolerance"),
        (("jenike", "shear", "velocty"), 0.01, "did you mean 'jenike.shear.velocity'?"),
    ],
)
def test_bad_values_name_the_key(raw_default_config, path, value, expected):
    with pytest.raises(ConfigError) as caught:
        validate_config(_with(raw_default_config, path, value))
    assert expected in str(caught.value)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("field", ["sliding_friction", "rolling_friction"])
@pytest.mark.parametrize("value", [-0.1, 1.5])
def test_friction_outside_unit_interval_is_rejected(raw_default_config, field, value):
    config = copy.deepcopy(raw_default_config)
    config["contacts"][1][field] = value
    with pytest.raises(ConfigError, match=rf"config key 'contacts\[1\]\.{field}': {value} is"):
        validate_config(config)


def test_restitution_below_an_engines_limit_is_the_engines_to_refuse(raw_default_config):
    config = copy.deepcopy(raw_default_config)
    config["contacts"][0]["restitution"] = 1e-4
    validated = validate_config(config)  # the schema only asks for 0 < e <= 1
    case = build_silo_case(validated)
    with pytest.raises(CaseNotSupported, match=r"config key 'contacts': restitution 0.0001 of the pair \[hdpe, hdpe\] "
                                               r"is not accepted by LIGGGHTS 3.8, which requires 0.05 < e <= 1"):
        engine_for(validated, "silo_flat").check_case(case)
    config["contacts"][0]["restitution"] = 0.0
    with pytest.raises(ConfigError, match=r"contacts\[0\]\.restitution': 0.0 is less than or equal to the minimum of 0"):
        validate_config(config)


def test_renamed_keys_are_refused_with_their_new_name(raw_default_config):
    old = copy.deepcopy(raw_default_config)
    old["blending"] = old.pop("silo_recirculation")
    with pytest.raises(ConfigError, match="config key 'blending' was renamed 'silo_recirculation'"):
        validate_config(old)
    old = copy.deepcopy(raw_default_config)
    old["engine"]["executable"] = "liggghts"
    with pytest.raises(ConfigError, match="config key 'engine.executable' was renamed 'engine.liggghts.executable'"):
        validate_config(old)


def test_case_sections_inherit_shared_keys_from_defaults_leaf_by_leaf(raw_default_config):
    raw = copy.deepcopy(raw_default_config)
    raw["defaults"]["fill"]["insertion_velocity"] = 0.5
    raw["blender"]["fill"] = {"heap_angle": 35.0}
    raw["silo_recirculation"]["particle_model"] = "sphere4"
    config = validate_config(raw)
    assert config["silo_flat"]["fill"]["insertion_velocity"] == 0.5
    assert config["blender"]["fill"]["insertion_velocity"] == 0.5 and config["blender"]["fill"]["heap_angle"] == 35.0
    assert config["silo_flat"]["fill"]["heap_angle"] == raw["defaults"]["fill"]["heap_angle"]
    assert config["silo_recirculation"]["particle_model"] == "sphere4"
    assert config["silo_flat"]["particle_model"] == config["blender"]["particle_model"] == "sphere2"


def test_a_case_section_naming_an_unknown_material_is_refused(raw_default_config):
    raw = copy.deepcopy(raw_default_config)
    raw["blender"]["wall_materials"] = {"side": "steel", "bottom": "aluminium", "front_back": "perspex"}
    with pytest.raises(ConfigError, match="config key 'blender.wall_materials.side': unknown material 'steel'"):
        validate_config(raw)


def test_yaml_exponent_without_sign_gets_a_hint(raw_default_config):
    raw = yaml.safe_load("youngs_modulus: 5.0e6")
    config = copy.deepcopy(raw_default_config)
    config["materials"]["hdpe"]["youngs_modulus"] = raw["youngs_modulus"]
    with pytest.raises(ConfigError, match=r"materials.hdpe.youngs_modulus.*write the exponent with a sign"):
        validate_config(config)


def test_missing_contact_pair_is_named(raw_default_config):
    config = copy.deepcopy(raw_default_config)
    config["contacts"] = [c for c in config["contacts"] if set(c["materials"]) != {"hdpe", "perspex"}]
    with pytest.raises(ConfigError, match=r"no contact parameters for the pair \[hdpe, perspex\]"):
        validate_config(config)


def test_duplicate_contact_pair_is_named(raw_default_config):
    config = copy.deepcopy(raw_default_config)
    config["contacts"].append({**config["contacts"][1], "materials": ["aluminium", "hdpe"]})
    last = len(config["contacts"]) - 1
    with pytest.raises(ConfigError, match=rf"contacts\[{last}\]': material pair \['aluminium', 'hdpe'\] is already defined in contacts\[1\]"):
        validate_config(config)


def test_injected_material_name_is_rejected(raw_default_config):
    config = copy.deepcopy(raw_default_config)
    config["silo_flat"]["particle_material"] = "hdpe\nshell rm -rf /"
    with pytest.raises(ConfigError, match=r"silo_flat.particle_material"):
        validate_config(config)


def test_file_errors_name_the_file(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("silo_flat:\n  depth: -1.0\n")
    with pytest.raises(ConfigError, match=rf"{path}: config key 'silo_flat.depth'"):
        load_config(path)


@pytest.mark.parametrize("kind", ["silo_flat", "silo_recirculation", "blender"])
def test_replicates_add_reseeded_runs_and_keep_the_first(raw_default_config, kind):
    single = cases_of(validate_config(raw_default_config), kind)
    raw = copy.deepcopy(raw_default_config)
    raw["defaults"]["replicates"] = 3
    replicated = cases_of(validate_config(raw), kind)
    assert len(replicated) == 3 * len(single)
    assert set(single) <= set(replicated)  # raising N keeps the runs already done
    seeds = [getattr(case, "seeds", None) or case.silo.seeds for case in replicated.values()]
    assert len(set(seeds)) == 3  # one engine seed set per replicate, shared by the configurations of one seed


def test_replicates_must_be_at_least_one(raw_default_config):
    raw = copy.deepcopy(raw_default_config)
    raw["blender"]["replicates"] = 0
    with pytest.raises(ConfigError, match="blender.replicates"):
        validate_config(raw)


@pytest.mark.parametrize("section", ["silo_flat", "silo_recirculation", "blender"])
def test_an_outlet_as_wide_as_its_silo_is_refused_in_every_silo_type_section(section):
    raw = {section: {"width": 0.1, "outlet_width": 0.1}}
    with pytest.raises(ConfigError, match=rf"^config key '{section}.outlet_width': 0.1 m must be smaller than "
                                          rf"{section}.width \(0.1 m\)$"):
        validate_config(raw)
    validate_config({section: {"width": 0.1, "outlet_width": 0.099}})


def update_config_copy(base: dict, layer: dict) -> dict:
    """``layer`` over ``base`` as Snakemake merges two --configfile files."""
    merged = copy.deepcopy(base)
    update_config(merged, layer)
    return merged


def test_the_bayesian_twin_configuration_layers_over_the_default_one():
    raw = load_config_file(REPO_ROOT / "config" / "config.yaml")
    twin = load_config_file(REPO_ROOT / "config" / "bayesian_twin.yaml")
    config = validate_config(update_config_copy(raw, twin))
    bayesian = config["calibration"]["bayesian"]
    assert bayesian["twin"]["enabled"] and bayesian["engines"] == ["liggghts"]
    assert config["jenike"]["sweep"]["tests"] == ["internal", "aluminium"]
    assert config["jenike"]["cell"]["inner_diameter"] == 0.04


def test_a_silo_on_the_posterior_needs_its_engine_calibrated():
    with pytest.raises(ConfigError, match=r"^config key 'silo_flat.parameters': bayesian takes the posterior on the "
                                          r"silo's engine \(yade\), which calibration.bayesian.engines \['liggghts'\] "
                                          r"does not calibrate$"):
        validate_config({"silo_flat": {"parameters": "bayesian", "engine": "yade"}})
    assert validate_config({"silo_flat": {"parameters": "bayesian"}})["silo_flat"]["parameters"] == "bayesian"


@pytest.mark.parametrize("given, expected", [({}, "png"), ({"format": "pdf"}, "pdf"), ({"format": "svg"}, "svg")])
def test_every_plot_takes_the_configured_format_png_by_default(given, expected):
    assert validate_config({"plots": given})["plots"] == {"format": expected}
    assert validate_config({})["plots"] == {"format": "png"}


def test_a_plot_format_of_none_of_the_writers_is_refused_naming_the_key():
    with pytest.raises(ConfigError, match=r"^config key 'plots.format': 'jpg' is not one of \['png', 'pdf', 'svg'\]"):
        validate_config({"plots": {"format": "jpg"}})
