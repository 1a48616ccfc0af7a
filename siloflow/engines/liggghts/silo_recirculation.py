"""LIGGGHTS decks and runs of the recirculating silo (blending study).

The run directory has the layout of :mod:`siloflow.engines.liggghts.run` (``deck/``, ``dumps/``, ``log.liggghts``,
``engine.out``, ``run.json`` written last). Periodic boundaries and multisphere clumps work together in
LIGGGHTS 3.8, serially and under MPI with the domain split along the periodic direction: clumps cross the
bottom boundary whole and re-enter at the top with their ids. The recirculation stage therefore runs with
``thermo_modify lost error``, and the run is checked for an unchanged clump count.

A run that starts from the flat-bottom silo's assembly (``silo_recirculation.assembly: silo_flat``) reads a copy of
that run's settled fill in ``deck/`` (``liggghts/assembled.lmp.j2``): its box is the flat-bottom silo's, extended down
to the channel's bottom and made periodic in z once read.
"""

from __future__ import annotations

from pathlib import Path

from siloflow.model.cases.silo_recirculation import CHANNEL_MESHES, RecirculationCase, recirculation_meshes
from siloflow.engines.liggghts.run import ASSEMBLY_RESTART, Resume, run_checked
from siloflow.model.record import RunRecord
from siloflow.engines.liggghts.silo_flat import silo_deck_context
from siloflow.engines.silo_checks import check_silo_run, expected_simulated_time, recirculation_labels, silo_run_record
from siloflow.engines.liggghts.inputs import ENGINE_NAME, write_case_inputs
from siloflow.engines.templating import render_deck

def recirculation_deck_context(case: RecirculationCase) -> dict:
    """The rendering context of ``siloflow/templates/liggghts/silo_recirculation.lmp.j2``."""
    context = silo_deck_context(case.silo)
    bottom = case.silo.materials.type_of(case.silo.wall_materials["bottom"])
    context["title"] = f"siloflow-silo_recirculation-{case.run_id}"
    # The vertical boundary is periodic: what leaves the channel bottom re-enters at the top.
    context["boundary"] = [context["boundary"][0], context["boundary"][1], "p"]
    context["meshes"] = context["meshes"] + [
        {"id": name, "file": f"deck/meshes/{name}.stl", "type": bottom} for name in CHANNEL_MESHES
    ]
    context["closed_floor"] = context["closed_floor"] + list(CHANNEL_MESHES)
    context["open_floor"] = context["open_floor"] + list(CHANNEL_MESHES)
    context["assembly_restart"] = None   # its own fill serves no other run
    if case.assembly is not None:
        assembly_meshes = [mesh for mesh in context["meshes"] if mesh["id"] not in CHANNEL_MESHES]
        context.update(
            case_template="liggghts/silo_recirculation.lmp.j2",
            assembly={"restart_file": f"deck/{ASSEMBLY_RESTART}", "meshes": assembly_meshes,
                      "floor": [mesh["id"] for mesh in assembly_meshes],
                      "added_meshes": [mesh for mesh in context["meshes"] if mesh["id"] in CHANNEL_MESHES]},
        )
    context["feeder"] = {
        "zone": list(case.feeder_zone),
        "velocity": case.feeder_velocity,
        # the atoms of one clump as the deck inserts them (a one-sphere model's has an inner sphere)
        "spheres_per_clump": len(context["particle"]["spheres"]),
    }
    # the discharge after the recirculations: the last final_discharge steps of the discharge stage
    context["final_discharge"] = {"steps": case.final_discharge_steps} if case.final_discharge_steps else None
    return context


def render_recirculation_deck(case: RecirculationCase) -> str:
    """The LIGGGHTS deck of a recirculation run (from the assembly's restart file when it starts from one)."""
    template = "liggghts/assembled.lmp.j2" if case.assembly is not None else "liggghts/silo_recirculation.lmp.j2"
    return render_deck(template, recirculation_deck_context(case))


def write_recirculation_inputs(case: RecirculationCase, deck_dir: str | Path) -> Path:
    """Write deck, meshes and ``case.json`` into ``deck_dir``; returns the deck path. A run that starts from an
    assembly needs its restart file in ``deck_dir`` (:meth:`siloflow.engines.interface.Engine.write_inputs` puts it
    there)."""
    return write_case_inputs(recirculation_meshes(case), case.summary(), render_recirculation_deck(case), deck_dir)


def check_recirculation_run(case: RecirculationCase, markers, dump_files, run_dir: Path) -> dict:
    """Check a finished recirculation run: the batch silo's checks, then no clump lost while recirculating, and the
    discharge after the recirculations finished where the case has one.

    Raises
    ------
    EngineRunError
        As :func:`siloflow.engines.liggghts.run.check_silo_run`, or when the clump count changed during recirculation.
    """
    return check_silo_run(case.silo, markers, dump_files, run_dir, last_stage="recirculated", clumps_conserved=True,
                          then="discharged" if case.final_discharge_steps else None,
                          assembled=case.assembly is not None)


def run_recirculation(
    case: RecirculationCase, run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1,
    mpirun: str = "mpirun",
) -> RunRecord:
    """Run a rendered recirculation deck, check it and write ``run.json``; returns the record."""
    return run_checked(
        run_dir,
        lambda markers, dumps: check_recirculation_run(case, markers, dumps, Path(run_dir)),
        {"executable": executable, "mpi_ranks": mpi_ranks, "mpirun": mpirun,
         "target_time": expected_simulated_time(case.silo, assembled=case.assembly is not None)},
        lambda checked: silo_run_record(
            ENGINE_NAME,
            "silo_recirculation", case.run_id, checked,
            recirculation_labels(case),
            [-case.channel_length, case.silo.domain_top]),
        Resume("liggghts/silo_recirculation.lmp.j2", recirculation_deck_context(case), case.silo.discharge_steps),
    )
