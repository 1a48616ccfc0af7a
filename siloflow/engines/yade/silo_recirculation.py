"""YADE scripts of the recirculating silo (blending study): the batch silo's script (:mod:`siloflow.engines.yade.silo_flat`)
with the channel below the outlet, the feeder in its lower half and a vertical boundary through which clumps leave at
the channel bottom and re-enter at the top of the domain, as the LIGGGHTS deck's periodic z.

YADE's periodic cell would also wrap x and y, so the script moves a clump that fell below the channel bottom to the
top of the domain itself (whole, with its x, y and velocity) at every feeder check. The feeder blocks the z velocity of
the clumps in its zone at the feeder velocity (x and y stay free), as the LIGGGHTS deck's ``setforce`` in z; it is
checked every :data:`FEEDER_EVERY` steps, so a clump may enter the zone up to that many steps before it is held.
"""

from __future__ import annotations

from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.silo_recirculation import CHANNEL_MESHES, RecirculationCase, recirculation_meshes
from siloflow.engines.silo_checks import recirculation_labels
from siloflow.engines.templating import render_deck
from siloflow.engines.yade.inputs import write_script_inputs
from siloflow.engines.yade.run import ASSEMBLY_STATE, YadeOptions
from siloflow.engines.yade.silo_flat import check_silo_case, run_silo_type, silo_script_context

__all__ = ["FEEDER_EVERY", "recirculation_script_context", "render_recirculation_script", "run_recirculation",
           "write_recirculation_inputs"]

#: Steps between the feeder's checks (and the re-entry of the clumps below the channel).
FEEDER_EVERY = 10


def recirculation_script_context(case: RecirculationCase) -> dict:
    """The rendering context of ``siloflow/templates/yade/silo_recirculation.py.j2``."""
    context = silo_script_context(case.silo)
    bottom = context["meshes"][0]["material"]
    context.update({
        "title": f"siloflow-silo_recirculation-{case.run_id}",
        "meshes": [{"id": name, "material": bottom} for name in recirculation_meshes(case)],
        "channel_bottom": -case.channel_length,
        "feeder": {"zone": list(case.feeder_zone), "velocity": case.feeder_velocity, "every": FEEDER_EVERY},
        # with a discharge after the recirculations, the script says "recirculated" when the re-entry stops and
        # "discharged" at the end
        "discharge": {**context["discharge"], "stage": "recirculate",
                      "marker": "discharged" if case.final_discharge_steps else "recirculated"},
        "final_discharge_steps": case.final_discharge_steps,
        "assembly_state": None,   # its own fill serves no other run
    })
    if case.assembly is not None:
        # the scene is built as the assembly's run built it (so its walls keep their ids), the channel added once loaded
        added = [mesh for mesh in context["meshes"] if mesh["id"] in CHANNEL_MESHES]
        context["meshes"] = [mesh for mesh in context["meshes"] if mesh["id"] not in CHANNEL_MESHES]
        context["assembly"] = {"state_file": f"deck/{ASSEMBLY_STATE}", "added_meshes": added}
    return context


def render_recirculation_script(case: RecirculationCase) -> str:
    """The YADE script of a recirculation run."""
    check_silo_case(case.silo)
    return render_deck("yade/silo_recirculation.py.j2", recirculation_script_context(case))


def write_recirculation_inputs(case: RecirculationCase, deck_dir: str | Path) -> Path:
    """Write the script, the meshes and ``case.json`` into ``deck_dir``; returns the script path."""
    return write_script_inputs(case.summary(), render_recirculation_script(case), deck_dir, recirculation_meshes(case))


def run_recirculation(case: RecirculationCase, run_dir: str | Path, options: YadeOptions) -> RunRecord:
    """Run a rendered recirculation script, check it (the batch silo's checks, no clump lost while recirculating,
    the discharge after the recirculations finished where the case has one) and write ``run.json``; returns the
    record."""
    return run_silo_type(case.silo, "silo_recirculation", case.run_id, run_dir, options, last_stage="recirculated",
                         clumps_conserved=True, then="discharged" if case.final_discharge_steps else None,
                         labels=recirculation_labels(case), domain_z=[-case.channel_length, case.silo.domain_top],
                         assembled=case.assembly is not None)
