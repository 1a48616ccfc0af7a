"""The validation tier in groups: which runs each group makes, what it costs on the cores at hand, and whether the
record in the repository still matches what the configuration plans.

`make validate GROUP=<name>` runs one group (`make validate` all of them); `make estimate` prints each group's cost;
`make validate-status` says which groups of the record are complete, stale or missing. Pure computation: callers
pass estimates and run ids; the record's files are read at the edge (:mod:`analysis.studies.validation.record`).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

from engines.cases import REFERENCE, VARIANT
from engines.cases.jenike_sweep import CALIBRATION_CHART, CHECK, SHAPE_CHART
from engines.estimates import BLENDER, JENIKE, RECIRCULATION, SILO_FLAT, RunEstimate

@dataclass(frozen=True)
class Group:
    """One validation group: the runs it makes and the groups whose runs its rows also draw on.

    Attributes
    ----------
    kind : str
        The case kind whose runs it makes.
    roles : tuple of str, optional
        The roles of that kind's runs it makes (:func:`engines.cases.run_roles`); None: all of them.
    reads : tuple of str
        Groups (earlier in :data:`GROUPS`) whose runs its rows compare against.
    """

    kind: str
    roles: tuple[str, ...] | None = None
    reads: tuple[str, ...] = ()

    def makes(self, kind: str, role: str) -> bool:
        """Whether this group makes a run of ``kind`` with ``role``."""
        return kind == self.kind and (self.roles is None or role in self.roles)


#: The groups in the order `make validate` runs them, each one stage of the study, so that its rows can be judged on
#: its own runs and those it reads (`make estimate` flags a group over :data:`GROUP_BUDGET_S`): the calibration in three (the calibration shape's charts,
#: the other shapes' charts, and the checks against the charts: rotation blocked, the other lid, restitution, shear
#: speed, seeds), the flat-bottom silo in two (its base configuration over seeds, and the front-wall friction series
#: compared against it).
GROUPS: dict[str, Group] = {
    "calibration": Group(JENIKE, (CALIBRATION_CHART,)),
    "calibration_shapes": Group(JENIKE, (SHAPE_CHART,)),
    "calibration_checks": Group(JENIKE, (CHECK,), reads=("calibration", "calibration_shapes")),
    "silo": Group(SILO_FLAT, (REFERENCE,)),
    "silo_series": Group(SILO_FLAT, (VARIANT,), reads=("silo",)),
    "blending": Group(RECIRCULATION),
    "blender": Group(BLENDER),
}

#: The longest a group may take on the cores of one machine (s): a working session.
GROUP_BUDGET_S = 2.5 * 3600.0

#: A group's status against the record (:func:`group_status`).
COMPLETE, STALE, MISSING = "complete", "stale", "missing"


def group_of(kind: str, role: str) -> str:
    """The group that makes a run of case kind ``kind`` with ``role`` (:func:`engines.cases.run_roles`)."""
    for name, group in GROUPS.items():
        if group.makes(kind, role):
            return name
    raise KeyError(f"no validation group makes {role!r} runs of kind {kind!r}; the groups are {', '.join(GROUPS)}")


def assign(estimates: Sequence[RunEstimate], roles: Mapping[str, str]) -> dict[str, list[RunEstimate]]:
    """The runs each group makes: ``{group: [estimate]}`` in :data:`GROUPS` order.

    Parameters
    ----------
    estimates : sequence of RunEstimate
        A configuration's run estimates (:func:`engines.planning.config_estimates`).
    roles : mapping
        ``{run id: role}`` of every run (:func:`engines.cases.run_roles`).
    """
    made: dict[str, list[RunEstimate]] = {name: [] for name in GROUPS}
    for estimate in estimates:
        made[group_of(estimate.kind, roles[estimate.run_id])].append(estimate)
    return made


def check_group(name: str) -> str:
    """``name`` when it is a group; otherwise a ValueError that lists the groups."""
    if name not in GROUPS:
        raise ValueError(f"unknown validation group {name!r}; the groups are {', '.join(GROUPS)}")
    return name


def check_reads(name: str, status: Mapping[str, str]) -> None:
    """Refuse (ValueError) to run group ``name`` before the groups it reads are complete in the record (``status``
    of :func:`group_status`): Snakemake would make their runs too, past the group's budget."""
    waiting = [other for other in GROUPS[name].reads if status.get(other, COMPLETE) != COMPLETE]
    if waiting:
        raise ValueError(f"validation group {name!r} compares against the runs of {', '.join(waiting)}, whose record is "
                         f"{' and '.join(status[other] for other in waiting)}: run "
                         f"{' then '.join(f'make validate GROUP={other}' for other in waiting)} first")


def makespan(core_seconds: Iterable[float], cores: int) -> float:
    """Wall time of independent single-core jobs on ``cores`` cores, the longest started first (s).

    Snakemake starts the longest runs first (:func:`engines.planning.run_priorities`); each job goes to the core
    that frees up first (longest-processing-time scheduling, within 4/3 of the best possible).

    Parameters
    ----------
    core_seconds : iterable of float
        Each job's time on one core (s), >= 0.
    cores : int
        Cores, >= 1.

    Returns
    -------
    float
        The time the last job ends (s); 0 without jobs.
    """
    if cores < 1:
        raise ValueError(f"cores must be >= 1, got {cores!r}")
    jobs = sorted((float(t) for t in core_seconds), reverse=True)
    if any(not math.isfinite(t) or t < 0.0 for t in jobs):
        raise ValueError("job times must be finite and >= 0")
    ends = [0.0] * min(cores, max(len(jobs), 1))
    for job in jobs:
        heapq.heappush(ends, heapq.heappop(ends) + job)
    return max(ends)


def runs_wall_time(runs: Iterable[tuple[float, int]], cores: int) -> float:
    """Wall time of runs ``(wall time s, MPI ranks)`` on ``cores`` cores (:func:`makespan`): a run on r ranks holds r
    cores for its wall time, as r jobs of that length."""
    return makespan([wall for wall, ranks in runs for _ in range(min(ranks, cores))], cores)


@dataclass(frozen=True)
class GroupCost:
    """What one group costs.

    Attributes
    ----------
    name : str
        The group.
    runs : int
        Engine runs it makes.
    core_seconds : float
        Their CPU time together (s).
    wall_time_s : float
        Its wall time on the cores given (s): :func:`makespan` of its runs, each on its MPI ranks.
    over_budget : bool
        Whether the wall time exceeds :data:`GROUP_BUDGET_S`.
    """

    name: str
    runs: int
    core_seconds: float
    wall_time_s: float
    over_budget: bool


def group_costs(made: Mapping[str, Sequence[RunEstimate]], cores: int) -> list[GroupCost]:
    """The cost of each group of the runs it makes (:func:`assign`) on ``cores`` cores; a run on several MPI ranks
    takes that many cores for its wall time."""
    costs = []
    for name, members in made.items():
        wall = runs_wall_time(((e.wall_time_s, e.mpi_ranks) for e in members), cores)
        costs.append(GroupCost(name, len(members), math.fsum(e.core_seconds for e in members), wall,
                               wall > GROUP_BUDGET_S))
    return costs


def planned_runs(made: Mapping[str, Sequence[RunEstimate]]) -> dict[str, set[str]]:
    """The run ids behind each group's rows (:func:`assign`'s runs it makes and those of the groups it reads):
    ``{group: {run id}}`` of the groups that make a run in this configuration (a silo without a front-wall series
    has no series group)."""
    own = {name: {estimate.run_id for estimate in members} for name, members in made.items()}
    return {name: own[name].union(*(own.get(other, set()) for other in GROUPS[name].reads))
            for name in own if own[name]}


def group_status(planned: Mapping[str, set[str]], recorded: Mapping[str, set[str]]) -> dict[str, str]:
    """Each group's status in the record against the plan.

    Parameters
    ----------
    planned : mapping
        ``{group: {run id}}`` the configuration plans (:func:`planned_runs`).
    recorded : mapping
        ``{group: {run id}}`` of the runs behind the record's rows (its provenance); a group absent or empty has no
        record.

    Returns
    -------
    dict
        ``{group: status}`` for every group of ``planned``: :data:`MISSING` without a record, :data:`COMPLETE` when
        the record's runs are exactly those planned, else :data:`STALE` (a run changed, was added or left out).
    """
    status = {}
    for name, runs in planned.items():
        held = set(recorded.get(name, ()))
        status[name] = MISSING if not held else COMPLETE if held == set(runs) else STALE
    return status


def status_lines(planned: Mapping[str, set[str]], recorded: Mapping[str, set[str]]) -> list[str]:
    """`make validate-status`'s lines: per group, its status and the runs that differ from the plan."""
    lines = []
    for name, status in group_status(planned, recorded).items():
        held, runs = set(recorded.get(name, ())), set(planned[name])
        line = f"{name:18s} {status:9s} {len(held & runs)} of {len(runs)} planned runs recorded"
        if status == STALE:
            gone, new = sorted(held - runs), sorted(runs - held)
            line += (f"; recorded but no longer planned: {', '.join(gone) or 'none'}; planned but not recorded: "
                     f"{', '.join(new) or 'none'}")
        lines.append(line)
    return lines


def cost_lines(costs: Sequence[GroupCost], cores: int) -> list[str]:
    """`make estimate`'s lines on the groups: each group's runs, core time and wall time on ``cores`` cores (the
    groups that make no run of the configuration left out)."""
    lines = [f"Validation groups (make validate GROUP=<name>) on {cores} core(s), each at most "
             f"{GROUP_BUDGET_S / 3600:g} h:"]
    for cost in (cost for cost in costs if cost.runs):
        flag = "  OVER BUDGET: split it" if cost.over_budget else ""
        lines.append(f"  {cost.name:18s} {cost.runs:3d} runs  {cost.core_seconds / 3600:6.2f} core-h  "
                     f"{cost.wall_time_s / 3600:5.2f} h wall{flag}")
    return lines
