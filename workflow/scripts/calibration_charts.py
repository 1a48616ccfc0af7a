"""Snakemake adapter: one calibration chart (bulk versus particle friction) per shape and test."""

import csv
from pathlib import Path

from calibration.charts import plot_calibration_chart
from calibration.inversion import curves_from_table
from calibration.sweep import chart_rows
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    calibration = snakemake.params.calibration
    with open(snakemake.input.table, newline="") as handle:
        rows = chart_rows(csv.DictReader(handle), snakemake.params.base_restitution, snakemake.params.lid,
                          snakemake.params.shear_velocity)
    curves = curves_from_table(rows)
    for path in snakemake.output.charts:
        shape, test = Path(path).stem.split("_", 1)
        selected = [c for c in curves if c.shape == shape and c.test == ("internal" if test == "internal" else "wall")
                    and (test == "internal" or c.wall_material == test)]
        target = calibration["targets_deg"].get(test)
        plot_calibration_chart(selected, path, title=f"{shape}, {'internal friction' if test == 'internal' else test + ' wall friction'}",
                               target_angle_deg=target, tolerance_deg=calibration["tolerance_deg"] if target else None)
        log.info("chart %s: %d curves", path, len(selected))
