"""What a run of a silo-type case kind costs: the flat-bottom silo, the recirculating silo and the blender.

Their decks share the stages fill, settle, open and a dumped last stage (discharge or recirculation); the work of
each follows :mod:`siloflow.model.cost`'s pieces. Pure computation on cases.
"""

from __future__ import annotations

import math

from siloflow.model.cases.blender import BlenderCase
from siloflow.model.cases.silo_flat import SiloCase
from siloflow.model.cases.silo_recirculation import ASSEMBLY_STAGES, RecirculationCase
from siloflow.model.cost import (CostModel, RunEstimate, StageWork, is_finite, beverloo_clump_rate, drain_sphere_steps,
                        dump_frames, estimate_run, pour_sphere_steps)

#: Contact snapshots the silo decks write: one local dump of the settled fill (``contacts_<step>.txt``).
SILO_CONTACT_SNAPSHOTS = 1


def settle_checks(silo: SiloCase, settle_fraction: float = 1.0) -> int:
    """Settling checks a silo fill is expected to need: ``settle_fraction`` of ``settle_max_checks``, rounded up,
    at least one."""
    return max(1, math.ceil(settle_fraction * silo.settle_max_checks - 1e-9))


def silo_run_steps(silo: SiloCase, settle_fraction: float = 1.0) -> int:
    """Steps of a silo deck: fill + settling + discharge, settling counted as ``settle_fraction`` of its longest
    time (``settle_max_checks * settle_check_steps``; 1 is the worst case), in whole checks.

    The extra insertion events the deck allows when crowded insertions place fewer clumps than asked are not
    counted (they run only then, ``insert_every`` steps each).
    """
    return silo.fill.fill_steps + settle_checks(silo, settle_fraction) * silo.settle_check_steps + silo.discharge_steps


def silo_stage_work(
    silo: SiloCase,
    settle_fraction: float = 1.0,
    last: str = "discharge",
    drain_rate: float = 0.0,
    drain_delay: float = 0.0,
) -> tuple[StageWork, ...]:
    """Steps and sphere-steps of the stages of a silo deck (flat silo, recirculating silo, blender).

    - fill: the pour in batches (:func:`pour_sphere_steps`), from 0 to N clumps;
    - settle: N clumps for ``settle_fraction`` of the longest settling time, in whole checks;
    - ``last`` (discharge or recirculate): N clumps draining at ``drain_rate`` once the first have fallen out
      of the domain (:func:`drain_sphere_steps`); a rate of 0 keeps all N.

    Opening the outlet takes no steps.

    Parameters
    ----------
    silo : SiloCase
        The silo (its fill plan, settle checks, discharge steps and time step).
    settle_fraction : float
        Share of the longest settling time counted, in (0, 1] (-).
    last : str
        Kind of the last stage.
    drain_rate : float
        Clumps leaving per second (1/s, >= 0).
    drain_delay : float
        Time from opening until the first clumps leave the domain (s, >= 0).

    Returns
    -------
    tuple of StageWork
        fill, settle and the last stage.
    """
    spheres = silo.spheres_per_clump
    fill = silo.fill
    settle_steps = settle_checks(silo, settle_fraction) * silo.settle_check_steps
    dt = silo.timestep
    return (
        StageWork("fill", fill.fill_steps, spheres * pour_sphere_steps(
            fill.n_clumps, fill.clumps_per_insertion, fill.insert_every, fill.fill_steps)),
        StageWork("settle", settle_steps, float(spheres * fill.n_clumps * settle_steps)),
        StageWork(last, silo.discharge_steps, drain_sphere_steps(
            float(spheres * fill.n_clumps), spheres * drain_rate * dt, drain_delay / dt, silo.discharge_steps)),
    )


def sink_fall_time(sink_depth: float, gravity: float) -> float:
    """Time a clump takes to fall ``sink_depth`` below the outlet from rest, ``sqrt(2 s / g)`` (s): how long the
    discharged clumps stay in the domain before it loses them."""
    if not is_finite(sink_depth) or sink_depth < 0 or not is_finite(gravity) or gravity <= 0:
        raise ValueError(f"need sink_depth >= 0 m and gravity > 0 m/s^2, got {sink_depth!r}, {gravity!r}")
    return math.sqrt(2.0 * sink_depth / gravity)


def silo_drain_rate(silo: SiloCase, fill_volume: float, gravity: float) -> float:
    """Clumps per second a batch silo loses through its slot outlet (:func:`beverloo_clump_rate`), with the clumps
    per volume the fill was sized by (``n_clumps / fill_volume``), the clump's volume-equivalent diameter and the
    silo depth as slot length.

    Parameters
    ----------
    silo : SiloCase
        The silo.
    fill_volume : float
        Volume the fill occupies (m^3, > 0).
    gravity : float
        Gravitational acceleration of the run (m/s^2).
    """
    if not is_finite(fill_volume) or fill_volume <= 0:
        raise ValueError(f"fill_volume must be > 0 m^3, got {fill_volume!r}")
    return beverloo_clump_rate(silo.fill.n_clumps / fill_volume, silo.outlet_width, silo.depth,
                               silo.particle.equivalent_diameter, gravity)


def _estimate_silo_deck(
    run_id: str, kind: str, silo: SiloCase, mpi_ranks: int, model: CostModel, stages: tuple[StageWork, ...]
) -> RunEstimate:
    """Silo, recirculating silo and blender decks: fill, settle, open, then the dumped last stage."""
    return estimate_run(
        run_id,
        kind,
        clumps=silo.fill.n_clumps,
        spheres_per_clump=silo.spheres_per_clump,
        steps=sum(stage.steps for stage in stages),
        timestep=silo.timestep,
        dump_frames=dump_frames(silo.discharge_steps, silo.dump_every),
        mpi_ranks=mpi_ranks,
        model=model,
        contact_frames=SILO_CONTACT_SNAPSHOTS,
        paraview_frames=dump_frames(silo.discharge_steps, silo.dump_every),
        stages=stages,
    )


def estimate_silo_case(case: SiloCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a flat-bottom silo run (:class:`siloflow.model.cases.silo_flat.SiloCase`).

    The discharge drains the fill at Beverloo's rate (:func:`silo_drain_rate`, fill volume W T H) once the first
    clumps have fallen ``sink_depth`` out of the domain (:func:`sink_fall_time`); the stagnant zones a flat floor
    keeps are left out (a few per cent of the discharge's work, when the silo runs empty at all).
    """
    gravity = case.gravity
    rate = silo_drain_rate(case, case.width * case.depth * case.fill_height, gravity)
    stages = silo_stage_work(case, model.settle_fraction, "discharge", rate, sink_fall_time(case.sink_depth, gravity))
    return _estimate_silo_deck(case.run_id, "silo_flat", case, mpi_ranks, model, stages)


def estimate_recirculation_case(
    case: RecirculationCase, mpi_ranks: int = 1, model: CostModel = CostModel()
) -> RunEstimate:
    """Estimate a recirculating-silo run of the blending study: its silo's discharge is the recirculation, whose
    clumps re-enter at the top, so the count holds. A run that starts from another run's settled fill (its
    ``assembly``) neither pours nor settles: that run's estimate counts them."""
    stages = silo_stage_work(case.silo, model.settle_fraction, "recirculate")
    if case.assembly is not None:
        stages = tuple(stage for stage in stages if stage.stage not in ASSEMBLY_STAGES)
    return _estimate_silo_deck(case.run_id, "silo_recirculation", case.silo, mpi_ranks, model, stages)


def estimate_blender_case(case: BlenderCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a blender run; its silo's steps and dump interval are already scaled for the gravity factor.

    In ``continuous`` mode the discharged clumps re-enter at the top and the count holds; in ``batch`` mode the
    hopper drains at Beverloo's rate at the run's gravity (fill volume: the open cross-section below the fill
    height times the depth) once the first clumps have fallen ``sink_depth`` out of the domain.
    """
    silo, rate, delay = case.silo, 0.0, 0.0
    if case.mode == "batch":
        rate = silo_drain_rate(silo, case.fill_area * silo.depth, case.gravity)
        delay = sink_fall_time(silo.sink_depth, case.gravity)
    stages = silo_stage_work(silo, model.settle_fraction, "discharge", rate, delay)
    return _estimate_silo_deck(case.run_id, "blender", silo, mpi_ranks, model, stages)
