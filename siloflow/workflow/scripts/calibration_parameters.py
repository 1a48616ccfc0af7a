"""Snakemake adapter: invert the calibration chart at the measured bulk friction angles."""

import json
from pathlib import Path

import yaml

from siloflow.calibration.inversion import curves_from_table, invert_calibration
from siloflow.calibration.sweep import chart_rows
from siloflow.calibration.table import point_table
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration = snakemake.params.calibration
    rows = chart_rows(point_table([json.loads(Path(path).read_text()) for path in snakemake.input.summaries]),
                      snakemake.params.base_restitution, snakemake.params.lid, snakemake.params.shear_velocity)
    curves = curves_from_table(rows)
    tested = {"internal" if c.test == "internal" else c.wall_material for c in curves}
    targets = {name: angle for name, angle in calibration["targets_deg"].items() if name in tested}
    skipped = sorted(set(calibration["targets_deg"]) - set(targets))
    if skipped:
        log.warning("no shear test for %s: those targets are not inverted", ", ".join(skipped))
    parameters = invert_calibration(curves, targets, calibration["tolerance_deg"], shape=calibration["shape"],
                                    rolling_friction=calibration["rolling_friction"], record_unreachable=True)
    for name, reason in parameters["unreachable"].items():
        log.warning("target %s: %s", name, reason)
    parameters["not_tested"] = skipped
    with open(snakemake.output.parameters, "w") as handle:
        yaml.safe_dump(parameters, handle, sort_keys=False)
    log.info("parameters: %s", parameters)
