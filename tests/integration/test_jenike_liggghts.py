"""Real LIGGGHTS runs of a small Jenike cell: the normal force holds, bulk friction responds to particle friction,
and the lid + shear ring estimate agrees with the bottom-ring estimate; the levelled sample is at rest before the lid
(force balance of its settled-fill snapshot).

The cell is scaled down (inner diameter 40 mm, rings 8 + 10 mm, about 650 two-sphere clumps after levelling)
and sheared faster (0.03 m/s over 4 mm); each run takes about 45 s on one core, and two run side by side. `make test`
runs the rigid lid's internal point at particle friction 0.5 and its wall point; the physics tier (make test-physics)
adds the internal point at 0.1 (bulk friction grows with particle friction) and the servo lid's run, and compares both
lids over a whole calibration (test_calibration_pipeline.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from siloflow.engines.liggghts.dumps import list_dumps, parse_legacy_vtk_polydata
from siloflow.model.record import RunRecord
from siloflow.analysis.numerics.force_balance import BalanceTolerances, balance_problems, settled_fill_balance
from siloflow.calibration.friction import BulkFriction, bulk_friction
from siloflow.calibration.shear import ShearSignals, shear_signals
from siloflow.engines.config import validate_config
from siloflow.model.cases.jenike import JenikeCase, build_jenike_case
from siloflow.model.cases.jenike_contacts import LID_TYPE
from siloflow.engines.liggghts.run import DUMP_PREFIX
from siloflow.engines.liggghts.jenike import (
    FORCES_NAME,
    PAIR_CONTACT_PREFIX,
    WALL_CONTACT_PREFIX,
    read_contact_dump,
)
from siloflow.engines.jenike_checks import read_jenike_force_history
from siloflow.engines.interface import EngineOptions
from tests.conftest import RunsOnDemand, liggghts, require_liggghts

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(100)]

SMALL_JENIKE = {
    "cell": {"inner_diameter": 0.04, "bottom_ring_height": 0.008, "shear_ring_height": 0.01},
    "fill": {"settle_time": 0.1},
    "consolidation": {"time": 0.05},
    "shear": {"velocity": 0.03, "displacement": 0.004},
}

POINT = {"shape": "sphere2", "test": "internal", "rolling_friction": 0.0, "restitution": 0.1, "rotation_blocked": False}

RUNS = {
    "rigid_0.1": ("rigid", {**POINT, "sliding_friction": 0.1}),
    "rigid_0.5": ("rigid", {**POINT, "sliding_friction": 0.5}),
    "servo_0.5": ("servo", {**POINT, "sliding_friction": 0.5}),
    "wall_0.3": ("rigid", {**POINT, "test": "aluminium", "sliding_friction": 0.3}),
}


@dataclass
class Run:
    case: JenikeCase
    run_dir: Path
    record: RunRecord
    history: dict
    signals: ShearSignals
    friction: BulkFriction


def _run(case: JenikeCase, run_dir: Path) -> Run:
    engine = liggghts()
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions())
    # the engine's own columns (with the step) for the contact dump check; the neutral history for the friction
    history = read_jenike_force_history(run_dir / FORCES_NAME)
    signals = shear_signals(engine.wall_forces(run_dir, record), record.labels["shear_start_s"], record.labels["shear_end_s"])
    # A 4 mm shear of a 40 mm cell is too short for a plateau: average over its second half.
    half = signals.time[0] + 0.5 * (signals.time[-1] - signals.time[0])
    friction = bulk_friction(
        signals.time,
        signals.lid_force,
        signals.ring_force,
        signals.bottom_force,
        signals.normal_force,
        signals.weight_above,
        window=(half, signals.time[-1]),
    )
    return Run(case, run_dir, record, history, signals, friction)


#: the runs of the physics tier only: the servo lid, and the low-friction point of the rigid lid's growth with particle
#: friction (the calibration pipeline's fast tier checks that growth over its own points)
PHYSICS_RUNS = ("servo_0.5", "rigid_0.1")


def _case(name: str) -> JenikeCase:
    lid, point = RUNS[name]
    return build_jenike_case(validate_config({"jenike": {**SMALL_JENIKE, "lid": lid}}), point)


def _tiered(names) -> list:
    """Parameters over runs, the physics tier's marked as such."""
    return [pytest.param(name, marks=pytest.mark.physics) if name in PHYSICS_RUNS else name for name in names]


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Run]:
    require_liggghts()
    root = tmp_path_factory.mktemp("jenike")

    def make(name: str) -> Run:
        case = _case(name)
        return _run(case, root / case.run_id)

    return RunsOnDemand(make, ahead=[name for name in RUNS if name not in PHYSICS_RUNS])


def test_runs_fill_level_and_keep_every_clump(runs):
    # the runs made so far: the fast tier's, and the physics tier's once one of its tests asked for them
    for name, run in runs.items():
        record = run.record
        assert record.labels["n_clumps_created"] == run.case.fill.n_clumps, name
        assert 0 < record.n_clumps < record.labels["n_clumps_created"], name
        assert record.stage("shear")["clumps"] == record.n_clumps, name
        assert (run.run_dir / "run.json").exists() and list_dumps(run.run_dir / "dumps", DUMP_PREFIX), name


@pytest.mark.parametrize("name", _tiered(["rigid_0.1", "rigid_0.5", "wall_0.3"]))
def test_rigid_lid_holds_the_normal_force_during_shear(name, runs):
    run = runs[name]
    deviation = run.signals.normal_force / run.case.normal_force - 1.0
    assert np.abs(deviation).max() <= 0.05
    assert abs(deviation.mean()) <= 0.01


@pytest.mark.physics
def test_servo_lid_holds_the_normal_force_during_shear(runs):
    run = runs["servo_0.5"]
    deviation = run.signals.normal_force / run.case.normal_force - 1.0
    assert np.mean(np.abs(deviation) <= 0.05) >= 0.95
    assert abs(deviation.mean()) <= 0.01


@pytest.mark.physics
def test_bulk_friction_grows_with_particle_friction(runs):
    low, high = runs["rigid_0.1"].friction, runs["rigid_0.5"].friction
    assert high.coefficient > low.coefficient + 3 * (high.standard_error + low.standard_error)
    assert high.bottom_coefficient > low.bottom_coefficient


@pytest.mark.parametrize("name", _tiered(RUNS))
def test_lid_and_ring_estimate_agrees_with_the_bottom_estimate(name, runs):
    friction = runs[name].friction
    assert friction.coefficient > 0
    assert friction.relative_difference < 0.10


def test_bulk_wall_friction_does_not_exceed_the_particle_wall_friction(runs):
    friction = runs["wall_0.3"].friction
    assert 0.0 < friction.bottom_coefficient <= 0.3 * 1.02


def test_rigid_lid_moves_with_the_shear_ring(runs):
    run = runs["rigid_0.5"]
    dumps = list_dumps(run.run_dir / "dumps", DUMP_PREFIX)
    shear_start = int(run.record.stage("consolidate")["step"])
    x = []
    for path in (dumps[0], dumps[-1]):
        frame = parse_legacy_vtk_polydata(path.read_bytes(), str(path))
        x.append(frame["points"][frame["type"] == LID_TYPE, 0].mean())
    last_step = int(dumps[-1].stem.rsplit("_", 1)[1])
    expected = run.case.shear_velocity * (last_step - shear_start) * run.case.timestep
    assert expected > 0.5 * run.case.geometry.shear_displacement
    assert x[1] - x[0] == pytest.approx(expected, rel=1e-3)


def test_contact_dumps_carry_the_plate_load(runs):
    """The plate contacts of the wall-contact dump add up to the plate's measured vertical force.

    Only normal forces are checked: LIGGGHTS 3.8's ``force_tangential`` (and ``force``) of these computes
    exceed the applied tangential forces (their sum over the plate contacts is about 20 % above the plate's
    measured horizontal force, and single weak contacts show |F_t| / |F_n| far above the sliding friction),
    while the mesh forces balance the lid and ring forces exactly.
    """
    run = runs["wall_0.3"]
    paths = sorted((run.run_dir / "dumps").glob(f"{WALL_CONTACT_PREFIX}_*.txt"))
    assert paths and sorted((run.run_dir / "dumps").glob(f"{PAIR_CONTACT_PREFIX}_*.txt"))
    contacts = read_contact_dump(paths[-1])
    plate = contacts["id1"] == 0  # mesh index 0: the base (plate)
    assert plate.sum() > 10
    load = (contacts["fn_z"] + contacts["ft_z"])[plate].sum()
    row = int(np.searchsorted(run.history["step"], contacts["step"][0]))
    measured = -run.history["bottom_fz"][row - 1 : row + 1].mean()
    assert load == pytest.approx(measured, rel=0.02)


@pytest.mark.parametrize("name", _tiered(RUNS))
def test_the_levelled_sample_carries_its_weight_before_the_lid(name, runs):
    run = runs[name]
    settled = liggghts().settled_fill(run.run_dir, run.record)
    assert [step.floor_walls for step in settled] == [("base",), ("base",)]
    # the levelled top 2-3 clump layers are still moving when the lid comes: the wall test's 10 mm sample is all top
    fractions = (0.25,) if run.case.test != "internal" else (0.25, 0.5)
    heights = [fraction * run.case.fill_height for fraction in fractions]
    balance = settled_fill_balance(settled, heights, run.case.gravity)
    assert balance.n_clumps == run.record.n_clumps
    assert balance.support_ratio == pytest.approx(1.0, abs=0.01)  # base + rings carry the sample's weight
    for plane in balance.planes:
        assert plane.closure == pytest.approx(1.0, abs=0.01), plane
    assert balance_problems(balance, BalanceTolerances()) == []
    # the walls' own sums (6 digits) and the spheres' wall forces are of the same two steps
    assert sum(balance.wall_support.values()) == pytest.approx(balance.support, rel=1e-4)
