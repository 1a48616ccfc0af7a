"""Snakemake adapter: the twin experiment's targets on one engine, the mean bulk friction angle of its runs at the
known parameters per test (twin/targets.json, with the truth)."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.bayes.joint import calibration_of, twin_targets, twin_truth
from siloflow.calibration.bayes.runs import observations
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration = calibration_of(snakemake.config)
    summaries = {summary["run_id"]: summary
                 for summary in (json.loads(Path(path).read_text()) for path in snakemake.input.summaries)}
    _, angles, _ = observations(calibration, snakemake.params.sets, summaries)
    targets = {**twin_targets(calibration, angles), "truth": dict(zip(calibration.names, twin_truth(calibration).tolist())),
               "runs": len(snakemake.params.sets) * len(calibration.tests)}
    write_json(snakemake.output.targets, targets)
    log.info("twin targets %s (standard errors %s) at the truth %s", targets["targets_deg"],
             targets["standard_error_deg"], targets["truth"])
