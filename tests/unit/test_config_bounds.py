"""Numbers bounded where an engine or the machine is: a value just beyond a bound is refused naming the key, within a
second and before anything is written; the value at the bound is accepted, and where it is cheap to build, builds.
No number of the default config set to an extreme (1e300, 1e-300, -1e300) overflows the planner or hangs it: each is
accepted or refused with a ValueError, and values within their bounds that do not fit together are refused naming a key.
"""

from __future__ import annotations

import copy
import signal

import pytest

from siloflow.model.cases import cases_of
from siloflow.model.cases.kinds import configured_kinds
from siloflow.model.cases.cross_engine import cross_engine_cases, cross_engine_jenike_cases
from siloflow.model.cases.jenike_cell import segments_for_chord
from siloflow.model.cases.physics import MAX_STEPS, engine_seeds, free_fall_time, steps_for
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.engines.config import ConfigError, load_config_file, load_schema, validate_config
from tests.repo import REPO_ROOT
from siloflow.engines.planning import config_estimates

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

#: The longest length of a case (m) and simulated time of a case (s): the schema's case_length and case_duration.
LENGTH_MAX, DURATION_MAX = 100.0, 3600.0
#: Every length of a case the engine builds or moves (case_length, and the tube width and ring offset, which may be 0).
CASE_LENGTHS = [
    ("defaults", "fill", "zone_height"),
    *[("silo_flat", key) for key in ("width", "depth", "fill_height", "outlet_width", "sink_depth")],
    *[("silo_recirculation", key) for key in ("width", "depth", "fill_height", "outlet_width", "channel_length")],
    *[("silo_recirculation", "verification", key) for key in ("width", "depth", "fill_height")],
    *[("blender", key) for key in ("width", "depth", "vertical_height", "outlet_width", "fill_height", "wall_thickness",
                                   "tube_width", "sink_depth")],
    *[("jenike", "cell", key) for key in ("inner_diameter", "wall_thickness", "bottom_ring_height",
                                          "shear_ring_height", "initial_offset", "plate_size")],
    ("jenike", "shear", "displacement"),
    *[("cross_engine", key) for key in ("width", "fill_height", "outlet_width")],
    *[("cross_engine", "jenike", key) for key in ("inner_diameter", "bottom_ring_height", "shear_ring_height",
                                                  "shear_displacement")],
]
#: The lengths that validation requires to be less than another (the outlets of the sections whose silo width it knows).
NARROWER = [("silo_flat", "outlet_width"), ("silo_recirculation", "outlet_width"), ("blender", "outlet_width")]
#: Every simulated time of a case (case_duration).
CASE_DURATIONS = [
    ("defaults", "settle", "check_interval"), ("defaults", "settle", "max_time"),
    ("silo_flat", "discharge_time"), ("silo_flat", "dump_interval"), ("silo_recirculation", "dump_interval"),
    ("blender", "discharge", "time"), ("blender", "dump_interval"),
    ("jenike", "fill", "settle_time"), ("jenike", "consolidation", "time"), ("jenike", "output_interval"),
    ("cross_engine", "discharge_time"), ("cross_engine", "jenike", "settle_time"),
    ("cross_engine", "jenike", "consolidation_time"),
]


def _sphere(position=(0.0, 0.0, 0.0), radius=0.0019) -> list:
    """The spheres of a one-sphere particle model."""
    return [{"position": list(position), "radius": radius}]


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
    ("jenike.consolidation.normal_stress", ("jenike", "consolidation", "normal_stress"), 1.0e7, 1.0001e7, {}),
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
    # magnitudes where no material, machine or engine run goes, which would overflow the planner
    *[(".".join(path), path, LENGTH_MAX, LENGTH_MAX + 0.1, {}) for path in CASE_LENGTHS if path not in NARROWER],
    # an outlet narrower than the silo is checked on validation: the widest accepted is just below the bound
    *[(".".join(path), path, LENGTH_MAX - 0.1, LENGTH_MAX + 0.1, {path[0]: {"width": LENGTH_MAX}})
      for path in NARROWER],
    *[(".".join(path), path, DURATION_MAX, DURATION_MAX + 0.1, {}) for path in CASE_DURATIONS],
    ("materials.hdpe.youngs_modulus", ("materials", "hdpe", "youngs_modulus"), 1e13, 1.01e13, {}),
    ("materials.hdpe.youngs_modulus", ("materials", "hdpe", "youngs_modulus"), 1e3, 990.0, {}),
    ("materials.hdpe.density", ("materials", "hdpe", "density"), 1e5, 1.01e5, {}),
    ("materials.hdpe.density", ("materials", "hdpe", "density"), 1.0, 0.99, {}),
    ("particle_models.sphere.spheres[0].radius", ("particle_models", "sphere", "spheres"), _sphere(radius=1.0),
     _sphere(radius=1.01), {}),
    ("particle_models.sphere.spheres[0].radius", ("particle_models", "sphere", "spheres"), _sphere(radius=1e-6),
     _sphere(radius=0.99e-6), {}),
    ("particle_models.sphere.spheres[0].position[0]", ("particle_models", "sphere", "spheres"),
     _sphere(position=(1.0, 0.0, 0.0)), _sphere(position=(1.01, 0.0, 0.0)), {}),
    ("particle_models.sphere.spheres[0].position[2]", ("particle_models", "sphere", "spheres"),
     _sphere(position=(0.0, 0.0, -1.0)), _sphere(position=(0.0, 0.0, -1.01)), {}),
    ("defaults.fill.bulk_density_estimate", ("defaults", "fill", "bulk_density_estimate"), 1e5, 1.01e5, {}),
    ("defaults.fill.bulk_density_estimate", ("defaults", "fill", "bulk_density_estimate"), 1.0, 0.99, {}),
    ("defaults.fill.insertion_velocity", ("defaults", "fill", "insertion_velocity"), 100, 100.1, {}),
    ("silo_recirculation.feeder_velocity", ("silo_recirculation", "feeder_velocity"), 100, 100.1, {}),
    ("silo_recirculation.feeder_velocity", ("silo_recirculation", "feeder_velocity"), 1e-3, 0.99e-3, {}),
    ("silo_recirculation.channel_density_ratio", ("silo_recirculation", "channel_density_ratio"), 0.1, 0.099, {}),
    ("silo_recirculation.recirculations", ("silo_recirculation", "recirculations"), 100, 100.1, {}),
    ("silo_recirculation.verification.recirculations", ("silo_recirculation", "verification", "recirculations"), 100,
     100.1, {}),
    ("silo_recirculation.residence_time_ratios.internal_flow",
     ("silo_recirculation", "residence_time_ratios", "internal_flow"), 100, 100.1, {}),
    ("blender.hopper_half_angle", ("blender", "hopper_half_angle"), 1.0, 0.99, {}),
    ("blender.gravity_factors[0]", ("blender", "gravity_factors"), [1000.0], [1000.1], {}),
    ("blender.gravity_factors[0]", ("blender", "gravity_factors"), [0.01], [0.0099], {}),
    ("jenike.shear.velocity", ("jenike", "shear", "velocity"), 100, 100.1, {}),
    ("jenike.shear.velocity", ("jenike", "shear", "velocity"), 1e-5, 0.99e-5, {}),
    ("jenike.sweep.shear_velocity_sensitivity[0]", ("jenike", "sweep", "shear_velocity_sensitivity"), [1e-5],
     [0.99e-5], {}),
    ("jenike.sweep.shear_velocity_sensitivity[0]", ("jenike", "sweep", "shear_velocity_sensitivity"), [100.0],
     [100.1], {}),
    ("jenike.fill.overfill", ("jenike", "fill", "overfill"), 1.0, 1.01, {}),
    ("estimates.seconds_per_sphere_step", ("estimates", "seconds_per_sphere_step"), 1e-3, 1.01e-3, {}),
    ("estimates.seconds_per_sphere_step_by_case.jenike", ("estimates", "seconds_per_sphere_step_by_case"),
     {"jenike": 1e-3}, {"jenike": 1.01e-3}, {}),
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
    with pytest.raises(ConfigError, match=r" is (less|greater) than the (minimum|maximum) of ") as caught:
        validate_config(_with(raw_default_config, path, beyond, extra))
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
    primes = engine_seeds(SEED_MAX + REPLICATES_MAX - 1, 3)
    # LIGGGHTS adds the MPI rank to a seed; the schema's description says 21 times below
    assert max(primes) + MPI_RANKS_MAX < PARK_MILLER_MAX / 20
    raw = copy.deepcopy(raw_default_config)
    for section in SECTIONS:
        raw.setdefault(section, {})["seed"] = SEED_MAX
    raw["defaults"].update(replicates=REPLICATES_MAX, reference_replicates=REPLICATES_MAX)
    raw["jenike"].setdefault("sweep", {})["reference_replicates"] = REPLICATES_MAX
    raw.setdefault("cross_engine", {})["seeds"] = REPLICATES_MAX
    config = validate_config(raw)
    cases = [case for kind in configured_kinds() for case in cases_of(config, kind).values()]
    cases += [case for runs in cross_engine_cases(config).values() for case in runs.values()]
    cases += [case for runs in cross_engine_jenike_cases(config).values() for _, case in runs.values()]
    assert len(cases) > 500  # about 800 runs
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
    # the schema bounds each value on its own; values within their bounds can still plan too many steps together, and
    # the step count refuses them: the stiffest material (1e13 Pa, a step of 1.6e-8 s) discharged for an hour
    raw = copy.deepcopy(raw_default_config)
    raw["materials"]["hdpe"]["youngs_modulus"] = 1e13
    raw["silo_flat"]["discharge_time"] = DURATION_MAX
    with pytest.raises(ValueError, match=r"3600.0 s at a time step of .* would take 2.2\de\+11 time steps.*2\^31 - 1"):
        build_silo_case(validate_config(raw))


#: The values the sweep gives each number of the default config in turn: beyond every bound, next to 0, negative.
EXTREMES = (1e300, 1e-300, -1e300)
#: The longest one outcome of the sweep may take before it counts as a hang (s): a hang, not a speed (a speed target
#: would belong in a benchmark, the machine's load moves it).
HANG_S = 10.0


class _Hang(BaseException):
    """Raised by the alarm of a configuration that takes :data:`HANG_S`; not an Exception, which code may catch."""


def _numeric_leaves(node, path: tuple = ()):
    """The path of every number of a configuration (booleans are no numbers here), depth first."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _numeric_leaves(value, (*path, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from _numeric_leaves(value, (*path, index))
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield path


def _hang(signum, frame):
    raise _Hang()


def test_no_number_of_the_default_config_at_an_extreme_overflows_the_planner(default_config):
    """Every number of the validated default config, set in turn to each of :data:`EXTREMES`, is accepted or refused
    with a ConfigError or a ValueError: never an OverflowError, ZeroDivisionError or other ArithmeticError, nor a hang
    (no outcome within :data:`HANG_S`; how fast an outcome comes is no test's business, it varies with the machine's
    load). Each configuration is validated, planned (:func:`siloflow.engines.planning.config_estimates`,
    which builds every case kind's runs with ``cases_of``) and its cross-engine check's runs are built. The sweep is
    the full one, all of the config's some 350 numbers (about 1050 configurations, 15 to 20 s on the busy 2-core
    development machine)."""
    paths = list(_numeric_leaves(default_config))
    assert len(paths) > 300  # the walk reached the nested sections and lists
    defects = []
    previous = signal.signal(signal.SIGALRM, _hang)
    try:
        for path in paths:
            for value in EXTREMES:
                config = copy.deepcopy(default_config)
                node = config
                for key in path[:-1]:
                    node = node[key]
                node[path[-1]] = value
                where = f"{'.'.join(map(str, path))} = {value:g}"
                signal.setitimer(signal.ITIMER_REAL, HANG_S)
                try:
                    planned = validate_config(config)
                    config_estimates(planned)
                    cross_engine_cases(planned)
                    cross_engine_jenike_cases(planned)
                except ValueError:  # a ConfigError (naming the key) or a case builder's refusal
                    pass
                except _Hang:
                    defects.append(f"{where}: no outcome within {HANG_S:g} s")
                except Exception as error:  # an OverflowError, ZeroDivisionError, ...: the defect
                    defects.append(f"{where}: {type(error).__name__}: {error}")
                finally:
                    signal.setitimer(signal.ITIMER_REAL, 0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert defects == []


#: Values within their bounds that do not fit together, each refused by a case builder naming the key:
#: (id, path, value, the case kind, what the message says).
MISFITS = [
    ("huge-cell", ("jenike", "cell", "inner_diameter"), LENGTH_MAX, "jenike",
     r"jenike.cell.inner_diameter \(100.0 m\) for spheres of radius 0.0015 m: a lid of radius 50 m .* up to 1.78e\+09 "
     r"spheres, more than the 1000000"),
    ("micrometre-spheres", ("particle_models", "sphere2", "spheres"),
     _sphere((-1e-6, 0.0, 0.0), 1e-6) + _sphere((1e-6, 0.0, 0.0), 1e-6), "jenike",
     r"jenike.cell.inner_diameter \(0.04 m\) for spheres of radius 1e-06 m: a lid .* more than the 1000000"),
    ("cell-narrower-than-a-clump", ("jenike", "cell", "inner_diameter"), 0.003, "jenike",
     r"jenike.cell.inner_diameter \(0.003 m\) is too small for clumps of bounding diameter 0.00375 m"),
    ("zone-lower-than-a-clump", ("defaults", "fill", "zone_height"), 0.003, "silo_flat",
     r"fill.zone_height \(0.003 m\) must exceed the clump's bounding diameter \(0.00375 m\)"),
    ("outlet-narrower-than-a-clump", ("silo_recirculation", "outlet_width"), 0.003, "silo_recirculation",
     r"^silo_recirculation.outlet_width \(0.003 m\) is narrower than one clump \(0.00375 m\)"),
]


@pytest.mark.parametrize("path, value, kind, message", [misfit[1:] for misfit in MISFITS],
                         ids=[misfit[0] for misfit in MISFITS])
def test_values_within_their_bounds_that_do_not_fit_together_are_refused_naming_the_key(
        raw_default_config, path, value, kind, message):
    config = validate_config(_with(raw_default_config, path, value, {}))
    with pytest.raises(ValueError, match=message):
        cases_of(config, kind)


def test_free_falls_and_polygons_stay_finite_where_a_difference_would_round_to_zero():
    # a fall of 1e-15 m at 100 m/s takes 1e-17 s, not the 0 s of (sqrt(v^2 + 2 g h) - v) / g
    assert free_fall_time(100.0, 1e-15, 9.81) == pytest.approx(1e-17, rel=1e-9)
    # 1 - s / R rounds to 1 below s / R = 1e-16: acos gives 0, which divided pi by zero
    assert segments_for_chord(50.0, 1e-8) == 157080  # the finest the schema's bounds allow (a 100 m cell, 1 um spheres)
    with pytest.raises(ValueError, match=r"needs 4.06e\+11 polygon sides, more than the 1000000"):
        segments_for_chord(5e17, 1.5e-5)


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
