"""YADE scripts of the flat-bottom silo: the rendering context of ``siloflow/templates/yade/silo_flat.py.j2``, the inputs
written into a run's ``deck/`` folder, and the run, checked as every engine's silo runs are
(:mod:`siloflow.engines.silo_checks`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from siloflow.model.record import RunRecord
from siloflow.model.constants import GRAVITY
from siloflow.model.cases.silo_flat import SiloCase, silo_meshes
from siloflow.engines.interface import CaseNotSupported
from siloflow.engines.silo_checks import check_silo_run, expected_simulated_time, silo_run_record
from siloflow.engines.templating import render_deck
from siloflow.engines.yade.inputs import (
    ENGINE_NAME, GEOMETRY_PATH, common_context, exploded_speed, materials_context, rolling_friction, write_script_inputs,
)
from siloflow.engines.run_files import restart_every
from siloflow.engines.yade.run import (
    ASSEMBLY_STATE, DUMP_PREFIX, RESTART_DIR, RESUME_STEM, SETTLED_FILL_PREFIX, WALL_FORCES_NAME, YadeOptions, run_script_checked,
)

def check_silo_case(case: SiloCase) -> None:
    """Refuse what the YADE silo scripts (flat-bottom, recirculating, blender) do not build.

    Raises
    ------
    CaseNotSupported
        For contacts with different rolling frictions (YADE takes one eta), or a periodic depth
        (``silo_flat.front_back_walls: false``).
    """
    rolling_friction(case.materials, f"run {case.run_id}")
    if not case.front_back_walls:
        raise CaseNotSupported(
            f"config key 'silo_flat.front_back_walls': false (a periodic depth) is not built on YADE (run "
            f"{case.run_id}); YADE's periodic cell would also wrap the side walls' direction: give the silo front "
            "and back walls or run it on LIGGGHTS"
        )


def silo_script_context(case: SiloCase, gravity: float = GRAVITY) -> dict:
    """The rendering context of ``siloflow/templates/yade/silo_flat.py.j2``, under ``gravity`` (m/s^2; a blender's gravity
    series runs its silo at f g)."""
    table = case.materials
    side, bottom, front_back = (table.type_of(case.wall_materials[key]) - 1 for key in ("side", "bottom", "front_back"))
    half_width = 0.5 * case.width
    context = common_context(case, table, gravity=gravity)
    # poured and settled at the fill's contacts (their pairs; its rolling law is the run's), the run's switched on
    # before the outlet opens
    fill = case.fill_materials
    context["fill_pairs"] = (materials_context(case, fill, gravity=gravity)["pairs"] if fill is not None else None)
    context.update({
        "title": f"siloflow-silo_flat-{case.run_id}",
        "exploded_speed": exploded_speed(case.domain_top + case.sink_depth, case.fill.insertion_velocity),
        "half_width": half_width,
        "depth": case.depth,
        "sink_bottom": -case.sink_depth,
        "domain_top": case.domain_top,
        "primitive_walls": [
            {"id": "wall_left", "axis": 0, "position": -half_width, "material": side},
            {"id": "wall_right", "axis": 0, "position": half_width, "material": side},
            {"id": "wall_front", "axis": 1, "position": 0.0, "material": front_back},
            {"id": "wall_back", "axis": 1, "position": case.depth, "material": front_back},
        ],
        "meshes": [{"id": name, "material": bottom} for name in silo_meshes(case)],
        "geometry_path": GEOMETRY_PATH,
        "gate_mesh": "outlet_gate",
        "fill": {
            "seed": case.seeds[2],
            "zone": list(case.fill.zone),
            "n_clumps": case.fill.n_clumps,
            "clumps_per_insertion": case.fill.clumps_per_insertion,
            "insert_every": case.fill.insert_every,
            "insertion_velocity": case.fill.insertion_velocity,
            "steps": case.fill.fill_steps,
            "max_extra_insertions": int(np.ceil(case.fill.n_clumps / case.fill.clumps_per_insertion)) + 10,
        },
        "settle": {"threshold": case.settle_threshold, "check_steps": case.settle_check_steps,
                   "max_checks": case.settle_max_checks},
        "settled_fill": {"steps": 200},
        "discharge": {"steps": case.discharge_steps, "stage": "discharge", "marker": "discharged"},
        "sample_every": case.dump_every,
        "restart_every": restart_every(case.discharge_steps),
        "fill_restart_every": restart_every(case.fill.fill_steps),
        "wall_forces_path": WALL_FORCES_NAME,
        # the settled fill, kept for the runs that start from it (the recirculating silo's; the others set None), and
        # the assembly a run starts from (None: it pours its own)
        "assembly_state": ASSEMBLY_STATE,
        "assembly": None,
        "paths": {"dumps": DUMP_PREFIX, "settled": SETTLED_FILL_PREFIX, "restart": RESTART_DIR,
                  "resume_stem": RESUME_STEM},
    })
    return context


def render_silo_script(case: SiloCase) -> str:
    """The YADE script of a flat-bottom silo run."""
    check_silo_case(case)
    return render_deck("yade/silo_flat.py.j2", silo_script_context(case))


def write_silo_inputs(case: SiloCase, deck_dir: str | Path) -> Path:
    """Write the script and ``case.json`` into ``deck_dir``; returns the script path."""
    return write_script_inputs(case.summary(), render_silo_script(case), deck_dir, silo_meshes(case))


def run_silo_type(silo: SiloCase, case_kind: str, run_id: str, run_dir: str | Path, options: YadeOptions,
                  last_stage: str = "discharged", clumps_conserved: bool = False, labels: dict | None = None,
                  domain_z: list | None = None, then: str | None = None, assembled: bool = False) -> RunRecord:
    """Run a rendered silo-type script (flat-bottom, recirculating, blender), check it as every engine's silo-type
    runs are (:func:`siloflow.engines.silo_checks.check_silo_run`; ``assembled``: it started from another run's
    settled fill) and write ``run.json``; returns the record."""
    return run_script_checked(
        run_dir, options, expected_simulated_time(silo, assembled),
        lambda markers, dumps: check_silo_run(silo, markers, dumps, Path(run_dir), last_stage=last_stage,
                                              clumps_conserved=clumps_conserved, then=then, assembled=assembled),
        lambda checked: silo_run_record(ENGINE_NAME, case_kind, run_id, checked, labels, domain_z),
    )


def run_silo(case: SiloCase, run_dir: str | Path, options: YadeOptions) -> RunRecord:
    """Run a rendered flat-bottom silo script, check it and write ``run.json``; returns the record."""
    return run_silo_type(case, "silo_flat", case.run_id, run_dir, options)
