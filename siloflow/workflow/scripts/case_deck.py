"""Snakemake adapter: the engine inputs of one run of any case (deck/case.json written last), from the case the
workflow built."""

from pathlib import Path

from siloflow.engines.logs import logged_to
from siloflow.engines.runs import render_run

with logged_to(snakemake.log[0]):
    render_run(snakemake.config, snakemake.params.kind, snakemake.params.case, Path(snakemake.output.case).parent.parent)
