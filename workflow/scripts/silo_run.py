"""Snakemake adapter: run LIGGGHTS on one flat-bottom silo deck and check the run."""

from pathlib import Path

from calibration.parameters import calibrated_config
from engines.liggghts.silo_flat import run_silo
from engines.estimates import estimate_silo_case
from engines.logs import logged_to
from engines.planning import cost_model, preflight
from engines.cases.silo_flat import silo_case_for_run

with logged_to(snakemake.log[0]) as log:
    config = calibrated_config(snakemake.config, snakemake.input.get("parameters"))
    case = silo_case_for_run(config, snakemake.wildcards.run)
    engine = snakemake.params.engine
    estimate = estimate_silo_case(case, snakemake.params.engine["mpi_ranks"], cost_model(config))
    log.info(preflight(config, estimate, Path(snakemake.output.record).parent))
    run_silo(case, Path(snakemake.output.record).parent, **engine)
