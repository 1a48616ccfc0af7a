"""Snakemake adapter: run LIGGGHTS on one recirculation deck and check that no clump was lost."""

from pathlib import Path

from engines.blending import recirculation_case_for_run
from engines.liggghts_blending import run_recirculation
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = recirculation_case_for_run(snakemake.config, snakemake.wildcards.run)
    record_path = run_recirculation(case, Path(snakemake.output.record).parent, **snakemake.params.engine)
    log.info("run complete: %s", record_path)
