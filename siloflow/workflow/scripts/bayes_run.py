"""Snakemake adapter: render and run one Jenike run of the Bayesian calibration on its engine (run.json last), and
write its outcome: completed, or the engine's error (an unstable run does not stop the calibration)."""

from pathlib import Path

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.bayes.runs import engine_config
from siloflow.engines.interface import EngineRunError
from siloflow.engines.logs import logged_to
from siloflow.engines.runs import render_run, run_case

with logged_to(snakemake.log[0]) as log:
    config = engine_config(snakemake.config, snakemake.wildcards.engine)
    case = snakemake.params.case
    run_dir = Path(snakemake.output.outcome).parent
    render_run(config, "jenike", case, run_dir)
    try:
        run_case(config, "jenike", case, run_dir)
        outcome = {"run_id": case.run_id, "completed": True, "error": None}
    except EngineRunError as error:
        log.warning("run %s failed; its set is left out of the posterior: %s", case.run_id, error)
        outcome = {"run_id": case.run_id, "completed": False, "error": str(error)}
    write_json(snakemake.output.outcome, outcome)
