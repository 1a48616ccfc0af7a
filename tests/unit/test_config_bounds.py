"""Numbers bounded where an engine or the machine is: a value just beyond a bound is refused naming the key, within a
second and before anything is written; the value at the bound is accepted, and where it is cheap to build, builds.
"""

from __future__ import annotations

import copy
import time

import pytest

from engines.cases import CASE_BUILDERS, cases_of
from engines.cases.cross_engine import cross_engine_cases, cross_engine_jenike_cases
from engines.cases.physics import MAX_STEPS, engine_seeds, steps_for
from engines.cases.silo_flat import build_silo_case
from engines.config import REPO_ROOT, ConfigError, load_config_file, load_schema, validate_config

#: The bounds (schema maxima and minima): the largest seed, replicate count, MPI ranks, name length, and the
#: smallest time step fraction and particle model scale.
SEED_MAX, REPLICATES_MAX, MPI_RANKS_MAX, NAME_MAX = 100_000, 100, 1024, 64
FRACTION_MIN, SCALE_MIN = 0.01, 0.1
#: The largest seed LIGGGHTS' Park-Miller generator takes (it adds the MPI rank to some seeds).
PARK_MILLER_MAX = 2**31 - 1

#: The sections with their own seed and time step fractions, and those with replicates.
SECTIONS = ("defaults", "silo_flat", "silo_recirculation", "blender", "jenike")
REPLICATED_SECTIONS = SECTIONS[:-1]
ON_YADE = {"silo_flat": {"engine": "yade"}}  # YADE's settings are refused unless a case runs on it

#: (key named in the message, path, value at the bound, value just beyond it, other settings the value needs)
BOUNDS = [
    *[(f"{section}.seed", (section, "seed"), SEED_MAX, SEED_MAX + 1, {}) for section in SECTIONS],
    *[(f"{section}.{key}", (section, key), REPLICATES_MAX, REPLICATES_MAX + 1, {})
      for section in REPLICATED_SECTIONS for key in ("replicates", "reference_replicates")],
    ("jenike.sweep.reference_replicates", ("jenike", "sweep", "reference_replicates"), 100, 101, {}),
    ("cross_engine.seeds", ("cross_engine", "seeds"), 100, 101, {}),
    *[(f"{section}.{key}", (section, key), FRACTION_MIN, 0.0099, {})
      for section in SECTIONS for key in ("timestep_fraction", "timestep_hertz_fraction")],
    ("particle_models.sphere2.timestep_scale", ("particle_models", "sphere2", "timestep_scale"), SCALE_MIN, 0.099,
     {}),
    ("engine.mpi_ranks", ("engine", "mpi_ranks"), MPI_RANKS_MAX, MPI_RANKS_MAX + 1, {}),
    ("engine.yade.threads", ("engine", "yade", "threads"), 256, 257, ON_YADE),
    ("silo_flat.piv.resolutions[0][1]", ("silo_flat", "piv", "resolutions"), [[8192, 8192]], [[250, 8193]], {}),
    ("silo_flat.piv.window_px", ("silo_flat", "piv", "window_px"), 8192, 8193, {}),
    ("silo_flat.piv.overlap_px", ("silo_flat", "piv", "overlap_px"), 8191, 8192, {}),
    ("silo_flat.piv.passes", ("silo_flat", "piv", "passes"), 6, 7, {}),
    ("silo_flat.piv.frame_pairs", ("silo_flat", "piv", "frame_pairs"), 100, 101, {}),
    ("silo_flat.piv.measured.hampel.half_window", ("silo_flat", "piv", "measured", "hampel", "half_window"), 10,
     11, {}),
    ("silo_recirculation.layouts[0].sublayers", ("silo_recirculation", "layouts"),
     [{"name": "layered", "blue_fraction": 0.5, "sublayers": 100}],
     [{"name": "layered", "blue_fraction": 0.5, "sublayers": 101}], {}),
    ("silo_recirculation.tracer.bins", ("silo_recirculation", "tracer", "bins"), 1000, 1001, {}),
    ("silo_recirculation.verification.paths_shown", ("silo_recirculation", "verification", "paths_shown"), 100,
     101, {}),
    ("silo_recirculation.lti.passes", ("silo_recirculation", "lti", "passes"), 100, 101, {}),
    ("blender.discharge.profile_windows", ("blender", "discharge", "profile_windows"), 100, 101, {}),
    ("blender.rtd.bins", ("blender", "rtd", "bins"), 1000, 1001, {}),
    ("blender.discontinuous.passes", ("blender", "discontinuous", "passes"), 100, 101, {}),
]

#: Integers of the schema that need no maximum, and why.
UNBOUNDED_INTEGERS = {
    "silo_flat.fields.vtk_every": "every n-th frame is written: a larger value writes fewer files",
    "silo_flat.existing_runs.<entry>.open_step": "a step number of a run another program made, not a count",
}


def _with(raw: dict, path: tuple, value, extra: dict) -> dict:
    """A copy of ``raw`` with ``value`` at ``path`` and the sections of ``extra`` merged in."""
    config = copy.deepcopy(raw)
    for section, settings in extra.items():
        config.setdefault(section, {}).update(copy.deepcopy(settings))
    node = config
    for key in path[:-1]:
        node = node.setdefault(key, {})
    node[path[-1]] = copy.deepcopy(value)
    return config


@pytest.mark.parametrize("key, path, at, beyond, extra", BOUNDS, ids=[bound[0] for bound in BOUNDS])
def test_a_value_beyond_a_bound_is_refused_naming_the_key_and_the_bound_is_accepted(
        raw_default_config, tmp_path, monkeypatch, key, path, at, beyond, extra):
    monkeypatch.chdir(tmp_path)
    validate_config(_with(raw_default_config, path, at, extra))
    started = time.perf_counter()
    with pytest.raises(ConfigError, match=r" is (less|greater) than the (minimum|maximum) of ") as caught:
        validate_config(_with(raw_default_config, path, beyond, extra))
    assert time.perf_counter() - started < 1.0
    assert str(caught.value).startswith(f"config key '{key}': "), str(caught.value)
    assert list(tmp_path.iterdir()) == []  # refused before any run directory exists


def _integers(node: dict, definitions: dict, path: str = ""):
    """``(key, subschema)`` of every integer of the schema (``<entry>`` for any key of a mapping)."""
    reference = node.get("$ref", "")
    if reference.startswith("#/definitions/"):
        node = {**definitions[reference.rsplit("/", 1)[1]], **node}
    kinds = node.get("type")
    if kinds == "integer" or (isinstance(kinds, list) and "integer" in kinds):
        yield path, node
    for name, sub in node.get("properties", {}).items():
        yield from _integers(sub, definitions, f"{path}.{name}" if path else name)
    for key, suffix in (("additionalProperties", ".<entry>"), ("items", "[]")):
        if isinstance(node.get(key), dict):
            yield from _integers(node[key], definitions, path + suffix)


def test_every_count_in_the_schema_has_a_maximum():
    schema = load_schema()
    integers = dict(_integers(schema, schema["definitions"]))
    assert len(integers) >= 20  # the walk reached the nested sections
    # a new count needs a maximum (and its description the reason), or a place in UNBOUNDED_INTEGERS
    assert {key for key, node in integers.items() if "maximum" not in node} == set(UNBOUNDED_INTEGERS)


def test_the_largest_seeds_give_engine_seeds_far_below_the_engines_limit_and_build_fast(raw_default_config):
    started = time.perf_counter()
    primes = engine_seeds(SEED_MAX + REPLICATES_MAX - 1, 3)
    assert time.perf_counter() - started < 0.1
    # LIGGGHTS adds the MPI rank to a seed; the schema's description says 21 times below
    assert max(primes) + MPI_RANKS_MAX < PARK_MILLER_MAX / 20
    raw = copy.deepcopy(raw_default_config)
    for section in SECTIONS:
        raw.setdefault(section, {})["seed"] = SEED_MAX
    raw["defaults"].update(replicates=REPLICATES_MAX, reference_replicates=REPLICATES_MAX)
    raw["jenike"].setdefault("sweep", {})["reference_replicates"] = REPLICATES_MAX
    raw.setdefault("cross_engine", {})["seeds"] = REPLICATES_MAX
    config = validate_config(raw)
    started = time.perf_counter()
    cases = [case for kind in CASE_BUILDERS for case in cases_of(config, kind).values()]
    cases += [case for runs in cross_engine_cases(config).values() for case in runs.values()]
    cases += [case for runs in cross_engine_jenike_cases(config).values() for _, case in runs.values()]
    assert time.perf_counter() - started < 10.0  # about 800 runs
    seeds = {seed for case in cases for seed in case.seeds}
    assert min(seeds) > 10000 and max(seeds) + MPI_RANKS_MAX < PARK_MILLER_MAX / 20


def test_the_smallest_time_steps_plan_the_full_scale_study_within_one_engine_run_command():
    raw = load_config_file(REPO_ROOT / "config" / "thesis.yaml")
    for section in SECTIONS:
        raw.setdefault(section, {}).update(timestep_fraction=FRACTION_MIN, timestep_hertz_fraction=FRACTION_MIN)
    raw["particle_models"] = copy.deepcopy(validate_config(raw)["particle_models"])
    for model in raw["particle_models"].values():
        model["timestep_scale"] = SCALE_MIN
    config = validate_config(raw)
    # every stage of every run is checked against MAX_STEPS as the cases are built (a ValueError otherwise)
    blenders = cases_of(config, "blender").values()
    for kind in ("jenike", "silo_flat", "silo_recirculation"):
        cases_of(config, kind)
    longest = max(case.silo.fill.fill_steps for case in blenders)
    assert 5e8 < longest <= MAX_STEPS  # the full-scale blender's pour, the longest stage


def test_steps_beyond_one_engine_run_command_are_refused_not_overflowed(raw_default_config):
    assert steps_for(float(MAX_STEPS), 1.0) == MAX_STEPS
    for duration, timestep in ((MAX_STEPS + 1.0, 1.0), (1.0, 1e-320)):  # the second is infinitely many
        with pytest.raises(ValueError, match=r"more than the 2147483647 \(2\^31 - 1\) one engine run command takes"):
            steps_for(duration, timestep)
    # no schema bound stops an absurdly stiff material (1e18 times the Young's modulus of diamond); its step count does
    raw = copy.deepcopy(raw_default_config)
    raw["materials"]["hdpe"]["youngs_modulus"] = 1e30
    with pytest.raises(ValueError, match=r"2\^31 - 1"):
        build_silo_case(validate_config(raw))


def _long_names(raw: dict, model: str, material: str) -> dict:
    """``raw`` with a particle model and a wall material of the given names, used by the silo and the Jenike cell."""
    raw, filled = copy.deepcopy(raw), validate_config(raw)
    raw["particle_models"] = {**filled["particle_models"], model: filled["particle_models"]["sphere2"]}
    raw["materials"] = {**filled["materials"], material: filled["materials"]["aluminium"]}
    raw["contacts"] = [*filled["contacts"], {"materials": ["hdpe", material], "sliding_friction": 0.2,
                                             "rolling_friction": 0.1, "restitution": 0.1}]
    raw["silo_flat"]["particle_model"] = model
    raw["jenike"].setdefault("sweep", {}).update(shapes=[model], tests=["internal", material],
                                                 wall_test_shapes=None, sensitivity_shapes=None)
    raw.setdefault("calibration", {})["shape"] = model
    return raw


def test_names_of_the_longest_length_are_accepted_and_keep_run_ids_short(raw_default_config):
    config = validate_config(_long_names(raw_default_config, "p" * NAME_MAX, "m" * NAME_MAX))
    run_ids = [*cases_of(config, "jenike"), *cases_of(config, "silo_flat")]
    two_names = [run for run in run_ids if run.startswith(f"{'p' * NAME_MAX}-{'m' * NAME_MAX}-")]
    assert two_names and max(len(run) for run in run_ids) <= 2 * NAME_MAX + 12 < 255


@pytest.mark.parametrize("key", ["materials", "particle_models", "silo_flat.particle_model"])
def test_a_name_one_too_long_is_refused_naming_the_key(raw_default_config, tmp_path, monkeypatch, key):
    monkeypatch.chdir(tmp_path)
    raw, filled = copy.deepcopy(raw_default_config), validate_config(raw_default_config)
    name = "n" * (NAME_MAX + 1)
    if key == "silo_flat.particle_model":  # a name given as a value
        raw["silo_flat"]["particle_model"] = name
    else:  # a key of a mapping: a material or particle model that nothing uses yet
        raw[key] = {**filled[key], name: next(iter(filled[key].values()))}
    with pytest.raises(ConfigError, match=rf"^config key '{key}': 'n+' is too long"):
        validate_config(raw)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("length", [NAME_MAX, NAME_MAX + 1])
def test_an_existing_runs_name_is_at_most_64_characters(raw_default_config, length):
    raw = copy.deepcopy(raw_default_config)
    raw["silo_flat"]["existing_runs"] = {"r" * length: {
        "folder": "runs/mine", "dumps": "post/silo*.vtk", "width": 0.15, "depth": 0.04, "outlet_width": 0.04,
        "timestep": 1e-5, "open_step": 0}}
    if length <= NAME_MAX:
        assert list(validate_config(raw)["silo_flat"]["existing_runs"]) == ["r" * length]
    else:
        with pytest.raises(ConfigError, match=r"^config key 'silo_flat.existing_runs': 'r+' is too long"):
            validate_config(raw)


def test_a_bad_shared_value_is_named_where_it_was_given_not_where_it_was_inherited(raw_default_config):
    raw = copy.deepcopy(raw_default_config)
    raw["defaults"]["seed"] = SEED_MAX + 1
    for section in REPLICATED_SECTIONS[1:]:
        raw.get(section, {}).pop("seed", None)
    with pytest.raises(ConfigError, match=r"^config key 'defaults.seed': 100001 is greater than the maximum"):
        validate_config(raw)
