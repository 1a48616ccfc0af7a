"""Snakemake adapter: run LIGGGHTS on one blender deck and check it."""

from pathlib import Path

from engines.blender import blender_case_for_run
from engines.liggghts_blender import run_blender
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = blender_case_for_run(snakemake.config, snakemake.wildcards.run)
    record_path = run_blender(case, Path(snakemake.output.record).parent, **snakemake.params.engine)
    log.info("run complete: %s", record_path)
