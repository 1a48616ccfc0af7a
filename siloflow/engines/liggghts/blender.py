"""LIGGGHTS decks and runs of the multi-flow blender.

The run directory has the layout of :mod:`siloflow.engines.liggghts.run` (``deck/``, ``dumps/``, ``log.liggghts``,
``engine.out``, ``run.json`` written last). Every wall (hopper with its vertical section, insert plates, tube
plates) is a closed triangle mesh with real thickness; the front and back walls are planes. Continuous
discharge uses a periodic vertical boundary (as the recirculating flat silo, :mod:`siloflow.engines.liggghts.silo_recirculation`),
so the run is checked for an unchanged clump count.
"""

from __future__ import annotations

from pathlib import Path

from siloflow.model.cases.blender import GATE, BlenderCase, blender_mesh_set
from siloflow.engines.liggghts.run import Resume, run_checked
from siloflow.model.record import RunRecord
from siloflow.engines.liggghts.silo_flat import silo_deck_context
from siloflow.engines.silo_checks import check_silo_run, expected_simulated_time, silo_run_record
from siloflow.engines.liggghts.inputs import ENGINE_NAME, processor_grid, write_case_inputs
from siloflow.engines.templating import render_deck

def blender_deck_context(case: BlenderCase) -> dict:
    """The rendering context of ``siloflow/templates/liggghts/blender.lmp.j2``."""
    silo = case.silo
    context = silo_deck_context(silo)
    wall_type = silo.materials.type_of(silo.wall_materials["side"])
    walls = [name for name in blender_mesh_set(case) if name != GATE]
    # The meshes' outer faces are W/2 + t from the axis; leave a clump size of room for the domain box.
    half_span = 0.5 * case.geometry.width + case.geometry.wall_thickness + 2.0 * silo.particle.bounding_radius
    context.update(
        {
            "title": f"siloflow-blender-{case.run_id}",
            "boundary": ["f", "f", "p" if case.mode == "continuous" else "f"],
            "domain": {"x": [-half_span, half_span], "y": [0.0, silo.depth], "z": [-silo.sink_depth, silo.domain_top]},
            "gravity": case.gravity,
            "primitive_walls": [w for w in context["primitive_walls"] if w["plane"] == "yplane"],
            "meshes": [{"id": name, "file": f"deck/meshes/{name}.stl", "type": wall_type} for name in [*walls, GATE]],
            "closed_floor": [*walls, GATE],
            "open_floor": walls,
            "gate_mesh": GATE,
            "continuous": case.mode == "continuous",
            "assembly_restart": None,   # no run starts from a blender's fill
        }
    )
    context["processors"] = processor_grid(context["domain"])
    return context


def render_blender_deck(case: BlenderCase) -> str:
    """The LIGGGHTS deck of a blender run."""
    return render_deck("liggghts/blender.lmp.j2", blender_deck_context(case))


def write_blender_inputs(case: BlenderCase, deck_dir: str | Path) -> Path:
    """Write deck, meshes and ``case.json`` into ``deck_dir``; returns the deck path."""
    return write_case_inputs(blender_mesh_set(case), case.summary(), render_blender_deck(case), deck_dir)


def check_blender_run(case: BlenderCase, markers, dump_files, run_dir: Path) -> dict:
    """Check a finished blender run: the silo's stage checks, and in continuous mode no clump lost.

    Raises
    ------
    EngineRunError
        As :func:`siloflow.engines.liggghts.run.check_silo_run`, or when a continuous run lost clumps.
    """
    return check_silo_run(case.silo, markers, dump_files, run_dir, last_stage="discharged",
                          clumps_conserved=case.mode == "continuous")


def run_blender(
    case: BlenderCase, run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun"
) -> RunRecord:
    """Run a rendered blender deck, check it and write ``run.json``; returns the record."""
    return run_checked(
        run_dir,
        lambda markers, dumps: check_blender_run(case, markers, dumps, Path(run_dir)),
        {"executable": executable, "mpi_ranks": mpi_ranks, "mpirun": mpirun,
         "target_time": expected_simulated_time(case.silo)},
        lambda checked: silo_run_record(
            ENGINE_NAME,
            "blender", case.run_id, checked,
            {"configuration": case.configuration, "gravity_factor": case.gravity_factor, "mode": case.mode},
            [-case.silo.sink_depth, case.silo.domain_top]),
        Resume("liggghts/blender.lmp.j2", blender_deck_context(case), case.silo.discharge_steps),
    )
