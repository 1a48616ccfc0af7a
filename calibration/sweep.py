"""Design of the calibration sweep: the Jenike shear-cell runs a configuration asks for.

A sweep point is a plain dict (it keys the run and travels through Snakemake unchanged)::

    {"shape": "sphere2", "test": "internal" | <wall material>, "sliding_friction": 0.3,
     "rolling_friction": 0.1, "restitution": 0.1, "rotation_blocked": False}
"""

from __future__ import annotations

INTERNAL = "internal"


def sweep_points(sweep: dict) -> list[dict]:
    """Expand the ``jenike.sweep`` section into the list of distinct sweep points.

    The grid is every shape x test x sliding friction x rolling friction at the base restitution. The
    restitution sensitivity adds, per shape and test, the middle sliding friction at the first rolling
    friction for each extra restitution; the rotation-blocked reference adds every sliding friction at the
    first rolling friction with particle rotation blocked. Duplicates are dropped, order is stable.

    Parameters
    ----------
    sweep : dict
        The validated ``jenike.sweep`` configuration section.

    Returns
    -------
    list of dict
        Sweep points (friction coefficients and restitution are dimensionless).
    """
    sliding = list(sweep["sliding_friction"])
    rolling = list(sweep["rolling_friction"])
    base_restitution = sweep["restitution"]
    points: list[dict] = []

    def add(shape, test, mu, mu_r, restitution, blocked=False):
        point = {
            "shape": shape,
            "test": test,
            "sliding_friction": float(mu),
            "rolling_friction": float(mu_r),
            "restitution": float(restitution),
            "rotation_blocked": bool(blocked),
        }
        if point not in points:
            points.append(point)

    for shape in sweep["shapes"]:
        for test in sweep["tests"]:
            for mu_r in rolling:
                for mu in sliding:
                    add(shape, test, mu, mu_r, base_restitution)
            middle = sorted(sliding)[len(sliding) // 2]
            for restitution in sweep["restitution_sensitivity"]:
                add(shape, test, middle, rolling[0], restitution)
            if sweep["rotation_blocked"]:
                for mu in sliding:
                    add(shape, test, mu, rolling[0], base_restitution, blocked=True)
    return points


def is_chart_point(point: dict, base_restitution: float) -> bool:
    """Whether a point belongs on the calibration chart (base restitution, rotation free)."""
    return point["restitution"] == base_restitution and not point["rotation_blocked"]
