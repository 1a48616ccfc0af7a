"""Snakemake adapter: run LIGGGHTS on one blender deck and check it."""

from pathlib import Path

from engines.cases.blender import blender_case_for_run
from engines.liggghts.blender import run_blender
from engines.estimates import estimate_blender_case
from engines.logs import logged_to
from engines.planning import cost_model, preflight

with logged_to(snakemake.log[0]) as log:
    case = blender_case_for_run(snakemake.config, snakemake.wildcards.run)
    estimate = estimate_blender_case(case, snakemake.params.engine["mpi_ranks"], cost_model(snakemake.config))
    log.info(preflight(snakemake.config, estimate, Path(snakemake.output.record).parent))
    run_blender(case, Path(snakemake.output.record).parent, **snakemake.params.engine)
