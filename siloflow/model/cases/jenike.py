"""The Jenike direct shear cell: an engine-neutral case built from validated configuration.

Coordinates (SI units) and the cell's parts are those of :mod:`siloflow.model.cases.jenike_cell`: the cell axis is z,
shear is along +x. ``test = "internal"`` tests internal friction between a bottom ring and a shear ring;
``test = <wall material>`` tests wall friction, the bottom ring replaced by a flat plate of the wall material.

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

Lids (``rigid`` or ``servo``): :mod:`siloflow.model.cases.jenike_lids`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from siloflow.model.constants import GRAVITY
from siloflow.model.cases.jenike_cell import CellGeometry, circle_intersection_area, segments_for_chord
from siloflow.model.cases.jenike_contacts import PARTICLE_FRICTION_KEY, ContactSet, contact_sets, material_table
from siloflow.model.cases.jenike_lids import RigidLid, ServoLid, lid_sphere_layout
from siloflow.model.cases.particles import ParticleTemplate, model_parameters, particle_template
from siloflow.model.cases.physics import (
    ChosenTimestep, TimestepChoice, engine_seeds, free_fall_velocity, stable_timestep, steps_for,
)
from siloflow.model.cases.common import MaterialTable, engine_kind, run_id, without_fill_checks
from siloflow.model.cases.jenike_sweep import CONFIGURED_POUR, POURS, sweep_points
from siloflow.model.cases.stages import Stage

CASE_NAME = "jenike"

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
#: Particle dumps during consolidation and shear (one at the start, then this many during the shear).
SHEAR_DUMPS = 10


# ---------------------------------------------------------------------------------------------- the case


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


#: Force samples per output interval: each row of the force history averages them. The forces change on the scale
#: of a contact's duration (tens of steps here), so every step is not needed, and sampling every step was the shear
#: stage's largest cost next to the contacts (make bench).
FORCE_SAMPLES_PER_OUTPUT = 10


def force_sample_every(output_every: int) -> int:
    """Steps between the force samples of one output interval of ``output_every`` steps.

    The largest divisor of ``output_every`` that still gives at least :data:`FORCE_SAMPLES_PER_OUTPUT` samples per
    interval: both engines average equally spaced samples that end on the interval's last step (LIGGGHTS' ``fix
    ave/time`` needs the divisor).
    """
    if output_every < 1:
        raise ValueError(f"output_every must be >= 1 step, got {output_every!r}")
    divisors = [d for d in range(1, output_every + 1)
                if output_every % d == 0 and output_every // d >= FORCE_SAMPLES_PER_OUTPUT]
    return max(divisors, default=1)


@dataclass(frozen=True)
class JenikeCase(ChosenTimestep):
    """Everything that defines one Jenike shear run, derived from validated configuration and a sweep point."""

    particle: ParticleTemplate
    materials: MaterialTable
    point: dict
    lid_kind: str
    geometry: CellGeometry
    fill_contacts: ContactSet
    test_contacts: ContactSet
    rotation_blocked: bool
    timestep_choice: TimestepChoice
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
    #: The point as the sweep designed it (:func:`siloflow.model.cases.jenike_sweep.sweep_points`): ``point`` with ``lid``,
    #: ``replicate`` and ``shear_velocity`` where the sweep set them.
    sweep_point: dict = field(default_factory=dict, repr=False)
    #: How the sample was poured (:data:`~siloflow.model.cases.jenike_sweep.POURS`).
    pour: str = CONFIGURED_POUR

    @property
    def summary_point(self) -> dict:
        """The point as the shear test's summary records it: ``point`` with the lid, the shear velocity (m/s) and the
        pour it ran with."""
        return {**self.point, "lid": self.lid_kind, "shear_velocity": self.shear_velocity, "pour": self.pour}

    @property
    def fill_height(self) -> float:
        """Height of the levelled sample above the base (m): the height the force balance's planes refer to."""
        return self.geometry.sample_height

    @property
    def gravity(self) -> float:
        """Gravitational acceleration of the run (m/s^2)."""
        return GRAVITY

    @property
    def test(self) -> str:
        """``internal`` or the wall material of a wall-friction test."""
        return self.point["test"]

    @property
    def force_sample_every(self) -> int:
        """Steps between the force samples that each row of the force history averages (:func:`force_sample_every`)."""
        return force_sample_every(self.output_every)

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
            "pour": self.pour,
            "particle_model": self.particle.name,
            "spheres_per_clump": self.particle.n_spheres,
            "clump_mass_kg": self.particle.mass,
            "clump_volume_m3": self.particle.volume,
            **self.timestep_summary(),
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
    """The point with exactly :data:`POINT_KEYS` (and a wall test's optional :data:`PARTICLE_FRICTION_KEY`), numbers
    as floats. Its values come from the validated ``jenike.sweep`` section (:func:`siloflow.model.cases.jenike_sweep.sweep_points`)
    or a calibration's design: the schema and the design's bounds are their validators."""
    missing = [key for key in POINT_KEYS if key not in point]
    extra = sorted(set(point) - set(POINT_KEYS) - {PARTICLE_FRICTION_KEY})
    if missing or extra:
        raise ValueError(f"jenike point: missing keys {missing}, unknown keys {extra}; expected {list(POINT_KEYS)}")
    optional = {}
    if PARTICLE_FRICTION_KEY in point:
        if point["test"] == "internal":
            raise ValueError(f"jenike point: {PARTICLE_FRICTION_KEY} is a wall test's; an internal test's particle "
                             "friction is its sliding_friction")
        optional[PARTICLE_FRICTION_KEY] = float(point[PARTICLE_FRICTION_KEY])
    return {
        "shape": point["shape"],
        "test": point["test"],
        "sliding_friction": float(point["sliding_friction"]),
        "rolling_friction": float(point["rolling_friction"]),
        "restitution": float(point["restitution"]),
        "rotation_blocked": bool(point["rotation_blocked"]),
        **optional,
    }


#: Keys of ``jenike.fill`` whose whole effect is in the fill's contact set (``fill_contacts``, itself a defining
#: parameter): left out of the section in the run id, so that spelling out a value that changes no contact does not
#: rename the runs that already exist.
FILL_CONTACT_KEYS = ("restitution", "rotation_blocked_sliding_friction")


def _defining_section(jenike: dict) -> dict:
    """The ``jenike`` section as it defines a run: without its sweep (the point stands for it), the fill's checks
    (:func:`siloflow.model.cases.common.without_fill_checks`) and :data:`FILL_CONTACT_KEYS`."""
    section = without_fill_checks({key: value for key, value in jenike.items() if key != "sweep"})
    section["fill"] = {key: value for key, value in section["fill"].items() if key not in FILL_CONTACT_KEYS}
    return section


def check_cell_fits(inner_radius: float, particle: ParticleTemplate) -> None:
    """Refuse a cell whose inner radius R leaves no room for the pour's column, R - r_b > r_b (r_b the clump's
    bounding radius), naming ``jenike.cell.inner_diameter``."""
    if inner_radius - particle.bounding_radius <= particle.bounding_radius:
        raise ValueError(
            f"jenike.cell.inner_diameter ({2 * inner_radius} m) is too small for clumps of "
            f"bounding diameter {2 * particle.bounding_radius:.4g} m"
        )


def fill_column(
    geometry: CellGeometry, particle: ParticleTemplate, overfill: float
) -> tuple[int, tuple[float, ...], float, float, float]:
    """The loose column the sample is poured from: (clump count, region centres (m), region radius (m), its
    bottom and top (m)).

    n = FILL_SOLID_FRACTION (1 + overfill) pi R^2 H / V_clump with H the sample height. The column is the
    intersection of vertical cylinders of radius R - r_b (r_b the clump's bounding radius) about the
    bottom ring's and the shear ring's axes (only the latter in wall tests), from r_b above the base up
    to the height that holds n clumps at INSERT_SOLID_FRACTION.
    """
    r_b = particle.bounding_radius
    check_cell_fits(geometry.inner_radius, particle)
    radius = geometry.inner_radius - r_b
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
        raise ValueError("jenike.cell.inner_diameter: the cell is too small, less than one clump fits in its sample")
    column = n_clumps * particle.volume / (INSERT_SOLID_FRACTION * area)
    z_min = r_b
    return n_clumps, centres, radius, z_min, z_min + max(column, 2.0 * r_b)


def _sized_by_cell(cell_diameter: float, sphere_radius: float, make, *arguments):
    """``make(*arguments)``, a part whose size the cell's diameter over the spheres' radius sets (the rings' polygon
    sides, the lid's spheres); its refusal of a part too large names ``jenike.cell.inner_diameter``."""
    try:
        return make(*arguments)
    except ValueError as error:
        raise ValueError(f"jenike.cell.inner_diameter ({cell_diameter} m) for spheres of radius {sphere_radius:.4g} m: "
                         f"{error}") from None


def plan_fill(
    geometry: CellGeometry, particle: ParticleTemplate, overfill: float, settle_time: float, timestep: float,
    relax_time: float,
) -> JenikeFill:
    """Size the pour: clump count for the overfilled sample, the loose column it is created in
    (:func:`fill_column`), steps (the fall and ``settle_time`` before levelling, ``relax_time`` after it; s)."""
    n_clumps, centres, radius, z_min, z_max = fill_column(geometry, particle, overfill)
    fall_time = math.sqrt(2.0 * z_max / GRAVITY)
    largest_sphere = float(particle.sphere_radii.max())
    return JenikeFill(
        n_clumps=n_clumps,
        region_centres=centres,
        region_radius=radius,
        region_z=(z_min, z_max),
        steps=steps_for(fall_time + settle_time, timestep),
        level_z=geometry.ring_top - largest_sphere,
        relax_steps=steps_for(relax_time, timestep),
    )


def build_jenike_case(config: dict, point: dict) -> JenikeCase:
    """Derive a :class:`JenikeCase` from a validated configuration and one sweep point.

    Parameters
    ----------
    config : dict
        Validated configuration (:func:`siloflow.engines.config.validate_config`).
    point : dict
        ``{"shape": <particle model>, "test": "internal" | <wall material>, "sliding_friction": float,
        "rolling_friction": float, "restitution": float, "rotation_blocked": bool}``, optionally with
        ``"lid": "rigid" | "servo"`` overriding ``jenike.lid`` (used to compare the two lids on the same points)
        ``"replicate": k`` adding k to ``jenike.seed`` (the reference point's extra seeds) and
        ``"shear_velocity"`` overriding ``jenike.shear.velocity`` (m/s, the shear-speed study) and ``"pour"``
        (:data:`~siloflow.model.cases.jenike_sweep.POURS`): ``"own_friction"`` pours the sample at the test's particle
        friction whatever ``jenike.fill.sliding_friction`` says (the pour variant).

    Raises
    ------
    ValueError
        Naming the offending key: unknown shape or material, a missing contact pair, values out of range,
        a cell too small for the clumps, or a plate too small for the shear travel.
    """
    sweep_point = dict(point)
    lid = point.get("lid", config["jenike"]["lid"])
    if lid not in LID_KINDS:
        raise ValueError(f"jenike point: lid must be one of {', '.join(LID_KINDS)}, got {lid!r}")
    replicate = point.get("replicate", 0)
    if not isinstance(replicate, int) or isinstance(replicate, bool) or replicate < 0:
        raise ValueError(f"jenike point: replicate must be a whole number >= 0, got {replicate!r}")
    velocity = float(point.get("shear_velocity", config["jenike"]["shear"]["velocity"]))
    if not velocity > 0.0:
        raise ValueError(f"jenike point: shear_velocity must be > 0 m/s, got {velocity!r}")
    pour = point.get("pour", CONFIGURED_POUR)
    if pour not in POURS:
        raise ValueError(f"jenike point: pour must be one of {', '.join(POURS)}, got {pour!r}")
    point = _check_point({key: value for key, value in point.items()
                          if key not in ("lid", "replicate", "shear_velocity", "pour")})
    fill = config["jenike"]["fill"] if pour == CONFIGURED_POUR else {**config["jenike"]["fill"], "sliding_friction": None}
    jenike = {**config["jenike"], "lid": lid, "seed": config["jenike"]["seed"] + replicate,
              "shear": {**config["jenike"]["shear"], "velocity": velocity}, "fill": fill}
    config = {**config, "jenike": jenike}
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
    table = material_table(config, point, test_contacts)

    radius = 0.5 * cell["inner_diameter"]
    check_cell_fits(radius, particle)  # before the rings' polygons, which need a cell wider than the chord error
    segments = _sized_by_cell(cell["inner_diameter"], particle.smallest_radius, segments_for_chord, radius,
                              CHORD_TOLERANCE * particle.smallest_radius)
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
        segments=segments,
        lid_clearance=LID_CLEARANCE * particle.smallest_radius,
    )
    if wall_test:
        reach = radius + cell["wall_thickness"] + max(cell["initial_offset"], displacement - cell["initial_offset"])
        if 0.5 * cell["plate_size"] < reach:
            raise ValueError(
                f"jenike.cell.plate_size ({cell['plate_size']} m) must be at least {2 * reach:.4g} m so the "
                "shear ring stays on the plate over its whole travel"
            )
    # The highest clump of the loose column falls onto the floor: the largest impact the test sees (the
    # shear is a hundred times slower).
    column_top = fill_column(geometry, particle, overfill)[4]
    timestep_choice = stable_timestep(
        particle.smallest_radius, material["density"], material["youngs_modulus"], material["poisson_ratio"],
        free_fall_velocity(0.0, column_top, GRAVITY), jenike["timestep_fraction"], jenike["timestep_hertz_fraction"],
        particle.timestep_scale,
    )
    timestep = timestep_choice.timestep
    fill = plan_fill(geometry, particle, overfill, jenike["fill"]["settle_time"], timestep,
                     jenike["fill"]["relax_time"])

    normal_force = jenike["consolidation"]["normal_stress"] * geometry.area
    lid_radius = radius - geometry.lid_clearance
    sphere_radius = particle.smallest_radius
    lid_spheres = _sized_by_cell(cell["inner_diameter"], sphere_radius, lid_sphere_layout, lid_radius - sphere_radius,
                                 LID_SPHERE_SPACING * sphere_radius)
    rigid_lid = RigidLid(
        positions=lid_spheres + np.array(geometry.ring_centre),
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
        "particle_model": model_parameters(particle.name, config["particle_models"][particle.name]),
        "test_contacts": asdict(test_contacts),
        "fill_contacts": asdict(fill_contacts),
        "jenike": _defining_section(jenike),
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
        timestep_choice=timestep_choice,
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
        sweep_point=sweep_point,
        pour=pour,
    )


def jenike_cases(config: dict) -> dict[str, JenikeCase]:
    """The Jenike shear tests of the calibration sweep a validated configuration defines, keyed by run id.

    Raises
    ------
    ValueError
        Naming the sweep point whose cell cannot be built (e.g. a plate too small for the ring's travel).
    """
    cases = {}
    for point in sweep_points(config["jenike"]["sweep"], lid=config["jenike"]["lid"],
                              pour_friction=config["jenike"]["fill"]["sliding_friction"]):
        try:
            case = build_jenike_case(config, point)
        except ValueError as error:
            raise ValueError(f"jenike sweep point {point}: {error}") from None
        cases[case.run_id] = case
    return cases
