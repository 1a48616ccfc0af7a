"""A one-sphere particle model on LIGGGHTS: its clump template gets a concentric inner sphere (LIGGGHTS 3.8 refuses a
multisphere template of one sphere), which touches nothing; the Jenike cell runs, every clump weighs the sphere's
mass and the levelled sample carries its weight."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.numerics.force_balance import BalanceTolerances, balance_problems, settled_fill_balance
from siloflow.engines.config import validate_config
from siloflow.engines.interface import EngineOptions
from siloflow.engines.liggghts.inputs import INNER_SPHERE_FRACTION
from siloflow.engines.liggghts.jenike import PAIR_CONTACT_PREFIX, read_jenike_pair_contacts
from siloflow.engines.liggghts.dumps import list_dumps
from siloflow.model.cases.jenike import build_jenike_case
from tests.conftest import liggghts, require_liggghts

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(40)]

SMALL_JENIKE = {
    "cell": {"inner_diameter": 0.04, "bottom_ring_height": 0.008, "shear_ring_height": 0.01},
    "fill": {"settle_time": 0.1},
    "consolidation": {"time": 0.03},
    "shear": {"velocity": 0.03, "displacement": 0.002},
}
POINT = {"shape": "sphere", "test": "internal", "sliding_friction": 0.3, "rolling_friction": 0.1, "restitution": 0.1,
         "rotation_blocked": False}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    require_liggghts()
    case = build_jenike_case(validate_config({"jenike": SMALL_JENIKE}), POINT)
    run_dir = tmp_path_factory.mktemp("one_sphere") / case.run_id
    engine = liggghts()
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions())
    return case, run_dir, record, engine


def test_the_deck_gives_the_one_sphere_template_an_inner_sphere(run):
    case, run_dir, _, _ = run
    radius = float(case.particle.sphere_radii[0])
    deck = (run_dir / "deck" / "in.liggghts").read_text()
    inner = INNER_SPHERE_FRACTION * radius
    assert f"nspheres 2 ntry 1000000 spheres 0.0 0.0 0.0 {radius!r} 0.0 0.0 0.0 {inner!r} type 1" in deck


def test_every_clump_weighs_the_sphere_and_holds_two_atoms(run):
    case, run_dir, record, engine = run
    frame = engine.read_frames(run_dir, record)[-1]
    in_clump = frame.clump_id > 0  # the rigid lid's glued spheres are free spheres
    clumps, counts = np.unique(frame.clump_id[in_clump], return_counts=True)
    assert len(clumps) == record.n_clumps > 0
    assert set(counts.tolist()) == {2}
    radius = float(case.particle.sphere_radii[0])
    big = frame.radius[in_clump] > 0.5 * radius
    radii = frame.radius[in_clump]
    assert np.allclose(radii[big], radius) and np.allclose(radii[~big], INNER_SPHERE_FRACTION * radius)
    assert big.sum() == len(clumps)
    # LIGGGHTS writes the clump's mass on each of its spheres: its Monte Carlo volume is the sphere's
    sphere_mass = case.particle.density * 4.0 / 3.0 * math.pi * radius**3
    assert np.allclose(frame.mass[in_clump], sphere_mass, rtol=0.01)


def test_the_inner_spheres_touch_nothing(run):
    case, run_dir, record, engine = run
    frame = engine.read_frames(run_dir, record)[-1]
    inner = set(frame.id[(frame.clump_id > 0) & (frame.radius < 0.5 * float(case.particle.sphere_radii[0]))].tolist())
    assert inner
    dumps = list_dumps(run_dir / "dumps", PAIR_CONTACT_PREFIX, ".txt")
    assert dumps
    contacts = read_jenike_pair_contacts(dumps[-1])
    assert len(contacts.id_i) > 0
    assert not (set(contacts.id_i.tolist()) | set(contacts.id_j.tolist())) & inner


def test_the_levelled_sample_carries_its_weight(run):
    case, run_dir, record, engine = run
    settled = engine.settled_fill(run_dir, record)
    balance = settled_fill_balance(settled, [0.25 * case.fill_height, 0.5 * case.fill_height], case.gravity)
    assert balance.n_clumps == record.n_clumps
    assert balance.support_ratio == pytest.approx(1.0, abs=0.01)  # base + rings carry the sample's weight
    assert balance_problems(balance, BalanceTolerances()) == []
