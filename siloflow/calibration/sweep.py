"""The calibration sweep after its runs: which rows of its table make the charts and the lid comparison.

The sweep points themselves (the Jenike runs a configuration asks for), their roles and which get diagnostics are
designed by :mod:`siloflow.model.cases.jenike_sweep`.

A sweep point is a plain dict (it keys the run and travels through Snakemake unchanged)::

    {"shape": "sphere2", "test": "internal" | <wall material>, "sliding_friction": 0.3,
     "rolling_friction": 0.1, "restitution": 0.1, "rotation_blocked": False}
"""

from __future__ import annotations

from siloflow.model.cases.jenike_sweep import configured_pour

INTERNAL = "internal"

def chart_rows(rows, base_restitution: float, lid: str, shear_velocity: float) -> list[dict]:
    """Rows of the calibration table (as read from CSV) that belong on the chart.

    The chart holds the base restitution, free rotation, the configured lid, the configured shear velocity (m/s) and
    the configured pour; the sensitivity, rotation-blocked, lid-comparison, shear-speed and pour-variant rows are left
    out.
    """
    return [
        row
        for row in rows
        if float(row["restitution"]) == base_restitution
        and str(row["rotation_blocked"]) == "False"
        and row["lid"] == lid
        and float(row["shear_velocity"]) == shear_velocity
        and configured_pour(row)
    ]


def lid_comparison(rows, base_restitution: float, shear_velocity: float) -> list[dict]:
    """Pair the internal-friction results of the two lids at the same shape, rolling and sliding friction.

    Parameters
    ----------
    rows : iterable of dict
        Calibration table rows (strings as read from CSV are fine) with ``lid`` and ``bulk_friction``.
    base_restitution : float
        Only rows at this restitution, with free rotation, are compared.
    shear_velocity : float
        Only rows sheared at this velocity (m/s) are compared.

    Returns
    -------
    list of dict
        One row per pair: shape, rolling_friction, particle_friction, bulk friction with each lid and the
        servo-minus-rigid difference (dimensionless), sorted.
    """
    by_lid: dict[tuple, dict[str, float]] = {}
    for row in rows:
        if row["test"] != "internal" or str(row["rotation_blocked"]) != "False" or not configured_pour(row):
            continue
        if float(row["restitution"]) != base_restitution or float(row["shear_velocity"]) != shear_velocity:
            continue
        key = (row["shape"], float(row["rolling_friction"]), float(row["particle_friction"]))
        by_lid.setdefault(key, {})[row["lid"]] = float(row["bulk_friction"])
    paired = []
    for (shape, rolling, particle), lids in sorted(by_lid.items()):
        if {"rigid", "servo"} <= set(lids):
            paired.append(
                {
                    "shape": shape,
                    "rolling_friction": rolling,
                    "particle_friction": particle,
                    "bulk_friction_rigid_lid": lids["rigid"],
                    "bulk_friction_servo_lid": lids["servo"],
                    "servo_minus_rigid": lids["servo"] - lids["rigid"],
                }
            )
    return paired
