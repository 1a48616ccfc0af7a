"""Snakemake adapter: the bulk friction of every sweep point in one table (siloflow.calibration.table)."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_flow_table
from siloflow.calibration.table import point_table
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows = point_table([json.loads(Path(path).read_text()) for path in snakemake.input.summaries])
    write_flow_table(snakemake.output.table, rows)
    log.info("%d sweep points -> %s", len(rows), snakemake.output.table)
