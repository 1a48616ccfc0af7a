"""Snakemake adapter: run LIGGGHTS on one Jenike shear-cell deck and check the run."""

from pathlib import Path

from engines.cases.jenike import build_jenike_case
from engines.liggghts.jenike import run_jenike
from engines.estimates import estimate_jenike_case
from engines.logs import logged_to
from engines.planning import cost_model, preflight

with logged_to(snakemake.log[0]) as log:
    case = build_jenike_case(snakemake.config, snakemake.params.point)
    estimate = estimate_jenike_case(case, snakemake.params.engine["mpi_ranks"], cost_model(snakemake.config))
    log.info(preflight(snakemake.config, estimate, Path(snakemake.output.record).parent))
    run_jenike(case, Path(snakemake.output.record).parent, **snakemake.params.engine)
