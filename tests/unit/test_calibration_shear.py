"""The shear stage of a Jenike test cut out of its wall force history and signed for the bulk friction."""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.model.forces import WallForceHistory
from siloflow.calibration.shear import shear_signals


def _history(walls=("lid", "shear_ring", "base"), signals=True) -> WallForceHistory:
    """Forces the walls exert ON the particles: the particles push the lid back (-x) and up, the base along +x."""
    time = np.array([0.1, 0.2, 0.3, 0.4])
    zero = np.zeros(4)
    force = {
        "lid": np.column_stack([[0.0, 1.0, 2.0, 3.0], zero, np.full(4, -5.0)]),
        "shear_ring": np.column_stack([[0.0, 0.5, 0.5, 0.5], zero, zero]),
        "base": np.column_stack([[0.0, -1.5, -2.5, -3.5], zero, zero]),
    }
    return WallForceHistory(
        time=time,
        walls=walls,
        force={wall: force[wall] for wall in walls},
        torque={wall: np.full((4, 3), np.nan) for wall in walls},
        signals={"mass_above": np.full(4, 0.01)} if signals else {},
    )


def test_shear_signals_cut_the_shear_and_sign_the_forces():
    history = _history()
    signals = shear_signals(history, 0.15)
    np.testing.assert_array_equal(signals.time, [0.2, 0.3, 0.4])
    np.testing.assert_array_equal(signals.lid_force + signals.ring_force, signals.bottom_force)
    np.testing.assert_allclose(signals.weight_above, 0.01 * 9.81)
    with pytest.raises(ValueError, match="fewer than 2 samples"):
        shear_signals(history, 0.35)


def test_shear_signals_drive_forces_and_normal_force_have_the_signs_of_the_bulk_friction():
    signals = shear_signals(_history(), 0.15, shear_end=0.3)
    np.testing.assert_array_equal(signals.time, [0.2, 0.3])
    np.testing.assert_array_equal(signals.lid_force, [1.0, 2.0])
    np.testing.assert_array_equal(signals.ring_force, [0.5, 0.5])
    np.testing.assert_array_equal(signals.bottom_force, [1.5, 2.5])
    np.testing.assert_array_equal(signals.normal_force, [5.0, 5.0])
    np.testing.assert_allclose(shear_signals(_history(), 0.15, gravity=2.0).weight_above, 0.02)


@pytest.mark.parametrize("walls, signals", [(("lid", "shear_ring"), True), (("lid", "shear_ring", "base"), False)])
def test_shear_signals_name_what_a_jenike_history_lacks(walls, signals):
    with pytest.raises(ValueError, match="needs walls lid, shear_ring, base and the signal 'mass_above'"):
        shear_signals(_history(walls, signals), 0.15)
