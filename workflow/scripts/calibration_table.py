"""Snakemake adapter: collect the bulk friction of every sweep point into one table."""

import json
from pathlib import Path

from analysis.tables import write_flow_table
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows = [json.loads(Path(path).read_text()) for path in snakemake.input.summaries]
    rows.sort(key=lambda row: (row["shape"], row["test"], row["rolling_friction"], row["restitution"],
                               row["rotation_blocked"], row["particle_friction"]))
    write_flow_table(snakemake.output.table, rows)
    log.info("%d sweep points -> %s", len(rows), snakemake.output.table)
