"""Snakemake adapter: one iteration's posterior of the Bayesian calibration on one engine, from every run so far
(posterior.npz: the samples; posterior.json: their summary, the seed noise, the sampler's diagnostics and how far
the posterior moved)."""

import json
from pathlib import Path

import numpy as np

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.bayes.joint import calibration_of, iterate, with_targets
from siloflow.calibration.bayes.runs import completed_sets, failed_runs, observations
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration = calibration_of(snakemake.config)
    if snakemake.input.targets:  # a twin experiment: the engine's own angles at the truth
        calibration = with_targets(calibration, json.loads(Path(snakemake.input.targets[0]).read_text())["targets_deg"])
    sets = [chosen for path in snakemake.input.designs for chosen in json.loads(Path(path).read_text())["sets"]]
    summaries = {summary["run_id"]: summary
                 for summary in (json.loads(Path(path).read_text()) for path in snakemake.input.summaries)}
    failed = failed_runs(sets, summaries)
    for run in failed:
        log.warning("left out: the set %s, whose %s run %s failed", run["theta"], run["test"], run["run_id"])
    sets = completed_sets(sets, summaries)
    theta, angles, errors = observations(calibration, sets, summaries)
    previous = np.load(snakemake.input.previous[0])["samples"] if snakemake.input.previous else None
    result = iterate(calibration, theta, angles, errors, previous)
    np.savez(snakemake.output.samples, samples=result.sample.samples, log_probability=result.sample.log_probability)
    summary = {"iteration": int(snakemake.wildcards.iteration), "sets": len(sets),
               "runs": len(sets) * len(calibration.tests), "failed_runs": failed, **result.summary(calibration)}
    write_json(snakemake.output.summary, summary)
    log.info("iteration %s: %d sets; posterior means %s; seed noise %s deg; moved %s (shift %s)",
             snakemake.wildcards.iteration, len(sets),
             {name: round(value["mean"], 4) for name, value in summary["parameters"].items()},
             summary["seed_sd_deg"], result.moved, result.shift)
