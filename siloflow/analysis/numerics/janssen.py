"""Janssen's method for the mean vertical stress in a rectangular silo.

Pure functions; SI units (m, kg/m3, Pa). The stress ratio is Rankine's active one; the wall friction
coefficients are bulk values (from the calibration chart), not the particle-wall ones.
"""

from __future__ import annotations

import math

import numpy as np

from siloflow.model.constants import GRAVITY
from siloflow.model.checks import non_negative_number, positive_number

__all__ = ["janssen_coefficient", "janssen_characteristic_depth", "janssen_vertical_stress"]


def janssen_coefficient(internal_friction_angle_deg: float) -> float:
    """Janssen's (Rankine active) stress ratio ``K = (1 - sin phi) / (1 + sin phi)`` [-]."""
    phi = float(internal_friction_angle_deg)
    if not math.isfinite(phi) or not 0.0 <= phi < 90.0:
        raise ValueError(f"internal_friction_angle_deg must be in [0, 90), got {phi!r}")
    s = math.sin(math.radians(phi))
    return (1.0 - s) / (1.0 + s)


def janssen_characteristic_depth(
    width: float,
    depth: float,
    wall_friction_side: float,
    wall_friction_front: float,
    internal_friction_angle_deg: float,
) -> float:
    """Janssen depth ``z_c = W T / (2 K (T mu_sw + W mu_fw))`` of a W x T rectangle [m].

    Infinite when both wall friction coefficients are 0 (no wall support: hydrostatic).
    """
    width = positive_number("width", width)
    depth = positive_number("depth", depth)
    mu_side = non_negative_number("wall_friction_side", wall_friction_side)
    mu_front = non_negative_number("wall_friction_front", wall_friction_front)
    k = janssen_coefficient(internal_friction_angle_deg)
    support = 2.0 * k * (depth * mu_side + width * mu_front)
    return math.inf if support == 0.0 else width * depth / support


def janssen_vertical_stress(
    depth_below_surface,
    bulk_density: float,
    width: float,
    depth: float,
    wall_friction_side: float,
    wall_friction_front: float,
    internal_friction_angle_deg: float,
    gravity: float = GRAVITY,
):
    """Mean vertical stress in a rectangular silo by Janssen's method.

    ``sigma_v(h) = gamma z_c (1 - exp(-h / z_c))``, ``gamma = rho_b g``,
    ``z_c = W T / (2 K (T mu_sw + W mu_fw))``, ``K = (1 - sin phi) / (1 + sin phi)``.

    A slice of the W x T cross-section carries its weight ``gamma W T dh`` partly by the
    wall shear ``mu K sigma_v`` on the two side walls (area ``2 T dh``, friction mu_sw) and the
    front and back walls (area ``2 W dh``, friction mu_fw).

    Parameters
    ----------
    depth_below_surface : float or array_like
        Depth h below the free surface [m], >= 0.
    bulk_density : float
        Bulk density rho_b [kg/m3].
    width : float
        Silo width W (between the side walls) [m].
    depth : float
        Silo depth T (between front and back walls) [m].
    wall_friction_side : float
        Bulk wall friction coefficient mu_sw = tan(wall friction angle) of the side walls
        [-] (aluminium in the study); the bulk value from the calibration chart, not the
        particle-wall one.
    wall_friction_front : float
        Bulk wall friction coefficient mu_fw of the front and back walls [-] (perspex).
    internal_friction_angle_deg : float
        Bulk internal friction angle phi [deg].
    gravity : float, optional
        g [m/s2] (default :data:`siloflow.model.constants.GRAVITY`).

    Returns
    -------
    float or numpy.ndarray
        Vertical stress [Pa], compression positive; the shape of ``depth_below_surface``.
        Without wall friction it is the hydrostatic ``gamma h``.
    """
    h = np.asarray(depth_below_surface, dtype=float)
    if not np.all(np.isfinite(h)) or np.any(h < 0.0):
        raise ValueError("depth_below_surface must contain finite numbers >= 0")
    bulk_density = positive_number("bulk_density", bulk_density)
    gravity = positive_number("gravity", gravity)
    z_c = janssen_characteristic_depth(width, depth, wall_friction_side, wall_friction_front, internal_friction_angle_deg)
    gamma = bulk_density * gravity
    stress = gamma * h if math.isinf(z_c) else gamma * z_c * -np.expm1(-h / z_c)
    return float(stress) if stress.ndim == 0 else stress
