"""What a run will cost before it starts: engine steps, simulated and wall time, dump frames and disk space.

Pure computation: callers pass case objects (:mod:`engines.cases.silo_flat`, :mod:`engines.cases.silo_recirculation`,
:mod:`engines.cases.blender`, :mod:`engines.cases.jenike`), log text and numbers; nothing here reads or writes files.

The cost model (:class:`CostModel`) is linear in the work: a run of S steps over N spheres costs
``N S c`` seconds on one core, with c measured on this machine (each engine package can fit it to the timing
lines of its own logs). MPI ranks divide that by ``ranks * efficiency^log2(ranks)``.
Every estimate is a worst case: the settling stage counts all its checks, the sphere count is the largest the
run holds, and a dumped stage counts the largest number of dump frames its length allows.

Disk space: binary legacy VTK particle dumps (``bytes_per_sphere_per_dump`` plus a header per file) and text
contact dumps (``contact_bytes_per_sphere_per_dump``); the analyses keep no cache of parsed frames.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

from engines.cases.blender import BlenderCase
from engines.cases.jenike import JenikeCase
from engines.cases.silo_flat import SiloCase
from engines.cases.silo_recirculation import RecirculationCase

#: Kinds of run this module estimates.
SILO_FLAT, RECIRCULATION, BLENDER, JENIKE = "silo_flat", "silo_recirculation", "blender", "jenike"
KINDS = (SILO_FLAT, RECIRCULATION, BLENDER, JENIKE)

#: The Jenike deck runs one step after ``delete_atoms`` so LIGGGHTS removes the partner spheres of the
#: deleted clumps (:mod:`engines.cases.jenike`, stage 2).
JENIKE_LEVEL_DELETION_STEPS = 1

#: Contact snapshots the silo decks write: one local dump of the settled fill (``contacts_<step>.txt``).
SILO_CONTACT_SNAPSHOTS = 1


@dataclass(frozen=True)
class CostModel:
    """Cost of engine work and output, per sphere.

    Attributes
    ----------
    seconds_per_sphere_step : float
        CPU time per sphere and time step on one core (s). Measured here: 0.35 to 0.6 microseconds.
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

    def __post_init__(self) -> None:
        if not _finite(self.seconds_per_sphere_step) or self.seconds_per_sphere_step <= 0:
            raise ValueError(f"seconds_per_sphere_step must be > 0 s, got {self.seconds_per_sphere_step!r}")
        for name in ("bytes_per_sphere_per_dump", "dump_header_bytes",
                     "contact_bytes_per_sphere_per_dump"):
            value = getattr(self, name)
            if not _finite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in ("parallel_efficiency", "settle_fraction"):
            value = getattr(self, name)
            if not _finite(value) or not 0 < value <= 1:
                raise ValueError(f"{name} must lie in (0, 1], got {value!r}")


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


# ---------------------------------------------------------------------------------------------- estimates


@dataclass(frozen=True)
class RunEstimate:
    """What one run costs, worst case.

    Attributes
    ----------
    run_id : str
        Run directory name.
    kind : str
        One of :data:`KINDS`.
    clumps : int
        Clumps the run holds at most.
    spheres : int
        Spheres (atoms) the run holds at most: clump spheres plus other atoms such as lid spheres.
    steps : int
        Engine time steps in total, every stage at its longest.
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
    """

    run_id: str
    kind: str
    clumps: int
    spheres: int
    steps: int
    simulated_time_s: float
    wall_time_s: float
    dump_frames: int
    dump_bytes: int
    mpi_ranks: int


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
) -> RunEstimate:
    """The estimate every case kind shares.

    spheres N = clumps * spheres_per_clump + extra_spheres;
    wall time = N * steps * seconds_per_sphere_step / (ranks * efficiency^log2(ranks));
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

    Returns
    -------
    RunEstimate
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
    serial = spheres * steps * model.seconds_per_sphere_step
    particle_dumps = dump_frames * (model.dump_header_bytes + spheres * model.bytes_per_sphere_per_dump)
    contacts = contact_frames * (model.dump_header_bytes + spheres * model.contact_bytes_per_sphere_per_dump)
    return RunEstimate(
        run_id=run_id,
        kind=kind,
        clumps=clumps,
        spheres=spheres,
        steps=steps,
        simulated_time_s=steps * timestep,
        wall_time_s=wall_time(serial, mpi_ranks, model),
        dump_frames=dump_frames,
        dump_bytes=math.ceil(particle_dumps + contacts),
        mpi_ranks=mpi_ranks,
    )


def silo_run_steps(silo: SiloCase, settle_fraction: float = 1.0) -> int:
    """Steps of a silo deck: fill + settling + discharge, settling counted as ``settle_fraction`` of its longest
    time (``settle_max_checks * settle_check_steps``; 1 is the worst case), in whole checks.

    The extra insertion events the deck allows when crowded insertions place fewer clumps than asked are not
    counted (they run only then, ``insert_every`` steps each).
    """
    checks = max(1, math.ceil(settle_fraction * silo.settle_max_checks - 1e-9))
    return silo.fill.fill_steps + checks * silo.settle_check_steps + silo.discharge_steps


def _estimate_silo_deck(
    run_id: str, kind: str, silo: SiloCase, mpi_ranks: int, model: CostModel
) -> RunEstimate:
    """Silo, recirculating silo and blender decks: fill, settle, open, then the dumped last stage."""
    return estimate_run(
        run_id,
        kind,
        clumps=silo.fill.n_clumps,
        spheres_per_clump=silo.spheres_per_clump,
        steps=silo_run_steps(silo, model.settle_fraction),
        timestep=silo.timestep,
        dump_frames=dump_frames(silo.discharge_steps, silo.dump_every),
        mpi_ranks=mpi_ranks,
        model=model,
        contact_frames=SILO_CONTACT_SNAPSHOTS,
    )


def estimate_silo_case(case: SiloCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a flat-bottom silo run (:class:`engines.cases.silo_flat.SiloCase`).

    All clumps are counted over the whole run, also while the silo drains (worst case).
    """
    return _estimate_silo_deck(case.run_id, SILO_FLAT, case, mpi_ranks, model)


def estimate_recirculation_case(
    case: RecirculationCase, mpi_ranks: int = 1, model: CostModel = CostModel()
) -> RunEstimate:
    """Estimate a recirculating-silo run of the blending study (its silo's discharge is the recirculation)."""
    return _estimate_silo_deck(case.run_id, RECIRCULATION, case.silo, mpi_ranks, model)


def estimate_blender_case(case: BlenderCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a blender run; its silo's steps and dump interval are already scaled for the gravity factor."""
    return _estimate_silo_deck(case.run_id, BLENDER, case.silo, mpi_ranks, model)


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


def estimate_jenike_case(case: JenikeCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a Jenike shear-cell run.

    Approximations (all upper bounds):

    - clumps: the clumps created (``fill.n_clumps``) for every stage; levelling deletes the overfill,
      about overfill / (1 + overfill) of them, before consolidation and shear;
    - spheres: their spheres plus the lid's atoms (:func:`jenike_lid_atoms`) for every stage, although the lid
      is placed only after levelling;
    - dumps: particle dumps over consolidation and shear (:func:`dump_frames` of ramp + hold + shear at
      ``dump_every``), and as many pair-and-wall contact dumps (the deck writes one fewer); the calibration
      analysis keeps no parsed-frame cache.
    """
    dumped_steps = case.ramp_steps + case.hold_steps + case.shear_steps
    frames = dump_frames(dumped_steps, case.dump_every)
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
    "run", "kind", "mpi_ranks", "clumps", "spheres", "steps", "simulated_s", "wall_time", "core_time", "dump_frames",
    "disk",
)


def estimate_rows(estimates: Iterable[RunEstimate]) -> list[dict]:
    """Rows of the table ``make estimate`` prints: one per run, then a totals row.

    Columns (:data:`ESTIMATE_COLUMNS`): run, kind, mpi_ranks, clumps, spheres, steps, simulated_s (s),
    wall_time (formatted), core_time (wall time times MPI ranks, formatted: what a cluster account is charged),
    dump_frames, disk (formatted dumps). The totals row sums wall time (the runs one after another), core time,
    dump frames and disk; its other cells are empty.
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
            "simulated_s": estimate.simulated_time_s,
            "wall_time": format_duration(estimate.wall_time_s),
            "core_time": format_duration(estimate.wall_time_s * estimate.mpi_ranks),
            "dump_frames": estimate.dump_frames,
            "disk": format_bytes(estimate.dump_bytes),
        }
        for estimate in estimates
    ]
    totals = dict.fromkeys(ESTIMATE_COLUMNS, "")
    totals.update(
        run=f"total ({len(estimates)} run{'s' if len(estimates) != 1 else ''})",
        wall_time=format_duration(sum(e.wall_time_s for e in estimates)),
        core_time=format_duration(sum(e.wall_time_s * e.mpi_ranks for e in estimates)),
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
