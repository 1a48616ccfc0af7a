"""Snakemake adapter: the Bayesian posterior's mean on one engine as the parameters a silo takes
(``silo_flat.parameters: bayesian``), in the layout of the chart inversion's parameters.yaml, and the posterior draws of
the predictive check in the same layout (``silo_flat.posterior_draws``)."""

import json
from pathlib import Path

import yaml

from siloflow.calibration.bayes.joint import calibration_of, draw_estimates, point_estimate
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration = calibration_of(snakemake.config)
    engine = snakemake.wildcards.engine
    parameters = point_estimate(calibration, json.loads(Path(snakemake.input.posterior).read_text()), engine)
    draws = draw_estimates(calibration, json.loads(Path(snakemake.input.predictive_design).read_text())["sets"], engine)
    for path, content in ((snakemake.output.parameters, parameters), (snakemake.output.draws, draws)):
        with open(path, "w", encoding="utf-8") as handle:
            yaml.safe_dump(content, handle, sort_keys=False)
    log.info("parameters: %s; %d posterior draws", parameters, len(draws))
