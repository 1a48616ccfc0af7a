"""Snakemake adapter: collect the bulk friction of every sweep point into one table."""

import json
from pathlib import Path

from analysis.io.tables import write_flow_table
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows = [json.loads(Path(path).read_text()) for path in snakemake.input.summaries]
    rows.sort(key=lambda row: (row["shape"], row["test"], row["rolling_friction"], row["restitution"],
                               row["rotation_blocked"], row["particle_friction"]))
    leading = ["shape", "test", "wall_material", "lid", "rolling_friction", "restitution", "rotation_blocked",
               "particle_friction", "bulk_friction", "bulk_friction_error", "bulk_friction_stderr",
               "bulk_friction_angle_deg", "bulk_friction_angle_deg_error"]
    # a summary written before the errors existed lacks their keys: its row leaves those cells empty
    rows = [{**{key: row[key] for key in leading if key in row}, **row} for row in rows]
    write_flow_table(snakemake.output.table, rows)
    log.info("%d sweep points -> %s", len(rows), snakemake.output.table)
