"""A case kind is defined once: registering a minimal kind from this test (its case, builder, schema fragment, cost
model and one LIGGGHTS adapter) is all it takes for the configuration, the runs, the results layout, the estimates,
the run record and the engine to know it."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import pytest

from siloflow.engines.config import ConfigError, load_schema, validate_config
from siloflow.engines.estimates import estimate_case
from siloflow.engines.interface import CaseNotSupported, engine_for
from siloflow.engines.layout import case_root, run_path
from siloflow.engines.liggghts.engine import ADAPTERS, Adapter, LiggghtsEngine
from siloflow.engines.planning import config_estimates
from siloflow.model.cases import cases_of, reference_runs, run_roles
from siloflow.model.cases.common import run_id
from siloflow.model.cases.config_checks import ConfigError as ModelConfigError
from siloflow.model.cases.kinds import CASE_KINDS, CaseKind, case_kind, configured_kinds, kind_of_case, register_case_kind
from siloflow.model.cases.stages import Stage
from siloflow.model.cost import CostModel, estimate_run
from siloflow.model.record import RunRecord, RunRecordError

FRAGMENT = """\
description: A box of clumps poured and left to settle (a test's case kind).
type: object
additionalProperties: false
default: {}
properties:
  height:
    description: Fill height (m).
    type: number
    exclusiveMinimum: 0
    default: 0.1
  heights:
    description: Further fill heights, one run each (m).
    type: array
    items: {type: number, exclusiveMinimum: 0}
    default: []
  seed:
    description: Random seed of the pour.
    type: integer
    minimum: 1
    default: 7
  replicates:
    description: Runs of every configuration, with seeds seed, seed + 1, ...
    type: integer
    minimum: 1
    default: 1
"""


@dataclass(frozen=True)
class BoxCase:
    """The test kind's case: one fill height, one seed."""

    height: float
    seed: int

    @property
    def run_id(self) -> str:
        return run_id("box", {"height": self.height, "seed": self.seed})

    def stages(self) -> tuple[Stage, ...]:
        return (Stage("fill"), Stage("settle"))


def build_boxes(config) -> dict:
    box = config["box"]
    cases = [BoxCase(height, box["seed"]) for height in (box["height"], *box["heights"])]
    return {case.run_id: case for case in cases}


def check_box(config, contact_pairs) -> None:
    if config["box"]["height"] in config["box"]["heights"]:
        raise ModelConfigError("config key 'box.heights': repeats box.height")


def estimate_box(case: BoxCase, mpi_ranks: int = 1, model: CostModel = CostModel()):
    return estimate_run(case.run_id, "box", clumps=100, spheres_per_clump=2, steps=1000, timestep=1e-5,
                        dump_frames=0, mpi_ranks=mpi_ranks, model=model)


def write_box(case: BoxCase, deck: Path) -> None:
    deck.mkdir(parents=True, exist_ok=True)
    (deck / "case.json").write_text(json.dumps({"run_id": case.run_id, "height_m": case.height}))


@pytest.fixture
def box_kind(tmp_path, monkeypatch):
    """The test kind, registered for one test: one registry line, one LIGGGHTS adapter line."""
    fragment = tmp_path / "box.schema.yaml"
    fragment.write_text(FRAGMENT)
    kind = register_case_kind(CaseKind("box", BoxCase, "boxes", ("fill", "settle"), build_boxes, estimate_box,
                                       fragment, replicated=True, check_config=check_box))
    monkeypatch.setitem(ADAPTERS, "box", Adapter(write_box, None, lambda case: []))
    yield kind
    CASE_KINDS.pop("box")


def test_the_registry_holds_the_kinds_siloflow_runs():
    assert list(CASE_KINDS) == ["jenike", "silo_flat", "silo_recirculation", "blender", "verification"]
    assert configured_kinds() == ("jenike", "silo_flat", "silo_recirculation", "blender")
    assert [name for name, kind in CASE_KINDS.items() if kind.inherits_defaults] == [
        "silo_flat", "silo_recirculation", "blender"]
    assert all(kind.schema.is_file() for kind in CASE_KINDS.values() if kind.schema is not None)
    with pytest.raises(KeyError, match="unknown case 'hopper'; the cases are jenike, silo_flat, "):
        case_kind("hopper")


def test_a_kind_registered_from_a_test_is_known_everywhere(box_kind, tmp_path):
    # the configuration: its section from its schema fragment, with defaults, unknown keys named, its own check
    assert load_schema()["properties"]["box"]["properties"]["height"]["default"] == 0.1
    config = validate_config({"box": {"heights": [0.2]}})
    assert config["box"] == {"height": 0.1, "heights": [0.2], "seed": 7, "replicates": 1}
    with pytest.raises(ConfigError, match=r"config key 'box.heigth' is not a siloflow setting: did you mean "
                                          r"'box.height'\?"):
        validate_config({"box": {"heigth": 0.2}})
    with pytest.raises(ConfigError, match=r"^config key 'box.heights': repeats box.height$"):
        validate_config({"box": {"heights": [0.1]}})
    assert "box" in configured_kinds()

    # the runs, their replicates and roles
    runs = cases_of(config, "box")
    assert [(case.height, case.seed) for case in runs.values()] == [(0.1, 7), (0.2, 7)]
    replicated = cases_of(validate_config({"box": {"replicates": 2}}), "box")
    assert sorted(case.seed for case in replicated.values()) == [7, 8]
    first = BoxCase(0.1, 7).run_id
    assert reference_runs(config, "box") == [first]
    assert run_roles(config, "box") == {first: "reference", BoxCase(0.2, 7).run_id: "variant"}

    # the results layout, the estimates, the run record
    assert case_root("box") == "results/boxes"
    assert run_path("box", "metrics/x.csv", "b-1") == "results/boxes/b-1/metrics/x.csv"
    estimate = estimate_case(runs[first])
    assert (estimate.kind, estimate.sphere_steps) == ("box", 200_000.0)
    assert {e.run_id for e in config_estimates(config) if e.kind == "box"} == set(runs)
    assert kind_of_case(runs[first]) is box_kind
    record = {"schema_version": 1, "engine": "liggghts", "case": "box", "run_id": first, "timestep_s": 1e-5,
              "n_clumps": 100, "n_frames": 0, "mpi_ranks": 1, "resumed_attempts": 0, "output_bytes": 0, "stages": {}}
    assert RunRecord.from_dict(record).case == "box"

    # the engine: its adapter writes the deck, the stages are the entry's
    engine = engine_for(config, "box")
    assert isinstance(engine, LiggghtsEngine)
    summary = engine.write_inputs(runs[first], tmp_path / "run")
    assert json.loads(summary.read_text()) == {"run_id": first, "height_m": 0.1}


def test_an_unregistered_kind_is_refused_where_it_is_asked_for(box_kind):
    CASE_KINDS.pop("box")
    try:
        with pytest.raises(TypeError, match="a BoxCase is no registered case kind's case"):
            estimate_case(BoxCase(0.1, 7))
        with pytest.raises(ConfigError, match="config key 'box' is not a siloflow setting"):
            validate_config({"box": {}})
        record = {"schema_version": 1, "engine": "liggghts", "case": "box", "run_id": "b", "timestep_s": 1e-5,
                  "n_clumps": 1, "n_frames": 0, "mpi_ranks": 1, "resumed_attempts": 0, "output_bytes": 0,
                  "stages": {}}
        with pytest.raises(RunRecordError, match="key 'case': not a case kind siloflow knows"):
            RunRecord.from_dict(record)
    finally:
        CASE_KINDS["box"] = box_kind


def test_an_engine_without_an_adapter_for_a_kind_says_so(box_kind, monkeypatch):
    monkeypatch.delitem(ADAPTERS, "box")
    with pytest.raises(CaseNotSupported, match="LIGGGHTS has no deck for box cases; it runs silo_flat, "):
        LiggghtsEngine().check_case(BoxCase(0.1, 7))


def test_a_kind_is_registered_once():
    with pytest.raises(ValueError, match="case kind 'jenike' is registered already"):
        register_case_kind(CaseKind("jenike", BoxCase, "x", ("fill",)))
    silo = CASE_KINDS["silo_flat"].case_type
    with pytest.raises(ValueError, match="case class SiloCase is registered already, as 'silo_flat'"):
        register_case_kind(CaseKind("other", silo, "x", ("fill",)))
    with pytest.raises(ValueError, match="lower-case identifier"):
        CaseKind("Box kind", BoxCase, "x", ("fill",))
    with pytest.raises(ValueError, match="has no builder, so it has no config section"):
        CaseKind("box", BoxCase, "x", ("fill",), schema=Path("box.schema.yaml"))
