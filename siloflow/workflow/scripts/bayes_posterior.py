"""Snakemake adapter: one iteration's posterior of the Bayesian calibration on one engine, from every run so far
(posterior.npz: the samples, their log posterior and the surrogates' prediction at each; posterior.json: their
summary, the seed noise, the surrogates' kernels and leave-one-out checks, the sampler's diagnostics, the warnings,
how far the posterior moved and whether the calibration stops)."""

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
        twin = json.loads(Path(snakemake.input.targets[0]).read_text())
        calibration = with_targets(calibration, twin["targets_deg"],
                                   np.column_stack([twin["angles_deg"][test] for test in calibration.tests]))
    designs = [json.loads(Path(path).read_text())["sets"] for path in snakemake.input.designs]
    sets = [chosen for design in designs for chosen in design]
    summaries = {summary["run_id"]: summary
                 for summary in (json.loads(Path(path).read_text()) for path in snakemake.input.summaries)}
    failed = failed_runs(sets, summaries)
    for run in failed:
        log.warning("left out: the set %s, whose %s run %s failed", run["theta"], run["test"], run["run_id"])
    # the previous iterations' sets first: the previous surrogates predict the rest
    earlier = completed_sets([chosen for design in designs[:-1] for chosen in design], summaries)
    sets = completed_sets(sets, summaries)
    theta, angles, errors = observations(calibration, sets, summaries)
    previous, history = None, []
    if snakemake.input.previous:
        previous = np.load(snakemake.input.previous[0])["samples"]
        history = json.loads(Path(snakemake.input.previous[1]).read_text())["moved_history"]
    result = iterate(calibration, theta, angles, errors, previous, previous_count=len(earlier),
                     moved_history=history)
    np.savez(snakemake.output.samples, samples=result.sample.samples, log_probability=result.sample.log_probability,
             predicted_mean=result.predicted_mean, predicted_std=result.predicted_std)
    summary = {"iteration": int(snakemake.wildcards.iteration), "sets": len(sets),
               "runs": len(sets) * len(calibration.tests), "failed_runs": failed, **result.summary(calibration)}
    write_json(snakemake.output.summary, summary)
    log.info("iteration %s: %d sets; posterior means %s; seed noise %s deg; moved %s (shift %s); %s",
             snakemake.wildcards.iteration, len(sets),
             {name: round(value["mean"], 4) for name, value in summary["parameters"].items()},
             summary["seed_sd_deg"], result.moved, result.shift, result.stop_reason)
    for warning in result.warnings:
        log.warning("%s", warning)
