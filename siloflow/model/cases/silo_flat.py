"""The planar flat-bottom silo: an engine-neutral case built from validated configuration.

Geometry (SI units): inner width W along x (side walls at x = -W/2 and +W/2), depth T along y (front wall
at y = 0, back wall at y = T), z up with the floor and outlet plane at z = 0. A slot outlet of width B0,
centred on x = 0, spans the full depth; a gate closes it until the fill has settled.

Stages: pour clumps centrally from an insertion zone above the pile, settle until the mean kinetic energy
per clump is below a threshold (a fraction of the clump's m g d, or an absolute energy), remove the gate,
discharge for a given time. Discharged clumps fall ``sink_depth`` below the outlet plane and leave the domain
through its bottom boundary.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field

from siloflow.model.constants import GRAVITY
from siloflow.model.cases.common import (
    FillPlan, MaterialTable, SettleCriterion, defining_settle, engine_kind, fill_zone, largest_impact_velocity,
    fill_table, material_table, plan_fill, run_id, settle_criterion, without_fill_checks,
)
from siloflow.model.cases.config_checks import ConfigError
from siloflow.model.cases.geometry import horizontal_rectangle
from siloflow.model.cases.particles import ParticleTemplate, model_parameters, particle_template
from siloflow.model.cases.physics import ChosenTimestep, TimestepChoice, engine_seeds, stable_timestep, steps_for
from siloflow.model.cases.stages import Stage

CASE_NAME = "silo_flat"

#: Keys of ``silo_flat`` that only steer the analysis; they do not define (or rerun) the simulation.
#: Keys that do not define a run: analysis settings, the replicate count (each replicate is its own run, defined
#: by its seed), and the runs siloflow did not make, which it only analyses.
ANALYSIS_ONLY_KEYS = ("steady_window", "beverloo", "fields", "parametric", "replicates", "reference_replicates", "piv",
                      "existing_runs", "posterior_draws")


@dataclass(frozen=True)
class SiloCase(ChosenTimestep):
    """Everything that defines one flat-bottom silo run, derived from validated configuration."""

    particle: ParticleTemplate
    materials: MaterialTable
    width: float
    depth: float
    fill_height: float
    outlet_width: float
    wall_materials: dict
    front_back_walls: bool
    timestep_choice: TimestepChoice
    fill: FillPlan
    settle_criterion: SettleCriterion
    settle_check_steps: int
    settle_max_checks: int
    discharge_steps: int
    dump_every: int
    sink_depth: float
    domain_top: float
    seeds: tuple[int, ...]
    defining_parameters: dict = field(repr=False)
    #: the contacts it is poured and settled with, where they differ from ``materials``
    #: (:func:`siloflow.model.cases.common.fill_table`); the run's are switched on before the outlet opens
    fill_materials: MaterialTable | None = None

    @property
    def settle_threshold(self) -> float:
        """Mean translational kinetic energy per clump below which the fill counts as settled (J)."""
        return self.settle_criterion.threshold

    @property
    def run_id(self) -> str:
        """Directory name of the run: particle model plus a hash of every defining parameter."""
        return run_id(self.particle.name, self.defining_parameters)

    def stages(self, last: str = "discharge") -> tuple[Stage, ...]:
        """Pour, settle (contacts of the settled fill saved), open the outlet, then ``last`` (``discharge``, or
        ``recirculate`` for the recirculating silo) with frames and restart files; wall forces throughout."""
        return (
            Stage("fill", {"n_clumps": self.fill.n_clumps, "insertion_velocity_m_s": self.fill.insertion_velocity,
                           "duration_s": self.fill.fill_steps * self.timestep}, ("wall_forces",)),
            Stage("settle", {"kinetic_energy_threshold_J": self.settle_threshold,
                             "kinetic_energy_ratio": self.settle_criterion.ratio,
                             "max_duration_s": self.settle_max_checks * self.settle_check_steps * self.timestep},
                  ("contacts", "wall_forces")),
            Stage("open", {"gate": "outlet_gate"}),
            Stage(last, {"duration_s": self.discharge_steps * self.timestep,
                         "frame_interval_s": self.dump_every * self.timestep}, ("frames", "wall_forces", "restart")),
        )

    @property
    def gravity(self) -> float:
        """Magnitude of gravity (m/s^2)."""
        return GRAVITY

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
            **self.timestep_summary(),
            "n_clumps": self.fill.n_clumps,
            "dump_interval_s": self.dump_every * self.timestep,
            "width_m": self.width,
            "depth_m": self.depth,
            "fill_height_m": self.fill_height,
            "outlet_width_m": self.outlet_width,
            "fill": asdict(self.fill),
            "settle_threshold_J": self.settle_threshold,
            "settle_kinetic_energy_ratio": self.settle_criterion.ratio,
            "settle_energy_scale_J": self.settle_criterion.energy_scale,
            "settle_criterion": self.settle_criterion.key,
            "discharge_time_s": self.discharge_steps * self.timestep,
            "materials": list(self.materials.names),
            "parameters": self.defining_parameters,
        }

#: The meshes of the silo's floor: the plates left and right of the outlet and its gate.
FLOOR_MESHES = ("floor_left", "floor_right", "outlet_gate")


def silo_meshes(case: SiloCase) -> dict:
    """Floor plates left and right of the outlet and the gate that closes it (z = 0, normals up)."""
    half_width, half_outlet, depth = 0.5 * case.width, 0.5 * case.outlet_width, case.depth
    return {
        "floor_left": horizontal_rectangle(-half_width, -half_outlet, 0.0, depth, 0.0),
        "floor_right": horizontal_rectangle(half_outlet, half_width, 0.0, depth, 0.0),
        "outlet_gate": horizontal_rectangle(-half_outlet, half_outlet, 0.0, depth, 0.0),
    }


def build_silo_case(config: dict) -> SiloCase:
    """Derive the :class:`SiloCase` of the ``silo_flat`` section of a validated configuration
    (see :func:`siloflow.engines.config.validate_config`)."""
    return silo_case_from_section(config, config["silo_flat"], "silo_flat")


def silo_case_from_section(config: dict, silo: dict, section: str, reentry_velocity: float = 0.0) -> SiloCase:
    """Derive a :class:`SiloCase` from a silo-type section ``silo`` (the keys of ``silo_flat``, shared keys
    inherited from ``defaults``) and the configuration's materials, particle models and contacts.

    ``section`` names the config section in error messages and decides the engine (``<section>.engine`` or
    ``engine.kind``), which is part of the defining parameters and so of the run id. ``reentry_velocity`` (m/s)
    is the downward speed at which a case that sends discharged clumps back in at the top releases them there
    (the recirculating silo's feeder velocity); it enters the Hertz limit of the time step.
    """
    material_name = silo["particle_material"]
    material = config["materials"][material_name]
    particle = particle_template(
        silo["particle_model"], config["particle_models"][silo["particle_model"]], material["density"]
    )
    if silo["depth"] < 2.0 * particle.bounding_radius:
        raise ValueError(
            f"{section}.depth ({silo['depth']} m) is thinner than one clump ({2 * particle.bounding_radius:.4g} m)"
        )
    if silo["outlet_width"] < 2.0 * particle.bounding_radius:
        raise ValueError(f"{section}.outlet_width ({silo['outlet_width']} m) is narrower than one clump "
                         f"({2 * particle.bounding_radius:.4g} m): no clump would pass")
    walls = silo["wall_materials"]
    used_walls = [walls["side"], walls["bottom"]] + ([walls["front_back"]] if silo["front_back_walls"] else [])
    table = material_table(config, material_name, used_walls)
    zone = fill_zone(particle, silo["width"], silo["depth"], silo["fill_height"], silo["fill"])
    domain_top = zone[5] + 2.0 * particle.bounding_radius
    timestep_choice = stable_timestep(
        particle.smallest_radius, material["density"], material["youngs_modulus"], material["poisson_ratio"],
        largest_impact_velocity(silo["fill"], silo["fill_height"], domain_top, GRAVITY, reentry_velocity),
        silo["timestep_fraction"], silo["timestep_hertz_fraction"], particle.timestep_scale,
    )
    timestep = timestep_choice.timestep
    fill = plan_fill(particle, silo["width"], silo["depth"], silo["fill_height"], silo["fill"], timestep, GRAVITY)
    settle = silo["settle"]
    criterion = settle_criterion(settle, particle, GRAVITY, section)
    settle_check_steps = steps_for(settle["check_interval"], timestep)
    settle_max_checks = max(1, math.ceil(settle["max_time"] / (settle_check_steps * timestep)))
    sink_depth = silo["sink_depth"]
    if sink_depth < 2.0 * particle.bounding_radius:
        raise ValueError(
            f"{section}.sink_depth ({sink_depth} m) must exceed one clump size ({2 * particle.bounding_radius:.4g} m)"
        )

    defining = {
        "case": CASE_NAME,
        "engine": engine_kind(config, section),
        "materials": {name: config["materials"][name] for name in table.names},
        "particle_model": model_parameters(particle.name, config["particle_models"][particle.name]),
        "contacts": sorted(
            (c for c in config["contacts"] if set(c["materials"]) <= set(table.names)),
            key=lambda c: sorted(c["materials"]),
        ),
        "silo": without_fill_checks({k: v for k, v in silo.items() if k not in (*ANALYSIS_ONLY_KEYS, "engine")}),
    }
    defining["silo"]["settle"] = defining_settle(settle, criterion.threshold)
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
        timestep_choice=timestep_choice,
        fill=fill,
        settle_criterion=criterion,
        settle_check_steps=settle_check_steps,
        settle_max_checks=settle_max_checks,
        discharge_steps=steps_for(silo["discharge_time"], timestep),
        dump_every=steps_for(silo["dump_interval"], timestep),
        sink_depth=sink_depth,
        domain_top=domain_top,
        seeds=tuple(engine_seeds(silo["seed"], 3)),
        defining_parameters=defining,
        fill_materials=fill_table(table, silo["fill"]),
    )


def parametric_variants(config: dict) -> dict[str, list[tuple[str, dict]]]:
    """The configurations of the parametric studies: ``{study: [(label, config), ...]}``.

    Studies (thesis ch. 5): ``front_back_friction`` (particle-wall friction of the front and back walls,
    plus a run without them when ``periodic_front_back``), ``restitution`` (of all particle contacts) and
    ``friction`` (particle-particle sliding x rolling friction of all particle contacts). A front/back wall
    friction value gets its own material (a copy of the front/back wall material), so the side walls keep
    theirs. Labels are short and stable ("mu_fw=0.3", "periodic", "e=0.6", "mu=0.15,mu_r=0.1").
    """
    silo = config["silo_flat"]
    study = silo["parametric"]
    particle = silo["particle_material"]
    front_back = silo["wall_materials"]["front_back"]
    silo_materials = {particle, *silo["wall_materials"].values()}

    def variant(edit) -> dict:
        changed = copy.deepcopy(config)
        edit(changed)
        return changed

    def set_particle_contacts(changed, **values) -> None:
        for contact in changed["contacts"]:
            if particle in contact["materials"]:
                partner = [m for m in contact["materials"] if m != particle] or [particle]
                if partner[0] not in silo_materials:
                    continue  # a contact this silo never has (e.g. the Jenike lid's)
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


def check_silo_config(config: Mapping, contact_pairs: Mapping) -> None:
    """The flat-bottom silo's own checks: its fields' averaging window ``silo_flat.fields.average_window`` (times
    after the outlet opens, s) lies within the discharge, ``0 <= start < end <= silo_flat.discharge_time``, so that
    the profiles are never averaged over frames the run does not save. Its outlet is checked with every silo-type
    section's (:mod:`siloflow.engines.config`).

    Raises
    ------
    ConfigError
        Naming ``silo_flat.fields.average_window``, the window and the discharge time.
    """
    silo = config[CASE_NAME]
    window = silo["fields"]["average_window"]
    if window is None:
        return
    start, end = window
    if not 0.0 <= start < end <= silo["discharge_time"]:
        raise ConfigError(
            f"config key 'silo_flat.fields.average_window': {list(window)} s must be an increasing window within the "
            f"discharge, from the opening of the outlet (0 s) to silo_flat.discharge_time ({silo['discharge_time']} s)"
        )


def silo_cases(config: dict) -> dict[str, SiloCase]:
    """The flat-bottom silo runs a validated configuration defines (base run and parametric variants),
    keyed by run id."""
    cases = {}
    for run_config in [config, *(c for runs in parametric_variants(config).values() for _, c in runs)]:
        case = build_silo_case(run_config)
        cases[case.run_id] = case
    return cases
