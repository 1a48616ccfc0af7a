"""The settled fill snapshot's reader on hand-written dumps of two steps: exact spheres, wall forces, contacts and
per-wall split of each step."""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.engines.liggghts.contacts import ContactDumpError
from siloflow.engines.liggghts.jenike import SETTLED_CONTACT_PREFIX, read_jenike_pair_contacts
from siloflow.engines.liggghts.settled import SETTLED_COLUMNS, read_settled_fill

STEP = 200
TIMESTEP = 1e-5
# one two-sphere clump (atoms 1, 2; clump 7) resting on the floor and a free sphere (atom 3) on top of it
SPHERES = [
    (1, 1, 7, 0.000, 0.0, 0.0015, 0.0, 0.0, 0.0, 0.0015, 1.0e-5, 0.0, 0.0, 0.30e-3),
    (2, 1, 7, 0.002, 0.0, 0.0015, 0.0, 0.0, 0.0, 0.0015, 1.0e-5, 0.0, 0.0, 0.30e-3),
    (3, 1, -1, 0.001, 0.0, 0.0040, 0.0, 0.0, 0.0, 0.0015, 2.0e-5, 0.0, 0.0, 0.0),
]


def _sphere_dump(rows=SPHERES, columns=SETTLED_COLUMNS, step=STEP) -> str:
    lines = ["ITEM: TIMESTEP", str(step), "ITEM: NUMBER OF ATOMS", str(len(rows)), "ITEM: BOX BOUNDS ff ff ff",
             "-1 1", "-1 1", "0 1", "ITEM: ATOMS " + " ".join(columns)]
    lines += [" ".join(f"{value:.12g}" for value in row) for row in rows]
    return "\n".join(lines) + "\n"


def _local_dump(rows, step=STEP) -> str:
    lines = ["ITEM: TIMESTEP", str(step), "ITEM: NUMBER OF ENTRIES", str(len(rows)), "ITEM: BOX BOUNDS ff ff ff",
             "-1 1", "-1 1", "0 1", "ITEM: ENTRIES " + " ".join(f"c_contacts[{i + 1}]" for i in range(len(rows[0])))]
    lines += [" ".join(f"{value:.12g}" for value in row) for row in rows]
    return "\n".join(lines) + "\n"


def _walls_file(rows) -> str:
    """The snapshot's wall forces: walls floor and side, fx fy fz tx ty tz each; the set-up step first."""
    header = "# TimeStep " + " ".join(f"v_{wall}_{q}" for wall in ("floor", "side")
                                      for q in ("fx", "fy", "fz", "tx", "ty", "tz"))
    lines = [f"siloflow wall forces, time step {TIMESTEP} s", header]
    lines += [f"{step} " + " ".join(f"{value:g}" for value in values) for step, values in rows]
    return "\n".join(lines) + "\n"


WALL_ROWS = [
    (STEP - 1, [0, 0, 9.0, 0, 0, 0, 0, 0, 9.0, 0, 0, 0]),  # the set-up: not a step of the snapshot
    (STEP, [0, 0, 0.6e-3, 0, 0, 0, 1e-6, 0, 0, 0, 0, 0]),
    (STEP + 1, [0, 0, 0.5e-3, 0, 0, 0, 2e-6, 0, 0, 0, 0, 0]),
]


@pytest.fixture
def dumps(tmp_path):
    for step in (STEP, STEP + 1):
        (tmp_path / f"settled_fill_{step}.txt").write_text(_sphere_dump(step=step))
        # silo layout: both centres, both ids, periodic flag, force on i by j
        (tmp_path / f"contacts_{step}.txt").write_text(_local_dump([(0.001, 0, 0.004, 0.0, 0, 0.0015, 3, 1, 0,
                                                                     0.0, 0.0, 0.2e-3)], step))
        # Jenike layout: centres, ids and flag, normal and tangential force on i
        (tmp_path / f"{SETTLED_CONTACT_PREFIX}_{step}.txt").write_text(_local_dump(
            [(0.001, 0, 0.004, 0.0, 0, 0.0015, 3, 1, 0, 0.0, 0.0, 0.15e-3, 0.0, 0.0, 0.05e-3)], step))
    (tmp_path / "settled_walls.txt").write_text(_walls_file(WALL_ROWS))
    return tmp_path


def test_the_silo_snapshot_reads_each_step_with_the_walls_forces_of_that_step(dumps):
    first, second = read_settled_fill(dumps, TIMESTEP, ("floor",))
    assert (first.frame.step, second.frame.step) == (STEP, STEP + 1)
    assert first.frame.time == pytest.approx(STEP * TIMESTEP)
    np.testing.assert_array_equal(first.frame.id, [1, 2, 3])
    np.testing.assert_allclose(first.wall_force[:, 2], [0.3e-3, 0.3e-3, 0.0])
    np.testing.assert_allclose(first.contacts.force, [[0.0, 0.0, 0.2e-3]])
    np.testing.assert_array_equal(first.contacts.id_i, [3])
    # each step's row, not the set-up's
    np.testing.assert_allclose(first.wall_forces["floor"], [0, 0, 0.6e-3])
    np.testing.assert_allclose(second.wall_forces["floor"], [0, 0, 0.5e-3])
    np.testing.assert_allclose(second.wall_forces["side"], [2e-6, 0, 0])
    assert first.floor_walls == ("floor",)


def test_the_jenike_snapshot_reads_its_own_contact_layout(dumps):
    settled = read_settled_fill(dumps, TIMESTEP, ("floor",), SETTLED_CONTACT_PREFIX, read_jenike_pair_contacts)
    # the Jenike contact force is the sum of its normal and tangential parts
    np.testing.assert_allclose(settled[0].contacts.force, [[0.0, 0.0, 0.2e-3]])
    np.testing.assert_allclose(settled[0].wall_forces["floor"], [0, 0, 0.6e-3])


def test_missing_or_foreign_dumps_are_refused_with_the_file_named(tmp_path, dumps):
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="settled_fill_<step>"):
        read_settled_fill(tmp_path / "empty", TIMESTEP, ())
    (dumps / "settled_walls.txt").write_text(_walls_file(WALL_ROWS[:2]))
    with pytest.raises(ValueError, match=f"no row at step {STEP + 1}"):
        read_settled_fill(dumps, TIMESTEP, ())
    (dumps / "settled_walls.txt").unlink()
    with pytest.raises(FileNotFoundError, match="settled_walls.txt"):
        read_settled_fill(dumps, TIMESTEP, ())
    (dumps / "settled_walls.txt").write_text(_walls_file(WALL_ROWS))
    (dumps / f"contacts_{STEP}.txt").unlink()
    with pytest.raises(FileNotFoundError, match=f"contacts_{STEP}"):
        read_settled_fill(dumps, TIMESTEP, ())
    (dumps / f"settled_fill_{STEP}.txt").write_text(_sphere_dump(columns=SETTLED_COLUMNS[:-1] + ("fz",)))
    with pytest.raises(ContactDumpError, match="settled fill"):
        read_settled_fill(dumps, TIMESTEP, ())
