"""Force balance of a fill at rest, on hand-built static stacks of clumps with known forces (exact answers)."""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.model.contacts import ContactFrame
from siloflow.model.frames import ParticleFrame
from siloflow.model.settled import SettledFill
from siloflow.analysis.numerics.force_balance import (
    BalanceTolerances,
    balance_problems,
    fill_balance,
    mean_balance,
    plane_loads,
    settled_fill_balance,
)

G = 10.0
M = 0.5  # kg per clump: weight 5 N


def stack(wall_pull_on_top: float = 0.0):
    """Three upright two-sphere clumps A, B, C stacked on a floor (unit spheres, centres 1 apart):
    spheres 0,1 (A) at z = 0.5, 1.5; 2,3 (B) at 2.5, 3.5; 4,5 (C) at 4.5, 5.5. A wall pulls the top sphere down
    by ``wall_pull_on_top`` N; contacts 1-2 and 3-4 and the floor carry the rest."""
    weight = M * G
    sphere_clump = np.array([0, 0, 1, 1, 2, 2])
    clump_z = np.array([1.0, 3.0, 5.0])
    wall_force = np.zeros((6, 3))
    wall_force[0, 2] = 3 * weight + wall_pull_on_top  # the floor under sphere 0
    wall_force[5, 2] = -wall_pull_on_top
    # contact (i, j) with the force on i by j: 1-2 pushes 2 up; listed once as i=1 (force on 1 is down), and 4-3
    # listed as i=4 (force on 4 is up)
    i, j = np.array([1, 4]), np.array([2, 3])
    force = np.array([[0.0, 0.0, -(2 * weight + wall_pull_on_top)], [0.0, 0.0, weight + wall_pull_on_top]])
    return sphere_clump, np.full(3, M), clump_z, wall_force, i, j, force


def test_each_plane_carries_the_weight_above_it_when_the_walls_are_frictionless():
    sphere_clump, mass, z, wall, i, j, force = stack()
    loads = plane_loads(sphere_clump, mass, z, wall[:, 2], i, j, force[:, 2], [0.5, 2.0, 4.0, 6.0], G)
    assert [load.clumps_above for load in loads] == [3, 2, 1, 0]
    assert [load.weight_above for load in loads] == [15.0, 10.0, 5.0, 0.0]
    # the plane at 0.5 has every clump above it: only the floor (a wall) holds them
    assert [load.contact_force for load in loads] == [0.0, 10.0, 5.0, 0.0]
    assert [load.wall_force for load in loads] == [15.0, 0.0, 0.0, 0.0]
    assert [load.closure for load in loads[:3]] == [1.0, 1.0, 1.0]
    assert np.isnan(loads[3].contact_ratio)


def test_a_clump_that_straddles_a_plane_is_on_the_side_of_its_centre_of_mass():
    sphere_clump, mass, z, wall, i, j, force = stack()
    # B's spheres sit at 2.5 and 3.5: the planes at 2.9 and 3.1 both cut it; its centre (3.0) decides
    below_centre, above_centre = plane_loads(sphere_clump, mass, z, wall[:, 2], i, j, force[:, 2], [2.9, 3.1], G)
    assert (below_centre.clumps_above, below_centre.weight_above, below_centre.contact_force) == (2, 10.0, 10.0)
    assert (above_centre.clumps_above, above_centre.weight_above, above_centre.contact_force) == (1, 5.0, 5.0)


def test_a_wall_that_pulls_the_top_down_makes_the_contacts_carry_more_than_the_weight_and_fails():
    sphere_clump, mass, z, wall, i, j, force = stack(wall_pull_on_top=1.0)
    balance = fill_balance(sphere_clump, mass, z, wall, i, j, force, [2.0, 4.0], G,
                           wall_forces={"floor": [0.0, 0.0, 16.0], "wall": [0.0, 0.0, -1.0]}, floor_walls=["floor"])
    assert balance.weight == 15.0 and balance.support == 15.0 and balance.support_ratio == 1.0
    assert balance.floor_ratio == 16.0 / 15.0 and balance.walls_ratio == -1.0 / 15.0
    assert balance.silo_like is False
    assert [plane.contact_ratio for plane in balance.planes] == [11.0 / 10.0, 6.0 / 5.0]
    assert [plane.wall_ratio for plane in balance.planes] == [-1.0 / 10.0, -1.0 / 5.0]
    problems = balance_problems(balance, BalanceTolerances(support=0.01, plane=0.03))
    assert len(problems) == 2
    assert "plane at 2000 mm carry 1.100 of the weight above it" in problems[0]
    assert "walls hold the fill down" in problems[1]


def test_walls_that_carry_part_of_the_weight_pass():
    # a wall pushes the top sphere up by 1 N: the contacts below carry less than the weight above
    sphere_clump, mass, z, wall, i, j, force = stack(wall_pull_on_top=-1.0)
    balance = fill_balance(sphere_clump, mass, z, wall, i, j, force, [2.0, 4.0], G,
                           wall_forces={"floor": [0.0, 0.0, 14.0], "wall": [0.0, 0.0, 1.0]}, floor_walls=["floor"])
    assert [plane.contact_ratio for plane in balance.planes] == [9.0 / 10.0, 4.0 / 5.0]
    assert balance.silo_like is True and balance_problems(balance) == []


def test_a_column_on_frictionless_walls_carries_exactly_its_weight_on_the_floor():
    sphere_clump, mass, z, wall, i, j, force = stack()
    wall[2, 0], wall[3, 0] = 2.0, -2.0  # side walls push sideways only
    balance = fill_balance(sphere_clump, mass, z, wall, i, j, force, [2.0], G,
                           wall_forces={"floor": [0.0, 0.0, 15.0], "left": [2.0, 0.0, 0.0], "right": [-2.0, 0.0, 0.0]},
                           floor_walls=["floor"])
    assert balance.floor_ratio == 1.0 and balance.walls_ratio == 0.0 and balance.silo_like is True
    assert balance.wall_horizontal == {"floor": 0.0, "left": 2.0, "right": 2.0}
    assert balance.as_dict()["wall_support_ratio"] == {"floor": 1.0, "left": 0.0, "right": 0.0}


def test_a_fill_not_at_rest_fails_on_its_support():
    sphere_clump, mass, z, wall, i, j, force = stack()
    wall[0, 2] = 13.0  # the floor carries 2 N less than the weight
    balance = fill_balance(sphere_clump, mass, z, wall, i, j, force, [], G)
    assert balance.support_ratio == 13.0 / 15.0 and np.isnan(balance.floor_ratio) and balance.silo_like is None
    (problem,) = balance_problems(balance)
    assert problem.startswith("walls and floor carry 0.8667 of the fill's weight (15 N)")


def test_the_settled_fill_adapter_finds_clumps_and_contact_spheres_by_id():
    sphere_clump, mass, z, wall, i, j, force = stack(wall_pull_on_top=1.0)
    ids = np.array([16, 15, 14, 13, 12, 11])  # ids in another order than the rows
    sphere_z = np.array([0.5, 1.5, 2.5, 3.5, 4.5, 5.5])
    frame = ParticleFrame(time=1.0, step=10, id=ids, type=np.ones(6), clump_id=np.array([7, 7, 8, 8, 9, 9]),
                          position=np.column_stack([np.zeros(6), np.zeros(6), sphere_z]), velocity=np.zeros((6, 3)),
                          angular_velocity=None, radius=np.full(6, 0.5), mass=np.full(6, M))
    contacts = ContactFrame(step=10, position_i=np.zeros((2, 3)), position_j=np.zeros((2, 3)), id_i=ids[i],
                            id_j=ids[j], force=force)
    settled = SettledFill(frame=frame, wall_force=wall, contacts=contacts,
                          wall_forces={"floor": [0, 0, 16.0], "wall": [0, 0, -1.0]}, floor_walls=("floor",))
    balance = settled_fill_balance(settled, [2.0, 4.0], G)
    assert balance.weight == 15.0 and balance.n_clumps == 3
    assert [plane.contact_force for plane in balance.planes] == [11.0, 6.0]
    stray = ContactFrame(step=10, position_i=np.zeros((1, 3)), position_j=np.zeros((1, 3)), id_i=np.array([99]),
                         id_j=np.array([11]), force=np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"contacts name spheres \[99\]"):
        settled_fill_balance(SettledFill(frame=frame, wall_force=wall, contacts=stray), [2.0], G)


def test_two_steps_that_alternate_about_rest_average_to_the_balance_at_rest():
    """The floor and the contacts carry 1 N more, then 1 N less, than at rest: each step fails, their mean is exact."""
    sphere_clump, mass, z, wall, i, j, force = stack()
    frame = ParticleFrame(time=1.0, step=10, id=np.arange(1, 7), type=np.ones(6),
                          clump_id=np.array([7, 7, 8, 8, 9, 9]),
                          position=np.column_stack([np.zeros(6), np.zeros(6), [0.5, 1.5, 2.5, 3.5, 4.5, 5.5]]),
                          velocity=np.zeros((6, 3)), angular_velocity=None, radius=np.full(6, 0.5), mass=np.full(6, M))
    steps = []
    for offset in (1.0, -1.0):
        step_wall = wall.copy()
        step_wall[0, 2] += offset
        step_force = force.copy()
        step_force[0, 2] -= offset  # the force on sphere 1 (below the plane at 2) by sphere 2
        contacts = ContactFrame(step=10, position_i=np.zeros((2, 3)), position_j=np.zeros((2, 3)), id_i=i + 1,
                                id_j=j + 1, force=step_force)
        steps.append(SettledFill(frame=frame, wall_force=step_wall, contacts=contacts,
                                 wall_forces={"floor": [0, 0, 15.0 + offset], "wall": [0, 0, 0.0]},
                                 floor_walls=("floor",)))
    each = [settled_fill_balance(step, [2.0, 4.0], G) for step in steps]
    assert [balance.support_ratio for balance in each] == [16.0 / 15.0, 14.0 / 15.0]
    assert [balance.planes[0].contact_force for balance in each] == [11.0, 9.0]
    balance = settled_fill_balance(steps, [2.0, 4.0], G)
    assert balance.support_ratio == 1.0 and balance.floor_ratio == 1.0 and balance.walls_ratio == 0.0
    assert [plane.contact_force for plane in balance.planes] == [10.0, 5.0]
    assert [plane.closure for plane in balance.planes] == [1.0, 1.0]
    assert balance_problems(balance) == []


def test_balances_of_different_fills_are_not_averaged():
    sphere_clump, mass, z, wall, i, j, force = stack()
    one = fill_balance(sphere_clump, mass, z, wall, i, j, force, [2.0], G, {"floor": [0, 0, 15.0]}, ("floor",))
    other_planes = fill_balance(sphere_clump, mass, z, wall, i, j, force, [4.0], G, {"floor": [0, 0, 15.0]},
                                ("floor",))
    other_walls = fill_balance(sphere_clump, mass, z, wall, i, j, force, [2.0], G, {"base": [0, 0, 15.0]}, ("base",))
    assert mean_balance([one, one]) == one
    for other in (other_planes, other_walls):
        with pytest.raises(ValueError, match="not of one fill"):
            mean_balance([one, other])
    with pytest.raises(ValueError, match="no balance"):
        mean_balance([])
    with pytest.raises(ValueError, match="no step"):
        settled_fill_balance([], [2.0], G)


def test_bad_input_is_refused_with_its_name():
    sphere_clump, mass, z, wall, i, j, force = stack()
    with pytest.raises(ValueError, match="clump index outside"):
        plane_loads(sphere_clump + 1, mass, z, wall[:, 2], i, j, force[:, 2], [1.0], G)
    with pytest.raises(ValueError, match="sphere index outside"):
        plane_loads(sphere_clump, mass, z, wall[:, 2], i + 10, j, force[:, 2], [1.0], G)
    with pytest.raises(ValueError, match="no clumps"):
        fill_balance([], [], [], np.zeros((0, 3)), [], [], np.zeros((0, 3)), [1.0], G)
    with pytest.raises(ValueError, match=r"floor walls \['gate'\]"):
        fill_balance(sphere_clump, mass, z, wall, i, j, force, [1.0], G, wall_forces={"floor": [0, 0, 15.0]},
                     floor_walls=["gate"])
