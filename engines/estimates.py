"""What a run will cost before it starts: engine steps, sphere-steps, simulated and wall time, dump frames and disk.

Pure computation: callers pass case objects (:mod:`model.cases.silo_flat`, :mod:`model.cases.silo_recirculation`,
:mod:`model.cases.blender`, :mod:`model.cases.jenike`), log text and numbers; nothing here reads or writes files.

The cost model (:class:`CostModel`) is linear in the work, counted in sphere-steps: the spheres the engine holds,
summed over its time steps. A run of W sphere-steps costs ``W c`` seconds on one core, with c measured on this
machine (each engine package measures W and the CPU time from its own logs, :class:`MeasuredWork`). MPI ranks divide
that by ``ranks * efficiency^log2(ranks)``.

The sphere count of each stage follows what the case implies (:func:`silo_stage_work`, :func:`jenike_stage_work`):
a pour ramps it up batch by batch, a settling fill holds it, a batch silo drains at Beverloo's rate
(:func:`beverloo_clump_rate`), a silo that feeds its outflow back in keeps it, a Jenike cell loses its overfill at
levelling and gains its lid. The settling stage counts ``settle_fraction`` of its longest time.

Disk space is a worst case: binary legacy VTK particle dumps (``bytes_per_sphere_per_dump`` plus a header per file)
and text contact dumps (``contact_bytes_per_sphere_per_dump``), every dump at the largest sphere count the run
holds and a dumped stage at the largest number of dump frames its length allows; the analyses keep no cache of
parsed frames.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Mapping, Sequence

from model.cases.blender import BlenderCase
from model.cases.jenike import FILL_SOLID_FRACTION, JenikeCase
from model.cases.silo_flat import SiloCase
from model.cases.silo_recirculation import RecirculationCase

#: Kinds of run this module estimates.
SILO_FLAT, RECIRCULATION, BLENDER, JENIKE = "silo_flat", "silo_recirculation", "blender", "jenike"
KINDS = (SILO_FLAT, RECIRCULATION, BLENDER, JENIKE)

#: The Jenike deck runs one step after ``delete_atoms`` so LIGGGHTS removes the partner spheres of the
#: deleted clumps (:mod:`model.cases.jenike`, stage 2).
JENIKE_LEVEL_DELETION_STEPS = 1

#: Contact snapshots the silo decks write: one local dump of the settled fill (``contacts_<step>.txt``).
SILO_CONTACT_SNAPSHOTS = 1

#: Beverloo's discharge coefficient C and empty-annulus coefficient k with which the planner drains a batch silo
#: (-): the usual values for coarse particles, as the silo analysis's defaults. Only the time the silo takes to
#: empty depends on them, and so only the work of a discharge that runs it empty.
BEVERLOO_DISCHARGE_COEFFICIENT = 0.58
BEVERLOO_SHAPE_COEFFICIENT = 1.5


@dataclass(frozen=True)
class CostModel:
    """Cost of engine work and output, per sphere.

    Attributes
    ----------
    seconds_per_sphere_step : float
        CPU time per sphere-step on one core (s): per sphere the engine holds and time step, the count taken over
        time (:class:`MeasuredWork`). Measured here: 0.35 to 0.6 microseconds.
    kind_seconds_per_sphere_step : mapping
        The same for the case kinds that differ from it (``{kind: s}``): a sphere-step of the 95 mm Jenike cell,
        with its finely facetted ring walls and lid of glued spheres, costs about twice one of a silo.
    bytes_per_sphere_per_dump : float
        Size of one sphere in one binary VTK particle dump with the 16 fields siloflow dumps (bytes).
    dump_header_bytes : float
        Fixed size per dump file: VTK header plus the small bounding-box file LIGGGHTS writes with it (bytes).
    parallel_efficiency : float
        Efficiency per doubling of the MPI ranks, in (0, 1] (-):
        wall = serial / (ranks * efficiency^log2(ranks)).
    contact_bytes_per_sphere_per_dump : float
        Size of one sphere's share of a text contact dump (bytes): measured 140 to 240 bytes on the silo's
        settled-fill snapshot and the Jenike pair and wall contact dumps. 0 leaves contact dumps out.
    settle_fraction : float
        Share of the longest settling time a silo fill is expected to take, in (0, 1] (-): measured 0.05 to 0.25
        here; 1 gives the worst case.
    """

    seconds_per_sphere_step: float = 5.0e-7
    bytes_per_sphere_per_dump: float = 128.0
    dump_header_bytes: float = 1024.0
    parallel_efficiency: float = 0.8
    contact_bytes_per_sphere_per_dump: float = 200.0
    settle_fraction: float = 0.25
    kind_seconds_per_sphere_step: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not _finite(self.seconds_per_sphere_step) or self.seconds_per_sphere_step <= 0:
            raise ValueError(f"seconds_per_sphere_step must be > 0 s, got {self.seconds_per_sphere_step!r}")
        for kind, value in self.kind_seconds_per_sphere_step.items():
            if kind not in KINDS:
                raise ValueError(f"kind_seconds_per_sphere_step: unknown run kind {kind!r}; expected one of "
                                 f"{', '.join(KINDS)}")
            if not _finite(value) or value <= 0:
                raise ValueError(f"kind_seconds_per_sphere_step[{kind!r}] must be > 0 s, got {value!r}")
        for name in ("bytes_per_sphere_per_dump", "dump_header_bytes",
                     "contact_bytes_per_sphere_per_dump"):
            value = getattr(self, name)
            if not _finite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in ("parallel_efficiency", "settle_fraction"):
            value = getattr(self, name)
            if not _finite(value) or not 0 < value <= 1:
                raise ValueError(f"{name} must lie in (0, 1], got {value!r}")

    def seconds_for(self, kind: str) -> float:
        """CPU time per sphere-step of a run of case kind ``kind`` on one core (s)."""
        return self.kind_seconds_per_sphere_step.get(kind, self.seconds_per_sphere_step)


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


# ---------------------------------------------------------------------------------------------- time


def parallel_speedup(mpi_ranks: int, efficiency: float) -> float:
    """Speed-up over one core, ``ranks * efficiency^log2(ranks)`` (-).

    Parameters
    ----------
    mpi_ranks : int
        MPI ranks (>= 1).
    efficiency : float
        Efficiency per doubling of the ranks, in (0, 1] (-).
    """
    if isinstance(mpi_ranks, bool) or not isinstance(mpi_ranks, int) or mpi_ranks < 1:
        raise ValueError(f"mpi_ranks must be an integer >= 1, got {mpi_ranks!r}")
    if not _finite(efficiency) or not 0 < efficiency <= 1:
        raise ValueError(f"parallel efficiency must lie in (0, 1], got {efficiency!r}")
    return mpi_ranks * efficiency ** math.log2(mpi_ranks)


def wall_time(serial_seconds: float, mpi_ranks: int, model: CostModel) -> float:
    """Wall time of work that takes ``serial_seconds`` on one core, run on ``mpi_ranks`` ranks (s)."""
    if not _finite(serial_seconds) or serial_seconds < 0:
        raise ValueError(f"serial time must be a finite number >= 0 s, got {serial_seconds!r}")
    return serial_seconds / parallel_speedup(mpi_ranks, model.parallel_efficiency)


def dump_frames(stage_steps: int, dump_every: int) -> int:
    """Largest number of particle dumps of a dumped stage, ``1 + ceil(steps / every)``.

    A dump with ``first yes`` writes at the start of the stage and then at every step that is a multiple of
    ``dump_every``; a stage of S steps holds at most ceil(S / every) such multiples (exactly S / every when
    the stage starts on one).
    """
    for name, value in (("stage_steps", stage_steps), ("dump_every", dump_every)):
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f"{name} must be an integer, got {value!r}")
    if stage_steps < 0 or dump_every < 1:
        raise ValueError(f"need stage_steps >= 0 and dump_every >= 1, got {stage_steps}, {dump_every}")
    return 1 + -(-stage_steps // dump_every)


# ---------------------------------------------------------------------------------------------- work


@dataclass(frozen=True)
class StageWork:
    """The engine work one stage of a run is expected to take.

    Attributes
    ----------
    stage : str
        Stage kind (:data:`model.cases.stages.STAGE_KINDS`: ``fill``, ``settle``, ``discharge``, ...).
    steps : int
        Time steps of the stage (-).
    sphere_steps : float
        Spheres the engine holds, summed over the stage's steps (sphere-steps).
    """

    stage: str
    steps: int
    sphere_steps: float

    def __post_init__(self) -> None:
        _count("steps", self.steps, 0)
        if not _finite(self.sphere_steps) or self.sphere_steps < 0:
            raise ValueError(f"sphere_steps must be a finite number >= 0, got {self.sphere_steps!r}")

    @property
    def mean_spheres(self) -> float:
        """Spheres held on average over the stage (-); 0 for a stage without steps."""
        return self.sphere_steps / self.steps if self.steps else 0.0


@dataclass(frozen=True)
class MeasuredWork:
    """What a finished run took, as its engine timed it.

    Attributes
    ----------
    cpu_seconds : float
        CPU time of the engine's time stepping, summed over its processes and attempts (CPU s).
    sphere_steps : float
        Spheres the engine held, summed over the steps it timed (sphere-steps): the count over time, not at the end.
    """

    cpu_seconds: float
    sphere_steps: float

    def __post_init__(self) -> None:
        for name in ("cpu_seconds", "sphere_steps"):
            value = getattr(self, name)
            if not _finite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")

    @property
    def seconds_per_sphere_step(self) -> float:
        """CPU time per sphere-step (s); nan without sphere-steps."""
        return self.cpu_seconds / self.sphere_steps if self.sphere_steps > 0 else math.nan


# ---------------------------------------------------------------------------------------------- estimates


@dataclass(frozen=True)
class RunEstimate:
    """What one run costs: its work stage by stage, and the disk space of its dumps at most.

    Attributes
    ----------
    run_id : str
        Run directory name.
    kind : str
        One of :data:`KINDS`.
    clumps : int
        Clumps the run holds at most.
    spheres : int
        Spheres (atoms) the run holds at most: clump spheres plus other atoms such as lid spheres (-).
    steps : int
        Engine time steps in total, settling at the model's share of its longest time (-).
    sphere_steps : float
        Spheres held, summed over the steps: the sum over :attr:`stages` (sphere-steps).
    simulated_time_s : float
        ``steps * timestep`` (s).
    wall_time_s : float
        Wall time on ``mpi_ranks`` ranks (s).
    dump_frames : int
        Particle dump files at most.
    dump_bytes : int
        Disk space of particle dumps and contact dumps (bytes).
    mpi_ranks : int
        MPI ranks the estimate assumes.
    stages : tuple of StageWork
        Steps and sphere-steps of each stage that runs steps, in order.
    """

    run_id: str
    kind: str
    clumps: int
    spheres: int
    steps: int
    sphere_steps: float
    simulated_time_s: float
    wall_time_s: float
    dump_frames: int
    dump_bytes: int
    mpi_ranks: int
    stages: tuple[StageWork, ...] = ()

    @property
    def core_seconds(self) -> float:
        """CPU time over all ranks, ``wall_time_s * mpi_ranks`` (CPU s): what the engine's own timing adds up to."""
        return self.wall_time_s * self.mpi_ranks


def _count(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return value


def estimate_run(
    run_id: str,
    kind: str,
    clumps: int,
    spheres_per_clump: int,
    steps: int,
    timestep: float,
    dump_frames: int,
    mpi_ranks: int = 1,
    model: CostModel = CostModel(),
    *,
    extra_spheres: int = 0,
    contact_frames: int = 0,
    stages: Sequence[StageWork] | None = None,
) -> RunEstimate:
    """The estimate every case kind shares.

    spheres N = clumps * spheres_per_clump + extra_spheres (the most the run holds);
    work W = the sphere-steps of ``stages``, or N * steps without them (one stage at a constant count);
    wall time = W * seconds_per_sphere_step / (ranks * efficiency^log2(ranks));
    disk = frames (header + N bytes_per_sphere_per_dump)
    + contact_frames (header + N contact_bytes_per_sphere_per_dump).

    Parameters
    ----------
    run_id : str
        Run directory name.
    kind : str
        One of :data:`KINDS`.
    clumps : int
        Clumps in the run (>= 0).
    spheres_per_clump : int
        Spheres per clump (>= 1).
    steps : int
        Engine time steps in total (>= 0).
    timestep : float
        Time step (s, > 0).
    dump_frames : int
        Particle dump files (>= 0).
    mpi_ranks : int
        MPI ranks (>= 1).
    model : CostModel
        Costs per sphere.
    extra_spheres : int
        Atoms that belong to no clump (a lid of glued spheres, a servo proxy) (>= 0).
    contact_frames : int
        Text contact dump files (>= 0).
    stages : sequence of StageWork, optional
        The work of each stage; their steps must add up to ``steps``.

    Returns
    -------
    RunEstimate

    Raises
    ------
    ValueError
        Naming a value out of range, or when the stages' steps do not add up to ``steps``.
    """
    if kind not in KINDS:
        raise ValueError(f"unknown run kind {kind!r}; expected one of {', '.join(KINDS)}")
    clumps = _count("clumps", clumps, 0)
    spheres_per_clump = _count("spheres_per_clump", spheres_per_clump, 1)
    steps = _count("steps", steps, 0)
    dump_frames = _count("dump_frames", dump_frames, 0)
    extra_spheres = _count("extra_spheres", extra_spheres, 0)
    contact_frames = _count("contact_frames", contact_frames, 0)
    if not _finite(timestep) or timestep <= 0:
        raise ValueError(f"timestep must be > 0 s, got {timestep!r}")
    spheres = clumps * spheres_per_clump + extra_spheres
    if stages is None:
        stages = (StageWork("run", steps, float(spheres * steps)),)
    stages = tuple(stages)
    if sum(stage.steps for stage in stages) != steps:
        raise ValueError(f"the stages' steps add up to {sum(stage.steps for stage in stages)}, not to steps = {steps}")
    work = math.fsum(stage.sphere_steps for stage in stages)
    serial = work * model.seconds_for(kind)
    particle_dumps = dump_frames * (model.dump_header_bytes + spheres * model.bytes_per_sphere_per_dump)
    contacts = contact_frames * (model.dump_header_bytes + spheres * model.contact_bytes_per_sphere_per_dump)
    return RunEstimate(
        run_id=run_id,
        kind=kind,
        clumps=clumps,
        spheres=spheres,
        steps=steps,
        sphere_steps=work,
        simulated_time_s=steps * timestep,
        wall_time_s=wall_time(serial, mpi_ranks, model),
        dump_frames=dump_frames,
        dump_bytes=math.ceil(particle_dumps + contacts),
        mpi_ranks=mpi_ranks,
        stages=stages,
    )


def pour_sphere_steps(n_clumps: int, clumps_per_insertion: int, insert_every: int, steps: int) -> float:
    """Clumps held over a pour in batches, summed over its steps (clump-steps).

    An insertion at the start of every interval of ``insert_every`` steps adds ``clumps_per_insertion`` clumps
    (the last batch what is left) until all ``n_clumps`` are in; the count then holds for the rest of the stage:
    ``insert_every * sum_k min(N, k b) + N (steps - I insert_every)`` over the I = ceil(N / b) insertions that
    start inside the stage (a last interval cut by the end of the stage counts its steps inside).

    Parameters
    ----------
    n_clumps : int
        Clumps poured, N (>= 0).
    clumps_per_insertion : int
        Clumps per insertion event, b (>= 1).
    insert_every : int
        Steps between insertion events (>= 1).
    steps : int
        Steps of the stage (>= 0).

    Returns
    -------
    float
        Clump-steps (multiply by the spheres per clump for sphere-steps).
    """
    n, b = _count("n_clumps", n_clumps, 0), _count("clumps_per_insertion", clumps_per_insertion, 1)
    every, steps = _count("insert_every", insert_every, 1), _count("steps", steps, 0)
    insertions = -(-n // b)
    whole = min(insertions, steps // every)  # intervals that start and end inside the stage
    if whole < insertions:  # all but the last batch are full: k b < N for k < insertions
        held = b * whole * (whole + 1) // 2 * every
        if steps > whole * every:  # the interval cut by the end of the stage
            held += min(n, (whole + 1) * b) * (steps - whole * every)
        return float(held)
    return float((b * (insertions - 1) * insertions // 2 + n) * every + n * (steps - insertions * every))


def drain_sphere_steps(spheres: float, rate: float, delay_steps: float, steps: int) -> float:
    """Spheres held over a discharge that drains at a constant rate, summed over its steps (sphere-steps).

    The count stays at N for ``delay_steps`` (the first spheres out are still inside the domain), then falls by
    ``rate`` per step until the silo is empty: the integral of ``N - rate max(0, t - delay)``, floored at 0, over
    ``steps``. A rate of 0 keeps the count (a silo that feeds its outflow back in).

    Parameters
    ----------
    spheres : float
        Spheres at the start of the discharge, N (>= 0).
    rate : float
        Spheres leaving per step once the flow has reached the edge of the domain (>= 0).
    delay_steps : float
        Steps before the first spheres leave the domain (>= 0).
    steps : int
        Steps of the stage (>= 0).

    Returns
    -------
    float
        Sphere-steps.
    """
    for name, value in (("spheres", spheres), ("rate", rate), ("delay_steps", delay_steps)):
        if not _finite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    steps = _count("steps", steps, 0)
    held = min(float(steps), delay_steps)
    draining = steps - held
    if rate == 0.0 or draining <= spheres / rate:
        return spheres * steps - 0.5 * rate * draining**2
    return spheres * held + 0.5 * spheres * spheres / rate


def beverloo_clump_rate(
    clumps_per_volume: float,
    outlet_width: float,
    outlet_length: float,
    particle_diameter: float,
    gravity: float,
    discharge_coefficient: float = BEVERLOO_DISCHARGE_COEFFICIENT,
    shape_coefficient: float = BEVERLOO_SHAPE_COEFFICIENT,
) -> float:
    """Clumps per second through a slot outlet by Beverloo's law, ``n C sqrt(g) L (B0 - k d)^1.5``.

    Beverloo's mass flow rate ``C rho_b sqrt(g) L (B0 - k d)^1.5`` over the clump mass, with ``rho_b / m`` the
    clumps per volume of the fill.

    Parameters
    ----------
    clumps_per_volume : float
        Clumps per unit volume of the fill, n (1/m^3, >= 0).
    outlet_width : float
        Slot width B0 (m, > 0).
    outlet_length : float
        Slot length L (m, > 0): the silo depth.
    particle_diameter : float
        Particle diameter d (m, > 0): the clump's volume-equivalent diameter.
    gravity : float
        Gravitational acceleration g (m/s^2, > 0).
    discharge_coefficient, shape_coefficient : float
        Beverloo's C and k (-).

    Returns
    -------
    float
        Clumps per second (1/s); 0 when the outlet is no wider than ``k d`` (Beverloo predicts no flow).
    """
    for name, value in (("clumps_per_volume", clumps_per_volume), ("discharge_coefficient", discharge_coefficient),
                        ("shape_coefficient", shape_coefficient)):
        if not _finite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    for name, value in (("outlet_width", outlet_width), ("outlet_length", outlet_length),
                        ("particle_diameter", particle_diameter), ("gravity", gravity)):
        if not _finite(value) or value <= 0:
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    effective = outlet_width - shape_coefficient * particle_diameter
    if effective <= 0:
        return 0.0
    return clumps_per_volume * discharge_coefficient * math.sqrt(gravity) * outlet_length * effective**1.5


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
    if not _finite(sink_depth) or sink_depth < 0 or not _finite(gravity) or gravity <= 0:
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
    if not _finite(fill_volume) or fill_volume <= 0:
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
        stages=stages,
    )


def estimate_silo_case(case: SiloCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a flat-bottom silo run (:class:`model.cases.silo_flat.SiloCase`).

    The discharge drains the fill at Beverloo's rate (:func:`silo_drain_rate`, fill volume W T H) once the first
    clumps have fallen ``sink_depth`` out of the domain (:func:`sink_fall_time`); the stagnant zones a flat floor
    keeps are left out (a few per cent of the discharge's work, when the silo runs empty at all).
    """
    gravity = case.gravity
    rate = silo_drain_rate(case, case.width * case.depth * case.fill_height, gravity)
    stages = silo_stage_work(case, model.settle_fraction, "discharge", rate, sink_fall_time(case.sink_depth, gravity))
    return _estimate_silo_deck(case.run_id, SILO_FLAT, case, mpi_ranks, model, stages)


def estimate_recirculation_case(
    case: RecirculationCase, mpi_ranks: int = 1, model: CostModel = CostModel()
) -> RunEstimate:
    """Estimate a recirculating-silo run of the blending study: its silo's discharge is the recirculation, whose
    clumps re-enter at the top, so the count holds."""
    stages = silo_stage_work(case.silo, model.settle_fraction, "recirculate")
    return _estimate_silo_deck(case.run_id, RECIRCULATION, case.silo, mpi_ranks, model, stages)


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
    return _estimate_silo_deck(case.run_id, BLENDER, silo, mpi_ranks, model, stages)


def jenike_run_steps(case: JenikeCase) -> int:
    """Steps of a Jenike deck: fill + one deletion step + relaxation + load ramp + hold + shear."""
    return (
        case.fill.steps + JENIKE_LEVEL_DELETION_STEPS + case.fill.relax_steps
        + case.ramp_steps + case.hold_steps + case.shear_steps
    )


def jenike_lid_atoms(case: JenikeCase) -> int:
    """Atoms of the lid: the glued spheres of a rigid lid, or the proxy atoms of a servo lid."""
    if case.rigid_lid is not None:
        return case.rigid_lid.n_spheres
    if case.servo_lid is not None:
        return len(case.servo_lid.proxy_positions)
    return 0


def jenike_levelled_clumps(case: JenikeCase) -> int:
    """Clumps left after levelling: those the sample volume holds at the solid fraction the pour was sized with,
    ``round(phi A H / V_clump)`` (:data:`model.cases.jenike.FILL_SOLID_FRACTION`), at most the clumps created."""
    geometry = case.geometry
    kept = int(round(FILL_SOLID_FRACTION * geometry.area * geometry.sample_height / case.particle.volume))
    return min(case.fill.n_clumps, kept)


def jenike_stage_work(case: JenikeCase) -> tuple[StageWork, ...]:
    """Steps and sphere-steps of the stages of a Jenike deck.

    - fill: all clumps created at once, held for the fall and settling;
    - settle: the deletion step still at that count (the engine removes the spheres of the deleted clumps in
      it), then the relaxation at the levelled count (:func:`jenike_levelled_clumps`);
    - consolidate (load ramp and hold) and shear: the levelled clumps plus the lid's atoms, placed after levelling.
    """
    spheres = case.particle.n_spheres
    created = spheres * case.fill.n_clumps
    levelled = spheres * jenike_levelled_clumps(case)
    loaded = levelled + jenike_lid_atoms(case)
    relax = case.fill.relax_steps
    consolidation = case.ramp_steps + case.hold_steps
    return (
        StageWork("fill", case.fill.steps, float(created * case.fill.steps)),
        StageWork("settle", JENIKE_LEVEL_DELETION_STEPS + relax,
                  float(created * JENIKE_LEVEL_DELETION_STEPS + levelled * relax)),
        StageWork("consolidate", consolidation, float(loaded * consolidation)),
        StageWork("shear", case.shear_steps, float(loaded * case.shear_steps)),
    )


def estimate_jenike_case(case: JenikeCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a Jenike shear-cell run: work stage by stage (:func:`jenike_stage_work`).

    Disk (upper bounds): every dump counts the clumps created (``fill.n_clumps``) and the lid's atoms
    (:func:`jenike_lid_atoms`), although levelling deletes the overfill first; particle dumps over consolidation
    and shear (:func:`dump_frames` of ramp + hold + shear at ``dump_every``), and as many pair-and-wall contact
    dumps (the deck writes one fewer); the calibration analysis keeps no parsed-frame cache.
    """
    dumped_steps = case.ramp_steps + case.hold_steps + case.shear_steps
    frames = dump_frames(dumped_steps, case.dump_every)
    stages = jenike_stage_work(case)
    return estimate_run(
        case.run_id,
        JENIKE,
        clumps=case.fill.n_clumps,
        spheres_per_clump=case.particle.n_spheres,
        steps=jenike_run_steps(case),
        timestep=case.timestep,
        dump_frames=frames,
        mpi_ranks=mpi_ranks,
        model=model,
        extra_spheres=jenike_lid_atoms(case),
        contact_frames=frames,
        stages=stages,
    )


# ---------------------------------------------------------------------------------------------- disk and output


class InsufficientDiskSpace(RuntimeError):
    """The runs would need more disk space than is free."""


def check_disk_space(required_bytes: float, free_bytes: float, where: str, what: str) -> float:
    """Refuse runs whose dumps would not fit on the disk.

    Parameters
    ----------
    required_bytes : float
        Estimated disk space of the runs (bytes, >= 0).
    free_bytes : float
        Free space on the disk that holds the results (bytes, >= 0).
    where : str
        The disk or folder, for the message.
    what : str
        Which runs, for the message (e.g. ``"of the blender study"``).

    Returns
    -------
    float
        The margin, ``free_bytes - required_bytes`` (bytes, >= 0).

    Raises
    ------
    InsufficientDiskSpace
        When ``required_bytes > free_bytes``; the message names both sizes.
    """
    for name, value in (("required_bytes", required_bytes), ("free_bytes", free_bytes)):
        if not _finite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    if required_bytes > free_bytes:
        raise InsufficientDiskSpace(
            f"the runs {what} need about {format_bytes(required_bytes)} for dumps but only "
            f"{format_bytes(free_bytes)} are free on {where}; free space, move results/ to a larger disk, "
            "or raise dump intervals"
        )
    return free_bytes - required_bytes


def _scaled(value: float, units: tuple[tuple[str, float], ...], digits: int) -> str:
    """``value`` in the largest unit it reaches, ``digits`` significant digits; a value that rounds up to the
    next unit's size is written in that unit."""
    index = 0
    while index + 1 < len(units) and value >= units[index + 1][1]:
        index += 1
    while True:
        name, size = units[index]
        scaled = value / size
        text = f"{scaled:.{digits}g}"
        if "e+" in text:  # a value of 10**digits or more: all its integer digits
            text = f"{float(text):.0f}"
        if index + 1 < len(units) and float(text) * size >= units[index + 1][1]:
            index += 1
            continue
        return f"{text} {name}"


_BYTE_UNITS = (("B", 1.0), ("kB", 1e3), ("MB", 1e6), ("GB", 1e9), ("TB", 1e12))
_TIME_UNITS = (("s", 1.0), ("min", 60.0), ("h", 3600.0), ("d", 86400.0))


def format_bytes(size: float, digits: int = 3) -> str:
    """A size in B, kB, MB, GB or TB (powers of 1000) with ``digits`` significant digits: ``12.3 GB``."""
    if not _finite(size) or size < 0:
        raise ValueError(f"size must be a finite number >= 0 bytes, got {size!r}")
    if size < 1000:
        return f"{size:.0f} B"
    return _scaled(float(size), _BYTE_UNITS, digits)


def format_duration(seconds: float, digits: int = 2) -> str:
    """A duration in s, min, h or d with ``digits`` significant digits: ``5.6 min``."""
    if not _finite(seconds) or seconds < 0:
        raise ValueError(f"duration must be a finite number >= 0 s, got {seconds!r}")
    return _scaled(float(seconds), _TIME_UNITS, digits)


#: Columns of :func:`estimate_rows`, in order.
ESTIMATE_COLUMNS = (
    "run", "kind", "mpi_ranks", "clumps", "spheres", "steps", "sphere_steps", "simulated_s", "wall_time", "core_time",
    "dump_frames", "disk",
)


def estimate_rows(estimates: Iterable[RunEstimate]) -> list[dict]:
    """Rows of the table ``make estimate`` prints: one per run, then a totals row.

    Columns (:data:`ESTIMATE_COLUMNS`): run, kind, mpi_ranks, clumps, spheres (the most the run holds), steps,
    sphere_steps (the work, sphere-steps), simulated_s (s), wall_time (formatted), core_time (wall time times MPI
    ranks, formatted: what a cluster account is charged), dump_frames, disk (formatted dumps). The totals row sums
    sphere-steps, wall time (the runs one after another), core time, dump frames and disk; its other cells are
    empty.
    """
    estimates = list(estimates)
    rows = [
        {
            "run": estimate.run_id,
            "kind": estimate.kind,
            "mpi_ranks": estimate.mpi_ranks,
            "clumps": estimate.clumps,
            "spheres": estimate.spheres,
            "steps": estimate.steps,
            "sphere_steps": estimate.sphere_steps,
            "simulated_s": estimate.simulated_time_s,
            "wall_time": format_duration(estimate.wall_time_s),
            "core_time": format_duration(estimate.core_seconds),
            "dump_frames": estimate.dump_frames,
            "disk": format_bytes(estimate.dump_bytes),
        }
        for estimate in estimates
    ]
    totals = dict.fromkeys(ESTIMATE_COLUMNS, "")
    totals.update(
        run=f"total ({len(estimates)} run{'s' if len(estimates) != 1 else ''})",
        sphere_steps=math.fsum(e.sphere_steps for e in estimates),
        wall_time=format_duration(sum(e.wall_time_s for e in estimates)),
        core_time=format_duration(sum(e.core_seconds for e in estimates)),
        dump_frames=sum(e.dump_frames for e in estimates),
        disk=format_bytes(sum(e.dump_bytes for e in estimates)),
    )
    rows.append(totals)
    return rows


def total_dump_bytes(estimates: Iterable[RunEstimate]) -> int:
    """Disk space of all the runs' dumps (bytes), for :func:`check_disk_space`."""
    return sum(estimate.dump_bytes for estimate in estimates)


def estimate_case(case, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a run of any case kind (dispatch on the case's type)."""
    for case_type, estimate in ((SiloCase, estimate_silo_case), (RecirculationCase, estimate_recirculation_case),
                                (BlenderCase, estimate_blender_case), (JenikeCase, estimate_jenike_case)):
        if isinstance(case, case_type):
            return estimate(case, mpi_ranks, model)
    raise TypeError(f"no estimate for a {type(case).__name__}")
