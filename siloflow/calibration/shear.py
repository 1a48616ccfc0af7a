"""The shear stage of a Jenike direct shear test, cut out of its wall force history and signed for the bulk friction.

Input is the engine-neutral :class:`siloflow.model.forces.WallForceHistory` of a Jenike run: walls ``lid``,
``shear_ring`` and ``base`` (the bottom ring or the wall-test plate) with the forces they exert on the particles,
and the signal ``mass_above`` (clump mass above the shear plane, kg). Output is :class:`ShearSignals`, the input
of :func:`siloflow.calibration.friction.bulk_friction_of_shear`. SI units: s, N, kg, m/s^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.constants import GRAVITY
from siloflow.model.forces import WallForceHistory

__all__ = ["ShearSignals", "shear_signals"]

#: Walls and signal a Jenike wall force history must have.
LID, SHEAR_RING, BASE = "lid", "shear_ring", "base"
MASS_ABOVE = "mass_above"


@dataclass(frozen=True)
class ShearSignals:
    """The force histories of the shear stage, signed for :func:`siloflow.calibration.friction.bulk_friction`.

    Attributes
    ----------
    time : numpy.ndarray
        Sample times (s).
    lid_force, ring_force : numpy.ndarray
        Force needed to drive the lid and the shear ring along +x: minus the x force of the particles on
        them, i.e. the x force they exert on the particles (N).
    bottom_force : numpy.ndarray
        x force of the particles on the bottom ring or plate (N); by the force balance of the sample it
        equals lid_force + ring_force up to the sample's inertia.
    normal_force : numpy.ndarray
        Measured upward force of the particles on the lid (N).
    weight_above : numpy.ndarray
        Weight of the clumps above the shear plane (N).
    """

    time: np.ndarray
    lid_force: np.ndarray
    ring_force: np.ndarray
    bottom_force: np.ndarray
    normal_force: np.ndarray
    weight_above: np.ndarray


def shear_signals(history: WallForceHistory, shear_start: float, shear_end: float | None = None,
                  gravity: float = GRAVITY) -> ShearSignals:
    """Cut the shear stage out of a Jenike wall force history and sign its forces for the bulk friction.

    Parameters
    ----------
    history : siloflow.model.forces.WallForceHistory
        Walls ``lid``, ``shear_ring``, ``base`` (forces on the particles, N) and the signal ``mass_above`` (kg).
    shear_start, shear_end : float
        Times bounding the shear stage (s); samples after ``shear_start`` and no later than ``shear_end``
        (None: to the end) are kept.
    gravity : float
        Gravitational acceleration g (m/s^2) that turns the mass above the shear plane into its weight.

    Raises
    ------
    ValueError
        When the history lacks a wall or the signal, or holds fewer than 2 samples in the shear stage.
    """
    missing = [wall for wall in (LID, SHEAR_RING, BASE) if wall not in history.walls]
    if missing or MASS_ABOVE not in history.signals:
        raise ValueError(f"a Jenike wall force history needs walls lid, shear_ring, base and the signal "
                         f"{MASS_ABOVE!r}; it has walls {list(history.walls)} and signals {sorted(history.signals)}")
    keep = history.time > shear_start
    if shear_end is not None:
        keep &= history.time <= shear_end
    if keep.sum() < 2:
        raise ValueError(f"the force history holds fewer than 2 samples after t = {shear_start} s")
    return ShearSignals(
        time=history.time[keep],
        lid_force=history.force[LID][keep, 0],
        ring_force=history.force[SHEAR_RING][keep, 0],
        bottom_force=-history.force[BASE][keep, 0],
        normal_force=-history.force[LID][keep, 2],
        weight_above=history.signals[MASS_ABOVE][keep] * gravity,
    )
