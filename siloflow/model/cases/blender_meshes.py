"""Closed wall solids of the planar blender: thick walls extruded over the depth, and mesh checks.

Coordinates are those of :mod:`siloflow.model.cases.blender_geometry` (SI units, m): x across the width, y through the
depth, z up. Every wall is a 2-D outline in the x-z plane between its two surfaces (two matching polylines),
triangulated and extruded over y in [0, T] into a closed solid with outward normals, for the engine's mesh walls;
the left half mirrors the right one (:func:`mirror_x`). :func:`is_watertight` and :func:`signed_volume` check
such solids.
"""

from __future__ import annotations

import math

import numpy as np

from siloflow.model.cases.blender_geometry import BlenderGeometry, positive_number
from siloflow.model.cases.geometry import TriangleMesh


def _subdivided_rails(inner: np.ndarray, outer: np.ndarray, max_edge: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Matching polylines along the two sides of a wall, each segment split into the same number of pieces."""
    inner_rail, outer_rail = [inner[:1]], [outer[:1]]
    for k in range(len(inner) - 1):
        longest = max(np.linalg.norm(inner[k + 1] - inner[k]), np.linalg.norm(outer[k + 1] - outer[k]))
        pieces = 1 if max_edge is None else max(1, math.ceil(longest / max_edge))
        fractions = (np.arange(1, pieces + 1) / pieces)[:, None]
        inner_rail.append(inner[k] + fractions * (inner[k + 1] - inner[k]))
        outer_rail.append(outer[k] + fractions * (outer[k + 1] - outer[k]))
    return np.concatenate(inner_rail), np.concatenate(outer_rail)


def _signed_area2(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Twice the signed area of 2-D triangles (positive when counter-clockwise)."""
    a, b, c = (points[triangles[:, i]] for i in range(3))
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def _strip_cap(inner: np.ndarray, outer: np.ndarray, max_edge: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Triangulate the 2-D outline of a wall between two matching polylines (its two surfaces).

    The outline is inner[0] -> inner[-1] -> outer[-1] -> outer[0] -> inner[0]. Points are laid out as a grid:
    rails subdivided by ``max_edge``, and rungs between matching rail points split into the same number of
    pieces, enough that the end rungs (outline edges) are no longer than ``max_edge``. Each grid cell is split
    along the diagonal that gives the fatter pair of triangles, so non-convex cells (the hopper bend) are fine.

    Returns
    -------
    points : numpy.ndarray
        (n, 2) outline and interior points (x, z) (m).
    triangles : numpy.ndarray
        (m, 3) indices, counter-clockwise in the (x, z) plane.
    """
    inner_rail, outer_rail = _subdivided_rails(np.asarray(inner, float), np.asarray(outer, float), max_edge)
    end_rung = max(np.linalg.norm(outer_rail[0] - inner_rail[0]), np.linalg.norm(outer_rail[-1] - inner_rail[-1]))
    layers = 1 if max_edge is None else max(1, math.ceil(end_rung / max_edge))
    fractions = (np.arange(layers + 1) / layers)[None, :, None]
    grid = inner_rail[:, None, :] + fractions * (outer_rail - inner_rail)[:, None, :]
    n_rail = len(inner_rail)
    points = grid.reshape(-1, 2)
    index = np.arange(n_rail * (layers + 1)).reshape(n_rail, layers + 1)
    a, b = index[:-1, :-1].ravel(), index[1:, :-1].ravel()
    c, d = index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    options = (
        (np.column_stack([a, b, c]), np.column_stack([a, c, d])),
        (np.column_stack([a, b, d]), np.column_stack([b, c, d])),
    )
    # Orientation of each cell from its shoelace area; a diagonal is usable when both halves keep that sign.
    cell_sign = np.sign(_signed_area2(points, options[0][0]) + _signed_area2(points, options[0][1]))
    quality = []
    for first, second in options:
        smaller = np.minimum(_signed_area2(points, first) * cell_sign, _signed_area2(points, second) * cell_sign)
        quality.append(smaller)
    use_second = quality[1] > quality[0]
    best = np.where(use_second, quality[1], quality[0])
    if np.any(best <= 0.0):
        raise ValueError("degenerate wall outline: a cell of its triangulation has no positive-area split")
    first = np.where(use_second[:, None], options[1][0], options[0][0])
    second = np.where(use_second[:, None], options[1][1], options[0][1])
    triangles = np.concatenate([first, second])
    clockwise = _signed_area2(points, triangles) < 0
    triangles[clockwise] = triangles[clockwise][:, [0, 2, 1]]
    return points, triangles


def _extrude(points: np.ndarray, triangles: np.ndarray, depth: float) -> TriangleMesh:
    """Closed solid: the 2-D outline (x, z) with counter-clockwise ``triangles`` extruded over y in [0, depth]."""
    n = len(points)
    front = np.column_stack([points[:, 0], np.zeros(n), points[:, 1]])
    back = np.column_stack([points[:, 0], np.full(n, float(depth)), points[:, 1]])
    # Counter-clockwise in (x, z) has the right-hand normal x cross z = -y: outward on the front cap (y = 0).
    front_cap = triangles
    back_cap = triangles[:, [0, 2, 1]] + n
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    codes = edges[:, 0] * n + edges[:, 1]
    boundary = edges[~np.isin(codes, edges[:, 1] * n + edges[:, 0])]
    # A boundary edge a -> b runs counter-clockwise round the outline; the side face takes it as b -> a.
    a, b = boundary[:, 0], boundary[:, 1]
    sides = np.concatenate([np.column_stack([b, a, a + n]), np.column_stack([b, a + n, b + n])])
    faces = np.concatenate([front_cap, back_cap, sides]).astype(np.int64)
    return TriangleMesh(np.concatenate([front, back]), faces)


def mirror_x(mesh: TriangleMesh) -> TriangleMesh:
    """Mirror a mesh about the plane x = 0, reversing the vertex order so the normals stay outward."""
    vertices = np.array(mesh.vertices, dtype=float)
    # + 0.0 turns -0.0 into 0.0, so mirrored vertices on x = 0 stay identical to the originals in STL files.
    vertices[:, 0] = -vertices[:, 0] + 0.0
    return TriangleMesh(vertices, np.asarray(mesh.faces)[:, [0, 2, 1]].copy())


def is_watertight(mesh: TriangleMesh) -> bool:
    """Whether every edge is shared by exactly two triangles that traverse it in opposite directions."""
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        return False
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    if np.any(edges[:, 0] == edges[:, 1]):
        return False
    n = int(faces.max()) + 1
    codes = edges[:, 0] * n + edges[:, 1]
    # Each directed edge once, and its reverse present: every edge has exactly two opposite uses.
    if len(np.unique(codes)) != len(codes):
        return False
    return bool(np.all(np.isin(edges[:, 1] * n + edges[:, 0], codes)))


def signed_volume(mesh: TriangleMesh) -> float:
    """Enclosed volume (m^3) by the divergence theorem, sum of a . (b x c) / 6; positive for outward normals."""
    a, b, c = (np.asarray(mesh.vertices, dtype=float)[np.asarray(mesh.faces)[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def blender_meshes(geometry: BlenderGeometry, max_edge: float | None = None) -> dict[str, TriangleMesh]:
    """The closed wall solids of the blender, each extruded over the depth y in [0, T].

    Parameters
    ----------
    geometry : BlenderGeometry
        The blender.
    max_edge : float or None
        Longest outline edge (m): longer outline segments are subdivided (keeps triangles from being extremely
        elongated). Edges along the depth are not subdivided. None: no subdivision.

    Returns
    -------
    dict of str to TriangleMesh
        ``hopper_left``, ``hopper_right`` (inner surface (b, 0) -> (W/2, z_t) -> (W/2, z_top), thickened
        outward by t, ends horizontal at z = 0 and z_top), with an insert ``insert_left``, ``insert_right``
        (thickness t centred on the plate mid-line, ends square to it), with a tube ``tube_left``,
        ``tube_right`` (x in [tw - t/2, tw + t/2], z from tube outlet to inlet). Closed, outward normals.
    """
    if max_edge is not None:
        max_edge = positive_number("max_edge", max_edge)
    g = geometry
    t, b, half_width = g.wall_thickness, g.half_outlet, 0.5 * g.width
    alpha = math.radians(g.hopper_half_angle)
    # The outer surface of the hopper is the inner line moved t outward: x = b + t / cos(alpha) + z tan(alpha);
    # it meets the outer vertical surface x = W/2 + t at z_t - t tan(alpha / 2).
    hopper_inner = [(b, 0.0), (half_width, g.z_transition), (half_width, g.z_top)]
    hopper_outer = [
        (b + t / math.cos(alpha), 0.0),
        (half_width + t, g.z_transition - t * math.tan(alpha / 2.0)),
        (half_width + t, g.z_top),
    ]
    right = {"hopper": (hopper_inner, hopper_outer)}
    if g.has_insert:
        outlet, inlet = np.asarray(g.insert_outlet, float), np.asarray(g.insert_inlet, float)
        along = (inlet - outlet) / np.linalg.norm(inlet - outlet)
        across = 0.5 * t * np.array([along[1], -along[0]])
        right["insert"] = ([outlet - across, inlet - across], [outlet + across, inlet + across])
    if g.has_tube:
        tw, low, high = g.tube_half_width, g.z_tube_outlet, g.z_tube_inlet
        right["tube"] = ([(tw - 0.5 * t, low), (tw - 0.5 * t, high)], [(tw + 0.5 * t, low), (tw + 0.5 * t, high)])
    meshes: dict[str, TriangleMesh] = {}
    for name, (inner, outer) in right.items():
        mesh = _extrude(*_strip_cap(np.asarray(inner, float), np.asarray(outer, float), max_edge), g.depth)
        meshes[f"{name}_left"] = mirror_x(mesh)
        meshes[f"{name}_right"] = mesh
    return meshes
