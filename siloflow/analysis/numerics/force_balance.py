"""Force balance of a fill at rest: how its weight reaches the floor, the walls, and each horizontal plane.

A settled fill of rigid clumps is in equilibrium: the walls and the floor carry its weight, and for any horizontal
plane at height h the clumps above it (those whose centre of mass is above h: a rigid clump is on one side of a
plane, even where it straddles it) are held by the contact forces of the clumps below plus the walls' forces on
them::

    F_contacts(h) + F_walls(h) = W(h)        (vertical components)

In a silo the walls carry part of the weight by friction (Janssen), so the contacts across a plane carry at most
the weight above it. A fill whose contacts carry more than that is held down by its walls: the stress state a
violent pour locked in, not a silo's. Nothing here reads files; forces in N, heights in m, masses in kg.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.frames import clumps_from_frame
from siloflow.model.settled import SettledFill

__all__ = ["PlaneLoad", "FillBalance", "plane_loads", "fill_balance", "settled_fill_balance", "mean_balance",
           "BalanceTolerances", "balance_problems"]


@dataclass(frozen=True)
class PlaneLoad:
    """The vertical load across one horizontal plane.

    Attributes
    ----------
    height : float
        Height of the plane [m].
    clumps_above : int
        Clumps whose centre of mass is above the plane [-].
    weight_above : float
        Their weight [N].
    contact_force : float
        Upward force of the clumps below on the clumps above, summed over the contacts across the plane [N].
    wall_force : float
        Upward force of the walls (and floor) on the clumps above [N].
    """

    height: float
    clumps_above: int
    weight_above: float
    contact_force: float
    wall_force: float

    @property
    def contact_ratio(self) -> float:
        """Contacts' share of the weight above [-]; 1 on frictionless walls, below 1 in a silo."""
        return self.contact_force / self.weight_above if self.weight_above > 0 else float("nan")

    @property
    def wall_ratio(self) -> float:
        """Walls' share of the weight above [-]; negative where the walls hold the clumps down."""
        return self.wall_force / self.weight_above if self.weight_above > 0 else float("nan")

    @property
    def closure(self) -> float:
        """(contacts + walls) / weight above [-]: 1 at rest; the departure measures what is still moving."""
        return (self.contact_force + self.wall_force) / self.weight_above if self.weight_above > 0 else float("nan")


def plane_loads(
    sphere_clump: np.ndarray,
    clump_mass: np.ndarray,
    clump_z: np.ndarray,
    sphere_wall_force_z: np.ndarray,
    contact_sphere_i: np.ndarray,
    contact_sphere_j: np.ndarray,
    contact_force_z: np.ndarray,
    heights: Sequence[float],
    gravity: float,
) -> list[PlaneLoad]:
    """Vertical load across horizontal planes of a fill of rigid clumps.

    Parameters
    ----------
    sphere_clump : numpy.ndarray of int, shape (n_spheres,)
        Index (0..n_clumps-1) of the clump each sphere belongs to.
    clump_mass : numpy.ndarray, shape (n_clumps,)
        Clump masses [kg].
    clump_z : numpy.ndarray, shape (n_clumps,)
        Heights of the clumps' centres of mass [m].
    sphere_wall_force_z : numpy.ndarray, shape (n_spheres,)
        Vertical force of all walls on each sphere [N].
    contact_sphere_i, contact_sphere_j : numpy.ndarray of int, shape (n_contacts,)
        Sphere indices (rows of the sphere arrays) of the two spheres of each contact.
    contact_force_z : numpy.ndarray, shape (n_contacts,)
        Vertical force on sphere i by sphere j [N].
    heights : sequence of float
        Plane heights [m].
    gravity : float
        Magnitude of gravity, acting along -z [m/s^2].

    Returns
    -------
    list of PlaneLoad
        One per height, in the given order.

    Raises
    ------
    ValueError
        When an index is out of range or the array lengths disagree.
    """
    sphere_clump = np.asarray(sphere_clump, dtype=np.int64)
    clump_mass = np.asarray(clump_mass, dtype=float)
    clump_z = np.asarray(clump_z, dtype=float)
    wall_z = np.asarray(sphere_wall_force_z, dtype=float)
    i = np.asarray(contact_sphere_i, dtype=np.int64)
    j = np.asarray(contact_sphere_j, dtype=np.int64)
    force_z = np.asarray(contact_force_z, dtype=float)
    n_spheres, n_clumps = sphere_clump.shape[0], clump_mass.shape[0]
    if clump_z.shape != (n_clumps,):
        raise ValueError(f"clump_z has shape {clump_z.shape}, expected ({n_clumps},) like clump_mass")
    if wall_z.shape != (n_spheres,):
        raise ValueError(f"sphere_wall_force_z has shape {wall_z.shape}, expected ({n_spheres},) like sphere_clump")
    if not (i.shape == j.shape == force_z.shape and i.ndim == 1):
        raise ValueError("contact_sphere_i, contact_sphere_j and contact_force_z must be 1-D of one length")
    if n_spheres and (sphere_clump.min() < 0 or sphere_clump.max() >= n_clumps):
        raise ValueError(f"sphere_clump holds a clump index outside 0..{n_clumps - 1}")
    if i.size and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n_spheres):
        raise ValueError(f"a contact names a sphere index outside 0..{n_spheres - 1}")
    contact_clump_i, contact_clump_j = sphere_clump[i], sphere_clump[j]
    loads = []
    for height in heights:
        above = clump_z > height
        sphere_above = above[sphere_clump]
        above_i, above_j = above[contact_clump_i], above[contact_clump_j]
        # the force on the side above: on i where only i is above, the reaction on j where only j is
        contacts = force_z[above_i & ~above_j].sum() - force_z[above_j & ~above_i].sum()
        loads.append(PlaneLoad(
            height=float(height),
            clumps_above=int(above.sum()),
            weight_above=float(clump_mass[above].sum() * gravity),
            contact_force=float(contacts),
            wall_force=float(wall_z[sphere_above].sum()),
        ))
    return loads


@dataclass(frozen=True)
class FillBalance:
    """The force balance of a fill at rest.

    Attributes
    ----------
    weight : float
        Weight of the fill [N].
    n_clumps : int
        Clumps in the fill [-].
    support : float
        Upward force of all walls and the floor on the fill [N] (from the per-sphere wall forces).
    wall_support : dict of str to float
        Per wall, its upward force on the fill [N]; empty where the engine gives no per-wall split.
    wall_horizontal : dict of str to float
        Per wall, the magnitude of its horizontal force on the fill [N].
    floor_walls : tuple of str
        The walls that make the floor (plates, gate, base); the others are the walls.
    planes : list of PlaneLoad
        The load across each horizontal plane.
    """

    weight: float
    n_clumps: int
    support: float
    wall_support: dict
    wall_horizontal: dict
    floor_walls: tuple
    planes: list

    @property
    def support_ratio(self) -> float:
        """(walls + floor) / weight [-]; 1 at rest."""
        return self.support / self.weight

    @property
    def floor_ratio(self) -> float:
        """Floor's share of the weight [-]; NaN without a per-wall split."""
        if not self.wall_support:
            return float("nan")
        return sum(value for name, value in self.wall_support.items() if name in self.floor_walls) / self.weight

    @property
    def walls_ratio(self) -> float:
        """Walls' (not the floor's) share of the weight [-]; negative where the walls hold the fill down."""
        if not self.wall_support:
            return float("nan")
        return sum(value for name, value in self.wall_support.items() if name not in self.floor_walls) / self.weight

    @property
    def silo_like(self) -> bool | None:
        """Whether the walls carry part of the weight (share >= 0), as in a silo; None when unknown."""
        ratio = self.walls_ratio
        return None if not np.isfinite(ratio) else bool(ratio >= 0.0)

    def as_dict(self) -> dict:
        """Plain figures (for JSON), ratios to the weight included."""
        return {
            "weight_N": self.weight,
            "clumps": self.n_clumps,
            "support_ratio": self.support_ratio,
            "floor_ratio": self.floor_ratio,
            "walls_ratio": self.walls_ratio,
            "silo_like": self.silo_like,
            "floor_walls": list(self.floor_walls),
            "wall_support_ratio": {name: value / self.weight for name, value in self.wall_support.items()},
            "wall_horizontal_ratio": {name: value / self.weight for name, value in self.wall_horizontal.items()},
            "planes": [
                {"height_m": plane.height, "clumps_above": plane.clumps_above, "weight_above_N": plane.weight_above,
                 "contact_ratio": plane.contact_ratio, "wall_ratio": plane.wall_ratio, "closure": plane.closure}
                for plane in self.planes
            ],
        }


def fill_balance(
    sphere_clump: np.ndarray,
    clump_mass: np.ndarray,
    clump_z: np.ndarray,
    sphere_wall_force: np.ndarray,
    contact_sphere_i: np.ndarray,
    contact_sphere_j: np.ndarray,
    contact_force: np.ndarray,
    heights: Sequence[float],
    gravity: float,
    wall_forces: Mapping[str, np.ndarray] | None = None,
    floor_walls: Sequence[str] = (),
) -> FillBalance:
    """The force balance of a fill at rest (see :func:`plane_loads` for the arrays).

    Parameters
    ----------
    sphere_wall_force : numpy.ndarray, shape (n_spheres, 3)
        Force of all walls on each sphere [N].
    contact_force : numpy.ndarray, shape (n_contacts, 3)
        Force on sphere i by sphere j [N].
    wall_forces : mapping of str to array of 3 floats, optional
        Per wall, its total force on the particles at the same moment [N], for the split between floor and walls.
    floor_walls : sequence of str
        Names in ``wall_forces`` that make the floor.

    Raises
    ------
    ValueError
        When the fill is empty, or a floor wall is not among ``wall_forces``.
    """
    clump_mass = np.asarray(clump_mass, dtype=float)
    if clump_mass.size == 0:
        raise ValueError("the fill holds no clumps: nothing to balance")
    sphere_wall_force = np.asarray(sphere_wall_force, dtype=float).reshape(-1, 3)
    contact_force = np.asarray(contact_force, dtype=float).reshape(-1, 3)
    wall_forces = {name: np.asarray(value, dtype=float).reshape(3) for name, value in (wall_forces or {}).items()}
    unknown = [name for name in floor_walls if name not in wall_forces]
    if wall_forces and unknown:
        raise ValueError(f"floor walls {unknown} are not among the walls {sorted(wall_forces)}")
    planes = plane_loads(sphere_clump, clump_mass, clump_z, sphere_wall_force[:, 2], contact_sphere_i,
                         contact_sphere_j, contact_force[:, 2], heights, gravity)
    return FillBalance(
        weight=float(clump_mass.sum() * gravity),
        n_clumps=int(clump_mass.size),
        support=float(sphere_wall_force[:, 2].sum()),
        wall_support={name: float(value[2]) for name, value in wall_forces.items()},
        wall_horizontal={name: float(np.hypot(value[0], value[1])) for name, value in wall_forces.items()},
        floor_walls=tuple(floor_walls),
        planes=planes,
    )


def settled_fill_balance(settled: SettledFill | Sequence[SettledFill], heights: Sequence[float],
                         gravity: float) -> FillBalance:
    """The force balance of an engine's settled fill (:func:`fill_balance` on its spheres, contacts and walls),
    averaged over the steps of its snapshot (:func:`mean_balance`).

    A clump's centre of mass is the mean of its sphere centres (exact for the symmetric templates of siloflow's
    particle models); its mass is its own (see :func:`siloflow.model.frames.clumps_from_frame`).

    Parameters
    ----------
    settled : SettledFill or sequence of SettledFill
        The fill at one step, or at consecutive steps (an engine's fill at rest alternates about equilibrium
        from step to step; the mean of two steps removes it).

    Raises
    ------
    ValueError
        When no step is given, or a contact names a sphere that is not in the frame.
    """
    steps = [settled] if isinstance(settled, SettledFill) else list(settled)
    if not steps:
        raise ValueError("the settled fill has no step: nothing to balance")
    return mean_balance([_step_balance(step, heights, gravity) for step in steps])


def _step_balance(settled: SettledFill, heights: Sequence[float], gravity: float) -> FillBalance:
    frame = settled.frame
    clumps = clumps_from_frame(frame)
    sphere_clump = np.searchsorted(clumps.clump_id, frame.clump_id)
    order = np.argsort(frame.id)
    sorted_ids = frame.id[order]

    def rows(ids: np.ndarray) -> np.ndarray:
        found = np.searchsorted(sorted_ids, ids).clip(0, max(len(sorted_ids) - 1, 0))
        if ids.size and (sorted_ids.size == 0 or np.any(sorted_ids[found] != ids)):
            missing = ids[sorted_ids[found] != ids] if sorted_ids.size else ids
            raise ValueError(f"contacts name spheres {missing[:5].tolist()} that are not in the settled frame")
        return order[found]

    contacts = settled.contacts
    return fill_balance(sphere_clump, clumps.mass, clumps.position[:, 2], settled.wall_force,
                        rows(np.asarray(contacts.id_i, dtype=np.int64)), rows(np.asarray(contacts.id_j, dtype=np.int64)),
                        contacts.force, heights, gravity, settled.wall_forces, settled.floor_walls)


def mean_balance(balances: Sequence[FillBalance]) -> FillBalance:
    """The mean of the balances of one fill at several steps: every force the mean of its values.

    Parameters
    ----------
    balances : sequence of FillBalance
        The same fill (same clumps, walls and planes) at several steps.

    Returns
    -------
    FillBalance
        Forces averaged; the clump count and each plane's count of clumps above from the last step.

    Raises
    ------
    ValueError
        When there is no balance, or they differ in clumps, walls, floor or planes.
    """
    balances = list(balances)
    if not balances:
        raise ValueError("no balance to average")
    last = balances[-1]
    for other in balances[:-1]:
        if (other.n_clumps != last.n_clumps or set(other.wall_support) != set(last.wall_support)
                or other.floor_walls != last.floor_walls
                or [plane.height for plane in other.planes] != [plane.height for plane in last.planes]):
            raise ValueError("the balances to average are not of one fill: clumps, walls, floor or planes differ")

    def mean(values) -> float:
        return float(np.mean(list(values)))

    planes = [
        PlaneLoad(height=plane.height, clumps_above=plane.clumps_above,
                  weight_above=mean(b.planes[index].weight_above for b in balances),
                  contact_force=mean(b.planes[index].contact_force for b in balances),
                  wall_force=mean(b.planes[index].wall_force for b in balances))
        for index, plane in enumerate(last.planes)
    ]
    return FillBalance(
        weight=mean(b.weight for b in balances),
        n_clumps=last.n_clumps,
        support=mean(b.support for b in balances),
        wall_support={name: mean(b.wall_support[name] for b in balances) for name in last.wall_support},
        wall_horizontal={name: mean(b.wall_horizontal[name] for b in balances) for name in last.wall_horizontal},
        floor_walls=last.floor_walls,
        planes=planes,
    )


@dataclass(frozen=True)
class BalanceTolerances:
    """What a fill at rest must satisfy.

    Attributes
    ----------
    support : float
        |(walls + floor) / weight - 1| at most this [-]: the fill is at rest and nothing is missing.
    plane : float
        contacts / weight above at most 1 + this at every plane [-]: no plane carries more than the weight above
        it, so no wall holds the fill down.
    """

    support: float = 0.01
    plane: float = 0.03


def balance_problems(balance: FillBalance, tolerances: BalanceTolerances = BalanceTolerances()) -> list[str]:
    """What is wrong with a fill's balance, as sentences; empty when it passes.

    A fill fails when its walls and floor do not carry its weight, or a plane's contacts carry more than the weight
    above it, beyond the tolerances.
    """
    problems = []
    ratio = balance.support_ratio
    if not abs(ratio - 1.0) <= tolerances.support:
        problems.append(
            f"walls and floor carry {ratio:.4f} of the fill's weight ({balance.weight:.4g} N), not 1 within "
            f"{tolerances.support:g}: the fill is not at rest or a wall's force is missing")
    for plane in balance.planes:
        if plane.clumps_above and not plane.contact_ratio <= 1.0 + tolerances.plane:
            problems.append(
                f"contacts across the plane at {plane.height * 1e3:.0f} mm carry {plane.contact_ratio:.3f} of the "
                f"weight above it (limit 1 + {tolerances.plane:g}); walls carry {plane.wall_ratio:+.3f}: the walls "
                "hold the fill down, a stress state the pour locked in, not a silo's (pour more gently: lower "
                "fill.insertion_velocity or fill.momentum_flux_ratio)")
    return problems
