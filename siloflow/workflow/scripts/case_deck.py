"""Snakemake adapter: the engine inputs of one run of any case (deck/case.json written last), from the case the
workflow built; a run that starts from another run's settled fill gets that run's record as its ``assembly`` input."""

from pathlib import Path

from siloflow.engines.logs import logged_to
from siloflow.engines.runs import render_run

with logged_to(snakemake.log[0]):
    assembly = snakemake.input.get("assembly")
    render_run(snakemake.config, snakemake.params.kind, snakemake.params.case, Path(snakemake.output.case).parent.parent,
               Path(assembly).parent if assembly else None)
