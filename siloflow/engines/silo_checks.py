"""What a finished silo-type run (flat-bottom silo, recirculating silo, blender) must show, whatever engine ran it:
the stage markers its inputs print (:mod:`siloflow.engines.markers`), checked against the case, and the run record built from
them."""

from __future__ import annotations

from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.silo_flat import SiloCase
from siloflow.model.cases.silo_recirculation import RecirculationCase
from siloflow.model.cost import CostModel
from siloflow.model.cases.silo_cost import silo_run_steps
from siloflow.engines.interface import EngineRunError
from siloflow.engines.markers import Marker

__all__ = ["SILO_STAGE_MARKERS", "check_silo_run", "expected_simulated_time", "recirculation_labels", "silo_run_record"]


def check_silo_run(
    case: SiloCase, markers: list[Marker], dump_files: list[Path], run_dir: Path, last_stage: str = "discharged",
    clumps_conserved: bool = False, then: str | None = None, assembled: bool = False,
) -> dict:
    """Check that a finished silo run did what the case asked; returns the stage record.

    With ``assembled`` the run started from another run's settled fill (the recirculating silo from the flat-bottom
    silo's assembly): its log has an ``assembled`` marker with the fill's clumps instead of ``filled`` and
    ``settled``, whose checks that run's own passed; the record keeps it under that name.

    ``last_stage`` names the marker of the stage after the opening (``discharged`` in the batch silo, which
    drains; ``recirculated`` in the recirculating one); the record keeps it under that name. With
    ``clumps_conserved`` (periodic runs, where nothing may leave) the clump count must be unchanged at its end.
    ``then`` names the marker of a stage after it (the recirculating silo's discharge after its recirculations,
    ``discharged``), which must be there too; the record keeps it under that name.

    The ``settled`` stage carries, besides the marker's values, the settling criterion: ``ke_threshold_J`` (J),
    ``ke_threshold_ratio`` (the threshold over the clump's m g d, -) and ``ke_ratio`` (the settled fill's kinetic
    energy per clump over m g d, -).

    Raises
    ------
    EngineRunError
        When clumps are missing after filling, the fill did not settle, a stage marker or the dumps
        are missing.
    """
    by_event = {}
    for marker in markers:
        by_event.setdefault(marker.event, []).append(marker)
    start = ("assembled",) if assembled else ("filled", "settled")
    for event in start + ("opened", last_stage) + ((then,) if then else ()):
        if event not in by_event:
            raise EngineRunError(f"{run_dir}: the log has no '{event}' stage marker; the deck did not run to the end")
    if assembled:
        assembly = by_event["assembled"][-1].values
        if int(round(assembly["clumps"])) != case.fill.n_clumps:
            raise EngineRunError(f"{run_dir}: the settled fill it started from holds {int(round(assembly['clumps']))} "
                                 f"clumps, the case {case.fill.n_clumps}")
        return {"assembled": assembly,
                **_after_opening(case, by_event, dump_files, run_dir, last_stage, clumps_conserved, then),
                "settle_checks": []}
    filled = by_event["filled"][-1].values
    if int(round(filled["clumps"])) != case.fill.n_clumps:
        raise EngineRunError(
            f"{run_dir}: only {int(filled['clumps'])} of {case.fill.n_clumps} clumps were inserted; "
            "widen silo_flat.fill.zone_width_fraction or lower silo_flat.fill.volume_fraction"
        )
    settled = by_event["settled"][-1].values
    criterion = case.settle_criterion
    if not settled["ke_per_clump"] < criterion.threshold:
        section = criterion.key.split(".")[0]
        raise EngineRunError(
            f"{run_dir}: the fill did not settle: kinetic energy per clump {settled['ke_per_clump']:.3g} J "
            f"({settled['ke_per_clump'] / criterion.energy_scale:.3g} of the clump's m g d) is above the threshold "
            f"{criterion.threshold:.3g} J ({criterion.ratio:.3g} of m g d, set by {criterion.key}) after the longest "
            f"settling time; raise {section}.settle.max_time or {criterion.key}"
        )
    # The record keeps the criterion the fill was held to, in joules and in the clump's own scale.
    settled = {**settled, "ke_ratio": settled["ke_per_clump"] / criterion.energy_scale,
               "ke_threshold_J": criterion.threshold, "ke_threshold_ratio": criterion.ratio}
    return {"filled": filled, "settled": settled,
            **_after_opening(case, by_event, dump_files, run_dir, last_stage, clumps_conserved, then),
            "settle_checks": [m.values for m in by_event.get("settle", [])]}


def _after_opening(case: SiloCase, by_event: dict, dump_files: list[Path], run_dir: Path, last_stage: str,
                   clumps_conserved: bool, then: str | None) -> dict:
    """The checks and the stage record of a silo run from the opening of its outlet on (:func:`check_silo_run`)."""
    if len(dump_files) < 2:
        raise EngineRunError(f"{run_dir}: expected particle dumps of the discharge, found {len(dump_files)}")
    final = int(round(by_event[last_stage][-1].values["clumps"]))
    if clumps_conserved and final != case.fill.n_clumps:
        raise EngineRunError(
            f"{run_dir}: {case.fill.n_clumps} clumps were inserted but {final} remain after the '{last_stage}' stage; "
            "clumps were lost through a boundary"
        )
    opened = by_event["opened"][-1].values
    return {
        "opened": opened,
        last_stage: by_event[last_stage][-1].values,
        **({then: by_event[then][-1].values} if then else {}),
        "open_step": int(round(opened["step"])),
        "open_time_s": opened["time"],
        "timestep_s": case.timestep,
        "n_clumps": case.fill.n_clumps,
        "n_dumps": len(dump_files),
    }


def expected_simulated_time(silo: SiloCase, assembled: bool = False) -> float:
    """Simulated time a silo-type deck is expected to reach (s): fill, the expected share of the settling time
    (:class:`siloflow.engines.estimates.CostModel`), discharge, or the discharge alone for a run that starts from
    another run's settled fill (``assembled``; its clock starts there); the target of its progress reports."""
    if assembled:
        return silo.discharge_steps * silo.timestep
    return silo_run_steps(silo, CostModel().settle_fraction) * silo.timestep


#: Stage kinds of the markers a silo-type deck prints at the end of its stages.
SILO_STAGE_MARKERS = {"filled": "fill", "settled": "settle", "opened": "open", "discharged": "discharge",
                      "recirculated": "recirculate"}


def silo_run_record(engine: str, case_kind: str, run_id: str, checked: dict, labels: dict | None = None,
                    domain_z: list | None = None) -> RunRecord:
    """The run record of a checked silo-type run on engine ``engine`` (``checked``: :func:`check_silo_run` plus the run's ``mpi_ranks``,
    ``resumed_attempts`` and ``output_bytes``)."""
    return RunRecord(
        engine=engine,
        case=case_kind,
        run_id=run_id,
        timestep_s=checked["timestep_s"],
        n_clumps=checked["n_clumps"],
        n_frames=checked["n_dumps"],
        mpi_ranks=checked["mpi_ranks"],
        stages={kind: checked[marker] for marker, kind in SILO_STAGE_MARKERS.items() if marker in checked},
        resumed_attempts=checked["resumed_attempts"],
        output_bytes=checked["output_bytes"],
        settle_checks=checked["settle_checks"],
        open_step=checked["open_step"],
        open_time_s=checked["open_time_s"],
        domain_z=domain_z,
        outlet_z=0.0,
        labels=dict(labels or {}),
    )


def recirculation_labels(case: RecirculationCase) -> dict:
    """The labels of a recirculation run's record: its flow pattern, role and a-priori residence time (s), and the
    run whose settled fill it started from where it did not make its own."""
    assembly = {"assembly_run_id": case.assembly.run_id} if case.assembly is not None else {}
    return {"flow_pattern": case.pattern, "role": case.role,
            "estimated_residence_time_s": case.estimated_residence_time, **assembly}
