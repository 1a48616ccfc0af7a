"""The planar flat-bottom silo: an engine-neutral case built from validated configuration.

Geometry (SI units): inner width W along x (side walls at x = -W/2 and +W/2), depth T along y (front wall
at y = 0, back wall at y = T), z up with the floor and outlet plane at z = 0. A slot outlet of width B0,
centred on x = 0, spans the full depth; a gate closes it until the fill has settled.

Stages: pour clumps centrally from an insertion zone above the pile, settle until the mean kinetic energy
per clump is below a threshold, remove the gate, discharge for a given time. Discharged clumps fall
``sink_depth`` below the outlet plane and leave the domain through its bottom boundary.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
from dataclasses import asdict, dataclass, field

from engines.particles import ParticleTemplate, particle_template
from engines.physics import engine_seeds, rayleigh_time, steps_for

CASE_NAME = "silo_flat"

#: Keys of ``silo_flat`` that only steer the analysis; they do not define (or rerun) the simulation.
ANALYSIS_ONLY_KEYS = ("steady_window", "beverloo", "fields", "parametric")


@dataclass(frozen=True)
class MaterialTable:
    """Materials numbered as engine atom types, with per-pair contact parameters.

    Attributes
    ----------
    names : tuple of str
        Material names; type i + 1 is ``names[i]``; the particle material is type 1.
    youngs_modulus, poisson_ratio : tuple of float
        Per type (Pa, -).
    sliding_friction, rolling_friction, restitution : tuple of tuple of float
        Symmetric per-pair matrices (-). Pairs that never touch in the case (wall-wall) carry neutral
        values: friction 0, rolling friction 0, restitution 0.5.
    """

    names: tuple[str, ...]
    youngs_modulus: tuple[float, ...]
    poisson_ratio: tuple[float, ...]
    sliding_friction: tuple[tuple[float, ...], ...]
    rolling_friction: tuple[tuple[float, ...], ...]
    restitution: tuple[tuple[float, ...], ...]

    def type_of(self, name: str) -> int:
        """Engine atom type (1-based) of a material."""
        return self.names.index(name) + 1


NEUTRAL_CONTACT = {"sliding_friction": 0.0, "rolling_friction": 0.0, "restitution": 0.5}


def material_table(config: dict, particle_material: str, wall_materials: list[str]) -> MaterialTable:
    """Number the materials (particle first, then walls in order of appearance) and build pair matrices."""
    names: list[str] = [particle_material]
    for name in wall_materials:
        if name not in names:
            names.append(name)
    contacts = {frozenset(c["materials"]): c for c in config["contacts"]}

    def matrix(key: str) -> tuple[tuple[float, ...], ...]:
        rows = []
        for a in names:
            row = []
            for b in names:
                contact = contacts.get(frozenset((a, b)))
                if contact is None and particle_material in (a, b):
                    # validate_config guarantees these exist; a missing one here is a programming error.
                    raise KeyError(f"no contact parameters for [{a}, {b}]")
                row.append(float(contact[key]) if contact else NEUTRAL_CONTACT[key])
            rows.append(tuple(row))
        return tuple(rows)

    materials = config["materials"]
    return MaterialTable(
        names=tuple(names),
        youngs_modulus=tuple(float(materials[n]["youngs_modulus"]) for n in names),
        poisson_ratio=tuple(float(materials[n]["poisson_ratio"]) for n in names),
        sliding_friction=matrix("sliding_friction"),
        rolling_friction=matrix("rolling_friction"),
        restitution=matrix("restitution"),
    )


@dataclass(frozen=True)
class FillPlan:
    """How the silo is poured: an insertion zone above the heap and an insertion rate.

    Attributes
    ----------
    n_clumps : int
        Clumps to insert.
    zone : tuple of float
        Insertion zone (x_min, x_max, y_min, y_max, z_min, z_max) (m).
    insertion_velocity : float
        Downward velocity of inserted clumps (m/s).
    insert_every : int
        Steps between insertion events; long enough for a batch to leave the zone.
    clumps_per_insertion : int
        Clumps per insertion event.
    particle_rate : float
        Insertion rate (clumps/s).
    fill_steps : int
        Steps of the filling stage (all insertions plus the last batch's fall to the heap).
    """

    n_clumps: int
    zone: tuple[float, float, float, float, float, float]
    insertion_velocity: float
    insert_every: int
    clumps_per_insertion: int
    particle_rate: float
    fill_steps: int


@dataclass(frozen=True)
class SiloCase:
    """Everything that defines one flat-bottom silo run, derived from validated configuration."""

    particle: ParticleTemplate
    materials: MaterialTable
    width: float
    depth: float
    fill_height: float
    outlet_width: float
    wall_materials: dict
    front_back_walls: bool
    timestep: float
    rayleigh_time: float
    fill: FillPlan
    settle_threshold: float
    settle_check_steps: int
    settle_max_checks: int
    discharge_steps: int
    dump_every: int
    sink_depth: float
    domain_top: float
    seeds: tuple[int, ...]
    steady_window: tuple[float, float]
    beverloo: dict
    defining_parameters: dict = field(repr=False)

    @property
    def run_id(self) -> str:
        """Directory name of the run: particle model plus a hash of every defining parameter."""
        return run_id(self.particle.name, self.defining_parameters)

    @property
    def spheres_per_clump(self) -> int:
        return self.particle.n_spheres

    def summary(self) -> dict:
        """Plain-data summary of the derived quantities (for ``case.json``)."""
        return {
            "case": CASE_NAME,
            "run_id": self.run_id,
            "particle_model": self.particle.name,
            "spheres_per_clump": self.particle.n_spheres,
            "clump_mass_kg": self.particle.mass,
            "clump_volume_m3": self.particle.volume,
            "equivalent_diameter_m": self.particle.equivalent_diameter,
            "rayleigh_time_s": self.rayleigh_time,
            "timestep_s": self.timestep,
            "n_clumps": self.fill.n_clumps,
            "dump_interval_s": self.dump_every * self.timestep,
            "width_m": self.width,
            "depth_m": self.depth,
            "fill_height_m": self.fill_height,
            "outlet_width_m": self.outlet_width,
            "fill": asdict(self.fill),
            "settle_threshold_J": self.settle_threshold,
            "discharge_time_s": self.discharge_steps * self.timestep,
            "steady_window": list(self.steady_window),
            "beverloo": dict(self.beverloo),
            "materials": list(self.materials.names),
            "parameters": self.defining_parameters,
        }


def run_id(prefix: str, parameters: dict) -> str:
    """Stable run directory name: ``<prefix>-<first 10 hex digits of sha256 of canonical JSON>``."""
    canonical = json.dumps(parameters, sort_keys=True, separators=(",", ":"))
    return f"{prefix}-{hashlib.sha256(canonical.encode()).hexdigest()[:10]}"


def plan_fill(
    particle: ParticleTemplate,
    width: float,
    depth: float,
    fill_height: float,
    fill_config: dict,
    timestep: float,
    gravity: float,
    n_clumps: int | None = None,
) -> FillPlan:
    """Size the central pour: clump count from the target fill height, zone above the heap, rate.

    The clump count is n = rho_b,est W T H / m_clump unless given (a silo whose cross-section is not a rectangle
    counts its own). The insertion zone is centred and spans the whole depth
    (with ``all_in`` LIGGGHTS keeps each clump's bounding sphere inside the zone, so clumps never overlap the
    front and back walls, and a silo one clump thick still has room for the centres), and its floor sits above
    the highest heap the pile can form, H + (W/2) tan(heap angle), plus two clump diameters. Each insertion
    event fills the zone to the given solid fraction; the next one comes when the batch has moved one zone
    height down, so batches never overlap.
    """
    if n_clumps is None:
        n_clumps = int(round(fill_config["bulk_density_estimate"] * width * depth * fill_height / particle.mass))
    if n_clumps < 1:
        raise ValueError("fill_height too small: less than one clump fits")
    clearance = particle.bounding_radius
    zone_half_width = 0.5 * fill_config["zone_width_fraction"] * width
    x_min, x_max = -zone_half_width + clearance, zone_half_width - clearance
    y_min, y_max = 0.0, depth
    if x_max - x_min <= 2.0 * clearance or y_max - y_min <= 2.0 * clearance:
        raise ValueError("insertion zone thinner than one clump: increase silo depth or zone_width_fraction")
    heap_rise = 0.5 * width * math.tan(math.radians(fill_config["heap_angle"]))
    z_min = fill_height + heap_rise + 4.0 * particle.bounding_radius
    z_max = z_min + fill_config["zone_height"]
    zone_volume = (x_max - x_min) * (y_max - y_min) * (z_max - z_min)
    clumps_per_insertion = max(1, int(fill_config["volume_fraction"] * zone_volume / particle.volume))
    velocity = fill_config["insertion_velocity"]
    insert_every = steps_for(fill_config["zone_height"] / velocity, timestep)
    particle_rate = clumps_per_insertion / (insert_every * timestep)
    insertions = math.ceil(n_clumps / clumps_per_insertion)
    # Worst-case fall of the last batch from the top of the zone to the floor.
    fall_height = z_max
    fall_time = (-velocity + math.sqrt(velocity**2 + 2.0 * gravity * fall_height)) / gravity
    fill_steps = insertions * insert_every + steps_for(fall_time, timestep)
    return FillPlan(
        n_clumps=n_clumps,
        zone=(x_min, x_max, y_min, y_max, z_min, z_max),
        insertion_velocity=velocity,
        insert_every=insert_every,
        clumps_per_insertion=clumps_per_insertion,
        particle_rate=particle_rate,
        fill_steps=fill_steps,
    )


GRAVITY = 9.81


def build_silo_case(config: dict) -> SiloCase:
    """Derive a :class:`SiloCase` from a validated configuration (see :func:`engines.config.validate_config`)."""
    silo = config["silo_flat"]
    material_name = silo["particle_material"]
    material = config["materials"][material_name]
    particle = particle_template(
        silo["particle_model"], config["particle_models"][silo["particle_model"]], material["density"]
    )
    if silo["outlet_width"] >= silo["width"]:
        raise ValueError(
            f"silo_flat.outlet_width ({silo['outlet_width']} m) must be smaller than silo_flat.width ({silo['width']} m)"
        )
    if silo["depth"] < 2.0 * particle.bounding_radius:
        raise ValueError(
            f"silo_flat.depth ({silo['depth']} m) is thinner than one clump ({2 * particle.bounding_radius:.4g} m)"
        )
    walls = silo["wall_materials"]
    used_walls = [walls["side"], walls["bottom"]] + ([walls["front_back"]] if silo["front_back_walls"] else [])
    table = material_table(config, material_name, used_walls)
    t_rayleigh = rayleigh_time(
        particle.smallest_radius, material["density"], material["youngs_modulus"], material["poisson_ratio"]
    )
    timestep = silo["timestep_fraction"] * t_rayleigh
    fill = plan_fill(particle, silo["width"], silo["depth"], silo["fill_height"], silo["fill"], timestep, GRAVITY)
    settle = silo["settle"]
    settle_check_steps = steps_for(settle["check_interval"], timestep)
    settle_max_checks = max(1, math.ceil(settle["max_time"] / (settle_check_steps * timestep)))
    sink_depth = silo["sink_depth"]
    if sink_depth < 2.0 * particle.bounding_radius:
        raise ValueError(
            f"silo_flat.sink_depth ({sink_depth} m) must exceed one clump size ({2 * particle.bounding_radius:.4g} m)"
        )

    defining = {
        "case": CASE_NAME,
        "materials": {name: config["materials"][name] for name in table.names},
        "particle_model": {"name": particle.name, **config["particle_models"][particle.name]},
        "contacts": sorted(
            (c for c in config["contacts"] if set(c["materials"]) <= set(table.names)),
            key=lambda c: sorted(c["materials"]),
        ),
        "silo": {k: v for k, v in silo.items() if k not in ANALYSIS_ONLY_KEYS},
    }
    # Normalise the contact pair order so [a, b] and [b, a] key the same run.
    defining["contacts"] = [{**c, "materials": sorted(c["materials"])} for c in defining["contacts"]]

    return SiloCase(
        particle=particle,
        materials=table,
        width=silo["width"],
        depth=silo["depth"],
        fill_height=silo["fill_height"],
        outlet_width=silo["outlet_width"],
        wall_materials=dict(walls),
        front_back_walls=silo["front_back_walls"],
        timestep=timestep,
        rayleigh_time=t_rayleigh,
        fill=fill,
        settle_threshold=settle["kinetic_energy_threshold"],
        settle_check_steps=settle_check_steps,
        settle_max_checks=settle_max_checks,
        discharge_steps=steps_for(silo["discharge_time"], timestep),
        dump_every=steps_for(silo["dump_interval"], timestep),
        sink_depth=sink_depth,
        domain_top=fill.zone[5] + 2.0 * particle.bounding_radius,
        seeds=tuple(engine_seeds(silo["seed"], 3)),
        steady_window=tuple(silo["steady_window"]),
        beverloo=dict(silo["beverloo"]),
        defining_parameters=defining,
    )


def parametric_variants(config: dict) -> dict[str, list[tuple[str, dict]]]:
    """The configurations of the parametric studies: ``{study: [(label, config), ...]}``.

    Studies (digest section 3): ``front_back_friction`` (particle-wall friction of the front and back walls,
    plus a run without them when ``periodic_front_back``), ``restitution`` (of all particle contacts) and
    ``friction`` (particle-particle sliding x rolling friction of all particle contacts). A front/back wall
    friction value gets its own material (a copy of the front/back wall material), so the side walls keep
    theirs. Labels are short and stable ("mu_fw=0.3", "periodic", "e=0.6", "mu=0.15,mu_r=0.1").
    """
    silo = config["silo_flat"]
    study = silo["parametric"]
    particle = silo["particle_material"]
    front_back = silo["wall_materials"]["front_back"]

    def variant(edit) -> dict:
        changed = copy.deepcopy(config)
        edit(changed)
        return changed

    def set_particle_contacts(changed, **values) -> None:
        for contact in changed["contacts"]:
            if particle in contact["materials"]:
                partner = [m for m in contact["materials"] if m != particle] or [particle]
                if partner[0] == config["jenike"]["lid_material"]:
                    continue
                if "sliding_friction" in values and partner[0] != particle:
                    continue  # particle-particle sliding friction only
                contact.update(values)

    studies: dict[str, list[tuple[str, dict]]] = {}
    runs = []
    for value in study["front_back_friction"]:
        name = f"{front_back}_fw{int(round(value * 1000)):04d}"

        def edit(changed, value=value, name=name):
            changed["materials"][name] = dict(changed["materials"][front_back])
            base = next(c for c in changed["contacts"] if sorted(c["materials"]) == sorted([particle, front_back]))
            changed["contacts"].append({**base, "materials": [particle, name], "sliding_friction": float(value)})
            changed["silo_flat"]["wall_materials"]["front_back"] = name

        runs.append((f"mu_fw={value:g}", variant(edit)))
    if study["periodic_front_back"]:
        runs.append(("periodic", variant(lambda changed: changed["silo_flat"].update(front_back_walls=False))))
    if runs:
        studies["front_back_friction"] = runs
    if study["restitution"]:
        studies["restitution"] = [
            (f"e={value:g}", variant(lambda changed, value=value: set_particle_contacts(changed, restitution=float(value))))
            for value in study["restitution"]
        ]
    if study["sliding_friction"] and study["rolling_friction"]:
        studies["friction"] = [
            (
                f"mu={mu:g},mu_r={mu_r:g}",
                variant(lambda changed, mu=mu, mu_r=mu_r: (
                    set_particle_contacts(changed, rolling_friction=float(mu_r)),
                    set_particle_contacts(changed, sliding_friction=float(mu)),
                )),
            )
            for mu in study["sliding_friction"]
            for mu_r in study["rolling_friction"]
        ]
    return studies


def silo_cases(config: dict) -> dict[str, SiloCase]:
    """The flat-bottom silo runs a validated configuration defines (base run and parametric variants),
    keyed by run id."""
    cases = {}
    for run_config in [config, *(c for runs in parametric_variants(config).values() for _, c in runs)]:
        case = build_silo_case(run_config)
        cases[case.run_id] = case
    return cases


def silo_case_for_run(config: dict, run: str) -> SiloCase:
    """The case of run id ``run`` in ``config``; an error names the runs the config does define."""
    cases = silo_cases(config)
    if run not in cases:
        raise KeyError(f"run '{run}' is not defined by this configuration; it defines: {', '.join(sorted(cases))}")
    return cases[run]
