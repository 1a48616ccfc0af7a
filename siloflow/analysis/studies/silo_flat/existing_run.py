"""The flat-bottom silo study of a run siloflow did not make, from its particle frames and its user's description.

A user's own run leaves particle dumps only. :func:`analyse_existing_run` takes their frames (read by the run's
engine, :func:`siloflow.engines.existing_runs.read_existing_frames`, in the dumps' own coordinates) and the run's
description (:class:`~siloflow.model.existing_run.ExistingSiloRun`) and makes what siloflow makes of its own silo
runs from frames:

- the frames from the opening on (:func:`opening_frames`): a step dumped twice is kept once, the later copy; the
  fill at the opening is the last frame at or before the opening step (with the outlet shut nothing leaves, so a
  frame dumped before the opening stands for it, at the opening time); positions moved into siloflow's
  coordinates (:func:`to_silo_coordinates`);
- the flow metrics (:func:`existing_flow`, :func:`siloflow.analysis.studies.silo_flat.metrics.silo_flow_metrics`): filling
  bulk density, discharged mass, the mass that has left the silo (centre below the outlet plane, or gone from the
  frames), counted from the frames, the steady flow rate and its window, Beverloo's prediction. A user's deck may
  delete particles as they cross the outlet plane, so a particle that vanishes above the plane counts as
  discharged when it could have reached the outlet by the next frame; any other is reported as escaped;
- the coarse-grained fields, profiles, flow channel boundaries, kinematic constant and centreline velocity
  (:func:`existing_field_study`, :func:`siloflow.analysis.studies.silo_flat.field_study.analyse_silo_fields` without
  contacts).

What needs data the dumps do not hold is skipped, and :data:`SKIPPED_ANALYSES` says which and why: the settled
fill's contact stress, the Janssen comparison and the force chains (pair contact forces), and the fill's force
balance (the walls' forces). Nothing here reads or writes files. Coordinates as everywhere in siloflow: x across
the width (0 on the axis), y front to back (0 at the front wall), z up (0 at the outlet plane); SI units.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.existing_run import ExistingSiloRun
from siloflow.model.frames import ParticleFrame, clumps_from_frame
from siloflow.analysis.studies.silo_flat.field_study import SiloDimensions, SiloFieldOptions, SiloFieldStudy, analyse_silo_fields
from siloflow.analysis.studies.silo_flat.metrics import SiloFlowMetrics, flow_table_row, silo_flow_metrics

__all__ = [
    "SKIPPED_ANALYSES",
    "ExistingRunAnalysis",
    "ExistingSiloFlow",
    "SkippedAnalysis",
    "analyse_existing_run",
    "analyses_summary",
    "existing_field_study",
    "existing_flow",
    "existing_flow_row",
    "opening_frames",
    "particle_size",
    "silo_dimensions",
    "to_silo_coordinates",
]


@dataclass(frozen=True)
class SkippedAnalysis:
    """An analysis of siloflow's own silo runs that a run known only from its particle dumps cannot have.

    Attributes
    ----------
    analysis : str
        What is skipped.
    products : tuple of str
        The files it makes for siloflow's runs (relative to a run's folder).
    needs : str
        The data it needs that the dumps do not hold.
    """

    analysis: str
    products: tuple[str, ...]
    needs: str


#: What the dumps of a run siloflow did not make cannot give: particle dumps hold positions, velocities, radii and
#: masses, but neither the forces between particles nor those of the walls.
SKIPPED_ANALYSES = (
    SkippedAnalysis("settled contact stress", ("fields/settled_stress.vti",),
                    "the pair contact forces of the settled fill"),
    SkippedAnalysis("Janssen comparison", ("metrics/janssen.csv", "plots/janssen.png"),
                    "the pair contact forces of the settled fill (the vertical contact stress)"),
    SkippedAnalysis("force chains", ("plots/force_chains.png",), "the pair contact forces of the settled fill"),
    SkippedAnalysis("fill force balance", ("metrics/fill_balance.json",),
                    "the force of each wall on each particle and each wall's total force of the settled fill"),
)


# --------------------------------------------------------------------------- frames


def to_silo_coordinates(frame: ParticleFrame, origin: Sequence[float], time: float | None = None) -> ParticleFrame:
    """A frame moved into siloflow's coordinates: ``origin`` (m, the dumps' coordinates of the silo axis' x, the
    front wall's y and the outlet plane's z) becomes (0, 0, 0); velocities are unchanged. ``time`` (s) replaces the
    frame's time when given."""
    return dataclasses.replace(frame, position=frame.position - np.asarray(origin, dtype=float),
                               time=frame.time if time is None else time)


def opening_frames(frames: Sequence[ParticleFrame], run: ExistingSiloRun) -> list[ParticleFrame]:
    """The frames of the discharge in siloflow's coordinates: the fill at the opening, then every later frame.

    Parameters
    ----------
    frames : sequence of ParticleFrame
        Every frame of the run, in the dumps' coordinates, times = step x ``run.timestep``.
    run : ExistingSiloRun
        The run's description.

    Returns
    -------
    list of ParticleFrame
        Ascending step, one frame per step (of a step dumped twice, as an engine does at the end of one run and the
        start of the next into one file, the later copy). The first is the last frame at or before
        ``run.open_step``, at time ``run.open_time``: the outlet is shut until then, so nothing leaves between the
        two. The others are the frames after the opening.

    Raises
    ------
    ValueError
        When no frame lies at or before the opening, that frame holds no particle, or no frame follows it.
    """
    by_step = {frame.step: frame for frame in frames}  # the later copy of a step wins
    steps = sorted(by_step)
    before = [step for step in steps if step <= run.open_step]
    if not before:
        raise ValueError(f"{run.name}: no frame at or before the opening (step {run.open_step}); the first is of "
                         f"step {steps[0] if steps else None}")
    settled = by_step[before[-1]]
    if len(settled) == 0:
        raise ValueError(f"{run.name}: the frame of step {settled.step}, the last at or before the opening (step "
                         f"{run.open_step}), holds no particle")
    later = [by_step[step] for step in steps if step > run.open_step]
    if not later:
        raise ValueError(f"{run.name}: no frame after the opening (step {run.open_step})")
    return [to_silo_coordinates(settled, run.origin, time=run.open_time),
            *(to_silo_coordinates(frame, run.origin) for frame in later)]


def particle_size(settled: ParticleFrame, run: ExistingSiloRun) -> tuple[float, float]:
    """The particle's volume-equivalent diameter (m) and mean mass (kg) in the settled fill.

    The diameter is ``run.particle_diameter`` when given; otherwise, for a fill of single spheres, that of the mean
    sphere volume, ``2 (mean r^3)^(1/3)``.

    Raises
    ------
    ValueError
        For a fill of multisphere clumps without ``run.particle_diameter`` (overlapping spheres give no volume).
    """
    clumps = clumps_from_frame(settled)
    mass = float(np.mean(clumps.mass))
    if run.particle_diameter is not None:
        return run.particle_diameter, mass
    if np.any(clumps.n_spheres != 1):
        raise ValueError(f"{run.name}: the dumps hold multisphere clumps, whose overlapping spheres give no volume: "
                         "give particle_diameter (the volume-equivalent diameter, m)")
    return 2.0 * float(np.cbrt(np.mean(settled.radius**3))), mass


def silo_dimensions(settled: ParticleFrame, run: ExistingSiloRun) -> SiloDimensions:
    """The numbers of the silo the field study uses, from the description and the settled fill."""
    diameter, mass = particle_size(settled, run)
    return SiloDimensions(width=run.width, depth=run.depth, outlet_width=run.outlet_width,
                          particle_radius=0.5 * diameter, clump_mass=mass)


# --------------------------------------------------------------------------- the study


@dataclass(frozen=True)
class ExistingSiloFlow:
    """The flow of a run siloflow did not make (see :func:`existing_flow`).

    Attributes
    ----------
    silo : SiloDimensions
        The silo and its particle.
    settled_step : int
        Step of the frame that stands for the fill at the opening (-).
    n_particles : int
        Particles (clumps) in the settled fill (-).
    particle_model : str
        ``spheres`` or ``clumps``.
    metrics : SiloFlowMetrics
        Bulk density, discharge history, steady flow rate and Beverloo's prediction.
    """

    silo: SiloDimensions
    settled_step: int
    n_particles: int
    particle_model: str
    metrics: SiloFlowMetrics


def existing_flow(
    frames: Sequence[ParticleFrame], run: ExistingSiloRun, steady_window: tuple[float, float] = (0.2, 0.8),
    discharge_coefficient: float = 0.58, shape_coefficient: float = 1.5, beverloo_diameter: float | None = None,
) -> ExistingSiloFlow:
    """Flow metrics of a run siloflow did not make, from its frames alone.

    Parameters
    ----------
    frames : sequence of ParticleFrame
        Every frame of the run, in the dumps' coordinates (:func:`opening_frames` picks and moves them).
    run : ExistingSiloRun
        The run's description.
    steady_window : tuple of float
        Fractions of the finally discharged mass that bound the steady window (-).
    discharge_coefficient, shape_coefficient : float
        Beverloo's C and k (-).
    beverloo_diameter : float or None
        Particle diameter for Beverloo (m); None: the volume-equivalent one (:func:`particle_size`).

    Returns
    -------
    ExistingSiloFlow

    Raises
    ------
    ValueError
        From :func:`opening_frames` and :func:`particle_size`; ``EscapedParticles`` (a ValueError) when particles
        vanished other than through the outlet.
    """
    chosen = opening_frames(frames, run)
    silo = silo_dimensions(chosen[0], run)
    clumps = [clumps_from_frame(frame) for frame in chosen]
    metrics = silo_flow_metrics(
        clumps, width=run.width, depth=run.depth, outlet_width=run.outlet_width,
        particle_diameter=beverloo_diameter or 2.0 * silo.particle_radius, steady_window=tuple(steady_window),
        discharge_coefficient=discharge_coefficient, shape_coefficient=shape_coefficient, removed_at_outlet=True,
    )
    model = "spheres" if np.all(clumps[0].n_spheres == 1) else "clumps"
    return ExistingSiloFlow(silo=silo, settled_step=chosen[0].step, n_particles=len(clumps[0]),
                            particle_model=model, metrics=metrics)


def existing_flow_row(run: ExistingSiloRun, flow: ExistingSiloFlow) -> dict:
    """The row of ``metrics/flow.csv`` and ``flow.json``, as for siloflow's runs (run id: the run's name)."""
    return flow_table_row(run.name, flow.particle_model, flow.n_particles, flow.metrics)


def existing_field_study(
    frames: Sequence[ParticleFrame], run: ExistingSiloRun, options: SiloFieldOptions,
    steady_window: tuple[float, float], bulk_density: float, bulk_density_error: float | None = math.nan,
) -> SiloFieldStudy:
    """Coarse-grained fields, profiles, flow channel boundaries and kinematic constant of a run siloflow did not
    make, without contacts (:func:`siloflow.analysis.studies.silo_flat.field_study.analyse_silo_fields`).

    Parameters
    ----------
    frames : sequence of ParticleFrame
        Every frame of the run, in the dumps' coordinates.
    run : ExistingSiloRun
        The run's description; its ``profile_heights``, when given, replace those of ``options``.
    options : SiloFieldOptions
        The field settings.
    steady_window : tuple of float
        Steady flow window since the opening (s), from :func:`existing_flow`.
    bulk_density, bulk_density_error : float
        Filling bulk density and its standard error (kg/m^3), from :func:`existing_flow`.

    Returns
    -------
    SiloFieldStudy
        With ``stress``, ``janssen``, ``segments`` and ``n_contacts`` None.
    """
    chosen = opening_frames(frames, run)
    if run.profile_heights is not None:
        options = dataclasses.replace(options, profile_heights=run.profile_heights)
    return analyse_silo_fields([clumps_from_frame(frame) for frame in chosen], None, silo_dimensions(chosen[0], run),
                               options, steady_window=tuple(steady_window), bulk_density=bulk_density,
                               bulk_density_error=bulk_density_error)


@dataclass(frozen=True)
class ExistingRunAnalysis:
    """The silo study of a run siloflow did not make (see :func:`analyse_existing_run`).

    Attributes
    ----------
    flow : ExistingSiloFlow
        Flow metrics.
    fields : SiloFieldStudy
        Fields and profiles, without contacts.
    skipped : tuple of SkippedAnalysis
        What the dumps cannot give.
    """

    flow: ExistingSiloFlow
    fields: SiloFieldStudy
    skipped: tuple[SkippedAnalysis, ...] = SKIPPED_ANALYSES


def analyse_existing_run(
    frames: Sequence[ParticleFrame], run: ExistingSiloRun, options: SiloFieldOptions,
    steady_window: tuple[float, float] = (0.2, 0.8), discharge_coefficient: float = 0.58,
    shape_coefficient: float = 1.5, beverloo_diameter: float | None = None,
) -> ExistingRunAnalysis:
    """The flat-bottom silo study of a run siloflow did not make: flow metrics, then fields and profiles.

    Parameters
    ----------
    frames : sequence of ParticleFrame
        Every frame of the run (:func:`siloflow.engines.existing_runs.read_existing_frames`), in the dumps' coordinates.
    run : ExistingSiloRun
        The run's description.
    options : SiloFieldOptions
        The field settings (``silo_flat.fields``).
    steady_window, discharge_coefficient, shape_coefficient, beverloo_diameter
        As :func:`existing_flow`.

    Returns
    -------
    ExistingRunAnalysis

    Examples
    --------
    >>> run = ExistingSiloRun(name="mine", engine="liggghts", folder="runs/mine", dumps="post/silo*.vtk",
    ...                       width=0.04, depth=0.009, outlet_width=0.012, timestep=2e-5, open_step=10000,
    ...                       origin=(0.02, 0.0, 0.01), density=2500.0)        # doctest: +SKIP
    >>> frames = read_existing_frames(run)                                      # doctest: +SKIP
    >>> result = analyse_existing_run(frames, run, options)                     # doctest: +SKIP
    >>> result.flow.metrics.fit.mass_flow_rate                                  # doctest: +SKIP
    """
    flow = existing_flow(frames, run, steady_window, discharge_coefficient, shape_coefficient, beverloo_diameter)
    metrics = flow.metrics
    fields = existing_field_study(frames, run, options, (metrics.fit.t_start, metrics.fit.t_end),
                                  metrics.bulk_density.density, metrics.bulk_density_error)
    return ExistingRunAnalysis(flow=flow, fields=fields)


def analyses_summary(run: ExistingSiloRun, steps: Sequence[int], settled_step: int, made: Sequence[str],
                     skipped: Sequence[SkippedAnalysis] = SKIPPED_ANALYSES) -> dict:
    """The contents of ``metrics/analyses.json``: what was read, what was made and what was skipped and why.

    Parameters
    ----------
    run : ExistingSiloRun
        The run's description.
    steps : sequence of int
        Steps of the frames analysed (the settled fill first) (-).
    settled_step : int
        Step of the frame that stands for the fill at the opening (-).
    made : sequence of str
        The products made (relative to the run's results folder).
    skipped : sequence of SkippedAnalysis
        What was skipped.
    """
    return {
        "run": run.name,
        "engine": run.engine,
        "folder": run.folder,
        "dumps": run.dumps,
        "timestep_s": run.timestep,
        "open_step": run.open_step,
        "open_time_s": run.open_time,
        "settled_step": settled_step,
        "frames": len(steps),
        "first_step": steps[0],
        "last_step": steps[-1],
        "origin_m": list(run.origin),
        "density_kg_m3": run.density,
        "made": list(made),
        "skipped": [{"analysis": s.analysis, "products": list(s.products),
                     "reason": f"needs {s.needs}, which particle dumps do not hold"} for s in skipped],
    }
