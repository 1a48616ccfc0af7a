"""Multisphere particle templates: geometry and mass of a clump from its configuration."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.flow import clump_volume, equivalent_diameter


@dataclass(frozen=True)
class ParticleTemplate:
    """A rigid clump of overlapping spheres.

    Attributes
    ----------
    name : str
        Name of the particle model in the configuration.
    sphere_positions : numpy.ndarray
        (k, 3) sphere centres relative to the centroid (m).
    sphere_radii : numpy.ndarray
        (k,) sphere radii (m).
    density : float
        Solid density (kg/m^3).
    volume : float
        Volume of the union of the spheres (m^3).
    """

    name: str
    sphere_positions: np.ndarray
    sphere_radii: np.ndarray
    density: float
    volume: float

    @property
    def n_spheres(self) -> int:
        """Spheres per clump."""
        return int(self.sphere_radii.size)

    @property
    def mass(self) -> float:
        """Clump mass (kg)."""
        return self.density * self.volume

    @property
    def equivalent_diameter(self) -> float:
        """Diameter of the sphere of equal volume (m)."""
        return equivalent_diameter(self.volume)

    @property
    def smallest_radius(self) -> float:
        """Radius of the smallest sphere (m); it sets the time step."""
        return float(self.sphere_radii.min())

    @property
    def bounding_radius(self) -> float:
        """Radius of the smallest centroid-centred sphere enclosing the clump (m)."""
        return float((np.linalg.norm(self.sphere_positions, axis=1) + self.sphere_radii).max())


def particle_template(name: str, model: dict, density: float) -> ParticleTemplate:
    """Build a :class:`ParticleTemplate` from a ``particle_models`` entry of the configuration.

    Sphere centres are shifted so that their centroid is the origin, which is the centre of mass for
    the symmetric templates siloflow uses (equal spheres placed symmetrically).
    """
    positions = np.array([sphere["position"] for sphere in model["spheres"]], dtype=float)
    radii = np.array([sphere["radius"] for sphere in model["spheres"]], dtype=float)
    positions = positions - positions.mean(axis=0)
    volume = float(clump_volume(positions, radii))
    return ParticleTemplate(name, positions, radii, float(density), volume)
