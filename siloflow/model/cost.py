"""What a run will cost before it starts: engine steps, sphere-steps, simulated and wall time, dump frames and disk.

Pure computation on numbers; nothing here reads or writes files. Each case kind turns its case into work with these
pieces in its own cost module (:mod:`siloflow.model.cases.silo_cost`, :mod:`siloflow.model.cases.jenike_cost`), which its registry
entry (:mod:`siloflow.model.cases.kinds`) names.

The cost model (:class:`CostModel`) is linear in the work, counted in sphere-steps: the spheres the engine holds,
summed over its time steps. A run of W sphere-steps costs ``W c`` seconds on one core, with c measured on this
machine (each engine package measures W and the CPU time from its own logs, :class:`MeasuredWork`). MPI ranks divide
that by ``ranks * efficiency^log2(ranks)``.

The sphere count of each stage follows what the case implies (:func:`siloflow.model.cases.silo_cost.silo_stage_work`,
:func:`siloflow.model.cases.jenike_cost.jenike_stage_work`):
a pour ramps it up batch by batch, a settling fill holds it, a batch silo drains at Beverloo's rate
(:func:`beverloo_clump_rate`), a silo that feeds its outflow back in keeps it, a Jenike cell loses its overfill at
levelling and gains its lid. The settling stage counts ``settle_fraction`` of its longest time.

Disk space is a worst case: binary legacy VTK particle dumps (``bytes_per_sphere_per_dump`` plus a header per file)
and text contact dumps (``contact_bytes_per_sphere_per_dump``), with the ParaView copy of a silo-type run's
particle frames (``paraview_bytes_per_sphere_per_dump``, counted whether or not ``paraview.enabled`` asks for it), every
dump at the largest sphere count the run
holds and a dumped stage at the largest number of dump frames its length allows; the analyses keep no cache of
parsed frames.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Mapping, Sequence

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
    paraview_bytes_per_sphere_per_dump : float
        Size of one sphere in the ParaView copy of one particle frame (bytes): compressed float32 VTP, measured
        37 MB beside 95 MB of particle dumps on the default silo, about 0.4 of ``bytes_per_sphere_per_dump``.
    settle_fraction : float
        Share of the longest settling time a silo fill is expected to take, in (0, 1] (-): measured 0.05 to 0.25
        here; 1 gives the worst case.
    """

    seconds_per_sphere_step: float = 5.0e-7
    bytes_per_sphere_per_dump: float = 128.0
    dump_header_bytes: float = 1024.0
    parallel_efficiency: float = 0.8
    contact_bytes_per_sphere_per_dump: float = 200.0
    paraview_bytes_per_sphere_per_dump: float = 50.0
    settle_fraction: float = 0.25
    kind_seconds_per_sphere_step: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not is_finite(self.seconds_per_sphere_step) or self.seconds_per_sphere_step <= 0:
            raise ValueError(f"seconds_per_sphere_step must be > 0 s, got {self.seconds_per_sphere_step!r}")
        for kind, value in self.kind_seconds_per_sphere_step.items():
            # which names are case kinds is the registry's (siloflow.model.cases.kinds); the configuration schema takes them
            if not isinstance(kind, str) or not kind:
                raise ValueError(f"kind_seconds_per_sphere_step: keys are case kinds' names, got {kind!r}")
            if not is_finite(value) or value <= 0:
                raise ValueError(f"kind_seconds_per_sphere_step[{kind!r}] must be > 0 s, got {value!r}")
        for name in ("bytes_per_sphere_per_dump", "dump_header_bytes",
                     "contact_bytes_per_sphere_per_dump", "paraview_bytes_per_sphere_per_dump"):
            value = getattr(self, name)
            if not is_finite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in ("parallel_efficiency", "settle_fraction"):
            value = getattr(self, name)
            if not is_finite(value) or not 0 < value <= 1:
                raise ValueError(f"{name} must lie in (0, 1], got {value!r}")

    def seconds_for(self, kind: str) -> float:
        """CPU time per sphere-step of a run of case kind ``kind`` on one core (s)."""
        return self.kind_seconds_per_sphere_step.get(kind, self.seconds_per_sphere_step)


def is_finite(value) -> bool:
    """Whether ``value`` is an int or float (not a bool) and finite."""
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
    if not is_finite(efficiency) or not 0 < efficiency <= 1:
        raise ValueError(f"parallel efficiency must lie in (0, 1], got {efficiency!r}")
    return mpi_ranks * efficiency ** math.log2(mpi_ranks)


def wall_time(serial_seconds: float, mpi_ranks: int, model: CostModel) -> float:
    """Wall time of work that takes ``serial_seconds`` on one core, run on ``mpi_ranks`` ranks (s)."""
    if not is_finite(serial_seconds) or serial_seconds < 0:
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
        Stage kind (:data:`siloflow.model.cases.stages.STAGE_KINDS`: ``fill``, ``settle``, ``discharge``, ...).
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
        if not is_finite(self.sphere_steps) or self.sphere_steps < 0:
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
            if not is_finite(value) or value < 0:
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
        The case kind (:data:`siloflow.model.cases.kinds.CASE_KINDS`).
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


def on_ranks(estimate: RunEstimate, mpi_ranks: int, model: CostModel) -> RunEstimate:
    """``estimate`` of the same run on ``mpi_ranks`` ranks: the same work at the model's speed-up
    (:func:`parallel_speedup`), so ``wall = serial / speedup(mpi_ranks)`` with ``serial`` the estimate's."""
    efficiency = model.parallel_efficiency
    serial = estimate.wall_time_s * parallel_speedup(estimate.mpi_ranks, efficiency)
    return dataclasses.replace(estimate, wall_time_s=serial / parallel_speedup(mpi_ranks, efficiency),
                               mpi_ranks=mpi_ranks)


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
    paraview_frames: int = 0,
    stages: Sequence[StageWork] | None = None,
) -> RunEstimate:
    """The estimate every case kind shares.

    spheres N = clumps * spheres_per_clump + extra_spheres (the most the run holds);
    work W = the sphere-steps of ``stages``, or N * steps without them (one stage at a constant count);
    wall time = W * seconds_per_sphere_step / (ranks * efficiency^log2(ranks));
    disk = frames (header + N bytes_per_sphere_per_dump)
    + contact_frames (header + N contact_bytes_per_sphere_per_dump)
    + paraview_frames (header + N paraview_bytes_per_sphere_per_dump).

    Parameters
    ----------
    run_id : str
        Run directory name.
    kind : str
        The case kind (:data:`siloflow.model.cases.kinds.CASE_KINDS`).
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
    paraview_frames : int
        ParaView copies of particle frames (>= 0): a silo-type run's, one per dump frame.
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
    if not isinstance(kind, str) or not kind:
        raise ValueError(f"kind must name a case kind, got {kind!r}")
    clumps = _count("clumps", clumps, 0)
    spheres_per_clump = _count("spheres_per_clump", spheres_per_clump, 1)
    steps = _count("steps", steps, 0)
    dump_frames = _count("dump_frames", dump_frames, 0)
    extra_spheres = _count("extra_spheres", extra_spheres, 0)
    contact_frames = _count("contact_frames", contact_frames, 0)
    paraview_frames = _count("paraview_frames", paraview_frames, 0)
    if not is_finite(timestep) or timestep <= 0:
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
    paraview = paraview_frames * (model.dump_header_bytes + spheres * model.paraview_bytes_per_sphere_per_dump)
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
        dump_bytes=math.ceil(particle_dumps + contacts + paraview),
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
        if not is_finite(value) or value < 0:
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
        if not is_finite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    for name, value in (("outlet_width", outlet_width), ("outlet_length", outlet_length),
                        ("particle_diameter", particle_diameter), ("gravity", gravity)):
        if not is_finite(value) or value <= 0:
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    effective = outlet_width - shape_coefficient * particle_diameter
    if effective <= 0:
        return 0.0
    return clumps_per_volume * discharge_coefficient * math.sqrt(gravity) * outlet_length * effective**1.5


