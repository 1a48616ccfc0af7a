"""Parts every case shares: materials and their contact pairs, the run id, the central pour.

Engine-neutral data only: a material table numbers materials as engine types, but what a type means to an
engine is the engine's business.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass

from siloflow.model.cases.particles import ParticleTemplate
from siloflow.model.rolling import ROLLING_LAW
from siloflow.model.cases.physics import check_steps, free_fall_time, free_fall_velocity, steps_for


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


def fill_table(table: MaterialTable, fill: dict) -> MaterialTable | None:
    """The contacts a silo is poured and settled with: ``table`` with the particle-particle sliding friction of
    ``fill["sliding_friction"]`` (-), or None when that is null (the run's own contacts throughout). The study packs its
    silo at 0.15 and switches to the run's frictions afterwards (thesis §5.3); whether it changed other contacts
    while filling it does not say, so they stay the run's."""
    friction = fill.get("sliding_friction")
    if friction is None:
        return None
    rows = [list(row) for row in table.sliding_friction]
    rows[0][0] = float(friction)
    return dataclasses.replace(table, sliding_friction=tuple(tuple(row) for row in rows))


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
    impact_velocity : float
        Speed of the stream where it lands on the finished fill: the insertion velocity plus the free fall from the
        zone's floor to fill_height (m/s).
    momentum_flux_ratio : float
        The stream's momentum flux there (mass rate times impact velocity) over the fill's weight (-).
    """

    n_clumps: int
    zone: tuple[float, float, float, float, float, float]
    insertion_velocity: float
    insert_every: int
    clumps_per_insertion: int
    particle_rate: float
    fill_steps: int
    impact_velocity: float
    momentum_flux_ratio: float


#: Keys of a ``fill`` section that only steer the check of the settled fill: they do not define (or rerun) a run.
FILL_CHECK_KEYS = ("balance_planes", "balance_tolerance")


def without_fill_checks(section: dict) -> dict:
    """A copy of a case section (or of its ``fill``) without the :data:`FILL_CHECK_KEYS` of its fill, for the
    parameters that define a run (a new tolerance must not rerun a simulation)."""
    fill = section.get("fill")
    if isinstance(fill, dict):
        return {**section, "fill": {key: value for key, value in fill.items() if key not in FILL_CHECK_KEYS}}
    return dict(section)


#: The keys of a case section's ``settle`` that give its settling criterion, one at most: a ratio to the clump's own
#: energy scale m g d (the default), or an absolute kinetic energy (J), which wins when set.
SETTLE_RATIO_KEY = "kinetic_energy_ratio"
SETTLE_ENERGY_KEY = "kinetic_energy_threshold"


@dataclass(frozen=True)
class SettleCriterion:
    """The kinetic energy per clump below which a fill counts as settled, and where it came from.

    Attributes
    ----------
    threshold : float
        Mean translational kinetic energy per clump below which the fill counts as settled (J).
    energy_scale : float
        The clump's energy scale m g d: clump mass times the case's gravity times the volume-equivalent
        diameter (J).
    key : str
        The config key that set it (e.g. ``silo_flat.settle.kinetic_energy_ratio``), for messages.
    """

    threshold: float
    energy_scale: float
    key: str

    @property
    def ratio(self) -> float:
        """The threshold over m g d (-), also when an absolute threshold set it."""
        return self.threshold / self.energy_scale


def clump_energy_scale(particle: ParticleTemplate, gravity: float) -> float:
    """The energy scale of a clump at rest in a fill: m g d (J).

    Parameters
    ----------
    particle : ParticleTemplate
        The clump: its mass m (kg) and volume-equivalent diameter d (m).
    gravity : float
        The case's gravity magnitude g (m/s^2), including any gravity factor.

    Returns
    -------
    float
        m g d (J): the work of lifting the clump by its own size.
    """
    if not gravity > 0:
        raise ValueError(f"gravity must be > 0, got {gravity!r}")
    return particle.mass * gravity * particle.equivalent_diameter


def settle_criterion(settle: dict, particle: ParticleTemplate, gravity: float, section: str) -> SettleCriterion:
    """The settling criterion of a case section's validated ``settle`` (keys :data:`SETTLE_RATIO_KEY`,
    :data:`SETTLE_ENERGY_KEY`).

    Parameters
    ----------
    settle : dict
        The section's ``settle``: ``kinetic_energy_ratio`` (-) and ``kinetic_energy_threshold`` (J or None).
    particle : ParticleTemplate
        The clump.
    gravity : float
        The case's gravity magnitude (m/s^2).
    section : str
        The config section, for the key the criterion names.

    Returns
    -------
    SettleCriterion
        The absolute threshold when one is set (J), else ratio times m g d.
    """
    scale = clump_energy_scale(particle, gravity)
    if settle.get(SETTLE_ENERGY_KEY) is not None:
        return SettleCriterion(float(settle[SETTLE_ENERGY_KEY]), scale, f"{section}.settle.{SETTLE_ENERGY_KEY}")
    return SettleCriterion(settle[SETTLE_RATIO_KEY] * scale, scale, f"{section}.settle.{SETTLE_RATIO_KEY}")


def defining_settle(settle: dict, threshold: float) -> dict:
    """A section's ``settle`` for the parameters that define a run: its threshold in joules instead of the keys
    that gave it, so a ratio and an absolute threshold of equal energy define the same run."""
    defining = {key: value for key, value in settle.items() if key not in (SETTLE_RATIO_KEY, SETTLE_ENERGY_KEY)}
    return {**defining, SETTLE_ENERGY_KEY: threshold}


def run_id(prefix: str, parameters: dict) -> str:
    """Stable run directory name: ``<prefix>-<first 10 hex digits of sha256 of canonical JSON>`` of ``parameters``
    and the rolling law the engines are given (:data:`siloflow.model.rolling.ROLLING_LAW`): a run made under another
    law is another run."""
    canonical = json.dumps({**parameters, "rolling_law": ROLLING_LAW}, sort_keys=True, separators=(",", ":"))
    return f"{prefix}-{hashlib.sha256(canonical.encode()).hexdigest()[:10]}"


def fill_zone(
    particle: ParticleTemplate, width: float, depth: float, fill_height: float, fill_config: dict
) -> tuple[float, float, float, float, float, float]:
    """The central insertion zone (x_min, x_max, y_min, y_max, z_min, z_max) (m) of :func:`plan_fill`.

    Centred, spanning the whole depth, its floor above the highest heap the pile can form,
    H + (W/2) tan(heap angle), plus two clump diameters. LIGGGHTS inserts a clump only with its bounding sphere
    inside the zone (``all_in``), so the zone must be wider, deeper and taller than one clump.
    """
    clearance = particle.bounding_radius
    zone_half_width = 0.5 * fill_config["zone_width_fraction"] * width
    x_min, x_max = -zone_half_width + clearance, zone_half_width - clearance
    if x_max - x_min <= 2.0 * clearance or depth <= 2.0 * clearance:
        raise ValueError("insertion zone thinner than one clump: increase silo depth or zone_width_fraction")
    if fill_config["zone_height"] <= 2.0 * clearance:
        raise ValueError(f"insertion zone lower than one clump: fill.zone_height ({fill_config['zone_height']} m) must "
                         f"exceed the clump's bounding diameter ({2.0 * clearance:.4g} m)")
    heap_rise = 0.5 * width * math.tan(math.radians(fill_config["heap_angle"]))
    z_min = fill_height + heap_rise + 4.0 * particle.bounding_radius
    return (x_min, x_max, 0.0, depth, z_min, z_min + fill_config["zone_height"])


def largest_impact_velocity(
    fill_config: dict, fill_height: float, drop_top: float, gravity: float, reentry_velocity: float = 0.0
) -> float:
    """The largest impact velocity a silo-type case expects (m/s), for the Hertz time-step limit.

    A clump that starts at ``drop_top`` (m; the top of the pouring zone or of the domain) moving down at the
    insertion velocity, or at ``reentry_velocity`` when the case sends discharged clumps back in at the top,
    falls freely to the fill height. Flow inside the silo is far slower than this fall.
    """
    start = max(fill_config["insertion_velocity"], reentry_velocity)
    return free_fall_velocity(start, drop_top - fill_height, gravity)


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
    event fills the zone to the given solid fraction; the next one comes as soon as the batch has fallen one zone
    height (at the insertion velocity, gravity helping), so batches never overlap.

    The pour is gentle: the stream's momentum flux where it lands on the finished fill (mass rate times impact
    velocity, the insertion velocity plus the free fall from the zone's floor to fill_height) stays below
    ``momentum_flux_ratio`` times the fill's weight; the planner puts fewer clumps into each insertion event until
    it does. A stream whose momentum flux is comparable to the weight compacts the bed, which springs back when the
    pour stops and is then held down by its walls (the settled fill's force balance shows it). The momentum flux, not
    the spacing of the batches, sets how fast the silo fills.
    """
    if n_clumps is None:
        n_clumps = int(round(fill_config["bulk_density_estimate"] * width * depth * fill_height / particle.mass))
    if n_clumps < 1:
        raise ValueError("fill_height too small: less than one clump fits")
    x_min, x_max, y_min, y_max, z_min, z_max = fill_zone(particle, width, depth, fill_height, fill_config)
    zone_volume = (x_max - x_min) * (y_max - y_min) * (z_max - z_min)
    clumps_per_insertion = max(1, int(fill_config["volume_fraction"] * zone_volume / particle.volume))
    velocity = fill_config["insertion_velocity"]
    # A batch has left the zone once it has fallen one zone height, gravity helping.
    insert_every = steps_for(free_fall_time(velocity, fill_config["zone_height"], gravity), timestep)
    impact_velocity = free_fall_velocity(velocity, z_min - fill_height, gravity)
    weight = n_clumps * particle.mass * gravity
    gentle_rate = fill_config["momentum_flux_ratio"] * weight / (impact_velocity * particle.mass)  # clumps/s
    clumps_per_insertion = max(1, min(clumps_per_insertion, int(gentle_rate * insert_every * timestep)))
    particle_rate = clumps_per_insertion / (insert_every * timestep)
    insertions = math.ceil(n_clumps / clumps_per_insertion)
    # Worst-case fall of the last batch from the top of the zone to the floor. The pour is one engine run command.
    fill_steps = insertions * insert_every + steps_for(free_fall_time(velocity, z_max, gravity), timestep)
    check_steps(fill_steps, f"the pour of {n_clumps} clumps")
    return FillPlan(
        n_clumps=n_clumps,
        zone=(x_min, x_max, y_min, y_max, z_min, z_max),
        insertion_velocity=velocity,
        insert_every=insert_every,
        clumps_per_insertion=clumps_per_insertion,
        particle_rate=particle_rate,
        fill_steps=fill_steps,
        impact_velocity=impact_velocity,
        momentum_flux_ratio=particle_rate * particle.mass * impact_velocity / weight,
    )


def engine_kind(config: dict, section: str) -> str:
    """The engine that runs the cases of config section ``section``: its own ``engine`` key, else ``engine.kind``.

    The engine is part of what defines a run, so it enters every run id."""
    return config[section].get("engine") or config["engine"]["kind"]
