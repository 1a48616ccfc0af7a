"""Loading and validating siloflow configuration.

The schema in ``siloflow/workflow/schemas/config.schema.yaml`` is the single source of truth: it declares every key
with a description and a default. Validation first lets the silo-type case sections (``silo_flat``,
``silo_recirculation``, ``blender``) inherit, leaf by leaf, every shared key they leave out from the ``defaults``
section (:data:`SHARED_KEYS`), then fills the schema's defaults (as Snakemake's ``validate`` does) and checks what a
JSON schema cannot express: that names refer to defined materials and particle models, that every material pair
a case brings into contact has contact parameters, and that a section's settling criterion is given once. Limits of
one engine (LIGGGHTS' restitution > 0.05) are not checked here but by that engine when it accepts a case
(:meth:`siloflow.engines.interface.Engine.check_case`).

Errors are reported as one :class:`ConfigError` naming the offending key, before any simulation starts.
"""

from __future__ import annotations

import copy
import difflib
import functools
import math
from pathlib import Path
from typing import Any, Iterable, Mapping

import jsonschema
import yaml

from siloflow.model.existing_run import ExistingRunError, ExistingSiloRun
from siloflow.model.cases.common import SETTLE_ENERGY_KEY, SETTLE_RATIO_KEY
from siloflow.model.cases.config_checks import ConfigError, require
from siloflow.model.cases.kinds import CASE_KINDS, configured_kinds
from siloflow.engines.config_yaml import ConfigFileError, read_config_file

#: The installed package's folder: the workflow, its schemas and the templates are package data under it.
PACKAGE_ROOT = Path(__file__).resolve().parent.parent
SCHEMA_PATH = PACKAGE_ROOT / "workflow" / "schemas" / "config.schema.yaml"


#: Keys a silo-type case section inherits from ``defaults`` when it leaves them out.
SHARED_KEYS = (
    "particle_model", "particle_material", "wall_materials", "fill", "settle", "timestep_fraction", "timestep_hertz_fraction",
    "seed", "replicates", "reference_replicates",
)
def inheriting_sections() -> tuple[str, ...]:
    """The case sections that inherit from ``defaults`` (their registry entries say so)."""
    return tuple(name for name, kind in CASE_KINDS.items() if kind.inherits_defaults)

#: Keys of earlier siloflow versions and where their values went: a config using one is refused with the new name.
RENAMED_KEYS = {
    ("blending",): "silo_recirculation",
    ("engine", "executable"): "engine.liggghts.executable",
    ("blender", "timestep_fraction"): None,  # only its null ("take silo_flat's") is gone
}
#: Keys of earlier siloflow versions replaced by a key of another unit: a config using one is refused with what to
#: set instead.
REPLACED_KEYS = {
    ("blender", "settle_threshold"): (
        "blender.settle_kinetic_energy_ratio", "the mean kinetic energy per clump over the clump's m g d (-); 1.7e-2 "
        "is about the 1e-8 J of the sphere2 clump of hdpe at 1 g",
    ),
}
#: Settings given by either of two keys of a case section's mapping, one at most: a section that sets one inherits
#: neither from ``defaults`` (a silo that sets an absolute settle threshold drops the ratio of ``defaults``).
ALTERNATIVE_KEYS = {"settle": (SETTLE_RATIO_KEY, SETTLE_ENERGY_KEY)}
#: The sections whose ``settle`` criterion is used: the blender settles to its own ``settle_kinetic_energy_ratio``.
SETTLE_CRITERION_SECTIONS = ("defaults", "silo_flat", "silo_recirculation")


def _deep_merge(base: Mapping, override: Mapping) -> dict:
    """``override`` over ``base``, leaf by leaf (mappings merge, every other value replaces)."""
    merged = copy.deepcopy(dict(base))
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = _deep_merge(merged[key], value)
        else:
            merged[key] = copy.deepcopy(value)
    return merged


def inherit_defaults(config: Mapping) -> dict:
    """A copy of ``config`` in which each silo-type case section carries the shared keys of ``defaults`` it leaves
    out (leaf by leaf: a section that sets only ``fill.insertion_velocity`` keeps the other fill keys of
    ``defaults``). Applied to the raw configuration, before the schema fills its defaults."""
    inherited = copy.deepcopy(dict(config))
    defaults = inherited.get("defaults") or {}
    if not isinstance(defaults, Mapping):
        return inherited  # the schema reports the wrong type
    shared = {key: value for key, value in defaults.items() if key in SHARED_KEYS}
    for section in inheriting_sections():
        own = inherited.get(section)
        if own is None:
            own = {}
        if isinstance(own, Mapping):
            inherited[section] = _deep_merge(shared, own)
            _drop_inherited_alternatives(inherited[section], own)
    return inherited


def _drop_inherited_alternatives(merged: dict, own: Mapping) -> None:
    """Where the section's own mapping sets one of :data:`ALTERNATIVE_KEYS` (not null), drop the others it
    inherited from ``defaults``."""
    for key, alternatives in ALTERNATIVE_KEYS.items():
        given = own.get(key)
        if not (isinstance(given, Mapping) and isinstance(merged.get(key), dict)):
            continue
        if any(given.get(name) is not None for name in alternatives):
            for name in alternatives:
                if name not in given:
                    merged[key].pop(name, None)


def _check_renamed(config: Mapping) -> None:
    for path, new in RENAMED_KEYS.items():
        node = config
        for part in path[:-1]:
            node = node.get(part) if isinstance(node, Mapping) else None
        if not (isinstance(node, Mapping) and path[-1] in node):
            continue
        old = ".".join(path)
        if new is None:
            if node[path[-1]] is None:
                raise ConfigError(f"config key '{old}': null is no longer accepted; leave the key out to inherit "
                                  "defaults.timestep_fraction")
            continue
        raise ConfigError(f"config key '{old}' was renamed '{new}'; rename it in your config file")
    for path, (new, meaning) in REPLACED_KEYS.items():
        node = config
        for part in path[:-1]:
            node = node.get(part) if isinstance(node, Mapping) else None
        if isinstance(node, Mapping) and path[-1] in node:
            raise ConfigError(f"config key '{'.'.join(path)}' was replaced by '{new}', {meaning}; set that instead")


#: PyYAML's C loader where libyaml is there (Debian's python3-yaml and the PyPI wheels have it): the schema is
#: 1,800 lines, which the pure-Python loader takes a quarter of a second to read.
SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


@functools.lru_cache(maxsize=8)
def _parsed_schema(path: Path, modified_ns: int) -> dict:
    # keyed by the file's modification time, so that an edited schema is read again
    with open(path, encoding="utf-8") as handle:
        return yaml.load(handle, Loader=SAFE_LOADER)


def load_schema(path: Path = SCHEMA_PATH) -> dict:
    """Read the configuration JSON schema (YAML syntax): parsed once per process and file version, a fresh copy
    for each caller. Every validation reads it, and parsing it every time took most of a validation's half second.
    """
    path = Path(path)
    return _with_case_kinds(copy.deepcopy(_parsed_schema(path, path.stat().st_mtime_ns)))


def _with_case_kinds(schema: dict) -> dict:
    """``schema`` with each registered case kind's section (its schema fragment, :mod:`siloflow.model.cases.kinds`) among its
    properties, right after ``defaults`` (the order a configuration's sections are listed in), and the kinds' names
    where the schema keys a mapping by case kind."""
    properties = {}
    for key, value in schema["properties"].items():
        properties[key] = value
        if key == "defaults":
            for name, kind in CASE_KINDS.items():
                if kind.schema is not None:
                    fragment = Path(kind.schema)
                    properties[name] = copy.deepcopy(_parsed_schema(fragment, fragment.stat().st_mtime_ns))
    schema["properties"] = properties
    by_case = properties["estimates"]["properties"]["seconds_per_sphere_step_by_case"]
    by_case["propertyNames"] = {"enum": list(configured_kinds())}
    return schema


def load_config_file(path: str | Path) -> dict:
    """Read a YAML configuration file into a dict as plain data (:func:`siloflow.engines.config_yaml.read_config_file`; no
    validation against the schema).

    Raises
    ------
    ConfigError
        Naming the file and the key or line, for what :func:`siloflow.engines.config_yaml.read_config_file` refuses.
    """
    try:
        return read_config_file(path)
    except ConfigFileError as error:
        raise ConfigError(str(error)) from None


def layered_config(paths: Iterable[str | Path]) -> dict:
    """Configuration files read as plain data (:func:`load_config_file`) and layered in order, as Snakemake layers
    ``--configfile A B``: a later file's mappings merge key by key into the earlier ones', its other values replace
    theirs. Not validated.

    Raises
    ------
    ConfigError
        Naming the file and the key or line a file is refused for.
    """
    layered: dict = {}
    for path in paths:
        layered = _deep_merge(layered, load_config_file(path))
    return layered


def _with_defaults(validator_class, definitions: Mapping):
    """Extend a jsonschema validator so that ``properties`` fills in declared defaults (also those of a
    ``#/definitions/...`` reference, which the shared case keys use)."""
    validate_properties = validator_class.VALIDATORS["properties"]

    def set_defaults(validator, properties, instance, schema):
        if isinstance(instance, dict):
            for name, subschema in properties.items():
                holder = subschema
                reference = subschema.get("$ref", "")
                if "default" not in subschema and reference.startswith("#/definitions/"):
                    holder = definitions[reference.rsplit("/", 1)[1]]
                if name not in instance and "default" in holder:
                    instance[name] = copy.deepcopy(holder["default"])
        yield from validate_properties(validator, properties, instance, schema)

    return jsonschema.validators.extend(validator_class, {"properties": set_defaults})




def _key_path(path: Iterable[Any]) -> str:
    parts = []
    for element in path:
        if isinstance(element, int):
            parts.append(f"[{element}]")
        else:
            parts.append(("." if parts else "") + str(element))
    return "".join(parts) or "<top level>"


def _describe(error: jsonschema.ValidationError) -> str:
    key = _key_path(error.absolute_path)
    value = error.instance
    message = error.message
    if error.validator == "additionalProperties" and isinstance(value, Mapping):
        return _unknown_key(error.absolute_path, value, error.schema)
    if error.validator == "type" and isinstance(value, str):
        try:
            float(value)
        except ValueError:
            pass
        else:
            message += f" (YAML reads '{value}' as a string: write the exponent with a sign, e.g. 5.0e+6)"
    description = error.schema.get("description") if isinstance(error.schema, dict) else None
    if description is None and len(error.relative_schema_path) > 1:
        parent = error.parent
        description = parent.schema.get("description") if parent is not None else None
    suffix = f" [{description.strip()}]" if description else ""
    return f"config key '{key}': {message}{suffix}"


def _unknown_key(path: Iterable[Any], given: Mapping, schema: Mapping) -> str:
    """The message of a key the schema does not declare in the mapping at ``path``: the key in full, the declared
    key nearest in spelling (difflib's ratio of at least 0.6, a transposition or a letter or two away) and the keys
    that mapping takes."""
    known = sorted(schema.get("properties", {}))
    unknown = sorted(str(name) for name in given if name not in known)[0]
    key = _key_path([*path, unknown])
    nearest = difflib.get_close_matches(unknown, known, n=1, cutoff=0.6)
    hint = f"did you mean '{_key_path([*path, nearest[0]])}'? " if nearest else ""
    keys = ", ".join(known) if len(known) <= 20 else f"{', '.join(known[:20])}, ... ({len(known)} in all)"
    return f"config key '{key}' is not a siloflow setting: {hint}the keys here are {keys or 'none'}"


def _is_given(raw: Any, path: Iterable[Any]) -> bool:
    """Whether the configuration as the user gave it holds the key at ``path`` (not only inherited or filled)."""
    node = raw
    for element in path:
        if isinstance(node, Mapping) and element in node:
            node = node[element]
        elif isinstance(node, list) and isinstance(element, int) and 0 <= element < len(node):
            node = node[element]
        else:
            return False
    return True


def _error_rank(raw: Mapping):
    """Sort key of schema errors, the one to report first: the deepest (the most specific, e.g. the friction value
    rather than its parent object), and among those one at a key the user gave: a bad ``defaults.seed`` is reported
    there, not at the ``blender.seed`` that inherited it."""
    def rank(error: jsonschema.ValidationError):
        path = list(error.absolute_path)
        return (-len(path), not _is_given(raw, path), str(path))
    return rank


def validate_config(config: Mapping[str, Any], schema: dict | None = None) -> dict:
    """Validate a configuration and fill in defaults.

    Parameters
    ----------
    config : mapping
        The raw configuration (as read from YAML or as Snakemake's ``config``).
    schema : dict, optional
        The JSON schema; defaults to ``siloflow/workflow/schemas/config.schema.yaml``.

    Returns
    -------
    dict
        A new dict with every default filled in.

    Raises
    ------
    ConfigError
        One message naming the first offending key.
    """
    schema = load_schema() if schema is None else schema
    _check_renamed(config)
    filled = inherit_defaults(config)
    # What the user set, before the schema fills its defaults (a filled default is no choice of theirs).
    given = copy.deepcopy(filled)
    validator = _with_defaults(jsonschema.Draft7Validator, schema.get("definitions", {}))(schema)
    errors = sorted(validator.iter_errors(filled), key=_error_rank(config))
    if errors:
        best = errors[0]
        # oneOf/anyOf wrap the real reason; report the most relevant inner error.
        if best.context:
            best = jsonschema.exceptions.best_match(best.context) or best
        raise ConfigError(_describe(best))
    _check_finite(filled, ())
    _check_references(filled)
    _check_engine_settings(config, filled)
    _check_settle_criteria(config, given)
    _settle_criteria_in_use(filled)
    existing_silo_runs(filled)
    return filled


#: Where the flat-bottom silo runs siloflow did not make are configured.
EXISTING_RUNS_KEY = "silo_flat.existing_runs"


def existing_silo_runs(config: Mapping) -> dict[str, ExistingSiloRun]:
    """The flat-bottom silo runs siloflow did not make (``silo_flat.existing_runs``) of a validated configuration.

    Only the description is checked here (required keys given, the opening given once, the outlet narrower than the
    silo); :func:`siloflow.engines.existing_runs.check_existing_runs` checks the folders and their dumps.

    Returns
    -------
    dict of str to ExistingSiloRun
        By name, in the configuration's order.

    Raises
    ------
    ConfigError
        Naming the key, e.g. ``config key 'silo_flat.existing_runs.mine.width': required: ...``.
    """
    runs = {}
    for name, section in config["silo_flat"]["existing_runs"].items():
        try:
            runs[name] = ExistingSiloRun.from_config(name, section)
        except ExistingRunError as error:
            key = f"{EXISTING_RUNS_KEY}.{name}" + ("" if error.key == "name" else f".{error.key}")
            raise ConfigError(f"config key '{key}': {error.reason}") from None
    return runs


def _check_settle_criteria(raw: Mapping, given: Mapping) -> None:
    """Refuse a settle criterion given twice (a ratio and an absolute threshold, in one section or in ``defaults``
    for a section that sets neither) or given to the blender's ``settle``, which does not use it.

    ``raw`` is the configuration as given, ``given`` the same after inheritance from ``defaults``, before the
    schema's defaults."""
    ratio, energy = ALTERNATIVE_KEYS["settle"]
    for section in SETTLE_CRITERION_SECTIONS:
        settle = (given.get(section) or {}).get("settle") or {}
        if settle.get(ratio) is not None and settle.get(energy) is not None:
            raise ConfigError(
                f"config keys '{section}.settle.{ratio}' and '{section}.settle.{energy}' are both set; set one: the "
                f"ratio of the kinetic energy per clump to the clump's m g d (-), or an absolute threshold (J)"
            )
        if ratio in settle and settle[ratio] is None and settle.get(energy) is None:
            raise ConfigError(
                f"config key '{section}.settle.{ratio}': null needs {section}.settle.{energy} (J); set one of them"
            )
    blender_settle = (raw.get("blender") or {}).get("settle") or {}
    for name in (ratio, energy):
        if blender_settle.get(name) is not None:
            raise ConfigError(
                f"config key 'blender.settle.{name}': the blender settles to blender.settle_kinetic_energy_ratio; "
                "set that instead"
            )


#: The case sections, each run by its own ``engine`` or by ``engine.kind``.
#: Settings of one engine only: ``engine.<kind>.*``, and the MPI keys, which only LIGGGHTS uses.
ENGINE_ONLY_KEYS = {"liggghts": (("engine", "mpi_ranks"), ("engine", "mpirun")), "yade": ()}


def engines_in_use(filled: Mapping) -> set[str]:
    """The engines that run at least one case section of a validated configuration."""
    return {filled[section].get("engine") or filled["engine"]["kind"] for section in configured_kinds()}


def _engine_defaults() -> dict:
    """The schema's defaults of the ``engine`` section, each engine's settings one level down."""
    section = load_schema()["properties"]["engine"]["properties"]
    return {key: ({name: spec.get("default") for name, spec in value.get("properties", {}).items()}
                  if value.get("type") == "object" else value.get("default"))
            for key, value in section.items()}


def _check_engine_settings(raw: Mapping, filled: Mapping) -> None:
    """Refuse a setting the user gave for an engine that runs no case: ``engine.<kind>.*`` or an MPI key of
    LIGGGHTS' (it would be silently ignored)."""
    used = engines_in_use(filled)
    given = raw.get("engine") or {}
    defaults = _engine_defaults()
    for kind, only in ENGINE_ONLY_KEYS.items():
        if kind in used:
            continue
        # a value equal to its default changes nothing (and a validated configuration carries every default)
        own = given.get(kind) or {}
        keys = [f"engine.{kind}.{key}" for key in sorted(own) if own[key] != defaults[kind].get(key)]
        keys += [".".join(path) for path in only if path[1] in given and given[path[1]] != defaults[path[1]]]
        if keys:
            runs = ", ".join(sorted(used))
            raise ConfigError(
                f"config key '{keys[0]}' is a {kind} setting, but no case runs on {kind} (the cases run on {runs}: "
                f"engine.kind and the sections' 'engine'); remove it, or run a case on {kind}"
            )


def _check_finite(node: Any, path: tuple) -> None:
    if isinstance(node, dict):
        for key, value in node.items():
            _check_finite(value, path + (key,))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            _check_finite(value, path + (index,))
    elif isinstance(node, float) and not math.isfinite(node):
        raise ConfigError(f"config key '{_key_path(path)}': {node} is not a finite number")


def _check_references(config: dict) -> None:
    materials = config["materials"]

    for index, contact in enumerate(config["contacts"]):
        for material in contact["materials"]:
            require(material, materials, f"contacts[{index}].materials", "material")
    seen: dict[frozenset, int] = {}
    for index, contact in enumerate(config["contacts"]):
        pair = frozenset(contact["materials"])
        if pair in seen:
            raise ConfigError(
                f"config key 'contacts[{index}]': material pair {sorted(pair)} is already defined "
                f"in contacts[{seen[pair]}]"
            )
        seen[pair] = index

    for section in ("defaults", *inheriting_sections()):
        _check_case_materials(config, section, seen)
    for section in inheriting_sections():
        _check_outlet(config[section], section)
    _check_bayesian(config)
    for kind in CASE_KINDS.values():
        if kind.check_config is not None:
            kind.check_config(config, seen)


def _check_bayesian(config: Mapping) -> None:
    """The Bayesian calibration's priors have a box with their mean inside, both or neither of mean and sd; each of
    its targets has a standard error; its walkers are at least twice its parameters; its budget holds the first
    design, its replicates and the predictive draws; its engines are engines siloflow has."""
    settings = config["calibration"]["bayesian"]
    key = "calibration.bayesian"
    for name, prior in settings["priors"].items():
        if not prior["lower"] < prior["upper"]:
            raise ConfigError(f"config key '{key}.priors.{name}': lower ({prior['lower']}) must be below upper "
                              f"({prior['upper']})")
        if (prior["mean"] is None) != (prior["sd"] is None):
            raise ConfigError(f"config key '{key}.priors.{name}': give both mean and sd (a Gaussian prior) or neither "
                              "(a uniform one)")
        if prior["mean"] is not None and not prior["lower"] <= prior["mean"] <= prior["upper"]:
            raise ConfigError(f"config key '{key}.priors.{name}.mean': {prior['mean']} lies outside the bounds "
                              f"[{prior['lower']}, {prior['upper']}]")
    used = [test for test in config["calibration"]["targets_deg"] if test in config["jenike"]["sweep"]["tests"]]
    missing = [test for test in used if test not in config["calibration"]["target_sd_deg"]]
    if missing:
        raise ConfigError(f"config key 'calibration.target_sd_deg': no standard error for the target(s) "
                          f"{', '.join(missing)}, which the Bayesian calibration fits (calibration.targets_deg); give "
                          "each the standard error of its measured mean (deg)")
    walls = [test for test in used if test != "internal"]
    held = settings["fixed"]
    parameters = ((held["sliding_friction"] is None) + (held["rolling_friction"] is None)
                  + (len(walls) if held["wall_sliding_friction"] is None else 0))
    if parameters == 0:
        raise ConfigError(f"config key '{key}.fixed': every parameter is held fixed; leave at least one to calibrate")
    if settings["walkers"] < 2 * parameters:
        raise ConfigError(f"config key '{key}.walkers': {settings['walkers']} walkers for {parameters} parameters; "
                          f"the ensemble sampler needs at least {2 * parameters}")
    silo_engine = config["silo_flat"].get("engine") or config["engine"]["kind"]
    if config["silo_flat"]["parameters"] == "bayesian" and silo_engine not in settings["engines"]:
        raise ConfigError(f"config key 'silo_flat.parameters': bayesian takes the posterior on the silo's engine "
                          f"({silo_engine}), which {key}.engines {settings['engines']} does not calibrate")
    if config["silo_flat"]["posterior_draws"] and config["silo_flat"]["parameters"] != "bayesian":
        raise ConfigError("config key 'silo_flat.posterior_draws': the silo runs at posterior draws only with "
                          f"silo_flat.parameters: bayesian (it is {config['silo_flat']['parameters']!r})")
    least = settings["initial_sets"] + settings["replicates"] - 1 + settings["predictive_draws"]
    if settings["max_sets"] < least:
        raise ConfigError(f"config key '{key}.max_sets': {settings['max_sets']} parameter sets cannot hold the first "
                          f"design ({settings['initial_sets']}), its replicates ({settings['replicates'] - 1} more) and "
                          f"the predictive draws ({settings['predictive_draws']}): at least {least}")


def _check_outlet(silo: Mapping, section: str) -> None:
    """A silo-type section's slot outlet is narrower than its silo: checked here only, for every such section."""
    if silo["outlet_width"] >= silo["width"]:
        raise ConfigError(f"config key '{section}.outlet_width': {silo['outlet_width']} m must be smaller than "
                          f"{section}.width ({silo['width']} m)")


def _check_case_materials(config: dict, section: str, contact_pairs: dict) -> None:
    """The particle model, particle material and wall materials of a silo-type section exist, the particle
    material has a density and every particle-wall pair it uses has contact parameters."""
    case = config[section]
    materials = config["materials"]
    require(case["particle_model"], config["particle_models"], f"{section}.particle_model", "particle model")
    require(case["particle_material"], materials, f"{section}.particle_material", "material")
    for wall, material in case["wall_materials"].items():
        require(material, materials, f"{section}.wall_materials.{wall}", "material")
    particle_material = case["particle_material"]
    if "density" not in materials[particle_material]:
        raise ConfigError(
            f"config key 'materials.{particle_material}.density': the particle material needs a density"
        )
    for material in sorted({particle_material, *case["wall_materials"].values()}):
        if frozenset((particle_material, material)) not in contact_pairs:
            raise ConfigError(
                f"config key 'contacts': no contact parameters for the pair "
                f"[{particle_material}, {material}] used by {section}"
            )


def _settle_criteria_in_use(filled: dict) -> None:
    """Null, in a validated configuration, the settle keys that are not in use: the ratio of a section with an
    absolute threshold, both in the blender's ``settle``. The schema fills the ratio's default wherever it is left
    out; nulled, a validated configuration validates again as it is."""
    ratio, energy = ALTERNATIVE_KEYS["settle"]
    for section in SETTLE_CRITERION_SECTIONS:
        settle = filled[section]["settle"]
        if settle[energy] is not None:
            settle[ratio] = None
    filled["blender"]["settle"].update({ratio: None, energy: None})


def load_config(path: str | Path) -> dict:
    """Read and validate a configuration file (defaults filled)."""
    data = load_config_file(path)  # its errors name the file already
    try:
        return validate_config(data)
    except ConfigError as error:
        raise ConfigError(f"{path}: {error}") from None
