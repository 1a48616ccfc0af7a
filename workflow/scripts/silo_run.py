"""Snakemake adapter: run LIGGGHTS on one flat-bottom silo deck and check the run."""

from pathlib import Path

from calibration.parameters import calibrated_config
from engines.liggghts import run_silo
from engines.logs import logged_to
from engines.silo import silo_case_for_run

with logged_to(snakemake.log[0]) as log:
    config = calibrated_config(snakemake.config, snakemake.input.get("parameters"))
    case = silo_case_for_run(config, snakemake.wildcards.run)
    engine = snakemake.params.engine
    record_path = run_silo(case, Path(snakemake.output.record).parent, **engine)
    log.info("run complete: %s", record_path)
