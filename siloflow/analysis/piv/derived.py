"""What the study reads off a planar velocity field, the same for a PIV field and for the DEM's front wall: the v_z
profile at a height, its centreline value, the flow channel boundary and the kinematic constant B.

Each quantity is computed by the project's profile functions (:mod:`siloflow.analysis.numerics.profiles`,
:mod:`siloflow.analysis.numerics.kinematic`) on the valid nodes of the node row nearest the height, so that a PIV field and a
DEM field on the same grid go through exactly the same arithmetic.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.analysis.numerics.kinematic import fit_kinematic_constant
from siloflow.analysis.numerics.profiles import VelocityProfile, flow_channel_boundary
from siloflow.analysis.piv.field import PlanarField

__all__ = ["FieldQuantities", "field_quantities", "planar_profile"]


def planar_profile(field: PlanarField, height: float) -> VelocityProfile:
    """The profile (x, u, w) [m, m/s] of the valid nodes in the node row nearest ``height`` [m]; ``z`` is that row's
    height.

    Raises
    ------
    ValueError
        When ``height`` lies more than half a row spacing outside the rows, or the row has fewer than two valid nodes.
    """
    height = float(height)
    spacing = float(np.min(np.diff(field.z))) if field.z.size > 1 else 0.0
    if not (field.z[0] - 0.5 * spacing - 1e-12 <= height <= field.z[-1] + 0.5 * spacing + 1e-12):
        raise ValueError(f"height {height:g} m lies outside the field's rows [{field.z[0]:g}, {field.z[-1]:g}] m")
    row = int(np.argmin(np.abs(field.z - height)))
    valid = field.valid[row]
    if valid.sum() < 2:
        raise ValueError(f"the row at z = {field.z[row]:g} m has {int(valid.sum())} valid node(s); a profile needs 2")
    return VelocityProfile(z=float(field.z[row]), x=field.x[valid].copy(), v_x=field.u[row, valid].copy(),
                           v_z=field.w[row, valid].copy())


@dataclass(frozen=True)
class FieldQuantities:
    """The derived quantities of one profile.

    Attributes
    ----------
    z : float
        Height of the node row [m].
    centreline_w : float
        v_z interpolated to x = 0 [m/s].
    fcb_left, fcb_right : float
        Flow channel boundary, where |v_z| falls to ``fraction`` of its centreline value on each side [m]; NaN when
        it does not fall that far inside the field.
    fraction : float
        That fraction.
    kinematic_b : float
        Kinematic constant B of the Gaussian fit [m]; NaN when the fit fails.
    """

    z: float
    centreline_w: float
    fcb_left: float
    fcb_right: float
    fraction: float
    kinematic_b: float


def field_quantities(field: PlanarField, heights: Sequence[float], fraction: float = 0.05) -> list[FieldQuantities]:
    """:class:`FieldQuantities` at each height (the nearest node row; see :func:`planar_profile`). Where a node next
    to the axis (the node at x = 0, or the two either side of it) is not valid, the centreline is not measured: the
    centreline, boundary and B are NaN rather than read off an interpolation across the gap.

    Raises
    ------
    ValueError
        From :func:`planar_profile`, or when the valid nodes of a row do not span the axis x = 0.
    """
    quantities = []
    for height in heights:
        profile = planar_profile(field, height)
        if not profile.x[0] <= 0.0 <= profile.x[-1]:
            raise ValueError(f"the valid nodes at z = {profile.z:g} m do not span the axis x = 0")
        row = int(np.argmin(np.abs(field.z - profile.z)))
        right = int(np.searchsorted(field.x, 0.0))
        beside = [right] if field.x[right] == 0.0 else [right - 1, right]
        if not field.valid[row, beside].all():
            quantities.append(FieldQuantities(profile.z, math.nan, math.nan, math.nan, float(fraction), math.nan))
            continue
        centre = float(np.interp(0.0, profile.x, profile.v_z))
        try:
            boundary = flow_channel_boundary(profile.x, profile.v_z, (fraction,))
            left, right_boundary = float(boundary.left[0]), float(boundary.right[0])
        except ValueError:  # a zero centreline velocity has no channel
            left = right_boundary = math.nan
        try:
            b = fit_kinematic_constant(profile.x, profile.v_z, profile.z).B if profile.z > 0 else math.nan
        except ValueError:
            b = math.nan
        quantities.append(FieldQuantities(profile.z, centre, left, right_boundary, float(fraction), float(b)))
    return quantities
