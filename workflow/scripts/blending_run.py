"""Snakemake adapter: run LIGGGHTS on one recirculation deck and check that no clump was lost."""

from pathlib import Path

from engines.cases.silo_recirculation import recirculation_case_for_run
from engines.liggghts.silo_recirculation import run_recirculation
from engines.estimates import estimate_recirculation_case
from engines.logs import logged_to
from engines.planning import cost_model, preflight

with logged_to(snakemake.log[0]) as log:
    case = recirculation_case_for_run(snakemake.config, snakemake.wildcards.run)
    estimate = estimate_recirculation_case(case, snakemake.params.engine["mpi_ranks"], cost_model(snakemake.config))
    log.info(preflight(snakemake.config, estimate, Path(snakemake.output.record).parent))
    run_recirculation(case, Path(snakemake.output.record).parent, **snakemake.params.engine)
