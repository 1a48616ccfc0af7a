"""The calibration table: one row per sweep point from the bulk friction summaries of its runs.

Each run's ``metrics/bulk_friction.json`` is a flat record (:func:`siloflow.calibration.shear_record.bulk_friction_summary` plus
its point). A point run with several seeds (the sweep's reference point) becomes one row: the mean of each figure,
its error (the larger of the seeds' standard error and the within-run errors), the seeds' standard deviation and
``replicates`` (:func:`siloflow.analysis.numerics.replicates.combine_replicates`); it reached a steady shear window only when
every seed did. Pure: summaries in, rows out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from siloflow.analysis.numerics.replicates import combine_replicates
from siloflow.calibration.shear_record import combined_window_method

__all__ = ["POINT_COLUMNS", "point_table"]

#: The columns that name a sweep point in the table.
POINT_COLUMNS = ("shape", "test", "wall_material", "lid", "rolling_friction", "restitution", "rotation_blocked",
                 "particle_friction", "shear_velocity", "pour")
#: The columns the table puts first, where a row has them.
LEADING = ("shape", "test", "wall_material", "lid", "rolling_friction", "restitution", "rotation_blocked",
           "particle_friction", "bulk_friction", "bulk_friction_error", "bulk_friction_stderr",
           "bulk_friction_angle_deg", "bulk_friction_angle_deg_error")


def point_table(summaries: Sequence[Mapping]) -> list[dict]:
    """One row per sweep point, sorted by shape, test, rolling friction, restitution, rotation and particle friction.

    Parameters
    ----------
    summaries : sequence of mapping
        The runs' bulk friction summaries, each with :data:`POINT_COLUMNS` and ``window_method``.

    Raises
    ------
    KeyError
        If a summary lacks a point column (the message names it).
    """
    rows = combine_replicates(summaries, list(POINT_COLUMNS))
    for row in rows:
        row["window_method"] = combined_window_method(
            [summary["window_method"] for summary in summaries if all(summary[key] == row[key] for key in POINT_COLUMNS)])
    rows.sort(key=lambda row: (row["shape"], row["test"], row["rolling_friction"], row["restitution"],
                               row["rotation_blocked"], row["particle_friction"]))
    # a summary written before the errors existed lacks their keys: its row leaves those cells empty
    return [{**{key: row[key] for key in LEADING if key in row}, **row} for row in rows]
