"""Snakemake adapter: the Bayesian posterior's mean on one engine as the parameters a silo takes
(``silo_flat.parameters: bayesian``), in the layout of the chart inversion's parameters.yaml."""

import json
from pathlib import Path

import yaml

from calibration.bayes.joint import calibration_of, point_estimate
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    parameters = point_estimate(calibration_of(snakemake.config), json.loads(Path(snakemake.input.posterior).read_text()),
                                snakemake.wildcards.engine)
    with open(snakemake.output.parameters, "w", encoding="utf-8") as handle:
        yaml.safe_dump(parameters, handle, sort_keys=False)
    log.info("parameters: %s", parameters)
