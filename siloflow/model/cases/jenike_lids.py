"""The lids of the Jenike shear cell: the rigid lid of glued spheres and the servo lid's proxy body.

``rigid``: a disk of glued spheres (one layer, :func:`lid_sphere_layout`) integrated as one rigid
body that translates vertically and may tilt and rotate, loaded by a constant vertical force F_N
with its weight cancelled. Its spheres have the radius of the smallest particle sphere and the
particle density (the lid material has no density in the configuration).

``servo``: a flat disk mesh (:meth:`siloflow.model.cases.jenike_cell.CellGeometry.servo_lid`) that cannot tilt
or rotate, loaded by the same constant force. A lid held still while the shear ring moves away would turn
the test into a wall-friction test of the ring against the sample; so the lid mesh moves along x at the
shear velocity (with the ring) and along z with a proxy body of the lid's mass driven by the particles'
force on the mesh minus F_N (:class:`ServoLid`).

Coordinates (SI units) are those of the cell (:mod:`siloflow.model.cases.jenike_cell`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.constants import GRAVITY


#: The most spheres a rigid lid may have: far above a 1 m cell's lid of the study's 3 mm spheres (some 2e5), and a
#: few tens of megabytes of centres; a cell thousands of sphere diameters across would need billions.
MAX_LID_SPHERES = 1_000_000


def lid_sphere_layout(outer_radius: float, spacing: float) -> np.ndarray:
    """Centres (x, y) of the lid spheres relative to the lid axis: a centre sphere and concentric rings.

    Rings lie at radii k * outer_radius / K, k = 1..K, K = ceil(outer_radius / spacing), so the outermost
    ring lies exactly at ``outer_radius`` and the radial step is at most ``spacing``; ring k holds
    ceil(2 pi r_k / spacing) equally spaced spheres, every other ring turned by half a step.

    Parameters
    ----------
    outer_radius : float
        Radius of the outermost ring of centres (m).
    spacing : float
        Largest centre spacing along and between rings (m).

    Returns
    -------
    numpy.ndarray
        (k, 2) centres (m).

    Raises
    ------
    ValueError
        For a radius or spacing that is not positive, or a lid of more than :data:`MAX_LID_SPHERES` spheres.
    """
    if not (outer_radius > 0 and spacing > 0):
        raise ValueError(f"need positive outer_radius and spacing, got {outer_radius!r}, {spacing!r}")
    # K <= R / s + 1 rings, ring k at most 2 pi k + 1 spheres: at most 1 + K + pi K (K + 1), counted before laying
    # them out (in floats, which reach inf rather than overflow)
    most_rings = outer_radius / spacing + 1.0
    most = 1.0 + most_rings + math.pi * most_rings * (most_rings + 1.0)
    if not most <= MAX_LID_SPHERES:
        raise ValueError(f"a lid of radius {outer_radius:.4g} m with spheres {spacing:.4g} m apart would hold up to "
                         f"{most:.3g} spheres, more than the {MAX_LID_SPHERES} a lid is given")
    rings = math.ceil(outer_radius / spacing - 1e-9)
    step = outer_radius / rings
    points = [np.zeros((1, 2))]
    for k in range(1, rings + 1):
        radius = k * step
        count = math.ceil(2.0 * math.pi * radius / spacing - 1e-9)
        angles = 2.0 * np.pi * (np.arange(count) + 0.5 * (k % 2)) / count
        points.append(np.column_stack([radius * np.cos(angles), radius * np.sin(angles)]))
    return np.vstack(points)


@dataclass(frozen=True)
class RigidLid:
    """A lid of glued spheres integrated as one rigid body.

    Attributes
    ----------
    positions : numpy.ndarray
        (k, 2) sphere centres (x, y) in the cell frame (m).
    sphere_radius : float
        Radius of every lid sphere (m).
    density : float
        Density of the lid spheres (kg/m^3).
    height_above_sample : float
        Lid sphere centres are placed this far above the highest sample sphere centre (m).
    normal_force : float
        Vertical load F_N (N).
    """

    positions: np.ndarray
    sphere_radius: float
    density: float
    height_above_sample: float
    normal_force: float

    @property
    def n_spheres(self) -> int:
        return int(len(self.positions))

    @property
    def sphere_mass(self) -> float:
        """Mass of one lid sphere (kg)."""
        return self.density * 4.0 / 3.0 * math.pi * self.sphere_radius**3

    @property
    def mass(self) -> float:
        """Lid mass (kg); overlaps of the glued spheres count twice (the lid's mass is a free choice)."""
        return self.n_spheres * self.sphere_mass

    @property
    def sphere_weight(self) -> float:
        """Weight of one lid sphere, m g (N); each sphere carries an upward force of this to cancel it."""
        return self.sphere_mass * GRAVITY

    @property
    def load_per_sphere(self) -> float:
        """Share of F_N applied downwards to each lid sphere (N)."""
        return self.normal_force / self.n_spheres


@dataclass(frozen=True)
class ServoLid:
    """A flat disk mesh that cannot tilt or rotate, loaded by a constant vertical force.

    The lid mesh moves along x at the shear velocity (with the ring) and along z at the velocity of a proxy
    rigid body (two point masses without contacts, placed above the lid plane) of the lid's mass, integrated
    under the particles' vertical force on the mesh minus F_N (its weight cancelled); a proportional force
    controller would lag behind the dilation of the sheared sample. The lid is thus an ideal force servo: a flat rigid
    lid free to move vertically only, with the same mass as the rigid lid of the same cell.

    Attributes
    ----------
    height_above_sample : float
        The lid plane is placed this far above the highest sample sphere centre (m).
    normal_force : float
        Vertical load F_N (N).
    mass : float
        Mass of the proxy (kg).
    proxy_radius : float
        Radius of the proxy spheres (m); only their mass matters.
    centre : tuple of float
        (x, y) of the lid axis (m).
    """

    height_above_sample: float
    normal_force: float
    mass: float
    proxy_radius: float
    centre: tuple[float, float]

    @property
    def proxy_positions(self) -> np.ndarray:
        """(2, 2) centres (x, y) of the two proxy spheres, touching, about the lid axis (m)."""
        x, y = self.centre
        return np.array([[x - self.proxy_radius, y], [x + self.proxy_radius, y]])

    @property
    def proxy_height(self) -> float:
        """Height of the proxy's centres above the lid plane (m), clear of any contact with the lid mesh."""
        return 4.0 * self.proxy_radius

    @property
    def proxy_density(self) -> float:
        """Density that gives the two proxy spheres together the lid's mass (kg/m^3)."""
        return self.mass / (2.0 * 4.0 / 3.0 * math.pi * self.proxy_radius**3)

    @property
    def weight(self) -> float:
        """Weight of the proxy, M g (N); cancelled by an equal upward force."""
        return self.mass * GRAVITY
