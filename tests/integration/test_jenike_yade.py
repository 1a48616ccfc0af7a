"""Real YADE runs of a small Jenike cell (rigid lid and servo lid, internal friction): each point gives a bulk
friction, the lid holds the normal force during the shear, the rigid lid moves with the shear ring, the levelled
sample is at rest before the lid (force balance of its settled-fill snapshot), and frames and contacts read back.

The cell is smaller than the default's (inner diameter 30 mm, rings 6 + 8 mm, about 300 two-sphere clumps after
levelling) and sheared over 3 mm: YADE is about ten times slower than LIGGGHTS on this case. The two runs go side
by side, one per core, about 1.5 min each.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from siloflow.model.record import RunRecord
from siloflow.analysis.numerics.force_balance import BalanceTolerances, balance_problems, settled_fill_balance
from siloflow.calibration.friction import BulkFriction, bulk_friction
from siloflow.calibration.shear import ShearSignals, shear_signals
from siloflow.model.cases.jenike import JenikeCase, build_jenike_case
from siloflow.engines.config import validate_config
from siloflow.engines.interface import EngineOptions, engine_named
from tests.conftest import RunsOnDemand, require_yade

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(170)]

YADE_JENIKE = {
    "engine": "yade",
    "cell": {"inner_diameter": 0.03, "bottom_ring_height": 0.006, "shear_ring_height": 0.008},
    "fill": {"settle_time": 0.05},
    "consolidation": {"time": 0.03},
    "shear": {"velocity": 0.03, "displacement": 0.003},
}
POINT = {"shape": "sphere2", "test": "internal", "sliding_friction": 0.3, "rolling_friction": 0.1,
         "restitution": 0.1, "rotation_blocked": False}


@dataclass
class Run:
    case: JenikeCase
    run_dir: Path
    record: RunRecord
    signals: ShearSignals
    friction: BulkFriction


def _run(case: JenikeCase, run_dir: Path) -> Run:
    engine = engine_named("yade")
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions())
    signals = shear_signals(engine.wall_forces(run_dir, record), record.labels["shear_start_s"],
                            record.labels["shear_end_s"])
    # a 3 mm shear of a 30 mm cell is too short for a plateau: average over its second half
    half = signals.time[0] + 0.5 * (signals.time[-1] - signals.time[0])
    friction = bulk_friction(signals.time, signals.lid_force, signals.ring_force, signals.bottom_force,
                             signals.normal_force, signals.weight_above, window=(half, signals.time[-1]))
    return Run(case, run_dir, record, signals, friction)


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Run]:
    require_yade()
    root = tmp_path_factory.mktemp("jenike_yade")

    def make(lid: str) -> Run:
        # the point's run with that lid, made on first use: the fast tier asks for the rigid lid only
        return _run(build_jenike_case(validate_config({"jenike": {**YADE_JENIKE, "lid": lid}}), POINT), root / lid)

    return RunsOnDemand(make)


#: the rigid lid in the fast tier; the servo lid's run (the same stages with the other lid) in the physics tier
LIDS = ["rigid", pytest.param("servo", marks=pytest.mark.physics)]


@pytest.mark.parametrize("lid", LIDS)
def test_a_jenike_point_on_yade_gives_a_bulk_friction(lid, runs):
    run = runs[lid]
    assert run.record.engine == "yade" and run.record.case == "jenike"
    assert run.record.labels["n_clumps_created"] == run.case.fill.n_clumps
    assert 0 < run.record.n_clumps < run.case.fill.n_clumps
    assert run.record.stage("shear")["clumps"] == run.record.n_clumps
    friction = run.friction
    # sliding friction 0.3 with rolling friction 0.1: a dense assembly's bulk friction is well above zero and below
    # the study's largest (about 0.8)
    assert 0.2 < friction.coefficient < 0.8, friction
    assert friction.standard_error < 0.1 * friction.coefficient
    # lid + ring and bottom estimates are two measurements of one shear plane
    assert friction.relative_difference < 0.15, friction


@pytest.mark.parametrize("lid", LIDS)
def test_the_lid_holds_the_normal_force_during_the_shear(lid, runs):
    run = runs[lid]
    deviation = run.signals.normal_force / run.case.normal_force - 1.0
    assert abs(deviation.mean()) <= 0.01
    assert np.mean(np.abs(deviation) <= 0.05) >= 0.95


@pytest.mark.parametrize("lid", LIDS)
def test_the_lid_moves_with_the_shear_ring(lid, runs):
    run = runs[lid]
    consolidated, sheared = run.record.stage("consolidate"), run.record.stage("shear")
    expected = run.case.shear_velocity * (sheared["time"] - consolidated["time"])
    assert expected == pytest.approx(run.case.geometry.shear_displacement, rel=1e-3)
    assert sheared["lid_x"] - consolidated["lid_x"] == pytest.approx(expected, rel=1e-6)


def test_frames_forces_and_contacts_read_back(runs):
    run = runs["rigid"]
    engine = engine_named("yade")
    frames = engine.read_frames(run.run_dir, run.record)
    assert len(frames) >= 5
    assert all(frame.angular_velocity is not None and frame.angular_velocity.shape == frame.position.shape
               for frame in frames)
    assert all(len(np.unique(frame.clump_id)) == run.record.n_clumps for frame in frames)  # no lid sphere in them
    history = engine.wall_forces(run.run_dir, run.record)
    assert history.walls == ("lid", "shear_ring", "base") and set(history.signals) == {"lid_z", "mass_above"}
    wall = engine.contacts(run.run_dir, run.record, "wall")[-1]
    assert set(wall.wall) <= {"base", "shear_ring", "mould", "lid"} and {"lid", "base"} <= set(wall.wall)
    # the lid's contacts carry F_N: the particles push it up with what it pushes down (it moves slowly)
    lid_load = wall.normal_force[wall.wall == "lid", 2].sum() + wall.tangential_force[wall.wall == "lid", 2].sum()
    assert -lid_load == pytest.approx(run.case.normal_force, rel=0.1)
    pairs = engine.contacts(run.run_dir, run.record, "pair")[-1]
    assert len(pairs) > run.record.n_clumps  # a dense sample: more than one contact per clump


@pytest.mark.parametrize("lid", LIDS)
def test_the_levelled_sample_carries_its_weight_before_the_lid(lid, runs):
    run = runs[lid]
    settled = engine_named("yade").settled_fill(run.run_dir, run.record)
    assert [step.floor_walls for step in settled] == [("base",), ("base",)]
    balance = settled_fill_balance(settled, [0.25 * run.case.fill_height], run.case.gravity)
    assert balance.n_clumps == run.record.n_clumps
    assert balance.support_ratio == pytest.approx(1.0, abs=0.01)
    assert balance_problems(balance, BalanceTolerances()) == []
