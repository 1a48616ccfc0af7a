"""The case kinds siloflow runs, each defined once in one registry entry that every other place asks.

A :class:`CaseKind` holds what siloflow knows of one kind of case: its config section and that section's schema
fragment, the function that builds its runs from a validated configuration, whether the section inherits the shared
keys of ``defaults`` and runs replicates, the folder of its runs under ``results/``, the stages its decks run, its
cost model, whether its settled fill's force balance is checked, its own configuration checks, its rule file and its
wall meshes (which a run's ParaView files draw).
:data:`CASE_KINDS` maps each kind's name to its entry; :func:`register_case_kind` adds one. The configuration
schema, the config checks, the results layout, the estimates, the engines' adapters, the run record and the workflow
all take the kinds from here.

Adding a case kind: its case model and cost model (``siloflow/model/cases/``), its schema fragment
(``siloflow/workflow/schemas/cases/``), its rule file (``siloflow/workflow/rules/``), its deck module and templates in each engine
that runs it, one :func:`register_case_kind` line here and one adapter line in each of those engines.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping

from siloflow.model.cases.blender import BlenderCase, blender_cases, blender_mesh_set, check_blender_config
from siloflow.model.cases.jenike import JenikeCase, jenike_cases
from siloflow.model.cases.jenike_cost import estimate_jenike_case
from siloflow.model.cases.jenike_sweep import check_jenike_config, jenike_run_role
from siloflow.model.cases.silo_cost import estimate_blender_case, estimate_recirculation_case, estimate_silo_case
from siloflow.model.cases.silo_flat import SiloCase, check_silo_config, silo_cases, silo_meshes
from siloflow.model.cases.silo_recirculation import (ASSEMBLY_STAGES, RecirculationCase, check_recirculation_config,
                                                     recirculation_cases, recirculation_meshes)
from siloflow.model.cases.verification import VerificationCase

__all__ = ["CASE_KINDS", "CaseKind", "SCHEMA_FRAGMENTS", "case_kind", "configured_kinds", "kind_of_case",
           "register_case_kind"]

#: The folder of the case kinds' schema fragments (``<kind>.schema.yaml``, the properties of the kind's section).
SCHEMA_FRAGMENTS = Path(__file__).resolve().parents[2] / "workflow" / "schemas" / "cases"


@dataclass(frozen=True)
class CaseKind:
    """One kind of case, as every part of siloflow knows it.

    Attributes
    ----------
    name : str
        The kind's name: its config section, the ``case`` of its run records, the prefix of its rules.
    case_type : type
        The class of its cases (one per run).
    results_root : str
        The folder of its runs under ``results/`` (:mod:`siloflow.engines.layout`).
    stages : tuple of str
        The stage kinds its decks run, in order (:data:`siloflow.model.cases.stages.STAGE_KINDS`).
    final_stages : tuple of str
        Stage kinds a run may add after ``stages``, all or none (the recirculating silo's discharge after its
        recirculations).
    assembled_stages : tuple of str
        Stage kinds a run leaves out when it starts from another run's settled fill (the recirculating silo from the
        flat-bottom silo's assembly); empty: its runs make their own.
    build : callable or None
        ``build(config) -> {run id: case}`` from a validated configuration, the reference configuration first;
        None for a kind no config section defines (the verification suite builds its own problems).
    estimate : callable or None
        ``estimate(case, mpi_ranks, cost_model) -> RunEstimate`` (:mod:`siloflow.model.cost`); None: not estimated.
    schema : Path or None
        The schema fragment of its config section (a JSON schema of an object, with a ``description``);
        :func:`siloflow.engines.config.load_schema` places it under ``properties.<name>``.
    inherits_defaults : bool
        Whether the section inherits, leaf by leaf, the shared keys it leaves out from ``defaults``.
    replicated : bool
        Whether the section has ``replicates`` and ``reference_replicates`` (:func:`siloflow.model.cases.cases_of`).
    fill_balance : bool
        Whether each run's settled fill is checked against its weight (``siloflow/workflow/rules/fill_balance.smk``).
    check_config : callable or None
        ``check_config(config, contact_pairs)``: what the schema cannot express of the section (names that must
        refer to defined things, windows inside durations), raising :class:`siloflow.model.cases.config_checks.ConfigError`
        naming the key; ``contact_pairs`` holds the material pairs ``contacts`` defines (frozensets).
    run_role : callable or None
        ``run_role(config, case) -> str`` for kinds whose runs have roles of their own (the Jenike sweep's); None:
        the reference configuration's runs are ``reference`` and the others ``variant``.
    rules : str or None
        Its rule file under ``siloflow/workflow/rules/``, which defines its rules and adds its targets to ``CASE_TARGETS``.
    walls : callable or None
        ``walls(case) -> {name: TriangleMesh}``: the wall meshes of a run (vertices in m), as the engines build their
        walls from them; a run's ParaView files draw them (``siloflow/workflow/rules/paraview.smk``). None: none drawn.
    """

    name: str
    case_type: type
    results_root: str
    stages: tuple[str, ...]
    build: Callable[[Mapping], dict] | None = None
    estimate: Callable | None = None
    schema: Path | None = None
    inherits_defaults: bool = False
    replicated: bool = False
    fill_balance: bool = False
    check_config: Callable[[Mapping, Mapping], None] | None = None
    run_role: Callable[[Mapping, object], str] | None = None
    rules: str | None = None
    walls: Callable[[object], dict] | None = None
    final_stages: tuple[str, ...] = ()
    assembled_stages: tuple[str, ...] = ()

    def runs_stages(self, kinds: tuple[str, ...]) -> bool:
        """Whether ``kinds`` is a stage sequence this kind's decks run: ``stages``, or ``stages`` then
        ``final_stages``; for a kind with ``assembled_stages``, either without those (a run that starts from another
        run's settled fill)."""
        full = (self.stages, self.stages + self.final_stages)
        assembled = tuple(tuple(kind for kind in stages if kind not in self.assembled_stages) for stages in full)
        return tuple(kinds) in full + (assembled if self.assembled_stages else ())

    def __post_init__(self) -> None:
        if not self.name.isidentifier() or not self.name.islower():
            raise ValueError(f"a case kind's name is a lower-case identifier (its config section), got {self.name!r}")
        if not self.stages:
            raise ValueError(f"case kind {self.name!r} has no stages")
        if self.build is None and (self.schema is not None or self.inherits_defaults or self.replicated):
            raise ValueError(f"case kind {self.name!r} has no builder, so it has no config section to describe")


#: Every registered case kind by name, in registration order (the order the workflow and the estimates list them).
CASE_KINDS: dict[str, CaseKind] = {}


def register_case_kind(kind: CaseKind) -> CaseKind:
    """Add ``kind`` to :data:`CASE_KINDS`; a name or case class registered already is refused."""
    if kind.name in CASE_KINDS:
        raise ValueError(f"case kind {kind.name!r} is registered already")
    for other in CASE_KINDS.values():
        if other.case_type is kind.case_type:
            raise ValueError(f"case class {kind.case_type.__name__} is registered already, as {other.name!r}")
    CASE_KINDS[kind.name] = kind
    return kind


def case_kind(name: str) -> CaseKind:
    """The entry of case kind ``name``; the error names the kinds there are."""
    try:
        return CASE_KINDS[name]
    except KeyError:
        raise KeyError(f"unknown case {name!r}; the cases are {', '.join(CASE_KINDS)}") from None


def configured_kinds() -> tuple[str, ...]:
    """The names of the kinds a config section defines (those with a builder), in registration order."""
    return tuple(name for name, kind in CASE_KINDS.items() if kind.build is not None)


def kind_of_case(case) -> CaseKind:
    """The entry of the kind whose class ``case`` is."""
    for kind in CASE_KINDS.values():
        if type(case) is kind.case_type:
            return kind
    raise TypeError(f"a {type(case).__name__} is no registered case kind's case; the kinds are {', '.join(CASE_KINDS)}")


register_case_kind(CaseKind(
    "jenike", JenikeCase, "calibration/runs", ("fill", "settle", "consolidate", "shear"), jenike_cases,
    estimate_jenike_case, SCHEMA_FRAGMENTS / "jenike.schema.yaml", fill_balance=True,
    check_config=check_jenike_config, run_role=jenike_run_role, rules="calibration.smk"))
register_case_kind(CaseKind(
    "silo_flat", SiloCase, "silo_flat", ("fill", "settle", "open", "discharge"), silo_cases, estimate_silo_case,
    SCHEMA_FRAGMENTS / "silo_flat.schema.yaml", inherits_defaults=True, replicated=True, fill_balance=True,
    check_config=check_silo_config, rules="silo.smk", walls=silo_meshes))
register_case_kind(CaseKind(
    "silo_recirculation", RecirculationCase, "silo_recirculation", ("fill", "settle", "open", "recirculate"),
    recirculation_cases, estimate_recirculation_case, SCHEMA_FRAGMENTS / "silo_recirculation.schema.yaml",
    inherits_defaults=True, replicated=True, fill_balance=True, check_config=check_recirculation_config,
    rules="silo_recirculation.smk", walls=recirculation_meshes, final_stages=("discharge",),
    assembled_stages=ASSEMBLY_STAGES))
register_case_kind(CaseKind(
    "blender", BlenderCase, "blender", ("fill", "settle", "open", "discharge"), blender_cases, estimate_blender_case,
    SCHEMA_FRAGMENTS / "blender.schema.yaml", inherits_defaults=True, replicated=True, fill_balance=True,
    check_config=check_blender_config, rules="blender.smk", walls=blender_mesh_set))
register_case_kind(CaseKind("verification", VerificationCase, "verification", ("release",)))
