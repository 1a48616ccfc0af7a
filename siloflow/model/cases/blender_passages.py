"""The passages of a planar blender between its walls, and its plain-data summary.

Functions of a :class:`~siloflow.model.cases.blender_geometry.BlenderGeometry` (coordinates and units as there: SI, m, the
right half x > 0): the clear x-intervals at a height (:func:`annulus_bounds`), the narrowest clear width of each
passage, which the case checks against the clump size (:func:`clear_widths`), and the summary the case records in
``case.json`` (:func:`geometry_summary`).
"""

from __future__ import annotations

import numpy as np

from siloflow.model.cases.blender_geometry import BlenderGeometry, finite_number


def annulus_bounds(geometry: BlenderGeometry, z: float) -> dict[str, tuple[float, float]]:
    """Clear x-intervals (right half) of the passages at height ``z``.

    Parameters
    ----------
    geometry : BlenderGeometry
        The blender.
    z : float
        Height (m) within [0, z_top].

    Returns
    -------
    dict
        ``"tube"`` (0, tw - t/2) where the tube spans z; ``"interior"`` (tw + t/2, or 0 without a tube, up to
        the plate's left surface) and ``"exterior"`` (the plate's right surface to wall_x(z)) where the
        insert spans z; otherwise ``"open"`` (tw + t/2 or 0, wall_x(z)). The inclined plate's surfaces are
        x_plate(z) -+ :attr:`BlenderGeometry.plate_half_thickness_x` (its horizontal cut; its square ends are ignored).
    """
    height = finite_number("z", z)
    wall = geometry.wall_x(height)
    t, tw = geometry.wall_thickness, geometry.tube_half_width
    bounds: dict[str, tuple[float, float]] = {}
    inner = 0.0
    if geometry.has_tube and geometry.z_tube_outlet <= height <= geometry.z_tube_inlet:
        bounds["tube"] = (0.0, tw - 0.5 * t)
        inner = tw + 0.5 * t
    if geometry.has_insert and geometry.insert_outlet[1] <= height <= geometry.insert_inlet[1]:
        x_plate, half = geometry.plate_x(height), geometry.plate_half_thickness_x
        bounds["interior"] = (inner, x_plate - half)
        bounds["exterior"] = (x_plate + half, wall)
    else:
        bounds["open"] = (inner, wall)
    return bounds


def clear_widths(geometry: BlenderGeometry) -> dict[str, float]:
    """Narrowest clear width of each passage (m): wall to wall, wall thicknesses taken off.

    Parameters
    ----------
    geometry : BlenderGeometry
        The blender.

    Returns
    -------
    dict
        ``"outlet"`` B0; with a tube ``"tube"`` tube_width - t; with an insert ``"interior annulus"`` and
        ``"exterior annulus"``, narrowest at the insert inlet or outlet (the interior width is linear and the
        exterior one concave in z; without a tube the interior passage spans both plates); with a tube and
        no insert ``"annulus"`` between tube and wall, narrowest at the tube outlet. The inclined plate
        counts with its horizontal thickness.
    """
    t, tw = geometry.wall_thickness, geometry.tube_half_width
    widths = {"outlet": geometry.outlet_width}
    if geometry.has_tube:
        widths["tube"] = geometry.tube_width - t
    if geometry.has_insert:
        half = geometry.plate_half_thickness_x
        ends = (geometry.insert_inlet, geometry.insert_outlet)
        if geometry.has_tube:
            interior = min(x - half - (tw + 0.5 * t) for x, _ in ends)
        else:
            interior = min(2.0 * (x - half) for x, _ in ends)
        widths["interior annulus"] = interior
        widths["exterior annulus"] = min(geometry.wall_x(z) - x - half for x, z in ends)
    elif geometry.has_tube:
        widths["annulus"] = geometry.wall_x(geometry.z_tube_outlet) - (tw + 0.5 * t)
    return widths


def geometry_summary(geometry: BlenderGeometry) -> dict:
    """Plain-data summary: plate end points, achieved ratios, angle and the key levels (m, degrees).

    Insert entries are None without an insert, tube entries None without a tube.
    """
    summary = {
        "insert": geometry.insert_name,
        "inlet": None,
        "outlet": None,
        "interior_ratio": None,
        "exterior_ratio": None,
        "area_ratio": None,
        "occupancy": None,
        "included_angle_deg": None,
        "plate_length": None,
        "z_transition": geometry.z_transition,
        "z_apex": geometry.z_apex,
        "circle_radius": geometry.circle_radius,
        "z_top": geometry.z_top,
        "z_insert_outlet": geometry.z_insert_outlet,
        "tube_width": geometry.tube_width if geometry.has_tube else None,
        "z_tube_outlet": geometry.z_tube_outlet if geometry.has_tube else None,
        "z_tube_inlet": geometry.z_tube_inlet if geometry.has_tube else None,
        "clear_widths": clear_widths(geometry),
    }
    if geometry.has_insert:
        summary.update(
            {
                "inlet": [float(v) for v in geometry.insert_inlet],
                "outlet": [float(v) for v in geometry.insert_outlet],
                "interior_ratio": geometry.interior_ratio,
                "exterior_ratio": geometry.exterior_ratio,
                "area_ratio": geometry.area_ratio,
                "occupancy": geometry.insert_occupancy,
                "included_angle_deg": geometry.included_angle,
                "plate_length": geometry.plate_length,
            }
        )
    return {key: (float(value) if isinstance(value, (float, np.floating)) else value) for key, value in summary.items()}
