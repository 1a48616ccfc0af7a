"""Jenike's preshear on both engines, on the smallest cells of their Jenike tests: the shear ring, the mould and the
lid go the shear displacement forward and back under the consolidation load, so the sample is dragged one way and
then the other with about the same force, and the measured shear starts after the preshear.

One pass each (three times the shear travel in all): LIGGGHTS about 1.5 min, YADE about 3 min on one core; the
physics tier (make test-physics) runs them.
"""

from __future__ import annotations

import numpy as np
import pytest

from engines.cases.jenike import build_jenike_case
from engines.config import validate_config
from engines.interface import EngineOptions, engine_named
from tests.conftest import RunsOnDemand, require_liggghts, require_yade

pytestmark = [pytest.mark.integration, pytest.mark.physics, pytest.mark.core_seconds(270)]

POINT = {"shape": "sphere2", "test": "internal", "sliding_friction": 0.3, "rolling_friction": 0.1,
         "restitution": 0.1, "rotation_blocked": False}
CELLS = {
    "liggghts": {"cell": {"inner_diameter": 0.04, "bottom_ring_height": 0.008, "shear_ring_height": 0.01},
                 "fill": {"settle_time": 0.1}, "consolidation": {"time": 0.05}},
    "yade": {"cell": {"inner_diameter": 0.03, "bottom_ring_height": 0.006, "shear_ring_height": 0.008},
             "fill": {"settle_time": 0.05}, "consolidation": {"time": 0.03}},
}
SHEAR = {"velocity": 0.03, "displacement": 0.003, "preshear_passes": 1}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("jenike_preshear")

    def make(engine_name: str):
        (require_liggghts if engine_name == "liggghts" else require_yade)()
        config = validate_config({"jenike": {**CELLS[engine_name], "engine": engine_name, "shear": SHEAR}})
        case = build_jenike_case(config, POINT)
        engine = engine_named(engine_name)
        run_dir = root / engine_name
        engine.write_inputs(case, run_dir)
        record = engine.run(case, run_dir, EngineOptions())
        return case, record, engine.wall_forces(run_dir, record)

    return RunsOnDemand(make, ahead=list(CELLS))


@pytest.mark.parametrize("engine_name", list(CELLS))
def test_the_measured_shear_starts_after_the_preshear(engine_name, runs):
    case, record, _ = runs[engine_name]
    dt = case.timestep
    assert case.preshear_steps == 2 * case.shear_steps
    loaded = record.labels["shear_start_s"] - record.labels["consolidation_start_s"]
    assert loaded == pytest.approx((case.ramp_steps + case.hold_steps + case.preshear_steps) * dt, abs=2 * dt)
    assert record.labels["shear_end_s"] - record.labels["shear_start_s"] == pytest.approx(case.shear_steps * dt,
                                                                                          abs=2 * dt)
    assert record.stage("shear")["clumps"] == record.n_clumps


@pytest.mark.parametrize("engine_name", list(CELLS))
def test_the_preshear_drags_the_sample_forward_then_back(engine_name, runs):
    case, record, forces = runs[engine_name]
    dt, steps = case.timestep, case.shear_steps
    start = record.labels["consolidation_start_s"] + (case.ramp_steps + case.hold_steps) * dt
    drag = forces.force["shear_ring"][:, 0] + forces.force["lid"][:, 0]

    def late_half(first: float, last: float) -> float:
        """Mean horizontal drag over the second half of a pass (past the mobilisation) [N]."""
        inside = (forces.time >= first + 0.5 * (last - first)) & (forces.time <= last)
        assert inside.sum() >= 3
        return float(drag[inside].mean())

    forward = late_half(start, start + steps * dt)
    back = late_half(start + steps * dt, start + 2 * steps * dt)
    measured = late_half(record.labels["shear_start_s"], record.labels["shear_end_s"])
    # the walls push the sample the way they move: one sign forward, the other back, the first sign again after
    assert np.sign(forward) == np.sign(measured) == -np.sign(back) != 0
    # about the same friction either way: within a factor of two
    assert 0.5 < abs(back) / abs(forward) < 2.0
