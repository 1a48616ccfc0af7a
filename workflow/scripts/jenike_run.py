"""Snakemake adapter: run LIGGGHTS on one Jenike shear-cell deck and check the run."""

from pathlib import Path

from engines.jenike import build_jenike_case
from engines.liggghts_jenike import run_jenike
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = build_jenike_case(snakemake.config, snakemake.params.point)
    record = run_jenike(case, Path(snakemake.output.record).parent, **snakemake.params.engine)
    log.info("run complete: %s", record)
