"""Snakemake adapter: one calibration chart (bulk versus particle friction) of one shape and test."""

import json
from pathlib import Path

from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.figure_findings import calibration_chart_findings
from siloflow.calibration.charts import plot_calibration_chart
from siloflow.calibration.inversion import curves_from_table
from siloflow.calibration.sweep import chart_rows
from siloflow.calibration.table import point_table
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration, params = snakemake.params.calibration, snakemake.params
    rows = chart_rows(point_table([json.loads(Path(path).read_text()) for path in snakemake.input.summaries]),
                      params.base_restitution, params.lid, params.shear_velocity)
    curves = curves_from_table(rows)
    shape, test = snakemake.wildcards.chart.split("_", 1)
    target = calibration["targets_deg"].get(test)
    plot_calibration_chart(curves, snakemake.output.chart,
                           title=f"{shape}, {'internal friction' if test == 'internal' else test + ' wall friction'}",
                           target_angle_deg=target, tolerance_deg=calibration["tolerance_deg"] if target else None,
                           findings=calibration_chart_findings(
                               shape, test, AgreementTolerances.from_config(params.validation)))
    log.info("chart %s: %d curves", snakemake.output.chart, len(curves))
