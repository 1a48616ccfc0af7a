"""Real LIGGGHTS run of a tiny settled fill: the force and torque each wall exerts on the particles, read back.

A silo of about 440 two-sphere clumps (40 mm wide, 12 mm deep, 25 mm high) fills, settles, opens and discharges for
20 ms (about 10 s on one core). At rest, in the last sample before the gate opens, the walls and the floor (with the
gate) carry the weight of the fill, every side wall pushes the particles inward, and the walls' torques about the
origin balance that of gravity; the gate's force is zero once it has gone.
"""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.model.frames import clumps_from_frame
from siloflow.model.constants import GRAVITY
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.engines.config import load_config_file, validate_config
from siloflow.engines.interface import EngineOptions, engine_for
from tests.conftest import DEFAULT_CONFIG, FAST_POUR, TINY_SETTLE, require_liggghts

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(10)]

TINY_FILL = {
    "width": 0.04,
    "depth": 0.012,
    "fill_height": 0.025,
    "outlet_width": 0.012,
    "front_back_walls": True,
    "fill": FAST_POUR,
    "settle": TINY_SETTLE,
    "discharge_time": 0.02,
    # the study's step: the checks of a fill at rest (weight and torque carried to 1e-3) were measured at it; at 0.2 of
    # the Rayleigh time this fill meets its rest criterion with a quarter of its weight not yet on the walls
    "timestep_fraction": 0.1,
}

SIDE_WALLS = {"wall_left": (0, +1.0), "wall_right": (0, -1.0), "wall_front": (1, +1.0), "wall_back": (1, -1.0)}


@pytest.fixture(scope="module")
def settled_fill(tmp_path_factory):
    require_liggghts()
    raw = load_config_file(DEFAULT_CONFIG)
    raw["silo_flat"] = {**raw["silo_flat"], **TINY_FILL}
    config = validate_config(raw)
    case = build_silo_case(config)
    engine = engine_for(config, "silo_flat")
    run_dir = tmp_path_factory.mktemp("wall_forces") / case.run_id
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions())
    history = engine.wall_forces(run_dir, record)
    frames = engine.read_frames(run_dir, record)
    # the last sample before the gate opened
    at_rest = int(np.flatnonzero(history.time <= record.open_time_s * (1 + 1e-12))[-1])
    return case, record, history, frames, at_rest


def test_every_wall_has_a_history_from_the_fill_on_at_the_dump_interval(settled_fill):
    case, record, history, _, _ = settled_fill
    assert history.walls == ("wall_left", "wall_right", "wall_front", "wall_back", "floor_left", "floor_right",
                             "outlet_gate")
    assert history.time[0] == 0.0
    np.testing.assert_allclose(np.diff(history.time), case.dump_every * case.timestep, rtol=1e-9)
    end = (record.open_step + case.discharge_steps) * case.timestep
    assert end - case.dump_every * case.timestep < history.time[-1] <= end * (1 + 1e-12)


def test_walls_and_floor_carry_the_weight_of_the_settled_fill(settled_fill):
    case, record, history, _, at_rest = settled_fill
    weight = record.n_clumps * case.particle.mass * GRAVITY
    vertical = history.total_force()[at_rest, 2]
    floor = history.total_force(["floor_left", "floor_right", "outlet_gate"])[at_rest, 2]
    print(f"settled fill: walls + floor + gate carry {vertical:.6g} N of the weight {weight:.6g} N "
          f"({vertical / weight:.4f}); floor and gate alone {floor / weight:.4f}")
    assert vertical == pytest.approx(weight, rel=0.02)
    assert history.force["outlet_gate"][at_rest, 2] > 0.0


def test_side_walls_push_the_particles_inward(settled_fill):
    _, _, history, _, at_rest = settled_fill
    for wall, (axis, inward) in SIDE_WALLS.items():
        print(f"{wall}: force on the particles {history.force[wall][at_rest]} N")
        assert inward * history.force[wall][at_rest, axis] > 0.0, wall


def test_wall_torques_balance_the_torque_of_gravity_at_rest(settled_fill):
    """Sum of the walls' torques about the origin = -(torque of the weight) = (g sum m y, -g sum m x, 0); rolling
    resistance couples are not in the wall torques, hence the tolerance (3 % of weight x half width)."""
    case, record, history, frames, at_rest = settled_fill
    clumps = clumps_from_frame(frames[0])  # the first frame is written at the opening, at rest
    assert clumps.step == record.open_step
    moment = clumps.mass @ clumps.position  # sum of m r over the clumps (kg m)
    expected = GRAVITY * np.array([moment[1], -moment[0], 0.0])
    measured = history.total_torque()[at_rest]
    scale = record.n_clumps * case.particle.mass * GRAVITY * 0.5 * case.width
    print(f"wall torques {measured} N m, expected {expected} N m, scale {scale:.3g} N m")
    np.testing.assert_allclose(measured, expected, atol=0.03 * scale)


def test_the_gate_exerts_no_force_once_the_outlet_opened(settled_fill):
    _, record, history, _, _ = settled_fill
    opened = history.time > record.open_time_s * (1 + 1e-12)
    assert opened.sum() >= 2
    assert np.all(history.force["outlet_gate"][opened] == 0.0)
    assert np.all(history.torque["outlet_gate"][opened] == 0.0)
