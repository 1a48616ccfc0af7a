"""The study's rolling law, stated once, and the geometry of a clump that each engine's adapter maps it with.

The study's law (EDEM's constant directional torque, thesis §4.2, METHODS §1): at each contact of particle i, a torque
against the particle's own spin,

    tau_i = - mu_r |F_n| R_i omega_i / |omega_i|,

with R_i the distance from the contact point to the clump's centre of mass. The configured ``rolling_friction`` of a
contact is this ``mu_r``.

Neither engine computes exactly this torque, so each adapter gives its own law the coefficients that reproduce the
study's torque for a clump of a given shape as closely as its law allows (``siloflow.engines.liggghts.rolling``,
``siloflow.engines.yade.inputs``). What they need of the clump is :class:`RollingGeometry`: the study's lever arm
averaged over the clump's exposed surface, and the radius of the sphere that makes the contact, averaged the same way.
The average is over the surface area with equal weight: a contact is taken as equally likely anywhere on the exposed
surface, which holds for a random packing of a convex-ish clump and is the one assumption of the mapping (the lever
arm of a two-sphere clump spans 1.45-1.875 mm about its mean of about 1.6 mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ROLLING_LAW", "RollingGeometry", "rolling_geometry", "study_torque", "SURFACE_POINTS"]

#: The rolling law the engines are given, by name: part of every run id (siloflow.model.cases.common.run_id), so
#: that a run made under another law is never taken for one made under this.
ROLLING_LAW = "study torque mu_r |Fn| R at the clump's mean lever arm"

#: Points per sphere of the surface quadrature (a Fibonacci lattice): the lever arm of the study's clumps converges
#: to 1e-5 of itself at this number (tests/unit/test_rolling.py).
SURFACE_POINTS = 20000


@dataclass(frozen=True)
class RollingGeometry:
    """What an engine's rolling law needs of a clump to reproduce the study's torque.

    Attributes
    ----------
    lever_arm : float
        The study's R_i averaged over the clump's exposed surface: the mean distance from a contact point to the
        centre of mass (m).
    contact_radius : float
        The radius of the sphere that makes a contact, averaged over the exposed surface (m): the lever arm the
        engines' own laws use.
    """

    lever_arm: float
    contact_radius: float

    @property
    def ratio(self) -> float:
        """The study's lever arm over the contact sphere's radius (-): 1 for a single sphere. Rounded to 12 digits:
        the quadrature knows it to 1e-5, and a sphere's lever arm is its radius to rounding, which must map to 1."""
        return round(self.lever_arm / self.contact_radius, 12)


def _fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` nearly uniform unit vectors (a Fibonacci lattice), each standing for an equal share of the area."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    azimuth = math.pi * (1.0 + 5.0**0.5) * k
    ring = np.sqrt(1.0 - z * z)
    return np.column_stack([ring * np.cos(azimuth), ring * np.sin(azimuth), z])


def rolling_geometry(sphere_positions, sphere_radii, points: int = SURFACE_POINTS) -> RollingGeometry:
    """The :class:`RollingGeometry` of a clump of overlapping spheres.

    Parameters
    ----------
    sphere_positions : array_like, shape (k, 3)
        Sphere centres relative to the clump's centre of mass (m), as
        :attr:`siloflow.model.cases.particles.ParticleTemplate.sphere_positions` (the centroid of the union: the
        centre of mass of a uniform clump).
    sphere_radii : array_like, shape (k,)
        Sphere radii (m). A sphere wholly inside another (a one-sphere model's inner sphere) has no exposed surface.
    points : int
        Quadrature points per sphere.
    """
    centres = np.asarray(sphere_positions, dtype=float).reshape(-1, 3)
    radii = np.asarray(sphere_radii, dtype=float).reshape(-1)
    if centres.shape[0] != radii.size or radii.size == 0 or np.any(radii <= 0):
        raise ValueError("one centre and one radius > 0 per sphere, at least one sphere")
    unit = _fibonacci_sphere(points)
    arm, radius, area = 0.0, 0.0, 0.0
    for k, (centre, r) in enumerate(zip(centres, radii)):
        surface = centre + r * unit
        exposed = np.ones(points, dtype=bool)
        for j, (other, s) in enumerate(zip(centres, radii)):
            if j != k:
                exposed &= np.linalg.norm(surface - other, axis=1) >= s
        share = 4.0 * math.pi * r * r / points
        arm += share * float(np.linalg.norm(surface[exposed], axis=1).sum())
        radius += share * r * int(exposed.sum())
        area += share * int(exposed.sum())
    if area == 0.0:
        raise ValueError("the clump has no exposed surface")
    return RollingGeometry(lever_arm=float(arm / area), contact_radius=float(radius / area))


def study_torque(rolling_friction: float, normal_force: float, lever_arm: float) -> float:
    """The magnitude of the study's rolling torque at one contact, ``mu_r |F_n| R_i`` (N m), from the coefficient
    (-), the normal force (N) and the distance from the contact point to the centre of mass (m)."""
    return abs(rolling_friction) * abs(normal_force) * lever_arm
