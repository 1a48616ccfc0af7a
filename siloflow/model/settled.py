"""A fill at rest, as one engine snapshot: the engine-neutral input of the force balance.

Nothing here reads or writes files. SI units: m, s, kg, N.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from siloflow.model.arrays import frozen_array
from siloflow.model.contacts import ContactFrame
from siloflow.model.frames import ParticleFrame

__all__ = ["SettledFill"]


@dataclass(frozen=True, eq=False)
class SettledFill:
    """The spheres of a settled fill with the force the walls exert on each, and the pair contacts, at one step.

    Attributes
    ----------
    frame : ParticleFrame
        The spheres at rest.
    wall_force : numpy.ndarray of float64, shape (n, 3)
        Row i: the force of all walls (and the floor) on sphere i of ``frame`` [N].
    contacts : ContactFrame
        The pair contacts at the same step (force on sphere i by sphere j).
    wall_forces : dict of str to numpy.ndarray, shape (3,)
        Per wall, its total force on the particles at (or within one output interval before) the snapshot [N];
        empty when the engine gives no per-wall split.
    floor_walls : tuple of str
        Names in ``wall_forces`` that make the floor (plates, gate, base).

    Raises
    ------
    ValueError
        When the steps of frame and contacts differ, a shape is wrong, or a floor wall is not a known wall.
    """

    frame: ParticleFrame
    wall_force: np.ndarray
    contacts: ContactFrame
    wall_forces: dict = field(default_factory=dict)
    floor_walls: tuple = ()

    def __post_init__(self) -> None:
        if self.frame.step != self.contacts.step:
            raise ValueError(f"spheres at step {self.frame.step} but contacts at step {self.contacts.step}")
        wall_force = frozen_array(self.wall_force, float, (3,), "wall_force", len(self.frame.id))
        if not np.all(np.isfinite(wall_force)):
            raise ValueError("wall_force holds a non-finite value")
        wall_forces = {str(name): frozen_array([value], float, (3,), f"force of wall {name!r}", 1)[0]
                       for name, value in dict(self.wall_forces).items()}
        floor_walls = tuple(self.floor_walls)
        unknown = [name for name in floor_walls if wall_forces and name not in wall_forces]
        if unknown:
            raise ValueError(f"floor walls {unknown} are not among the walls {sorted(wall_forces)}")
        object.__setattr__(self, "wall_force", wall_force)
        object.__setattr__(self, "wall_forces", wall_forces)
        object.__setattr__(self, "floor_walls", floor_walls)
