"""Snakemake adapter: the parameter sets of one iteration of the Bayesian calibration on one engine (design.json): the
first design, or the next sets where the previous posterior has mass and at its mode, or none when the previous
iteration decided to stop (two iterations in a row that did not move, their new runs as predicted), the iterations
ran out or the budget is spent."""

import json
from pathlib import Path

import numpy as np

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.bayes.joint import calibration_of, first_design, next_sets
from siloflow.calibration.bayes.runs import with_runs
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    config = snakemake.config
    calibration = calibration_of(config)
    settings = calibration.settings
    engine, iteration = snakemake.wildcards.engine, int(snakemake.wildcards.iteration)
    stopped, reason, sets = False, "", []
    if iteration == 0:
        sets = first_design(calibration)
    else:
        previous = json.loads(Path(snakemake.input.previous[0]).read_text())
        posterior = np.load(snakemake.input.previous[1])
        done = [chosen for path in snakemake.input.previous[2:] for chosen in json.loads(Path(path).read_text())["sets"]]
        if iteration > settings["max_iterations"]:
            stopped, reason = True, f"calibration.bayesian.max_iterations ({settings['max_iterations']}) reached"
        elif previous["stop"]:
            stopped, reason = True, previous["stop_reason"]
        else:
            sets = next_sets(calibration, posterior["samples"], posterior["log_probability"],
                             [chosen["theta"] for chosen in done], len(done), iteration)
            if not sets:
                stopped, reason = True, f"the budget of calibration.bayesian.max_sets ({settings['max_sets']}) is spent"
    write_json(snakemake.output.design, {"engine": engine, "iteration": iteration, "stopped": stopped,
                                         "reason": reason, "parameters": list(calibration.names),
                                         "sets": with_runs(config, calibration, sets, engine)})
    log.info("iteration %d on %s: %s", iteration, engine, reason if stopped else f"{len(sets)} parameter sets")
