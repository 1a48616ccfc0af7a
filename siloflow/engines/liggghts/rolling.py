"""The study's rolling law on LIGGGHTS: the coefficients of LIGGGHTS' constant directional torque (CDT) that give a
clump the study's torque (:mod:`siloflow.model.rolling`).

LIGGGHTS-PUBLIC 3.8's ``rolling_friction cdt`` (its ``src/rolling_model_cdt.h``) applies, at a contact of two spheres
of radii r_i and r_j (the spheres of two clumps), ``mu * (k_n delta_n) * r_i r_j / (r_i + r_j)`` along their relative
spin ``omega_i - omega_j``, equal and opposite on the two; at a wall contact ``mu * (k_n delta_n) * r_i`` along the
sphere's own spin. The study's torque is ``mu_r |F_n| R_i`` along the particle's own spin, R_i the distance from the
contact point to the clump's centre of mass. So the coefficient that gives the study's torque at the clump's mean lever
arm R (:class:`~siloflow.model.rolling.RollingGeometry`) is

- between particles, ``mu = mu_r R / (r / 2)``, r the contact sphere's radius (the reduced radius of two equal
  spheres is r / 2): 2.23 mu_r for the study's two-sphere clump, 2 mu_r for a single sphere;
- at a wall, ``mu = mu_r R / r``: 1.115 mu_r for the two-sphere clump, mu_r for a single sphere.

What no coefficient can map: the pair torque acts along the relative spin, so two neighbours spinning alike exert none
on each other where the study's law brakes each; and it gives the partner the opposite torque where the study's
gives the partner a torque against its own spin. A contact point's own lever arm (1.45-1.875 mm on the two-sphere
clump) is replaced by the mean. ``docs/engines.md`` gives the error the verification suite measures.
"""

from __future__ import annotations

from siloflow.model.rolling import RollingGeometry

__all__ = ["PARTICLE_TYPE", "cdt_matrix"]

#: The engine type of the particle material (:class:`siloflow.model.cases.common.MaterialTable`): every other type
#: is a wall.
PARTICLE_TYPE = 1


def cdt_matrix(rolling_friction, geometry: RollingGeometry) -> list[list[float]]:
    """LIGGGHTS' CDT coefficients per type pair for the study's coefficients ``rolling_friction`` (a symmetric
    matrix, type 1 the particle material), for a clump of ``geometry``: particle pairs times ``2 R / r``, particle-wall
    pairs times ``R / r``, wall-wall pairs (which never touch) as given."""
    pair, wall = 2.0 * geometry.ratio, geometry.ratio
    mapped = []
    for i, row in enumerate(rolling_friction, start=1):
        mapped.append([float(value) * (pair if i == j == PARTICLE_TYPE else wall if PARTICLE_TYPE in (i, j) else 1.0)
                       for j, value in enumerate(row, start=1)])
    return mapped
