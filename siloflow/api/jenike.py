"""The bulk friction of a Jenike shear run: its shear stage cut out of the wall force history and the friction
coefficient averaged over its steady part, as the calibration's sweep takes it.
"""

from __future__ import annotations

from siloflow.calibration.friction import BulkFriction, bulk_friction_of_shear
from siloflow.calibration.shear import shear_signals
from siloflow.api.runs import Run

__all__ = ["bulk_friction"]


def bulk_friction(run: Run) -> tuple[BulkFriction, str]:
    """The bulk friction coefficient ``mu = <F_lid + F_ring> / <F_N + W>`` of a Jenike run's shear stage.

    The shear stage lies between the record's labels ``shear_start_s`` and ``shear_end_s`` [s]; the coefficient is
    averaged over its detected steady window, or over its second half when the shear never reached a plateau
    (:func:`siloflow.calibration.friction.bulk_friction_of_shear`), with its standard error from batch means.

    Parameters
    ----------
    run : Run
        An open Jenike run (:func:`siloflow.open_run`).

    Returns
    -------
    friction : BulkFriction
        ``coefficient`` and ``standard_error`` [-], ``angle_deg`` [deg], the bottom side's coefficient, the window
        [s], the mean shear force and normal load [N].
    window : str
        ``"steady"`` or ``"second half"``: which window the averages are over.

    Raises
    ------
    ValueError
        For a run that is no Jenike shear test.
    """
    if run.kind != "jenike":
        raise ValueError(f"run {run.run_id} is a {run.kind} run, not a Jenike shear test")
    labels = run.record.labels
    signals = shear_signals(run.wall_forces(), labels["shear_start_s"], labels["shear_end_s"])
    return bulk_friction_of_shear(signals)
