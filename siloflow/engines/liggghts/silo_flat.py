"""LIGGGHTS decks of the silo-type cases (flat-bottom silo; the recirculating silo and the blender extend it):
rendering contexts, wall meshes and the inputs written into a run's ``deck/`` folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from siloflow.model.record import RunRecord
from siloflow.model.cases.silo_flat import SiloCase, silo_meshes
from siloflow.engines.liggghts.contacts import N_COLUMNS as N_CONTACT_COLUMNS
from siloflow.engines.liggghts.inputs import (ENGINE_NAME, common_context, contact_coefficients, processor_grid,
                                             write_case_inputs)
from siloflow.engines.liggghts.forces import RESUMED_WALL_FORCES_PREFIX
from siloflow.engines.liggghts.run import (
    ASSEMBLY_RESTART,
    CONTACT_PREFIX,
    DUMP_PREFIX,
    RESTART_PATH,
    Resume,
    WALL_FORCES_NAME,
    run_checked,
    settled_fill_context,
)
from siloflow.engines.run_files import restart_every
from siloflow.engines.silo_checks import check_silo_run, expected_simulated_time, silo_run_record
from siloflow.engines.templating import render_deck

#: What the silo-type decks dump per sphere: what their analyses read (ids, clump ids, centres, velocities,
#: radii, masses), in binary. Forces and angular velocities are left out (a third of the volume); contact forces
#: come from the separate contact dump.
SILO_DUMP_FIELDS = ("id", "type", "id_multisphere", "x", "y", "z", "vx", "vy", "vz", "radius", "mass")

def silo_deck_context(case: SiloCase) -> dict:
    """The rendering context of ``siloflow/templates/liggghts/silo_flat.lmp.j2``."""
    table = case.materials
    side, bottom = (table.type_of(case.wall_materials[key]) for key in ("side", "bottom"))
    front_back_type = table.type_of(case.wall_materials["front_back"]) if case.front_back_walls else None
    half_width = 0.5 * case.width
    context = common_context(case)
    # poured and settled at the fill's contacts, the run's switched on before the outlet opens
    context["fill_materials"] = (contact_coefficients(case.fill_materials, case.particle)
                                 if case.fill_materials is not None else None)
    dump_every = case.dump_every
    context.update(
        {
            "title": f"siloflow-silo_flat-{case.run_id}",
            # Without front and back walls the depth direction is periodic.
            "boundary": ["f", "f" if case.front_back_walls else "p", "f"],
            "domain": {
                "x": [-half_width, half_width],
                "y": [0.0, case.depth],
                "z": [-case.sink_depth, case.domain_top],
            },
            "primitive_walls": [
                {"id": "wall_left", "type": side, "plane": "xplane", "position": -half_width},
                {"id": "wall_right", "type": side, "plane": "xplane", "position": half_width},
                *(
                    [
                        {"id": "wall_front", "type": front_back_type, "plane": "yplane", "position": 0.0},
                        {"id": "wall_back", "type": front_back_type, "plane": "yplane", "position": case.depth},
                    ]
                    if case.front_back_walls
                    else []
                ),
            ],
            "meshes": [
                {"id": name, "file": f"deck/meshes/{name}.stl", "type": bottom}
                for name in ("floor_left", "floor_right", "outlet_gate")
            ],
            "closed_floor": ["floor_left", "floor_right", "outlet_gate"],
            "open_floor": ["floor_left", "floor_right"],
            "gate_mesh": "outlet_gate",
            "fill": {
                "seed": case.seeds[2],
                "zone": list(case.fill.zone),
                "n_clumps": case.fill.n_clumps,
                "particle_rate": case.fill.particle_rate,
                "insert_every": case.fill.insert_every,
                "insertion_velocity": case.fill.insertion_velocity,
                "steps": case.fill.fill_steps,
                # Crowded insertion events may place fewer clumps than asked: allow as many extra events again.
                "max_extra_insertions": int(np.ceil(case.fill.n_clumps / case.fill.clumps_per_insertion)) + 10,
            },
            "settle": {
                "threshold": case.settle_threshold,
                "check_steps": case.settle_check_steps,
                "max_checks": case.settle_max_checks,
            },
            "dump": {"id": "particle_dump", "every": dump_every, "path": f"dumps/{DUMP_PREFIX}_*.vtk",
                     "fields": list(SILO_DUMP_FIELDS)},
            "settled_fill": settled_fill_context(CONTACT_PREFIX, N_CONTACT_COLUMNS, case.timestep),
            "discharge": {"steps": case.discharge_steps, "upto": False},
            "restart": {"every": restart_every(case.discharge_steps), "path": RESTART_PATH},
            # the fill and the settling write restart files too, at 1/20 of the pour: a run stopped there resumes
            "fill_restart": {"every": restart_every(case.fill.fill_steps), "path": RESTART_PATH},
            # the first attempt's deck; a resumed attempt's names its restart file and stage (Resume)
            "resume": None,
            "thermo_every": dump_every,
            # the settled fill, kept for the runs that start from it (the recirculating silo's; the others set None)
            "assembly_restart": ASSEMBLY_RESTART,
            # force and torque of every wall on the particles, one sample per dump interval (siloflow.engines.liggghts.forces)
            "wall_forces": {"every": dump_every, "timestep": case.timestep, "path": WALL_FORCES_NAME,
                            "resume_prefix": RESUMED_WALL_FORCES_PREFIX},
        }
    )
    context["processors"] = processor_grid(context["domain"])
    return context


def render_silo_deck(case: SiloCase) -> str:
    """The LIGGGHTS deck of a flat-bottom silo run."""
    return render_deck("liggghts/silo_flat.lmp.j2", silo_deck_context(case))


def write_silo_inputs(case: SiloCase, deck_dir: str | Path) -> Path:
    """Write deck, meshes and ``case.json`` into ``deck_dir``; returns the deck path."""
    return write_case_inputs(silo_meshes(case), case.summary(), render_silo_deck(case), deck_dir)


def run_silo(
    case: SiloCase, run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun"
) -> RunRecord:
    """Run a rendered flat-bottom silo deck, check it and write ``run.json``; returns the record."""
    return run_checked(
        run_dir,
        lambda markers, dumps: check_silo_run(case, markers, dumps, Path(run_dir)),
        {"executable": executable, "mpi_ranks": mpi_ranks, "mpirun": mpirun,
         "target_time": expected_simulated_time(case)},
        lambda checked: silo_run_record(ENGINE_NAME, "silo_flat", case.run_id, checked),
        Resume("liggghts/silo_flat.lmp.j2", silo_deck_context(case), case.discharge_steps),
    )
