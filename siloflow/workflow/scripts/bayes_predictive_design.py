"""Snakemake adapter: the parameter sets of the posterior predictive check on one engine (draws from the final
posterior, on fresh seeds, with the surrogates' prediction at each), with their runs."""

import numpy as np

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.bayes.joint import calibration_of, predictive_sets
from siloflow.calibration.bayes.runs import with_runs
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration = calibration_of(snakemake.config)
    posterior = np.load(snakemake.input.samples)
    sets = predictive_sets(calibration, posterior["samples"], posterior["predicted_mean"], posterior["predicted_std"])
    write_json(snakemake.output.design, {"engine": snakemake.wildcards.engine, "stopped": False, "reason": "",
                                         "parameters": list(calibration.names),
                                         "sets": with_runs(snakemake.config, calibration, sets,
                                                           snakemake.wildcards.engine)})
    log.info("%d posterior draws to run", len(sets))
