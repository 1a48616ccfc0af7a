"""The Jenike direct shear cell: an engine-neutral case built from validated configuration.

Coordinates (SI units): the cell axis is z, shear is along +x, the origin lies on the axis of the bottom
ring at the bottom of the bottom ring (its base). The shear plane is z = bottom_ring_height.

Internal friction test (``test = "internal"``)
    Bottom ring: a closed cup, base disk at z = 0, inner wall of radius R up to the shear plane, and the
    wall's top annulus (width = wall thickness) at the shear plane, so clumps can rest on the ring edge.
    Shear ring: inner wall of radius R from the shear plane up to shear plane + shear_ring_height with its
    bottom and top annuli; it starts offset by ``initial_offset`` against the shear direction (axis at
    x = -offset: with the study's 3 mm its inner edge lies over the bottom ring's outer edge) and moves
    along +x by ``shear.displacement``.
Wall friction test (``test = <wall material>``)
    The digest: "for wall friction the bottom ring is replaced by a flat plate of the wall material". The
    plate is a square of side ``plate_size`` at z = 0, centred on the axis; the shear ring stands on it
    (its bottom annulus at z = 0) and holds the whole sample, so the shear plane is the plate surface
    (z = 0) and every clump lies above it. ``bottom_ring_height`` is not used.

Stages (:meth:`JenikeCase.stages`; how an engine carries them out is that engine's business):

1. fill: clumps are created at once in a loose column inside both rings and a mould
   ring stacked on the shear ring (as in the real test), at the fill friction (low, for a dense
   packing), fall and settle for ``fill.settle_time``. The clump count fills the cell to
   ``1 + fill.overfill`` times the sample height at an estimated solid fraction
   (:data:`FILL_SOLID_FRACTION`).
2. level: every clump with a sphere centre above ``ring top - largest sphere radius`` is deleted, so no
   sphere reaches above the top of the shear ring; the sample relaxes. The mould stays (now empty) and moves
   with the shear ring during the shear, a collar that keeps clumps from escaping past the lid's edge.
3. lid: placed just above the highest sphere of the sample (its centre height is measured in the deck).
4. test contact parameters replace the fill values; consolidation under F_N = sigma pi D^2 / 4, ramped
   from 0 over the first :data:`LOAD_RAMP_FRACTION` of ``consolidation.time``, then held.
5. shear: the shear ring moves at the shear velocity for the shear displacement; the lid moves with it
   (rigid lid: its x velocity is set to the shear velocity and its x, y translation is not integrated;
   servo lid: its mesh is moved at the same x velocity).

Lids
    ``rigid``: a disk of glued spheres (one layer, :func:`lid_sphere_layout`) integrated as one rigid
    body that translates vertically and may tilt and rotate, loaded by a constant vertical force F_N
    with its weight cancelled. Its spheres have the radius of the smallest particle sphere and the
    particle density (the lid material has no density in the configuration).
    ``servo``: a flat disk mesh that cannot tilt or rotate, loaded by the same constant force. A lid held
    still while the shear ring moves away would turn the test into a wall-friction test of the ring against
    the sample; so the lid mesh moves along x at the shear velocity (with the ring) and along z with a proxy
    body of the lid's mass driven by the particles' force on the mesh minus F_N (:class:`ServoLid`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from analysis.data.constants import GRAVITY
from engines.cases.geometry import TriangleMesh, horizontal_rectangle
from engines.cases.particles import ParticleTemplate, particle_template
from engines.cases.physics import engine_seeds, rayleigh_time, steps_for
from engines.cases.common import NEUTRAL_CONTACT, MaterialTable, engine_kind, run_id
from engines.cases.jenike_sweep import sweep_points
from engines.cases.stages import Stage

CASE_NAME = "jenike"

#: Engine atom types by role. The plate type exists only in wall tests; the rings share one material.
PARTICLE_TYPE, RING_TYPE, LID_TYPE, PLATE_TYPE = 1, 2, 3, 4

#: Estimated solid fraction of the settled low-friction fill (-); only sizes the pour, the overfill
#: above the shear ring absorbs the error (a denser packing than this leaves less to remove).
FILL_SOLID_FRACTION = 0.58
#: Solid fraction of the loose column the clumps are created in (-); insert/pack places clumps without
#: overlap, which stays fast below about 0.25 for two-sphere clumps.
INSERT_SOLID_FRACTION = 0.2
#: Largest chord deviation (sagitta) of a triangulated circle, as a fraction of the smallest particle
#: sphere radius (-).
CHORD_TOLERANCE = 0.01
#: Radial gap between the lid's edge and the ring wall, in smallest particle sphere radii (-).
LID_CLEARANCE = 0.2
#: Centre spacing of the lid spheres, in lid sphere radii (-); 1.4 leaves no point of the lid plane
#: farther than about one lid sphere radius from a sphere centre.
LID_SPHERE_SPACING = 1.4
#: Gap between the highest sample sphere and the lid when the lid is placed, in lid sphere radii (-).
LID_PLACEMENT_GAP = 0.05
#: Fraction of the consolidation time over which F_N is ramped up from 0 (-).
LOAD_RAMP_FRACTION = 0.25
#: Relaxation after levelling (s).
LEVEL_RELAX_TIME = 0.02
#: Particle dumps during consolidation and shear (one at the start, then this many during the shear).
SHEAR_DUMPS = 10


# ---------------------------------------------------------------------------------------------- meshes


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
    """
    if not (radius > 0 and 0 < max_sagitta < radius):
        raise ValueError(f"need 0 < max_sagitta < radius, got radius={radius!r}, max_sagitta={max_sagitta!r}")
    n = math.ceil(math.pi / math.acos(1.0 - max_sagitta / radius) - 1e-9)
    return max(8, n)


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


# ---------------------------------------------------------------------------------------------- the lid


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
    """
    if not (outer_radius > 0 and spacing > 0):
        raise ValueError(f"need positive outer_radius and spacing, got {outer_radius!r}, {spacing!r}")
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


# ---------------------------------------------------------------------------------------------- the case


@dataclass(frozen=True)
class ContactSet:
    """Per-pair contact matrices (row-major over the atom types) of one stage (-)."""

    sliding_friction: tuple[tuple[float, ...], ...]
    rolling_friction: tuple[tuple[float, ...], ...]
    restitution: tuple[tuple[float, ...], ...]


@dataclass(frozen=True)
class JenikeFill:
    """How the cell is filled and levelled.

    Attributes
    ----------
    n_clumps : int
        Clumps created.
    region_centres : tuple of float
        x of the axes of the vertical cylinders whose intersection is the insertion region (m).
    region_radius : float
        Radius of those cylinders (m): R minus the clump's bounding radius, so clumps whose centre lies
        inside are inside both rings.
    region_z : tuple of float
        (z_min, z_max) of the insertion region (m).
    steps : int
        Steps for the fall of the highest clump plus ``fill.settle_time``.
    level_z : float
        Clumps with a sphere centre above this height are deleted (m): the ring top minus the largest
        sphere radius.
    relax_steps : int
        Steps of relaxation after levelling.
    """

    n_clumps: int
    region_centres: tuple[float, ...]
    region_radius: float
    region_z: tuple[float, float]
    steps: int
    level_z: float
    relax_steps: int


@dataclass(frozen=True)
class JenikeCase:
    """Everything that defines one Jenike shear run, derived from validated configuration and a sweep point."""

    particle: ParticleTemplate
    materials: MaterialTable
    point: dict
    lid_kind: str
    geometry: CellGeometry
    fill_contacts: ContactSet
    test_contacts: ContactSet
    rotation_blocked: bool
    timestep: float
    rayleigh_time: float
    fill: JenikeFill
    normal_force: float
    rigid_lid: RigidLid | None
    servo_lid: ServoLid | None
    ramp_steps: int
    hold_steps: int
    shear_velocity: float
    shear_steps: int
    output_every: int
    dump_every: int
    domain: tuple[float, float, float, float, float, float]
    seeds: tuple[int, ...]
    defining_parameters: dict = field(repr=False)

    @property
    def test(self) -> str:
        """``internal`` or the wall material of a wall-friction test."""
        return self.point["test"]

    @property
    def run_id(self) -> str:
        """``<shape>-<test>-<hash of every defining parameter>``."""
        return run_id(f"{self.particle.name}-{self.test}", self.defining_parameters)

    def stages(self) -> tuple[Stage, ...]:
        """Pour into the cell, level it and let it settle, consolidate under the lid, shear; the wall forces
        (lid, shear ring, base) throughout, frames and contacts during consolidation and shear."""
        dt = self.timestep
        return (
            Stage("fill", {"n_clumps": self.fill.n_clumps, "duration_s": self.fill.steps * dt}),
            Stage("settle", {"level_z_m": self.fill.level_z, "duration_s": self.fill.relax_steps * dt}),
            Stage("consolidate", {"normal_force_N": self.normal_force, "lid": self.lid_kind,
                                  "duration_s": (self.ramp_steps + self.hold_steps) * dt},
                  ("frames", "wall_forces")),
            Stage("shear", {"velocity_m_s": self.shear_velocity, "duration_s": self.shear_steps * dt},
                  ("frames", "wall_forces", "contacts") + (("wall_contacts",) if self.lid_kind == "rigid" else ())),
        )

    @property
    def clump_sphere_mass(self) -> float:
        """Clump mass per sphere (kg): spheres above the shear plane times this is the mass above it."""
        return self.particle.mass / self.particle.n_spheres

    def summary(self) -> dict:
        """Plain-data summary of the derived quantities (for ``case.json``)."""
        lid = {"kind": self.lid_kind}
        if self.rigid_lid is not None:
            lid.update(
                n_spheres=self.rigid_lid.n_spheres,
                sphere_radius_m=self.rigid_lid.sphere_radius,
                mass_kg=self.rigid_lid.mass,
            )
        if self.servo_lid is not None:
            lid.update(mass_kg=self.servo_lid.mass)
        geometry = asdict(self.geometry)
        geometry.update(shear_plane=self.geometry.shear_plane, ring_top=self.geometry.ring_top)
        return {
            "case": CASE_NAME,
            "run_id": self.run_id,
            "point": dict(self.point),
            "particle_model": self.particle.name,
            "spheres_per_clump": self.particle.n_spheres,
            "clump_mass_kg": self.particle.mass,
            "clump_volume_m3": self.particle.volume,
            "rayleigh_time_s": self.rayleigh_time,
            "timestep_s": self.timestep,
            "geometry": geometry,
            "fill": asdict(self.fill),
            "normal_force_N": self.normal_force,
            "lid": lid,
            "consolidation_time_s": (self.ramp_steps + self.hold_steps) * self.timestep,
            "shear_velocity_m_s": self.shear_velocity,
            "shear_time_s": self.shear_steps * self.timestep,
            "output_interval_s": self.output_every * self.timestep,
            "materials": list(self.materials.names),
            "test_contacts": asdict(self.test_contacts),
            "fill_contacts": asdict(self.fill_contacts),
            "parameters": self.defining_parameters,
        }


LID_KINDS = ("rigid", "servo")
POINT_KEYS = ("shape", "test", "sliding_friction", "rolling_friction", "restitution", "rotation_blocked")


def _check_point(point: dict) -> dict:
    """The point with exactly :data:`POINT_KEYS`, numbers as floats. Its values come from the validated
    ``jenike.sweep`` section (:func:`engines.cases.jenike_sweep.sweep_points`): the schema is their one validator."""
    missing = [key for key in POINT_KEYS if key not in point]
    extra = sorted(set(point) - set(POINT_KEYS))
    if missing or extra:
        raise ValueError(f"jenike point: missing keys {missing}, unknown keys {extra}; expected {list(POINT_KEYS)}")
    return {
        "shape": point["shape"],
        "test": point["test"],
        "sliding_friction": float(point["sliding_friction"]),
        "rolling_friction": float(point["rolling_friction"]),
        "restitution": float(point["restitution"]),
        "rotation_blocked": bool(point["rotation_blocked"]),
    }


def _contact(config: dict, a: str, b: str) -> dict:
    for contact in config["contacts"]:
        if sorted(contact["materials"]) == sorted((a, b)):
            return contact
    raise ValueError(f"config key 'contacts': no contact parameters for the pair [{a}, {b}] used by jenike")


def _matrix(n_types: int, particle_row: dict[int, float], neutral: float) -> tuple[tuple[float, ...], ...]:
    """Symmetric matrix: particle (type 1) pairs from ``particle_row`` (type -> value), others neutral."""
    rows = [[neutral] * n_types for _ in range(n_types)]
    for other, value in particle_row.items():
        rows[PARTICLE_TYPE - 1][other - 1] = value
        rows[other - 1][PARTICLE_TYPE - 1] = value
    return tuple(tuple(float(v) for v in row) for row in rows)


def contact_sets(config: dict, point: dict, n_types: int) -> tuple[ContactSet, ContactSet]:
    """Contact matrices while filling and while testing.

    Testing: internal test, particle-particle sliding = point value; wall test, particle-plate sliding =
    point value and particle-particle sliding = ``jenike.sweep.wall_test_particle_friction``;
    particle-ring and particle-lid sliding from ``contacts``; rolling friction = point value for every
    particle contact (particles, rings, plate, lid); restitution = point value for every particle contact.
    Filling: every particle sliding friction = ``jenike.fill.sliding_friction``, rolling =
    ``jenike.fill.rolling_friction``, restitution as when testing. Pairs without a particle are neutral.
    """
    jenike = config["jenike"]
    particle = jenike["particle_material"]
    ring = _contact(config, particle, jenike["ring_material"])
    lid = _contact(config, particle, jenike["lid_material"])
    types = list(range(1, n_types + 1))
    wall_test = point["test"] != "internal"
    particle_particle = jenike["sweep"]["wall_test_particle_friction"] if wall_test else point["sliding_friction"]
    sliding = {PARTICLE_TYPE: particle_particle, RING_TYPE: ring["sliding_friction"], LID_TYPE: lid["sliding_friction"]}
    if wall_test:
        sliding[PLATE_TYPE] = point["sliding_friction"]
    rolling = {t: point["rolling_friction"] for t in types}
    restitution = {t: point["restitution"] for t in types}
    restitution_matrix = _matrix(n_types, restitution, NEUTRAL_CONTACT["restitution"])
    test = ContactSet(
        sliding_friction=_matrix(n_types, sliding, NEUTRAL_CONTACT["sliding_friction"]),
        rolling_friction=_matrix(n_types, rolling, NEUTRAL_CONTACT["rolling_friction"]),
        restitution=restitution_matrix,
    )
    fill = ContactSet(
        sliding_friction=_matrix(n_types, {t: jenike["fill"]["sliding_friction"] for t in types}, 0.0),
        rolling_friction=_matrix(n_types, {t: jenike["fill"]["rolling_friction"] for t in types}, 0.0),
        restitution=restitution_matrix,
    )
    return fill, test


def _material_table(config: dict, point: dict, test: ContactSet) -> MaterialTable:
    jenike = config["jenike"]
    names = [jenike["particle_material"], jenike["ring_material"], jenike["lid_material"]]
    if point["test"] != "internal":
        names.append(point["test"])
    materials = config["materials"]
    for name in names:
        if name not in materials:
            raise ValueError(f"jenike: material '{name}' is not defined under materials")
    if "density" not in materials[names[0]]:
        raise ValueError(f"config key 'materials.{names[0]}.density': the particle material needs a density")
    return MaterialTable(
        names=tuple(names),
        youngs_modulus=tuple(float(materials[n]["youngs_modulus"]) for n in names),
        poisson_ratio=tuple(float(materials[n]["poisson_ratio"]) for n in names),
        sliding_friction=test.sliding_friction,
        rolling_friction=test.rolling_friction,
        restitution=test.restitution,
    )


def plan_fill(
    geometry: CellGeometry, particle: ParticleTemplate, overfill: float, settle_time: float, timestep: float
) -> JenikeFill:
    """Size the pour: clump count for the overfilled sample, the loose column it is created in, steps.

    n = FILL_SOLID_FRACTION (1 + overfill) pi R^2 H / V_clump with H the sample height. The column is the
    intersection of vertical cylinders of radius R - r_b (r_b the clump's bounding radius) about the
    bottom ring's and the shear ring's axes (only the latter in wall tests), from r_b above the base up
    to the height that holds n clumps at INSERT_SOLID_FRACTION.
    """
    r_b = particle.bounding_radius
    radius = geometry.inner_radius - r_b
    if radius <= r_b:
        raise ValueError(
            f"jenike.cell.inner_diameter ({2 * geometry.inner_radius} m) is too small for clumps of "
            f"bounding diameter {2 * r_b:.4g} m"
        )
    if geometry.wall_test:
        centres: tuple[float, ...] = (geometry.ring_centre[0],)
        area = math.pi * radius**2
    else:
        centres = (0.0, geometry.ring_centre[0])
        area = circle_intersection_area(radius, geometry.initial_offset)
        if area <= 0.0:
            raise ValueError("jenike.cell.initial_offset leaves no overlap between the rings to fill through")
    sample_volume = geometry.area * geometry.sample_height
    n_clumps = int(round(FILL_SOLID_FRACTION * (1.0 + overfill) * sample_volume / particle.volume))
    if n_clumps < 1:
        raise ValueError("jenike cell too small: less than one clump fits")
    column = n_clumps * particle.volume / (INSERT_SOLID_FRACTION * area)
    z_min = r_b
    z_max = z_min + max(column, 2.0 * r_b)
    fall_time = math.sqrt(2.0 * z_max / GRAVITY)
    largest_sphere = float(particle.sphere_radii.max())
    return JenikeFill(
        n_clumps=n_clumps,
        region_centres=centres,
        region_radius=radius,
        region_z=(z_min, z_max),
        steps=steps_for(fall_time + settle_time, timestep),
        level_z=geometry.ring_top - largest_sphere,
        relax_steps=steps_for(LEVEL_RELAX_TIME, timestep),
    )


def build_jenike_case(config: dict, point: dict) -> JenikeCase:
    """Derive a :class:`JenikeCase` from a validated configuration and one sweep point.

    Parameters
    ----------
    config : dict
        Validated configuration (:func:`engines.config.validate_config`).
    point : dict
        ``{"shape": <particle model>, "test": "internal" | <wall material>, "sliding_friction": float,
        "rolling_friction": float, "restitution": float, "rotation_blocked": bool}``, optionally with
        ``"lid": "rigid" | "servo"`` overriding ``jenike.lid`` (used to compare the two lids on the same points).

    Raises
    ------
    ValueError
        Naming the offending key: unknown shape or material, a missing contact pair, values out of range,
        a cell too small for the clumps, or a plate too small for the shear travel.
    """
    lid = point.get("lid", config["jenike"]["lid"])
    if lid not in LID_KINDS:
        raise ValueError(f"jenike point: lid must be one of {', '.join(LID_KINDS)}, got {lid!r}")
    point = _check_point({key: value for key, value in point.items() if key != "lid"})
    jenike = {**config["jenike"], "lid": lid}
    cell = jenike["cell"]
    materials = config["materials"]
    particle_material = jenike["particle_material"]
    if particle_material not in materials or "density" not in materials[particle_material]:
        raise ValueError(f"jenike.particle_material '{particle_material}' must be a material with a density")
    material = materials[particle_material]
    particle = particle_template(point["shape"], config["particle_models"][point["shape"]], material["density"])
    wall_test = point["test"] != "internal"
    n_types = 4 if wall_test else 3
    fill_contacts, test_contacts = contact_sets(config, point, n_types)
    table = _material_table(config, point, test_contacts)

    t_rayleigh = rayleigh_time(
        particle.smallest_radius, material["density"], material["youngs_modulus"], material["poisson_ratio"]
    )
    timestep = jenike["timestep_fraction"] * t_rayleigh
    radius = 0.5 * cell["inner_diameter"]
    displacement = jenike["shear"]["displacement"]
    overfill = jenike["fill"]["overfill"]
    sample_height = cell["shear_ring_height"] + (0.0 if wall_test else cell["bottom_ring_height"])
    geometry = CellGeometry(
        wall_test=wall_test,
        inner_radius=radius,
        wall_thickness=cell["wall_thickness"],
        bottom_ring_height=0.0 if wall_test else cell["bottom_ring_height"],
        shear_ring_height=cell["shear_ring_height"],
        initial_offset=cell["initial_offset"],
        shear_displacement=displacement,
        plate_size=cell["plate_size"] if wall_test else 0.0,
        mould_height=2.0 * overfill * sample_height + 4.0 * particle.bounding_radius,
        segments=segments_for_chord(radius, CHORD_TOLERANCE * particle.smallest_radius),
        lid_clearance=LID_CLEARANCE * particle.smallest_radius,
    )
    if wall_test:
        reach = radius + cell["wall_thickness"] + max(cell["initial_offset"], displacement - cell["initial_offset"])
        if 0.5 * cell["plate_size"] < reach:
            raise ValueError(
                f"jenike.cell.plate_size ({cell['plate_size']} m) must be at least {2 * reach:.4g} m so the "
                "shear ring stays on the plate over its whole travel"
            )
    fill = plan_fill(geometry, particle, overfill, jenike["fill"]["settle_time"], timestep)

    normal_force = jenike["consolidation"]["normal_stress"] * geometry.area
    lid_radius = radius - geometry.lid_clearance
    sphere_radius = particle.smallest_radius
    rigid_lid = RigidLid(
        positions=lid_sphere_layout(lid_radius - sphere_radius, LID_SPHERE_SPACING * sphere_radius)
        + np.array(geometry.ring_centre),
        sphere_radius=sphere_radius,
        density=float(material["density"]),
        height_above_sample=float(particle.sphere_radii.max()) + (1.0 + LID_PLACEMENT_GAP) * sphere_radius,
        normal_force=normal_force,
    )
    servo_lid = None
    if jenike["lid"] == "servo":
        servo_lid = ServoLid(
            height_above_sample=float(particle.sphere_radii.max()) + LID_PLACEMENT_GAP * sphere_radius,
            normal_force=normal_force,
            mass=rigid_lid.mass,
            proxy_radius=sphere_radius,
            centre=geometry.ring_centre,
        )
        rigid_lid = None

    consolidation_steps = steps_for(jenike["consolidation"]["time"], timestep)
    ramp_steps = max(1, int(round(LOAD_RAMP_FRACTION * consolidation_steps)))
    shear_velocity = jenike["shear"]["velocity"]
    shear_steps = steps_for(displacement / shear_velocity, timestep)
    margin = 4.0 * particle.bounding_radius
    half = geometry.horizontal_extent() + margin
    z_top = max(fill.region_z[1] + particle.bounding_radius, geometry.ring_top + geometry.mould_height) + margin

    defining = {
        "case": CASE_NAME,
        "engine": engine_kind(config, CASE_NAME),
        "point": point,
        "lid": jenike["lid"],
        "materials": {name: materials[name] for name in sorted(set(table.names))},
        "particle_model": {"name": particle.name, **config["particle_models"][particle.name]},
        "test_contacts": asdict(test_contacts),
        "fill_contacts": asdict(fill_contacts),
        "jenike": {key: value for key, value in jenike.items() if key not in ("sweep",)},
    }
    return JenikeCase(
        particle=particle,
        materials=table,
        point=point,
        lid_kind=jenike["lid"],
        geometry=geometry,
        fill_contacts=fill_contacts,
        test_contacts=test_contacts,
        rotation_blocked=point["rotation_blocked"],
        timestep=timestep,
        rayleigh_time=t_rayleigh,
        fill=fill,
        normal_force=normal_force,
        rigid_lid=rigid_lid,
        servo_lid=servo_lid,
        ramp_steps=ramp_steps,
        hold_steps=max(1, consolidation_steps - ramp_steps),
        shear_velocity=shear_velocity,
        shear_steps=shear_steps,
        output_every=steps_for(jenike["output_interval"], timestep),
        dump_every=max(1, shear_steps // SHEAR_DUMPS),
        domain=(-half, half, -half, half, -margin, z_top),
        seeds=tuple(engine_seeds(jenike["seed"], 3)),
        defining_parameters=defining,
    )


def jenike_cases(config: dict) -> dict[str, JenikeCase]:
    """The Jenike shear tests of the calibration sweep a validated configuration defines, keyed by run id.

    Raises
    ------
    ValueError
        Naming the sweep point whose cell cannot be built (e.g. a plate too small for the ring's travel).
    """
    cases = {}
    for point in sweep_points(config["jenike"]["sweep"], lid=config["jenike"]["lid"]):
        try:
            case = build_jenike_case(config, point)
        except ValueError as error:
            raise ValueError(f"jenike sweep point {point}: {error}") from None
        cases[case.run_id] = case
    return cases
