"""The settled fill snapshot's readers on hand-written dumps: exact spheres, wall forces, contacts and per-wall split."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.data.forces import WallForceHistory
from engines.liggghts.contacts import ContactDumpError
from engines.liggghts.jenike import SETTLED_CONTACT_PREFIX, read_jenike_pair_contacts
from engines.liggghts.settled import SETTLED_COLUMNS, read_settled_fill, read_settled_jenike_fill

STEP = 200
TIMESTEP = 1e-5
# one two-sphere clump (atoms 1, 2; clump 7) resting on the floor and a free sphere (atom 3) on top of it
SPHERES = [
    (1, 1, 7, 0.000, 0.0, 0.0015, 0.0, 0.0, 0.0, 0.0015, 1.0e-5, 0.0, 0.0, 0.30e-3),
    (2, 1, 7, 0.002, 0.0, 0.0015, 0.0, 0.0, 0.0, 0.0015, 1.0e-5, 0.0, 0.0, 0.30e-3),
    (3, 1, -1, 0.001, 0.0, 0.0040, 0.0, 0.0, 0.0, 0.0015, 2.0e-5, 0.0, 0.0, 0.0),
]


def _sphere_dump(rows=SPHERES, columns=SETTLED_COLUMNS) -> str:
    lines = ["ITEM: TIMESTEP", str(STEP), "ITEM: NUMBER OF ATOMS", str(len(rows)), "ITEM: BOX BOUNDS ff ff ff",
             "-1 1", "-1 1", "0 1", "ITEM: ATOMS " + " ".join(columns)]
    lines += [" ".join(f"{value:.12g}" for value in row) for row in rows]
    return "\n".join(lines) + "\n"


def _local_dump(rows) -> str:
    lines = ["ITEM: TIMESTEP", str(STEP), "ITEM: NUMBER OF ENTRIES", str(len(rows)), "ITEM: BOX BOUNDS ff ff ff",
             "-1 1", "-1 1", "0 1", "ITEM: ENTRIES " + " ".join(f"c_contacts[{i + 1}]" for i in range(len(rows[0])))]
    lines += [" ".join(f"{value:.12g}" for value in row) for row in rows]
    return "\n".join(lines) + "\n"


@pytest.fixture
def dumps(tmp_path):
    (tmp_path / f"settled_fill_{STEP}.txt").write_text(_sphere_dump())
    # silo layout: both centres, both ids, periodic flag, force on i by j
    (tmp_path / f"contacts_{STEP}.txt").write_text(_local_dump([(0.001, 0, 0.004, 0.0, 0, 0.0015, 3, 1, 0,
                                                                  0.0, 0.0, 0.2e-3)]))
    # Jenike layout: centres, ids and flag, normal and tangential force on i
    (tmp_path / f"{SETTLED_CONTACT_PREFIX}_{STEP}.txt").write_text(_local_dump(
        [(0.001, 0, 0.004, 0.0, 0, 0.0015, 3, 1, 0, 0.0, 0.0, 0.15e-3, 0.0, 0.0, 0.05e-3)]))
    return tmp_path


def test_the_silo_snapshot_reads_spheres_wall_forces_contacts_and_the_wall_split_before_it(dumps):
    history = WallForceHistory(
        time=np.array([0.5 * STEP * TIMESTEP, STEP * TIMESTEP, 2.0 * STEP * TIMESTEP]),
        walls=("floor", "side"),
        force={"floor": np.array([[0, 0, 0.5e-3], [0, 0, 0.6e-3], [0, 0, 9.0]]),
               "side": np.array([[0, 0, 0.0], [0, 0, 0.0], [0, 0, 9.0]])},
        torque={"floor": np.zeros((3, 3)), "side": np.zeros((3, 3))},
    )
    settled = read_settled_fill(dumps, TIMESTEP, history, ("floor",))
    assert settled.frame.step == STEP and settled.frame.time == pytest.approx(STEP * TIMESTEP)
    np.testing.assert_array_equal(settled.frame.id, [1, 2, 3])
    np.testing.assert_allclose(settled.wall_force[:, 2], [0.3e-3, 0.3e-3, 0.0])
    np.testing.assert_allclose(settled.contacts.force, [[0.0, 0.0, 0.2e-3]])
    np.testing.assert_array_equal(settled.contacts.id_i, [3])
    # the sample at the snapshot's time, not the later one
    np.testing.assert_allclose(settled.wall_forces["floor"], [0, 0, 0.6e-3])
    assert settled.floor_walls == ("floor",)


def test_without_a_history_there_is_no_wall_split(dumps):
    settled = read_settled_fill(dumps, TIMESTEP, None, ("floor",))
    assert settled.wall_forces == {} and settled.floor_walls == ()


def test_the_jenike_snapshot_takes_each_mesh_force_from_the_marker_negated(dumps):
    marker = {"base_fx": 0.0, "base_fy": 0.0, "base_fz": -0.6e-3, "ring_fx": 1e-6, "ring_fy": 0.0, "ring_fz": 0.0}
    settled = read_settled_jenike_fill(dumps, TIMESTEP, marker, ("base", "ring"), ("base",), SETTLED_CONTACT_PREFIX,
                                       read_jenike_pair_contacts)
    np.testing.assert_allclose(settled.wall_forces["base"], [0.0, 0.0, 0.6e-3])  # on the particles: upwards
    np.testing.assert_allclose(settled.wall_forces["ring"], [-1e-6, 0.0, 0.0])
    # the Jenike contact force is the sum of its normal and tangential parts
    np.testing.assert_allclose(settled.contacts.force, [[0.0, 0.0, 0.2e-3]])
    assert settled.floor_walls == ("base",)


def test_a_marker_from_before_the_force_balance_is_named(dumps):
    with pytest.raises(KeyError, match="base_fz"):
        read_settled_jenike_fill(dumps, TIMESTEP, {"top": 0.01}, ("base",), ("base",), SETTLED_CONTACT_PREFIX,
                                 read_jenike_pair_contacts)


def test_missing_or_foreign_dumps_are_refused_with_the_file_named(tmp_path, dumps):
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="settled_fill_<step>"):
        read_settled_fill(tmp_path / "empty", TIMESTEP, None, ())
    (dumps / f"contacts_{STEP}.txt").unlink()
    with pytest.raises(FileNotFoundError, match=f"contacts_{STEP}"):
        read_settled_fill(dumps, TIMESTEP, None, ())
    (dumps / f"settled_fill_{STEP}.txt").write_text(_sphere_dump(columns=SETTLED_COLUMNS[:-1] + ("fz",)))
    with pytest.raises(ContactDumpError, match="settled fill"):
        read_settled_fill(dumps, TIMESTEP, None, ())
