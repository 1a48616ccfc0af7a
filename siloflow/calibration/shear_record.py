"""The record of one Jenike shear test (``metrics/bulk_friction.json``): its sweep point and its bulk friction figures
(:func:`shear_test_summary`), and the window method of a point run with several seeds. Pure: a
:class:`~siloflow.calibration.friction.BulkFriction` in, flat dicts out (the writer is the workflow's script).
"""

from __future__ import annotations

from siloflow.calibration.friction import SECOND_HALF, STEADY, BulkFriction

__all__ = ["combined_window_method", "shear_test_summary", "bulk_friction_summary"]


def combined_window_method(methods) -> str:
    """The window method of a point run with several seeds: :data:`STEADY` only when every seed's shear reached a
    steady window, else :data:`SECOND_HALF`.

    Raises
    ------
    ValueError
        Without methods, or with one that is neither.
    """
    methods = list(methods)
    unknown = sorted(set(methods) - {STEADY, SECOND_HALF})
    if not methods or unknown:
        raise ValueError(f"window methods must be {STEADY!r} or {SECOND_HALF!r}, at least one; got {methods!r}")
    return STEADY if all(method == STEADY for method in methods) else SECOND_HALF


def shear_test_summary(point: dict, run_id: str, n_clumps: int, friction: BulkFriction, window_method: str) -> dict:
    """The record of one Jenike shear test (``metrics/bulk_friction.json``): its point (shape, test, wall material,
    rolling friction, restitution, rotation, lid, particle friction, shear velocity in m/s, pour), the bulk friction
    figures of :func:`bulk_friction_summary` and the clumps sheared."""
    test = "internal" if point["test"] == "internal" else "wall"
    return {
        "run_id": run_id,
        "shape": point["shape"],
        "test": test,
        "wall_material": "" if test == "internal" else point["test"],
        "rolling_friction": point["rolling_friction"],
        "restitution": point["restitution"],
        "rotation_blocked": point["rotation_blocked"],
        "lid": point["lid"],
        "particle_friction": point["sliding_friction"],
        "shear_velocity": point["shear_velocity"],
        "pour": point["pour"],
        **bulk_friction_summary(friction, window_method),
        "n_clumps": n_clumps,
    }


def bulk_friction_summary(friction: BulkFriction, window_method: str) -> dict:
    """The bulk friction figures of one shear test as a flat record (``metrics/bulk_friction.json``).

    Each ``<key>_error`` is the standard error of ``<key>`` in its unit: the batch-means error of the ratio
    over the steady shear-stress/normal-stress window (:func:`bulk_friction`), and for the angle its first-order
    propagation (:attr:`BulkFriction.angle_standard_error_deg`). ``bulk_friction_stderr`` is the same error under
    its old name, kept for the readers of that key.

    Parameters
    ----------
    friction : BulkFriction
        The bulk friction of the test.
    window_method : str
        How the window was chosen (``"steady"`` or ``"second half"``, :func:`bulk_friction_of_shear`).

    Returns
    -------
    dict
        ``bulk_friction`` [-], ``bulk_friction_error`` [-], ``bulk_friction_stderr`` [-],
        ``bulk_friction_angle_deg`` [deg], ``bulk_friction_angle_deg_error`` [deg], ``bottom_bulk_friction`` [-],
        ``bottom_bulk_friction_error`` [-], ``ring_sides_relative_difference`` [-], ``window_start_s``,
        ``window_end_s`` [s], ``window_samples`` [-] and ``window_method``.
    """
    return {
        "bulk_friction": friction.coefficient,
        "bulk_friction_error": friction.standard_error,
        "bulk_friction_stderr": friction.standard_error,
        "bulk_friction_angle_deg": friction.angle_deg,
        "bulk_friction_angle_deg_error": friction.angle_standard_error_deg,
        "bottom_bulk_friction": friction.bottom_coefficient,
        "bottom_bulk_friction_error": friction.bottom_standard_error,
        "ring_sides_relative_difference": friction.relative_difference,
        "window_start_s": friction.window.t_start,
        "window_end_s": friction.window.t_end,
        "window_samples": friction.window.i_end - friction.window.i_start,
        "window_method": window_method,
    }
