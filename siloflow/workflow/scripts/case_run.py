"""Snakemake adapter: run the rendered inputs of one run of any case on its engine and check it (run.json last), from
the case the workflow built."""

from pathlib import Path

from siloflow.engines.logs import logged_to
from siloflow.engines.runs import run_case

with logged_to(snakemake.log[0]):
    run_case(snakemake.config, snakemake.params.kind, snakemake.params.case, Path(snakemake.output.record).parent)
