"""The multi-flow blender: an engine-neutral case built from validated configuration.

Geometry (SI units, :mod:`siloflow.model.cases.blender_geometry`): a planar silo of inner width W and depth T whose vertical
section sits on a planar hopper of half-angle alpha with a slot outlet of width B0 at z = 0; inside, a
cone-in-cone insert (two inclined plates) and a central blending tube, every wall ``wall_thickness`` thick.

Stages: pour clumps centrally from a zone above the pile, settle (to ``blender.settle_kinetic_energy_ratio`` of the
clump's m g d, looser than the flat silo's: the heap over the internals creeps for long), remove the gate,
discharge. In ``batch`` mode the silo empties and clumps leave the domain below the outlet; in ``continuous`` mode
the vertical boundary is periodic, so a clump that leaves the outlet falls ``sink_depth`` and re-enters at the top
of the silo with its id: the head stays constant and the silo is fed centrally with its own outflow (thesis
ch. 7).

Gravity scaling: at gravity factor f, gravity is f g and every time of the flow (discharge time, steady window,
dump interval, settling checks) is divided by sqrt(f). The moduli follow ``blender.gravity_moduli``:

- ``fixed``, the study's series (§7.9, the same material at every factor): the dimensionless stiffness
  E / (rho g d) falls as 1/f, so the overlaps under the pile's weight and at the pour's impacts grow, and the flow may
  depart from sqrt(g) scaling: the study's finding M4. The time step follows the Hertz limit of the faster impacts.
- ``scaled``: every Young's modulus is multiplied by f, so that E / (rho g d) is the same at every factor: the
  overlaps stay the fraction of a radius they are at 1 g, the flow scales with sqrt(g) by construction (a similarity
  check of the code), and the time step, which scales as 1 / sqrt(E) at the same impact overlap, falls by sqrt(f):
  a run makes about the same number of steps at every factor.

The settling threshold is a fraction of m g d, so as a kinetic energy it scales by f; the pour keeps its insertion
velocity.
"""

from __future__ import annotations

from typing import Mapping

import copy
import dataclasses
import math
from dataclasses import dataclass, field

from siloflow.model.cases.blender_geometry import BlenderGeometry, blender_geometry, INSERT_PRESETS
from siloflow.model.cases.config_checks import ConfigError, require, require_subset
from siloflow.model.cases.blender_passages import clear_widths, geometry_summary
from siloflow.model.cases.blender_meshes import blender_meshes
from siloflow.model.cases.geometry import horizontal_rectangle
from siloflow.model.cases.particles import model_parameters, particle_template
from siloflow.model.cases.physics import engine_seeds, free_fall_velocity, stable_timestep, steps_for
from siloflow.model.constants import GRAVITY
from siloflow.model.cases.common import (
    MaterialTable, SettleCriterion, clump_energy_scale, defining_settle, engine_kind, fill_table, largest_impact_velocity,
    material_table, plan_fill, run_id, without_fill_checks,
)
from siloflow.model.cases.silo_flat import SiloCase

CASE_NAME = "blender"
MODES = ("continuous", "batch")

#: Keys of ``blender`` that only steer the analysis or say how many runs to make; they do not define (or rerun) a
#: simulation (a replicate is defined by its seed).
ANALYSIS_ONLY_KEYS = (
    "enabled", "configurations", "gravity_factors", "gravity_configurations", "bin_size", "profile_heights_above",
    "pathlines", "rtd", "discontinuous", "continuous", "replicates", "reference_replicates",
)


@dataclass(frozen=True)
class BlenderCase:
    """Everything that defines one blender run.

    Attributes
    ----------
    configuration : str
        Insert configuration (preset or ``blender.inserts`` name).
    gravity_factor : float
        Gravity multiple f (-).
    geometry : BlenderGeometry
        Walls, insert and tube.
    silo : SiloCase
        The numbers the blender shares with the flat-bottom silo deck: particle, materials, time step, fill,
        settle, dump interval and discharge steps (already scaled for the gravity factor).
    mode : str
        ``"continuous"`` or ``"batch"``.
    steady_window : tuple of float
        Window after opening over which the steady flow is averaged (s, scaled).
    profile_windows : int
        Equal windows from opening to the end of the steady window for profiles over time.
    fill_area : float
        Open cross-section below the fill height (m^2): hopper and vertical section minus the walls inside.
    """

    configuration: str
    gravity_factor: float
    geometry: BlenderGeometry
    silo: SiloCase
    mode: str
    steady_window: tuple[float, float]
    profile_windows: int
    fill_area: float
    defining_parameters: dict = field(repr=False)

    @property
    def fill_height(self) -> float:
        """Fill height above the outlet (m)."""
        return self.silo.fill_height

    @property
    def run_id(self) -> str:
        """Directory name: configuration, gravity factor and a hash of every defining parameter."""
        return run_id(f"{self.configuration}-g{self.gravity_factor:g}", self.defining_parameters)

    @property
    def seeds(self) -> tuple[int, ...]:
        """The random seeds the engine is given: its silo deck's."""
        return self.silo.seeds

    @property
    def gravity(self) -> float:
        """Gravitational acceleration of the run (m/s^2)."""
        return GRAVITY * self.gravity_factor

    @property
    def time_scale(self) -> float:
        """Factor 1/sqrt(f) applied to the flow times of the run (-)."""
        return 1.0 / math.sqrt(self.gravity_factor)

    @property
    def domain_z(self) -> tuple[float, float]:
        """Bottom and top of the periodic domain (m): the sink below the outlet up to the silo's top."""
        return (-self.silo.sink_depth, self.silo.domain_top)

    @property
    def outlet_z(self) -> float:
        """Height of the outlet plane (m): the origin of z."""
        return 0.0

    def stages(self):
        """The silo's stages; the discharge is continuous (periodic, no clump may leave) or a batch."""
        return self.silo.stages(last="discharge")

    def summary(self) -> dict:
        """Plain-data summary for ``case.json``."""
        summary = self.silo.summary()
        summary.update(
            {
                "case": CASE_NAME,
                "run_id": self.run_id,
                "configuration": self.configuration,
                "gravity_factor": self.gravity_factor,
                "gravity_m_s2": self.gravity,
                "time_scale": self.time_scale,
                "mode": self.mode,
                "steady_window": list(self.steady_window),
                "profile_windows": self.profile_windows,
                "fill_area_m2": self.fill_area,
                "domain_z": list(self.domain_z),
                "outlet_z": self.outlet_z,
                "geometry": geometry_summary(self.geometry),
                "parameters": self.defining_parameters,
            }
        )
        return summary


def fill_cross_section_area(geometry: BlenderGeometry, height: float) -> float:
    """Open cross-section of the silo below ``height`` (m^2): the hopper and vertical section between the inner
    wall surfaces, minus the insert and tube walls (thickness times their length below ``height``).

    The hopper part is a trapezoid, 2 int_0^h wall_x dz = 2 b h + h^2 tan(alpha) for h <= z_t.
    """
    if not height > 0:
        raise ValueError(f"fill height must be > 0, got {height!r}")
    if height > geometry.z_top:
        raise ValueError(f"fill height {height} m is above the top of the silo ({geometry.z_top:.4g} m)")
    tan_alpha = math.tan(math.radians(geometry.hopper_half_angle))
    b, z_t = geometry.half_outlet, geometry.z_transition
    hopper = min(height, z_t)
    area = 2.0 * b * hopper + hopper**2 * tan_alpha + max(0.0, height - z_t) * geometry.width
    thickness = geometry.wall_thickness
    for lower, upper in geometry.internal_wall_spans():
        (x_low, z_low), (x_up, z_up) = lower, upper
        length = math.hypot(x_up - x_low, z_up - z_low)
        covered = min(max((height - z_low) / (z_up - z_low), 0.0), 1.0)
        area -= 2.0 * thickness * length * covered
    return area


def insert_spec(config: dict, configuration: str):
    """The insert specification of ``configuration`` for :func:`siloflow.model.cases.blender_geometry.blender_geometry`."""
    blender = config["blender"]
    if configuration in blender["inserts"]:
        return dict(blender["inserts"][configuration])
    if configuration in INSERT_PRESETS:
        return configuration
    known = ", ".join(sorted({*INSERT_PRESETS, *blender["inserts"]}))
    raise KeyError(f"unknown blender configuration '{configuration}'; defined: {known}")


def geometry_for(config: dict, configuration: str) -> BlenderGeometry:
    """The blender geometry of one configuration (ValueError names the offending key)."""
    blender = config["blender"]
    outlet_level = blender["insert_outlet"]
    try:
        return blender_geometry(
            width=blender["width"],
            depth=blender["depth"],
            vertical_height=blender["vertical_height"],
            hopper_half_angle=blender["hopper_half_angle"],
            outlet_width=blender["outlet_width"],
            wall_thickness=blender["wall_thickness"],
            tube_width=blender["tube_width"],
            tube_inlet_above_transition=blender["tube_inlet_fraction"] * blender["width"],
            insert=insert_spec(config, configuration),
            occupancy=outlet_level["occupancy"],
            reference_interior_ratio=outlet_level["interior_ratio"],
            reference_exterior_ratio=outlet_level["exterior_ratio"],
        )
    except ValueError as error:
        raise ValueError(f"blender configuration '{configuration}': {error}") from None


def gravity_scaled_stiffness(table: MaterialTable, gravity_factor: float) -> MaterialTable:
    """The material table with every Young's modulus multiplied by the gravity factor ``gravity_factor`` (-): the
    blender's similarity rule for its gravity series (see the module docstring)."""
    return dataclasses.replace(table, youngs_modulus=tuple(float(e) * gravity_factor for e in table.youngs_modulus))


def build_blender_case(config: dict, configuration: str, gravity_factor: float = 1.0) -> BlenderCase:
    """Derive the :class:`BlenderCase` of one configuration and gravity factor from a validated configuration.

    Raises
    ------
    ValueError
        When a passage is narrower than ``blender.min_passage_clumps`` clump sizes, the fill or its pouring zone
        does not fit below the top of the silo, or the steady window is outside the discharge.
    """
    if not gravity_factor > 0:
        raise ValueError(f"gravity factor must be > 0, got {gravity_factor!r}")
    blender = config["blender"]
    geometry = geometry_for(config, configuration)
    material_name = blender["particle_material"]
    material = config["materials"][material_name]
    particle = particle_template(
        blender["particle_model"], config["particle_models"][blender["particle_model"]], material["density"]
    )
    clump_size = 2.0 * particle.bounding_radius
    narrowest = blender["min_passage_clumps"] * clump_size
    for passage, width in clear_widths(geometry).items():
        if width < narrowest:
            raise ValueError(
                f"blender configuration '{configuration}': the {passage} is {width * 1000:.1f} mm wide, narrower than "
                f"blender.min_passage_clumps = {blender['min_passage_clumps']:g} clump sizes ({narrowest * 1000:.1f} mm); "
                "widen the silo (blender.width), the outlet or the tube"
            )
    walls = blender["wall_materials"]
    table = material_table(config, material_name, [walls["side"], walls["front_back"]])
    moduli_factor = gravity_factor if blender["gravity_moduli"] == "scaled" else 1.0
    table = gravity_scaled_stiffness(table, moduli_factor)
    scale = 1.0 / math.sqrt(gravity_factor)
    gravity = GRAVITY * gravity_factor

    fill_height = blender["fill_height"]
    fill_area = fill_cross_section_area(geometry, fill_height)
    fill_config = dict(blender["fill"])
    # The pour keeps its insertion velocity: at higher gravity the clumps hit the pile faster anyway, and the
    # soft contacts of the reduced stiffness do not stand much more.
    fill_config.update(zone_width_fraction=blender["fill_zone_width_fraction"])
    n_clumps = int(round(fill_config["bulk_density_estimate"] * fill_area * blender["depth"] / particle.mass))
    # The walls end one clump size below the top of the domain: LIGGGHTS refuses mesh nodes on a periodic
    # boundary, and re-entering clumps appear above the pile anyway.
    domain_top = geometry.z_top + clump_size
    # In continuous mode a discharged clump falls sink_depth below the outlet and re-enters at the top.
    reentry_velocity = (free_fall_velocity(0.0, blender["sink_depth"], gravity)
                        if blender["discharge"]["mode"] == "continuous" else 0.0)
    timestep_choice = stable_timestep(
        particle.smallest_radius, material["density"], table.youngs_modulus[0], material["poisson_ratio"],
        largest_impact_velocity(fill_config, fill_height, domain_top, gravity, reentry_velocity),
        blender["timestep_fraction"], blender["timestep_hertz_fraction"], particle.timestep_scale,
    )
    timestep = timestep_choice.timestep
    fill = plan_fill(particle, blender["width"], blender["depth"], fill_height, fill_config, timestep, gravity, n_clumps)
    if fill.zone[5] + clump_size > geometry.z_top:
        raise ValueError(
            f"blender configuration '{configuration}': the pouring zone above the heap reaches "
            f"{fill.zone[5] + clump_size:.4g} m, above the top of the silo ({geometry.z_top:.4g} m); raise "
            "blender.vertical_height or lower blender.fill_height"
        )
    settle = blender["settle"]
    # The blender's own, looser criterion; settle gives only the check interval and the longest time.
    energy_scale = clump_energy_scale(particle, gravity)
    criterion = SettleCriterion(blender["settle_kinetic_energy_ratio"] * energy_scale, energy_scale,
                                "blender.settle_kinetic_energy_ratio")
    settle_check_steps = steps_for(settle["check_interval"] * scale, timestep)
    settle_max_checks = max(1, math.ceil(settle["max_time"] * scale / (settle_check_steps * timestep)))
    discharge = blender["discharge"]
    start, end = discharge["steady_window"]
    if not start < end <= discharge["time"]:
        raise ValueError(
            f"blender.discharge.steady_window {discharge['steady_window']} must be an increasing window within "
            f"blender.discharge.time ({discharge['time']} s)"
        )
    if blender["sink_depth"] < clump_size:
        raise ValueError(f"blender.sink_depth ({blender['sink_depth']} m) must exceed one clump size ({clump_size:.4g} m)")

    defining = {
        "case": CASE_NAME,
        "configuration": configuration,
        "insert": insert_spec(config, configuration),
        "gravity_factor": float(gravity_factor),
        "materials": {name: config["materials"][name] for name in table.names},
        "particle_model": model_parameters(particle.name, config["particle_models"][particle.name]),
        "contacts": sorted(
            ({**c, "materials": sorted(c["materials"])} for c in config["contacts"] if set(c["materials"]) <= set(table.names)),
            key=lambda c: c["materials"],
        ),
        "engine": engine_kind(config, CASE_NAME),
        # the inserts enter through "insert"; the steady and profile windows only steer the analysis
        "blender": without_fill_checks({k: copy.deepcopy(v) for k, v in blender.items()
                                        if k not in (*ANALYSIS_ONLY_KEYS, "inserts", "discharge", "engine",
                                                     "settle_kinetic_energy_ratio", "gravity_moduli")}),
        "discharge": {"mode": discharge["mode"], "time": discharge["time"]},
    }
    if moduli_factor != 1.0:
        # the moduli the engine is given, only where they differ from the configuration's: blender.gravity_moduli
        # enters a run's id through it, so that a run at 1 g is the same run under either rule
        defining["youngs_modulus_factor"] = float(moduli_factor)
    # The threshold in joules defines the run; settle's own criterion keys (inherited, unused here) do not.
    defining["blender"]["settle"] = defining_settle(settle, criterion.threshold)
    silo = SiloCase(
        particle=particle,
        materials=table,
        width=blender["width"],
        depth=blender["depth"],
        fill_height=fill_height,
        outlet_width=blender["outlet_width"],
        wall_materials={"side": walls["side"], "bottom": walls["side"], "front_back": walls["front_back"]},
        front_back_walls=True,
        timestep_choice=timestep_choice,
        fill=fill,
        settle_criterion=criterion,
        settle_check_steps=settle_check_steps,
        settle_max_checks=settle_max_checks,
        discharge_steps=steps_for(discharge["time"] * scale, timestep),
        dump_every=steps_for(blender["dump_interval"] * scale, timestep),
        sink_depth=blender["sink_depth"],
        domain_top=domain_top,
        seeds=tuple(engine_seeds(blender["seed"], 3)),
        defining_parameters=defining,
        fill_materials=fill_table(table, blender["fill"]),
    )
    return BlenderCase(
        configuration=configuration,
        gravity_factor=float(gravity_factor),
        geometry=geometry,
        silo=silo,
        mode=discharge["mode"],
        steady_window=(start * scale, end * scale),
        profile_windows=discharge["profile_windows"],
        fill_area=fill_area,
        defining_parameters=defining,
    )


def blender_cases(config: dict) -> dict[str, BlenderCase]:
    """The blender runs of a validated configuration, keyed by run id: every configuration at the lowest gravity
    factor, those of ``gravity_configurations`` (null: all) at every factor; empty when ``blender.enabled`` is false."""
    blender = config["blender"]
    if not blender["enabled"]:
        return {}
    scaled = blender["gravity_configurations"] or blender["configurations"]
    lowest = [min(blender["gravity_factors"])]
    cases = [
        build_blender_case(config, configuration, factor)
        for configuration in blender["configurations"]
        for factor in (blender["gravity_factors"] if configuration in scaled else lowest)
    ]
    return {case.run_id: case for case in cases}


#: The gate over the outlet, removed when the outlet opens.
GATE = "outlet_gate"
#: Longest outline edge of a wall mesh (m): keeps triangles from being extremely elongated.
MAX_MESH_EDGE = 0.05


def blender_mesh_set(case: BlenderCase) -> dict:
    """The wall meshes of a run: the geometry's closed walls plus the gate over the outlet (z = 0, normal up)."""
    meshes = dict(blender_meshes(case.geometry, max_edge=MAX_MESH_EDGE))
    half_outlet = 0.5 * case.geometry.outlet_width
    meshes[GATE] = horizontal_rectangle(-half_outlet, half_outlet, 0.0, case.geometry.depth, 0.0)
    return meshes


def check_blender_config(config: Mapping, contact_pairs: Mapping) -> None:
    """The blender's own checks: its configurations name inserts (a preset's name is not taken), its pathlines start
    below the fill, its gravity series picks configurations, its steady window lies within the discharge. Its outlet
    is checked with every silo-type section's (:mod:`siloflow.engines.config`)."""
    blender = config["blender"]
    for name in blender["inserts"]:
        if name in INSERT_PRESETS:
            raise ConfigError(
                f"config key 'blender.inserts.{name}': '{name}' is a built-in preset; give your insert another name"
            )
    defined = {**{name: None for name in INSERT_PRESETS}, **blender["inserts"]}
    for index, name in enumerate(blender["configurations"]):
        require(name, defined, f"blender.configurations[{index}]", "insert configuration")
    if blender["pathlines"]["release_height"] >= blender["fill_height"]:
        raise ConfigError(
            f"config key 'blender.pathlines.release_height': {blender['pathlines']['release_height']} m must be below "
            f"the fill height blender.fill_height ({blender['fill_height']} m)"
        )
    require_subset(blender["gravity_configurations"], blender["configurations"], "blender.gravity_configurations",
                    "blender.configurations")
    start, end = blender["discharge"]["steady_window"]
    if not start < end <= blender["discharge"]["time"]:
        raise ConfigError(
            f"config key 'blender.discharge.steady_window': {[start, end]} must be an increasing window within "
            f"blender.discharge.time ({blender['discharge']['time']} s)"
        )
