"""Contacts at one saved instant: the engine-neutral form every engine reader returns.

SI units: positions in m, forces in N.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ContactFrame", "WallContactFrame"]


@dataclass(frozen=True)
class ContactFrame:
    """Pairwise contacts at one time step.

    Attributes
    ----------
    step : int
        Time step.
    position_i, position_j : numpy.ndarray
        (n, 3) centres of the two spheres in contact (m).
    id_i, id_j : numpy.ndarray
        (n,) sphere ids.
    force : numpy.ndarray
        (n, 3) contact force on sphere i by sphere j (N).
    """

    step: int
    position_i: np.ndarray
    position_j: np.ndarray
    id_i: np.ndarray
    id_j: np.ndarray
    force: np.ndarray

    def __len__(self) -> int:
        return int(self.id_i.shape[0])

    @property
    def branch(self) -> np.ndarray:
        """Branch vectors x_j - x_i (m)."""
        return self.position_j - self.position_i

    @property
    def normal_force(self) -> np.ndarray:
        """Magnitude of the force component along the branch vector (N); positive in compression."""
        branch = self.branch
        length = np.linalg.norm(branch, axis=1)
        safe = np.where(length > 0, length, 1.0)
        return -np.einsum("ij,ij->i", self.force, branch) / safe


@dataclass(frozen=True)
class WallContactFrame:
    """Particle-wall contacts at one time step.

    Attributes
    ----------
    step : int
        Time step.
    point : numpy.ndarray
        (n, 3) contact points on the walls (m).
    centre : numpy.ndarray
        (n, 3) centres of the spheres in contact (m).
    wall : numpy.ndarray
        (n,) name of the wall each contact is on (str).
    particle_id : numpy.ndarray
        (n,) sphere ids.
    normal_force, tangential_force : numpy.ndarray
        (n, 3) normal and tangential parts of the contact force on the sphere (N), as the engine reports them.
    """

    step: int
    point: np.ndarray
    centre: np.ndarray
    wall: np.ndarray
    particle_id: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray

    def __len__(self) -> int:
        return int(self.particle_id.shape[0])
