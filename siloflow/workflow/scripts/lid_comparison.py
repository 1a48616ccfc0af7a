"""Snakemake adapter: compare bulk friction measured with the rigid and the servo lid on the same points."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_flow_table
from siloflow.calibration.charts import plot_lid_comparison
from siloflow.calibration.sweep import lid_comparison
from siloflow.calibration.table import point_table
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows = lid_comparison(point_table([json.loads(Path(path).read_text()) for path in snakemake.input.summaries]),
                          snakemake.params.base_restitution, snakemake.params.shear_velocity)
    if not rows:
        raise ValueError("no sweep point was run with both lids; enable jenike.sweep.lid_comparison")
    write_flow_table(snakemake.output.table, rows)
    plot_lid_comparison(rows, snakemake.output.plot, "Internal friction: rigid (free) lid vs servo (flat) lid")
    for row in rows:
        log.info("%s", row)
