"""Geometry of the Jenike direct shear cell: rings, plate, mould and servo-lid meshes, and their primitives.

Coordinates (SI units): the cell axis is z, shear is along +x, the origin lies on the axis of the bottom
ring at the bottom of the bottom ring (its base). The shear plane is z = bottom_ring_height.

Internal friction test
    Bottom ring: a closed cup, base disk at z = 0, inner wall of radius R up to the shear plane, and the
    wall's top annulus (width = wall thickness) at the shear plane, so clumps can rest on the ring edge.
    Shear ring: inner wall of radius R from the shear plane up to shear plane + shear_ring_height with its
    bottom and top annuli; it starts offset by ``initial_offset`` against the shear direction (axis at
    x = -offset: with the study's 3 mm its inner edge lies over the bottom ring's outer edge) and moves
    along +x by ``shear.displacement``.
Wall friction test
    The digest: "for wall friction the bottom ring is replaced by a flat plate of the wall material". The
    plate is a square of side ``plate_size`` at z = 0, centred on the axis; the shear ring stands on it
    (its bottom annulus at z = 0) and holds the whole sample, so the shear plane is the plate surface
    (z = 0) and every clump lies above it. ``bottom_ring_height`` is not used.

Circles are n-gons (:func:`segments_for_chord`) built by the primitives :func:`cylinder_wall`,
:func:`annulus` and :func:`disk`; :class:`CellGeometry` assembles them into the case's meshes. The case
itself (:mod:`siloflow.model.cases.jenike`) derives a :class:`CellGeometry` from the configuration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.cases.geometry import TriangleMesh, horizontal_rectangle


# ---------------------------------------------------------------------------------------------- meshes

#: The most sides a circle's polygon may have: above the 1.6e5 the schema's bounds allow at worst (a 100 m cell
#: meshed for spheres of 1 micrometre), and below a mesh of millions of triangles per wall.
MAX_SEGMENTS = 1_000_000


def segments_for_chord(radius: float, max_sagitta: float) -> int:
    """Fewest polygon sides n whose chords deviate from a circle by at most ``max_sagitta``.

    The sagitta of a chord of an n-gon inscribed in a circle of radius R is R (1 - cos(pi / n)).

    Parameters
    ----------
    radius : float
        Circle radius R (m).
    max_sagitta : float
        Largest allowed deviation (m), 0 < max_sagitta < R.

    Returns
    -------
    int
        n >= 8.

    Raises
    ------
    ValueError
        Unless 0 < max_sagitta < radius, or when n would exceed :data:`MAX_SEGMENTS`.
    """
    if not (radius > 0 and 0 < max_sagitta < radius):
        raise ValueError(f"need 0 < max_sagitta < radius, got radius={radius!r}, max_sagitta={max_sagitta!r}")
    # The half angle pi / n of a chord with sagitta s: 1 - cos(a) = 2 sin(a / 2)^2 = s / R. Written with the sine, it
    # stays accurate where 1 - s / R rounds to 1 (acos of that is 0, and pi / 0 divides by zero).
    half_angle = 2.0 * math.asin(math.sqrt(0.5 * max_sagitta / radius))
    sides = math.pi / half_angle - 1e-9 if half_angle > 0 else math.inf
    if not sides <= MAX_SEGMENTS:
        raise ValueError(f"a circle of radius {radius!r} m within {max_sagitta!r} m needs {sides:.3g} polygon sides, "
                         f"more than the {MAX_SEGMENTS} a mesh is given")
    return max(8, math.ceil(sides))


def _circle(radius: float, segments: int, centre: tuple[float, float]) -> np.ndarray:
    angles = 2.0 * np.pi * np.arange(segments) / segments
    return np.column_stack([centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)])


def cylinder_wall(
    radius: float, z_bottom: float, z_top: float, segments: int, centre: tuple[float, float] = (0.0, 0.0)
) -> TriangleMesh:
    """Inner wall of a vertical cylinder (an n-gon prism side), normals pointing towards the axis.

    Parameters
    ----------
    radius : float
        Radius of the vertices (m); the faces lie inside the circle by at most the sagitta.
    z_bottom, z_top : float
        Extent along z (m), z_top > z_bottom.
    segments : int
        Polygon sides n (>= 3).
    centre : tuple of float
        Axis position (x, y) (m).
    """
    if not (z_top > z_bottom and radius > 0 and segments >= 3):
        raise ValueError(f"empty cylinder: radius {radius}, z [{z_bottom}, {z_top}], {segments} segments")
    ring = _circle(radius, segments, centre)
    bottom = np.column_stack([ring, np.full(segments, z_bottom)])
    top = np.column_stack([ring, np.full(segments, z_top)])
    vertices = np.vstack([bottom, top])
    k = np.arange(segments)
    k1 = (k + 1) % segments
    # Counter-clockwise (b_k, b_k+1, t_k+1) faces outwards; reversed they face the axis.
    faces = np.vstack([np.column_stack([k, segments + k1, k1]), np.column_stack([k, segments + k, segments + k1])])
    return TriangleMesh(vertices, faces.astype(np.int64))


def annulus(
    inner_radius: float,
    outer_radius: float,
    z: float,
    segments: int,
    centre: tuple[float, float] = (0.0, 0.0),
    normal_up: bool = True,
) -> TriangleMesh:
    """Flat ring between two n-gons in the plane z = const, normals up (+z) or down (-z)."""
    if not (outer_radius > inner_radius > 0 and segments >= 3):
        raise ValueError(f"empty annulus: radii [{inner_radius}, {outer_radius}], {segments} segments")
    inner = np.column_stack([_circle(inner_radius, segments, centre), np.full(segments, z)])
    outer = np.column_stack([_circle(outer_radius, segments, centre), np.full(segments, z)])
    vertices = np.vstack([inner, outer])
    k = np.arange(segments)
    k1 = (k + 1) % segments
    faces = np.vstack([np.column_stack([k, segments + k, segments + k1]), np.column_stack([k, segments + k1, k1])])
    if not normal_up:
        faces = faces[:, ::-1]
    return TriangleMesh(vertices, faces.astype(np.int64))


def disk(
    radius: float, z: float, segments: int, centre: tuple[float, float] = (0.0, 0.0), normal_up: bool = True
) -> TriangleMesh:
    """Flat n-gon in the plane z = const as a fan about its centre, normals up (+z) or down (-z).

    The fan's smallest angle is 2 pi / n, above LIGGGHTS' 0.5 degree quality limit for n < 720.
    """
    if not (radius > 0 and segments >= 3):
        raise ValueError(f"empty disk: radius {radius}, {segments} segments")
    rim = np.column_stack([_circle(radius, segments, centre), np.full(segments, z)])
    vertices = np.vstack([[centre[0], centre[1], z], rim])
    k = np.arange(segments)
    faces = np.column_stack([np.zeros(segments, dtype=np.int64), 1 + k, 1 + (k + 1) % segments])
    if not normal_up:
        faces = faces[:, ::-1]
    return TriangleMesh(vertices, faces.astype(np.int64))


def merge_meshes(*meshes: TriangleMesh) -> TriangleMesh:
    """One mesh holding the triangles of all given meshes (vertices are not merged)."""
    vertices, faces, offset = [], [], 0
    for mesh in meshes:
        vertices.append(mesh.vertices)
        faces.append(mesh.faces + offset)
        offset += len(mesh.vertices)
    return TriangleMesh(np.vstack(vertices), np.vstack(faces).astype(np.int64))


# ---------------------------------------------------------------------------------------------- the cell


@dataclass(frozen=True)
class CellGeometry:
    """Dimensions of the Jenike cell (m) and how its circles are triangulated.

    Attributes
    ----------
    wall_test : bool
        True for a wall-friction test (plate instead of the bottom ring).
    inner_radius : float
        Inner radius R of both rings (m).
    wall_thickness : float
        Ring wall thickness t (m).
    bottom_ring_height : float
        Height of the bottom ring (m); 0 in wall tests.
    shear_ring_height : float
        Height of the shear ring (m).
    initial_offset : float
        Initial position of the shear ring's axis, x = -initial_offset (m).
    shear_displacement : float
        Travel of the shear ring along +x (m).
    plate_size : float
        Side of the square plate of wall tests (m); 0 in internal tests.
    mould_height : float
        Height of the mould ring stacked on the shear ring (m); it holds the overfill while filling.
    segments : int
        Sides of the polygons that approximate the circles.
    lid_clearance : float
        Radial gap between the lid's edge and the ring wall (m).
    """

    wall_test: bool
    inner_radius: float
    wall_thickness: float
    bottom_ring_height: float
    shear_ring_height: float
    initial_offset: float
    shear_displacement: float
    plate_size: float
    mould_height: float
    segments: int
    lid_clearance: float

    @property
    def shear_plane(self) -> float:
        """Height of the shear plane (m): top of the bottom ring, or the plate surface."""
        return 0.0 if self.wall_test else self.bottom_ring_height

    @property
    def ring_top(self) -> float:
        """Height of the top of the shear ring (m), where the sample is levelled."""
        return self.shear_plane + self.shear_ring_height

    @property
    def sample_height(self) -> float:
        """Height of the levelled sample (m)."""
        return self.ring_top

    @property
    def ring_centre(self) -> tuple[float, float]:
        """Initial (x, y) of the shear ring's axis (m)."""
        return (-self.initial_offset, 0.0)

    @property
    def area(self) -> float:
        """Cross-section of the cell, pi R^2 (m^2)."""
        return math.pi * self.inner_radius**2

    def bottom_ring(self) -> TriangleMesh:
        """Bottom ring as a closed cup: base disk, inner wall, top annulus (internal tests only)."""
        if self.wall_test:
            raise ValueError("a wall-friction test has a plate, not a bottom ring")
        r, t, h, n = self.inner_radius, self.wall_thickness, self.bottom_ring_height, self.segments
        return merge_meshes(
            disk(r, 0.0, n, normal_up=True),
            cylinder_wall(r, 0.0, h, n),
            annulus(r, r + t, h, n, normal_up=True),
        )

    def plate(self) -> TriangleMesh:
        """Square plate of the wall material at z = 0, normals up (wall tests only)."""
        if not self.wall_test:
            raise ValueError("an internal-friction test has a bottom ring, not a plate")
        half = 0.5 * self.plate_size
        return horizontal_rectangle(-half, half, -half, half, 0.0)

    def shear_ring(self) -> TriangleMesh:
        """Shear ring at its initial position: inner wall, bottom annulus (normals down), top annulus (up)."""
        r, t, n, c = self.inner_radius, self.wall_thickness, self.segments, self.ring_centre
        return merge_meshes(
            annulus(r, r + t, self.shear_plane, n, c, normal_up=False),
            cylinder_wall(r, self.shear_plane, self.ring_top, n, c),
            annulus(r, r + t, self.ring_top, n, c, normal_up=True),
        )

    def mould_ring(self) -> TriangleMesh:
        """Inner wall of the filling mould stacked on the shear ring."""
        return cylinder_wall(
            self.inner_radius, self.ring_top, self.ring_top + self.mould_height, self.segments, self.ring_centre
        )

    def servo_lid(self) -> TriangleMesh:
        """Servo lid: a disk of radius R - clearance at z = 0 (moved into place by the deck), normals down."""
        return disk(self.inner_radius - self.lid_clearance, 0.0, self.segments, self.ring_centre, normal_up=False)

    def meshes(self, lid: str) -> dict[str, TriangleMesh]:
        """The case's meshes by deck name: base (bottom ring or plate), shear ring, mould, and a servo lid."""
        meshes = {
            "base": self.plate() if self.wall_test else self.bottom_ring(),
            "shear_ring": self.shear_ring(),
            "mould": self.mould_ring(),
        }
        if lid == "servo":
            meshes["lid"] = self.servo_lid()
        return meshes

    def horizontal_extent(self) -> float:
        """Largest |x| or |y| any mesh reaches during the test (m)."""
        outer = self.inner_radius + self.wall_thickness
        ring_reach = max(self.initial_offset, self.shear_displacement - self.initial_offset) + outer
        return max(ring_reach, outer, 0.5 * self.plate_size)


def circle_intersection_area(radius: float, distance: float) -> float:
    """Area of the intersection of two circles of equal radius whose centres are ``distance`` apart (m^2)."""
    if distance >= 2.0 * radius:
        return 0.0
    return 2.0 * radius**2 * math.acos(distance / (2.0 * radius)) - 0.5 * distance * math.sqrt(
        4.0 * radius**2 - distance**2
    )
