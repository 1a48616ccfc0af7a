"""Snakemake adapter: run the rendered inputs of one run of any case on its engine and check it (run.json last)."""

from pathlib import Path

from calibration.parameters import case_config
from engines.logs import logged_to
from engines.runs import run_case

with logged_to(snakemake.log[0]):
    config = case_config(snakemake.config, snakemake.params.case, snakemake.input.get("parameters"))
    run_case(config, snakemake.params.case, snakemake.wildcards.run, Path(snakemake.output.record).parent)
