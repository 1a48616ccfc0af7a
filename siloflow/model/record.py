"""The run record: what every engine writes when a run has finished and passed its checks (``run.json``).

One record per run directory, written last and atomically by the engine, so its presence means the run is
complete and checked; every analysis step reads it instead of the engine's own files. The record is engine-neutral:
it names the engine that made the run, never that engine's file names or formats (the engine reads those back
itself, through the engine interface).

Keys (version 1; SI units; times are simulated times since the start of the run)
-------------------------------------------------------------------------------
schema_version : int
    Version of this layout (:data:`SCHEMA_VERSION`); a reader refuses other versions.
engine : str
    Registry name of the engine that ran the case (``liggghts``).
case : str
    Case kind: a registered kind's name (:data:`siloflow.model.cases.kinds.CASE_KINDS`: ``jenike``, ``silo_flat``,
    ``silo_recirculation``, ``blender``, ``verification``).
run_id : str
    Run directory name: a label plus a hash of every parameter that defines the run, engine included.
timestep_s : float
    Integration time step (s).
n_clumps : int
    Clumps in the run after filling (Jenike: after levelling).
n_frames : int
    Particle frames the run saved.
mpi_ranks : int
    MPI ranks the engine ran on.
resumed_attempts : int
    How often a killed run was resumed from a restart file.
output_bytes : int
    Everything the run wrote (B).
stages : dict
    Stage name -> values at its end (``step``, ``time`` in s, ``clumps``, ``ke_per_clump`` in J, and what else the
    engine reports there), in the order the stages ran.
settle_checks : list of dict
    The settle-loop checks (same keys as a stage), in order; empty for cases that do not settle in a loop.
open_step, open_time_s : int or None, float or None
    Step and time at which the outlet opened (silo-type cases).
domain_z : list of float or None
    Lower and upper z of the simulation domain (m): the periodic extent of the recirculating cases.
outlet_z : float or None
    Height of the outlet plane (m).
labels : dict
    Case-specific descriptors (str or float): e.g. ``flow_pattern``, ``role``, ``estimated_residence_time_s``
    (recirculating silo); ``configuration``, ``gravity_factor``, ``mode`` (blender); ``consolidation_start_s``,
    ``shear_start_s``, ``shear_end_s``, ``n_clumps_created``, ``force_samples`` (Jenike cell).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import jsonschema

from siloflow.model.cases.kinds import CASE_KINDS

__all__ = ["SCHEMA_VERSION", "RUN_RECORD_SCHEMA", "RunRecord", "RunRecordError", "read_run_record"]

#: Version of the record layout written by this siloflow; bump it when a key changes meaning.
SCHEMA_VERSION = 1

_NUMBER = {"type": "number"}
_STAGE = {"type": "object", "additionalProperties": {"type": ["number", "string"]}}

#: JSON schema of ``run.json`` (draft 7); :meth:`RunRecord.from_dict` validates against it.
RUN_RECORD_SCHEMA = {
    "$schema": "http://json-schema.org/draft-07/schema#",
    "title": "siloflow run record",
    "type": "object",
    "additionalProperties": False,
    "required": ["schema_version", "engine", "case", "run_id", "timestep_s", "n_clumps", "n_frames", "mpi_ranks",
                 "resumed_attempts", "output_bytes", "stages"],
    "properties": {
        "schema_version": {"const": SCHEMA_VERSION},
        "engine": {"type": "string", "pattern": "^[a-z][a-z0-9_]*$(?!\\n)"},
        # one of the registered case kinds (siloflow.model.cases.kinds), checked after the schema
        "case": {"type": "string", "pattern": "^[a-z][a-z0-9_]*$(?!\\n)"},
        "run_id": {"type": "string", "pattern": "^[A-Za-z0-9_.=,+-]+$(?!\\n)"},
        "timestep_s": {"type": "number", "exclusiveMinimum": 0},
        "n_clumps": {"type": "integer", "minimum": 0},
        "n_frames": {"type": "integer", "minimum": 0},
        "mpi_ranks": {"type": "integer", "minimum": 1},
        "resumed_attempts": {"type": "integer", "minimum": 0},
        "output_bytes": {"type": "integer", "minimum": 0},
        "stages": {"type": "object", "additionalProperties": _STAGE},
        "settle_checks": {"type": "array", "items": _STAGE},
        "open_step": {"type": ["integer", "null"], "minimum": 0},
        "open_time_s": {"type": ["number", "null"]},
        "domain_z": {"oneOf": [{"type": "null"}, {"type": "array", "items": _NUMBER, "minItems": 2, "maxItems": 2}]},
        "outlet_z": {"type": ["number", "null"]},
        "labels": {"type": "object", "additionalProperties": {"type": ["number", "string"]}},
    },
}


class RunRecordError(ValueError):
    """A run record does not follow :data:`RUN_RECORD_SCHEMA`; the message names the file and the key."""


@dataclass(frozen=True)
class RunRecord:
    """A finished, checked run (see the module docstring for every key and its unit)."""

    engine: str
    case: str
    run_id: str
    timestep_s: float
    n_clumps: int
    n_frames: int
    mpi_ranks: int
    stages: dict
    resumed_attempts: int = 0
    output_bytes: int = 0
    settle_checks: list = field(default_factory=list)
    open_step: int | None = None
    open_time_s: float | None = None
    domain_z: list | None = None
    outlet_z: float | None = None
    labels: dict = field(default_factory=dict)
    schema_version: int = SCHEMA_VERSION

    def __post_init__(self) -> None:
        # Validate on construction, so an engine can never write a record a reader would refuse.
        _validate(self.to_dict(), "run record")

    def stage(self, name: str) -> dict:
        """The values at the end of stage ``name``; the error lists the stages the run has."""
        if name not in self.stages:
            raise KeyError(f"run {self.run_id} has no stage {name!r}; it has {', '.join(self.stages) or 'none'}")
        return self.stages[name]

    def to_dict(self) -> dict:
        """Plain data for JSON (numbers as float/int, no numpy types)."""
        return json.loads(json.dumps(asdict(self), default=_plain))

    def to_json(self) -> str:
        """The record as indented JSON text with sorted keys."""
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict, source: str = "run record") -> "RunRecord":
        """Validate ``data`` against :data:`RUN_RECORD_SCHEMA` and build the record.

        Raises
        ------
        RunRecordError
            Naming ``source`` and the first offending key.
        """
        _validate(data, source)
        return cls(**data)


def _plain(value):
    if hasattr(value, "item"):  # numpy scalars
        return value.item()
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {value!r}")


def _validate(data: dict, source: str) -> None:
    errors = sorted(jsonschema.Draft7Validator(RUN_RECORD_SCHEMA).iter_errors(data), key=lambda e: list(e.path))
    if errors:
        error = errors[0]
        key = ".".join(str(part) for part in error.absolute_path) or "<top level>"
        raise RunRecordError(f"{source}: key '{key}': {error.message}")
    if data["case"] not in CASE_KINDS:
        raise RunRecordError(f"{source}: key 'case': not a case kind siloflow knows; the kinds are "
                             f"{', '.join(CASE_KINDS)}")
    for key in ("timestep_s", "open_time_s", "outlet_z"):
        value = data.get(key)
        if isinstance(value, float) and not math.isfinite(value):
            raise RunRecordError(f"{source}: key '{key}': {value} is not a finite number")


def read_run_record(path: str | Path) -> RunRecord:
    """Read and validate ``run.json``.

    Raises
    ------
    FileNotFoundError
        When the run has no record (it has not finished, or failed a check).
    RunRecordError
        When the record is not valid JSON or does not follow the schema (e.g. written by an older siloflow).
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as error:
        raise RunRecordError(f"{path}: not valid JSON ({error})") from None
    if not isinstance(data, dict):
        raise RunRecordError(f"{path}: the top level must be an object")
    return RunRecord.from_dict(data, str(path))
