"""Snakemake adapter: the engine inputs of one run of any case (deck/case.json written last)."""

from pathlib import Path

from calibration.parameters import case_config
from engines.logs import logged_to
from engines.runs import render_run

with logged_to(snakemake.log[0]):
    config = case_config(snakemake.config, snakemake.params.case, snakemake.input.get("parameters"))
    render_run(config, snakemake.params.case, snakemake.wildcards.run, Path(snakemake.output.case).parent.parent)
