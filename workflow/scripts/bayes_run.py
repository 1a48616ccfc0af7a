"""Snakemake adapter: render and run one Jenike run of the Bayesian calibration on its engine (run.json last)."""

from pathlib import Path

from calibration.bayes.runs import engine_config
from engines.logs import logged_to
from engines.runs import render_run, run_case

with logged_to(snakemake.log[0]):
    config = engine_config(snakemake.config, snakemake.wildcards.engine)
    run_dir = Path(snakemake.output.record).parent
    render_run(config, "jenike", snakemake.params.case, run_dir)
    run_case(config, "jenike", snakemake.params.case, run_dir)
