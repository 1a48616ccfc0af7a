"""Snakemake adapter: gravity scaling of every configuration run at several gravity factors."""

import json
from pathlib import Path

from siloflow.analysis.studies.blender.plots import plot_gravity_scaling
from siloflow.analysis.studies.blender.tables import gravity_rows
from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.studies.validation.figure_findings import gravity_findings
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    summaries = [json.loads(Path(path).read_text()) for path in snakemake.input.summaries]
    rows, curves, skipped = gravity_rows(summaries, tolerance=0.1)
    for configuration, factors in skipped:
        log.info("%s: gravity factors %s, no scaling without 1 g and another factor", configuration, factors)
    if not rows:
        raise ValueError("no configuration was run at gravity factor 1 and another factor; set blender.gravity_factors")
    write_flow_table(snakemake.output.table, rows)
    plot_gravity_scaling(curves, snakemake.output.plot, "Gravity scaling: mean v_z of the silo content",
                         quantity="mean v_z", findings=gravity_findings())
    log.info("%d rows: %s", len(rows), rows)
