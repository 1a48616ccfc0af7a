"""LIGGGHTS decks of the silo-type cases (flat-bottom silo; the recirculating silo and the blender extend it):
rendering contexts, wall meshes and the inputs written into a run's ``deck/`` folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis.data.record import RunRecord
from engines.cases.geometry import horizontal_rectangle
from engines.cases.silo_flat import SiloCase
from engines.estimates import CostModel, silo_run_steps
from engines.liggghts.contacts import N_COLUMNS as N_CONTACT_COLUMNS
from engines.liggghts.inputs import ENGINE_NAME, common_context, write_case_inputs
from engines.liggghts.forces import RESUMED_WALL_FORCES_PREFIX
from engines.liggghts.run import WALL_FORCES_NAME
from engines.liggghts.run import (
    CONTACT_PREFIX,
    DUMP_PREFIX,
    RESTART_DIR,
    RESTART_PREFIX,
    Resume,
    restart_every,
    run_checked,
    settled_fill_context,
)
from engines.interface import EngineRunError
from engines.liggghts.markers import Marker
from engines.templating import render_deck

#: What the silo-type decks dump per sphere: what their analyses read (ids, clump ids, centres, velocities,
#: radii, masses), in binary. Forces and angular velocities are left out (a third of the volume); contact forces
#: come from the separate contact dump.
SILO_DUMP_FIELDS = ("id", "type", "id_multisphere", "x", "y", "z", "vx", "vy", "vz", "radius", "mass")

#: The meshes of the silo's floor: the plates left and right of the outlet and its gate.
FLOOR_MESHES = ("floor_left", "floor_right", "outlet_gate")


def silo_meshes(case: SiloCase) -> dict:
    """Floor plates left and right of the outlet and the gate that closes it (z = 0, normals up)."""
    half_width, half_outlet, depth = 0.5 * case.width, 0.5 * case.outlet_width, case.depth
    return {
        "floor_left": horizontal_rectangle(-half_width, -half_outlet, 0.0, depth, 0.0),
        "floor_right": horizontal_rectangle(half_outlet, half_width, 0.0, depth, 0.0),
        "outlet_gate": horizontal_rectangle(-half_outlet, half_outlet, 0.0, depth, 0.0),
    }


def silo_deck_context(case: SiloCase) -> dict:
    """The rendering context of ``templates/liggghts/silo_flat.lmp.j2``."""
    table = case.materials
    side, bottom = (table.type_of(case.wall_materials[key]) for key in ("side", "bottom"))
    front_back_type = table.type_of(case.wall_materials["front_back"]) if case.front_back_walls else None
    half_width = 0.5 * case.width
    context = common_context(case)
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
            "restart": {"every": restart_every(case.discharge_steps), "path": f"{RESTART_DIR}/{RESTART_PREFIX}_*.restart"},
            "thermo_every": dump_every,
            # force and torque of every wall on the particles, one sample per dump interval (engines.liggghts.forces)
            "wall_forces": {"every": dump_every, "timestep": case.timestep, "path": WALL_FORCES_NAME,
                            "resume_prefix": RESUMED_WALL_FORCES_PREFIX},
        }
    )
    return context


def render_silo_deck(case: SiloCase) -> str:
    """The LIGGGHTS deck of a flat-bottom silo run."""
    return render_deck("liggghts/silo_flat.lmp.j2", silo_deck_context(case))


def write_silo_inputs(case: SiloCase, deck_dir: str | Path) -> Path:
    """Write deck, meshes and ``case.json`` into ``deck_dir``; returns the deck path."""
    return write_case_inputs(silo_meshes(case), case.summary(), render_silo_deck(case), deck_dir)


def check_silo_run(
    case: SiloCase, markers: list[Marker], dump_files: list[Path], run_dir: Path, last_stage: str = "discharged",
    clumps_conserved: bool = False,
) -> dict:
    """Check that a finished silo run did what the case asked; returns the stage record.

    ``last_stage`` names the marker of the stage after the opening (``discharged`` in the batch silo, which
    drains; ``recirculated`` in the recirculating one); the record keeps it under that name. With
    ``clumps_conserved`` (periodic runs, where nothing may leave) the clump count must be unchanged at its end.

    Raises
    ------
    EngineRunError
        When clumps are missing after filling, the fill did not settle, a stage marker or the dumps
        are missing.
    """
    by_event = {}
    for marker in markers:
        by_event.setdefault(marker.event, []).append(marker)
    for event in ("filled", "settled", "opened", last_stage):
        if event not in by_event:
            raise EngineRunError(f"{run_dir}: the log has no '{event}' stage marker; the deck did not run to the end")
    filled = by_event["filled"][-1].values
    if int(round(filled["clumps"])) != case.fill.n_clumps:
        raise EngineRunError(
            f"{run_dir}: only {int(filled['clumps'])} of {case.fill.n_clumps} clumps were inserted; "
            "widen silo_flat.fill.zone_width_fraction or lower silo_flat.fill.volume_fraction"
        )
    settled = by_event["settled"][-1].values
    if not settled["ke_per_clump"] < case.settle_threshold:
        raise EngineRunError(
            f"{run_dir}: the fill did not settle: kinetic energy per clump {settled['ke_per_clump']:.3g} J is above "
            f"the threshold {case.settle_threshold:.3g} J after the longest settling time; raise "
            "silo_flat.settle.max_time or the threshold"
        )
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
        "filled": filled,
        "settled": settled,
        "opened": opened,
        last_stage: by_event[last_stage][-1].values,
        "settle_checks": [m.values for m in by_event.get("settle", [])],
        "open_step": int(round(opened["step"])),
        "open_time_s": opened["time"],
        "timestep_s": case.timestep,
        "n_clumps": case.fill.n_clumps,
        "n_dumps": len(dump_files),
    }


def expected_simulated_time(silo: SiloCase) -> float:
    """Simulated time a silo-type deck is expected to reach (s): fill, the expected share of the settling time
    (:class:`engines.estimates.CostModel`), discharge; the target of its progress reports."""
    return silo_run_steps(silo, CostModel().settle_fraction) * silo.timestep


#: Stage kinds of the markers a silo-type deck prints at the end of its stages.
SILO_STAGE_MARKERS = {"filled": "fill", "settled": "settle", "opened": "open", "discharged": "discharge",
                      "recirculated": "recirculate"}


def silo_run_record(case_kind: str, run_id: str, checked: dict, labels: dict | None = None,
                    domain_z: list | None = None) -> RunRecord:
    """The run record of a checked silo-type run (``checked``: :func:`check_silo_run` plus the run's ``mpi_ranks``,
    ``resumed_attempts`` and ``output_bytes``)."""
    return RunRecord(
        engine=ENGINE_NAME,
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


def run_silo(
    case: SiloCase, run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun"
) -> RunRecord:
    """Run a rendered flat-bottom silo deck, check it and write ``run.json``; returns the record."""
    return run_checked(
        run_dir,
        lambda markers, dumps: check_silo_run(case, markers, dumps, Path(run_dir)),
        {"executable": executable, "mpi_ranks": mpi_ranks, "mpirun": mpirun,
         "target_time": expected_simulated_time(case)},
        lambda checked: silo_run_record("silo_flat", case.run_id, checked),
        Resume("liggghts/silo_flat.lmp.j2", silo_deck_context(case), case.discharge_steps),
    )
