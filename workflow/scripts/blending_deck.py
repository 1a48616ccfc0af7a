"""Snakemake adapter: render the deck, meshes and case summary of one recirculation run."""

from pathlib import Path

from engines.cases.silo_recirculation import recirculation_case_for_run
from engines.liggghts.silo_recirculation import write_recirculation_inputs
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = recirculation_case_for_run(snakemake.config, snakemake.wildcards.run)
    deck = write_recirculation_inputs(case, Path(snakemake.output.deck).parent)
    log.info("deck %s: %s (%s), %d clumps, a-priori t_res %.3g s, recirculating %.3g s at V_out %.3g m/s",
             deck, case.pattern, case.role, case.silo.fill.n_clumps, case.estimated_residence_time,
             case.recirculation_time, case.feeder_velocity)
