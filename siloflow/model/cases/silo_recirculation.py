"""The recirculating flat-bottom silo of the blending study: an engine-neutral case from validated configuration.

Geometry (SI units, as :mod:`siloflow.model.cases.silo_flat`): the planar silo of width W and depth T with its floor and outlet
plane at z = 0, plus a vertical channel of the outlet width B0 from z = 0 down to z = -L (``channel_length``).
In the lower half of the channel a feeder holds the clumps at the downward velocity ``V_out``. The domain is
periodic in z: a clump leaving the bottom z = -L re-enters at the top of the domain (above the pile) and falls
back onto it, so the silo is fed with its own outflow (thesis ch. 6).

Stages: pour and settle exactly as the batch silo (the gate closes the outlet, the channel is empty), or, with
``assembly: silo_flat`` (the study's procedure, §6.2.2), start from the settled fill of the flat-bottom silo's
reference run with the same seed, the assembly that silo discharges; open the outlet and switch the feeder on, recirculate for ``recirculations`` a-priori mean residence times
(:func:`estimated_residence_time`); then, with ``final_discharge`` > 0, discharge for that many more: the re-entry
stops and a clump leaving the channel bottom is gone, the study's discharge after Nr recirculations (§6.4.2).

A flow pattern is a named preset of friction coefficients (``silo_recirculation.presets``); it replaces the particle-
particle and particle-wall friction of the contacts for this run. The front and back walls get their own copy
of their material (``<material>_front_back``), so that their friction can differ from the side walls' even
when both are made of the same material.
"""

from __future__ import annotations

from typing import Mapping

import copy
from dataclasses import dataclass, field

from siloflow.model.cases.common import engine_kind, run_id, without_fill_checks
from siloflow.model.cases.config_checks import ConfigError, require
from siloflow.model.cases.geometry import vertical_rectangle_x
from siloflow.model.cases.silo_flat import SiloCase, build_silo_case, silo_case_from_section, silo_meshes
from siloflow.model.cases.stages import Stage

CASE_NAME = "silo_recirculation"
#: The config section of the case.
SECTION = "silo_recirculation"
#: The silo keys the recirculating silo takes from its own section (the shared ones inherited from ``defaults``);
#: geometry, sink and discharge are set from the channel and the feeder. The settings of the batch silo's
#: analysis (steady window, Beverloo) keep their schema defaults.
SILO_KEYS = ("engine", "particle_model", "particle_material", "wall_materials", "fill", "settle", "timestep_fraction",
             "timestep_hertz_fraction", "seed")

#: The walls of the channel below the outlet (meshes; part of the floor, which holds the fill up).
CHANNEL_MESHES = ("channel_left", "channel_right")

#: Roles of a recirculation run: the blending study proper, or the one-particle-thick verification silo.
ROLES = ("blending", "verification")

#: Where a blending run's settled fill comes from (``silo_recirculation.assembly``): its own pour, or the flat-bottom
#: silo's reference run with the same seed (the study's one assembly, §6.2.2, §6.4).
OWN_ASSEMBLY, FLAT_SILO_ASSEMBLY = "own", "silo_flat"

#: The keys a recirculating silo that starts from the flat-bottom silo's assembly shares with it: its geometry and
#: everything its fill is made of. Its contacts, time step, dumps and run length stay its own.
ASSEMBLY_KEYS = ("width", "depth", "fill_height", "outlet_width", "particle_model", "particle_material",
                 "wall_materials", "fill", "settle", "seed")

#: The stages a run that starts from another run's settled fill does not run.
ASSEMBLY_STAGES = ("fill", "settle")


@dataclass(frozen=True)
class RecirculationCase:
    """Everything that defines one recirculation run.

    Attributes
    ----------
    pattern : str
        Name of the flow-pattern preset.
    role : str
        ``"blending"`` or ``"verification"``.
    silo : SiloCase
        The silo with the preset's contacts; its fill, settle, time step and dumps are used unchanged and its
        discharge stage is the recirculation stage.
    channel_length : float
        Length L of the channel below the outlet (m).
    feeder_velocity : float
        Downward velocity V_out held in the feeder (m/s).
    feeder_zone : tuple of float
        (x_min, x_max, z_min, z_max) of the feeder: the channel's width and lower half (m).
    estimated_residence_time : float
        ``W H / (B0 V_out)`` (s).
    recirculation_time : float
        Simulated time of the recirculation stage (s): from the opening to the end of the re-entry.
    final_discharge_time : float
        Simulated time of the discharge after the recirculations (s); 0 when the run ends recirculating.
    assembly : SiloCase or None
        The flat-bottom silo run whose settled fill this run starts from (``assembly: silo_flat``); None: the run
        pours and settles its own.
    """

    pattern: str
    role: str
    silo: SiloCase
    channel_length: float
    feeder_velocity: float
    feeder_zone: tuple[float, float, float, float]
    estimated_residence_time: float
    recirculation_time: float
    defining_parameters: dict = field(repr=False)
    final_discharge_time: float = 0.0
    assembly: SiloCase | None = None

    @property
    def fill_height(self) -> float:
        """Fill height of the silo (m)."""
        return self.silo.fill_height

    @property
    def gravity(self) -> float:
        """Magnitude of gravity (m/s^2)."""
        return self.silo.gravity

    @property
    def nominal_residence_time(self) -> float:
        """The study's nominal mean residence time ``W H / (B0 V_out)`` (s): the silo's contents over the feeder's
        volumetric rate with the channel as dense as the fill (§6.2.3.3, 2.75 s for its silo), whatever
        ``channel_density_ratio`` sized the run."""
        return estimated_residence_time(self.silo.width, self.fill_height, self.silo.outlet_width, self.feeder_velocity)

    @property
    def seeds(self) -> tuple[int, ...]:
        """The random seeds the engine is given: the silo's."""
        return self.silo.seeds

    @property
    def run_id(self) -> str:
        """Directory name: role, flow pattern and a hash of every defining parameter."""
        prefix = self.pattern if self.role == "blending" else f"thin-{self.pattern}"
        return run_id(prefix, self.defining_parameters)

    @property
    def domain_z(self) -> tuple[float, float]:
        """Bottom and top of the periodic domain (m): the return channel below the outlet up to the silo's top."""
        return (-self.channel_length, self.silo.domain_top)

    @property
    def recirculation_steps(self) -> int:
        """Steps of the recirculation stage (from the opening to the end of the re-entry) [-]."""
        return self.silo.discharge_steps - self.final_discharge_steps

    @property
    def final_discharge_steps(self) -> int:
        """Steps of the discharge after the recirculations [-]; 0 without one."""
        return int(round(self.final_discharge_time / self.silo.timestep))

    def reentry_stop(self, opening_time: float) -> float | None:
        """When the re-entry stops (s) on a clock that reads ``opening_time`` (s) when the outlet opens; None when the
        run ends recirculating (no discharge after the recirculations)."""
        return float(opening_time) + self.recirculation_time if self.final_discharge_steps else None

    def stages(self):
        """The batch silo's stages, its last one recirculating (:meth:`SiloCase.stages`), then the discharge after
        the recirculations where there is one; without fill and settle when the run starts from an assembly."""
        stages = self.silo.stages(last="recirculate")
        if self.assembly is not None:
            stages = tuple(stage for stage in stages if stage.kind not in ASSEMBLY_STAGES)
        if not self.final_discharge_steps:
            return stages
        *before, recirculate = stages
        frames = recirculate.controls["frame_interval_s"]
        return (*before,
                Stage("recirculate", {"duration_s": self.recirculation_time, "frame_interval_s": frames},
                      recirculate.outputs),
                Stage("discharge", {"duration_s": self.final_discharge_time, "frame_interval_s": frames},
                      recirculate.outputs))

    def summary(self) -> dict:
        """Plain-data summary for ``case.json``."""
        summary = self.silo.summary()
        summary.update(
            {
                "case": CASE_NAME,
                "run_id": self.run_id,
                "flow_pattern": self.pattern,
                "role": self.role,
                "channel_length_m": self.channel_length,
                "feeder_velocity_m_s": self.feeder_velocity,
                "feeder_zone": list(self.feeder_zone),
                "estimated_residence_time_s": self.estimated_residence_time,
                "recirculation_time_s": self.recirculation_time,
                "final_discharge_time_s": self.final_discharge_time,
                "domain_z": list(self.domain_z),
                "assembly_run_id": self.assembly.run_id if self.assembly is not None else None,
                "parameters": self.defining_parameters,
            }
        )
        return summary


def recirculation_meshes(case: RecirculationCase) -> dict:
    """The batch silo's floor and gate plus the two channel walls below the outlet (normals into the channel)."""
    half_outlet, depth, length = 0.5 * case.silo.outlet_width, case.silo.depth, case.channel_length
    meshes = silo_meshes(case.silo)
    meshes["channel_left"] = vertical_rectangle_x(-half_outlet, 0.0, depth, -length, 0.0, normal=1)
    meshes["channel_right"] = vertical_rectangle_x(half_outlet, 0.0, depth, -length, 0.0, normal=-1)
    return meshes


def estimated_residence_time(
    width: float, fill_height: float, outlet_width: float, feeder_velocity: float, channel_density_ratio: float = 1.0
) -> float:
    """A-priori mean residence time of the recirculating silo, ``t_res = W H / (B0 V_out r)`` (s).

    Holdup over throughput: the fill mass per unit depth ``rho_b W H`` over the mass flow per unit depth
    ``r rho_b B0 V_out`` through the channel, where ``r`` is the channel's bulk density relative to the fill's
    (the sheared channel is looser). Sizes the run only; the analysis measures holdup over throughput.
    """
    for name, value in (("width", width), ("fill_height", fill_height), ("outlet_width", outlet_width),
                        ("feeder_velocity", feeder_velocity), ("channel_density_ratio", channel_density_ratio)):
        if not value > 0:
            raise ValueError(f"{name} must be > 0, got {value!r}")
    return width * fill_height / (outlet_width * feeder_velocity * channel_density_ratio)


def apply_flow_pattern(config: dict, preset: dict, section: str = "silo_recirculation") -> dict:
    """A copy of ``config`` whose particle contacts carry the friction of a flow-pattern preset.

    Particle-particle: ``sliding_friction``, ``rolling_friction``. Particle with the side and bottom wall materials:
    ``wall_sliding_friction``, ``wall_rolling_friction``. The front/back walls get a new material
    ``<front_back>_front_back`` (a copy of theirs) with ``front_back_sliding_friction`` and
    ``wall_rolling_friction``. Restitution is kept from the particle's contact with the original material.
    """
    changed = copy.deepcopy(config)
    silo = changed[section]
    particle = silo["particle_material"]
    walls = silo["wall_materials"]
    contacts = changed["contacts"]

    def contact_of(material: str) -> dict:
        return next(c for c in contacts if sorted(c["materials"]) == sorted([particle, material]))

    contact_of(particle).update(
        sliding_friction=float(preset["sliding_friction"]), rolling_friction=float(preset["rolling_friction"])
    )
    for material in {walls["side"], walls["bottom"]}:
        contact_of(material).update(
            sliding_friction=float(preset["wall_sliding_friction"]),
            rolling_friction=float(preset["wall_rolling_friction"]),
        )
    front_back = walls["front_back"]
    dedicated = f"{front_back}_front_back"
    changed["materials"][dedicated] = dict(changed["materials"][front_back])
    contacts.append(
        {
            **contact_of(front_back),
            "materials": [particle, dedicated],
            "sliding_friction": float(preset["front_back_sliding_friction"]),
            "rolling_friction": float(preset["wall_rolling_friction"]),
        }
    )
    walls["front_back"] = dedicated
    return changed


def build_recirculation_case(config: dict, pattern: str, role: str = "blending") -> RecirculationCase:
    """Derive the :class:`RecirculationCase` of flow pattern ``pattern`` from a validated configuration.

    Everything comes from the ``silo_recirculation`` section (its shared keys inherited from ``defaults``):
    ``role="blending"`` takes the geometry from the section, ``role="verification"`` the thin silo of
    ``silo_recirculation.verification`` (same outlet, channel and feeder).
    """
    if role not in ROLES:
        raise ValueError(f"role must be one of {ROLES}, got {role!r}")
    section = config[SECTION]
    if pattern not in section["presets"]:
        known = ", ".join(sorted(section["presets"]))
        raise KeyError(f"unknown flow pattern '{pattern}'; {SECTION}.presets defines: {known}")
    geometry = section if role == "blending" else section["verification"]
    # The a-priori time misjudges each pattern differently (dead zones, a looser channel): the blending runs scale it
    # by the pattern's measured ratio, so that every pattern reaches the same number of measured recirculations.
    ratio = section["residence_time_ratios"].get(pattern, 1.0) if role == "blending" else 1.0
    recirculations = geometry["recirculations"] * ratio
    # the thin verification silo checks the recirculation itself: it ends recirculating
    final_discharge = section["final_discharge"] * ratio if role == "blending" else 0.0
    t_res = estimated_residence_time(
        geometry["width"], geometry["fill_height"], section["outlet_width"], section["feeder_velocity"],
        section["channel_density_ratio"],
    )
    # the study's one assembly (§6.2.2): the flat-bottom silo's reference run with this seed, whose geometry and fill
    # check_recirculation_config has found equal to this section's
    assembly = flat_silo_assembly(config) if role == "blending" and section["assembly"] == FLAT_SILO_ASSEMBLY else None
    changed = apply_flow_pattern(config, section["presets"][pattern], SECTION)
    silo = {key: copy.deepcopy(changed[SECTION][key]) for key in SILO_KEYS}
    silo.update(
        width=geometry["width"],
        depth=geometry["depth"],
        fill_height=geometry["fill_height"],
        outlet_width=section["outlet_width"],
        front_back_walls=True,
        sink_depth=section["channel_length"],
        discharge_time=(recirculations + final_discharge) * t_res,
        dump_interval=section["dump_interval"],
    )
    silo_case = silo_case_from_section(changed, silo, SECTION, reentry_velocity=section["feeder_velocity"])
    half_outlet = 0.5 * section["outlet_width"]
    channel = section["channel_length"]
    feeder_zone = (-half_outlet, half_outlet, -channel, -0.5 * channel)
    defining = {
        "case": CASE_NAME,
        "role": role,
        "pattern": pattern,
        "silo": silo_case.defining_parameters,
        "channel_length": channel,
        "feeder_velocity": section["feeder_velocity"],
    }
    if assembly is not None:
        if assembly.fill.n_clumps != silo_case.fill.n_clumps:
            raise ValueError(f"the flat-bottom silo's assembly holds {assembly.fill.n_clumps} clumps, the recirculating "
                             f"silo's fill plan {silo_case.fill.n_clumps}: their fills differ")
        defining["assembly"] = assembly.run_id
    timestep = silo_case.timestep
    final_steps = int(round(final_discharge * t_res / timestep))
    if final_steps:
        # only then: a run that ends recirculating keeps the id it had before the discharge existed
        defining["final_discharge_steps"] = final_steps
    return RecirculationCase(
        pattern=pattern,
        role=role,
        silo=silo_case,
        channel_length=channel,
        feeder_velocity=section["feeder_velocity"],
        feeder_zone=feeder_zone,
        estimated_residence_time=t_res,
        recirculation_time=(silo_case.discharge_steps - final_steps) * timestep,
        defining_parameters=defining,
        final_discharge_time=final_steps * timestep,
        assembly=assembly,
    )


def flat_silo_assembly(config: dict) -> SiloCase:
    """The flat-bottom silo run whose settled fill a blending run of ``config`` starts from: the flat-bottom silo's
    reference configuration (its base run) with the recirculating silo's seed, so that each replicate of a flow
    pattern starts from its own fill and every flow pattern of one seed from the same one."""
    reseeded = copy.deepcopy(config)
    reseeded["silo_flat"]["seed"] = config[SECTION]["seed"]
    return build_silo_case(reseeded)


def recirculation_cases(config: dict) -> dict[str, RecirculationCase]:
    """The recirculation runs a validated configuration defines (one per flow pattern, plus the thin silo when
    ``silo_recirculation.verification.enabled``), keyed by run id; empty when ``silo_recirculation.enabled`` is false."""
    section = config[SECTION]
    if not section["enabled"]:
        return {}
    cases = [build_recirculation_case(config, pattern) for pattern in section["flow_patterns"]]
    if section["verification"]["enabled"]:
        cases.append(build_recirculation_case(config, section["verification"]["flow_pattern"], "verification"))
    return {case.run_id: case for case in cases}


def check_recirculation_config(config: Mapping, contact_pairs: Mapping) -> None:
    """The recirculating silo's own checks: its flow patterns name presets, its layouts have distinct names, its
    bulk density slab is an increasing pair. Its outlet is checked with every silo-type
    section's (:mod:`siloflow.engines.config`)."""
    blending = config["silo_recirculation"]
    presets = blending["presets"]
    for index, pattern in enumerate(blending["flow_patterns"]):
        require(pattern, presets, f"silo_recirculation.flow_patterns[{index}]", "preset")
    require(blending["verification"]["flow_pattern"], presets, "silo_recirculation.verification.flow_pattern", "preset")
    for pattern in blending["residence_time_ratios"]:
        require(pattern, presets, f"silo_recirculation.residence_time_ratios.{pattern}", "preset")
    names = [layout["name"] for layout in blending["layouts"]]
    for index, name in enumerate(names):
        if names.index(name) != index:
            raise ConfigError(f"config key 'silo_recirculation.layouts[{index}].name': layout name '{name}' is used twice")
    low, high = blending["bulk_density_slab"]
    if not low < high:
        raise ConfigError(f"config key 'silo_recirculation.bulk_density_slab': {[low, high]} must be an increasing "
                          "pair of fractions of fill_height")
    if blending["assembly"] == FLAT_SILO_ASSEMBLY and blending["enabled"]:
        check_shared_assembly(config)


def _replicate_count(section: Mapping) -> int:
    return max(section["replicates"], section["reference_replicates"])


def check_shared_assembly(config: Mapping) -> None:
    """With ``silo_recirculation.assembly: silo_flat``, the recirculating silo must be the flat-bottom silo whose
    settled fills it starts from: equal :data:`ASSEMBLY_KEYS`, front and back walls, one engine, and its reference
    flow pattern's seeds among the flat-bottom silo's reference seeds.

    Raises
    ------
    ConfigError
        Naming the first key that differs and both values.
    """
    blending, flat = config[SECTION], config["silo_flat"]
    reason = ("with silo_recirculation.assembly: silo_flat every flow pattern starts from the flat-bottom silo's "
              "settled fill, so the recirculating silo is that silo")
    for key in ASSEMBLY_KEYS:
        mine, theirs = blending[key], flat[key]
        if key == "fill":
            mine, theirs = without_fill_checks({"fill": mine})["fill"], without_fill_checks({"fill": theirs})["fill"]
        if mine != theirs:
            raise ConfigError(f"config key 'silo_recirculation.{key}': {blending[key]!r} differs from silo_flat.{key} "
                              f"({flat[key]!r}); {reason}: set them equal, or silo_recirculation.assembly: own")
    if not flat["front_back_walls"]:
        raise ConfigError(f"config key 'silo_flat.front_back_walls': false; {reason}, which has front and back walls")
    engines = engine_kind(config, SECTION), engine_kind(config, "silo_flat")
    if engines[0] != engines[1]:
        raise ConfigError(f"config key 'silo_recirculation.engine': {engines[0]} differs from the flat-bottom silo's "
                          f"engine ({engines[1]}); {reason}, whose settled fill only its own engine can read")
    if _replicate_count(blending) > _replicate_count(flat):
        raise ConfigError(
            f"config key 'silo_recirculation.reference_replicates': the reference flow pattern runs "
            f"{_replicate_count(blending)} seeds, the flat-bottom silo's reference {_replicate_count(flat)} "
            "(silo_flat.replicates, silo_flat.reference_replicates); each seed starts from the flat-bottom silo's fill "
            "of that seed: run as many seeds of the flat-bottom silo")
