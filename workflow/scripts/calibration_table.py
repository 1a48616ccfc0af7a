"""Snakemake adapter: collect the bulk friction of every sweep point into one table, one row per point (a point run
with several seeds as their mean, its error and their standard deviation)."""

import json
from pathlib import Path

from analysis.io.tables import write_flow_table
from analysis.numerics.replicates import combine_replicates
from calibration.friction import combined_window_method
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    runs = [json.loads(Path(path).read_text()) for path in snakemake.input.summaries]
    point = ["shape", "test", "wall_material", "lid", "rolling_friction", "restitution", "rotation_blocked",
             "particle_friction", "shear_velocity"]
    rows = combine_replicates(runs, point)
    for row in rows:
        # a point is steady only when every seed's shear reached a steady window
        row["window_method"] = combined_window_method([run["window_method"] for run in runs
                                                       if all(run[key] == row[key] for key in point)])
    rows.sort(key=lambda row: (row["shape"], row["test"], row["rolling_friction"], row["restitution"],
                               row["rotation_blocked"], row["particle_friction"]))
    leading = ["shape", "test", "wall_material", "lid", "rolling_friction", "restitution", "rotation_blocked",
               "particle_friction", "bulk_friction", "bulk_friction_error", "bulk_friction_stderr",
               "bulk_friction_angle_deg", "bulk_friction_angle_deg_error"]
    # a summary written before the errors existed lacks their keys: its row leaves those cells empty
    rows = [{**{key: row[key] for key in leading if key in row}, **row} for row in rows]
    write_flow_table(snakemake.output.table, rows)
    log.info("%d sweep points -> %s", len(rows), snakemake.output.table)
