"""YADE scripts of the multi-flow blender: the batch silo's script (:mod:`siloflow.engines.yade.silo_flat`) with the blender's
closed wall meshes (hopper, insert and tube plates: :func:`siloflow.model.cases.blender.blender_mesh_set`) as facets and
front and back planes, at the case's gravity. Batch discharge removes clumps below the outlet; continuous discharge
moves a clump that fell below the domain to its top (whole, with its x, y and velocity) every :data:`REENTRY_EVERY`
steps, as the LIGGGHTS deck's periodic z, and the run is checked for an unchanged clump count.
"""

from __future__ import annotations

from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.blender import GATE, BlenderCase, blender_mesh_set
from siloflow.engines.templating import render_deck
from siloflow.engines.yade.inputs import exploded_speed, write_script_inputs
from siloflow.engines.yade.run import YadeOptions
from siloflow.engines.yade.silo_flat import check_silo_case, run_silo_type, silo_script_context

__all__ = ["REENTRY_EVERY", "blender_script_context", "render_blender_script", "run_blender", "write_blender_inputs"]

#: Steps between the re-entry checks of a continuous discharge.
REENTRY_EVERY = 10


def blender_script_context(case: BlenderCase) -> dict:
    """The rendering context of ``siloflow/templates/yade/blender.py.j2``."""
    silo = case.silo
    context = silo_script_context(silo, case.gravity)
    wall = silo.materials.type_of(silo.wall_materials["side"]) - 1
    # the meshes' outer faces are W/2 + t from the axis; a clump beyond them by its size has left the blender
    half_span = 0.5 * case.geometry.width + case.geometry.wall_thickness
    context.update({
        "title": f"siloflow-blender-{case.run_id}",
        "exploded_speed": exploded_speed(silo.domain_top + silo.sink_depth, silo.fill.insertion_velocity)
        * max(1.0, case.gravity_factor) ** 0.5,
        "half_width": half_span,
        "primitive_walls": [w for w in context["primitive_walls"] if w["axis"] == 1],
        "meshes": [{"id": name, "material": wall} for name in blender_mesh_set(case)],
        "gate_mesh": GATE,
        "continuous": case.mode == "continuous",
        "reentry_every": REENTRY_EVERY,
        "assembly_state": None,   # no run starts from a blender's fill
    })
    return context


def render_blender_script(case: BlenderCase) -> str:
    """The YADE script of a blender run."""
    check_silo_case(case.silo)
    return render_deck("yade/blender.py.j2", blender_script_context(case))


def write_blender_inputs(case: BlenderCase, deck_dir: str | Path) -> Path:
    """Write the script, the meshes and ``case.json`` into ``deck_dir``; returns the script path."""
    return write_script_inputs(case.summary(), render_blender_script(case), deck_dir, blender_mesh_set(case))


def run_blender(case: BlenderCase, run_dir: str | Path, options: YadeOptions) -> RunRecord:
    """Run a rendered blender script, check it (the silo's stage checks; in continuous mode no clump lost) and write
    ``run.json``; returns the record."""
    return run_silo_type(case.silo, "blender", case.run_id, run_dir, options,
                         clumps_conserved=case.mode == "continuous",
                         labels={"configuration": case.configuration, "gravity_factor": case.gravity_factor,
                                 "mode": case.mode},
                         domain_z=[-case.silo.sink_depth, case.silo.domain_top])
