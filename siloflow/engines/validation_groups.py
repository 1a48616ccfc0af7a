"""The validation tier in groups: which runs each group makes, how a group too long for one working session is split
into parts, what each costs, and whether the record in the repository still matches what the configuration plans.

A group is one stage of the study with its own rows in the record. `make validate GROUP=<name>` runs one group, or one
part of a group that takes longer than :data:`GROUP_BUDGET_S` on :data:`PART_CORES` cores (`silo_1`, `silo_2`, ...;
the part that makes the group's last run writes its record); `make validate` runs them all. `make estimate` prints
each group's and each part's cost; `make validate-status` says which groups of the record are complete, stale or
missing. Pure computation: callers pass estimates and run ids; the record's files are read at the edge
(:mod:`siloflow.analysis.studies.validation.record`).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

from siloflow.model.cases import REFERENCE, VARIANT
from siloflow.model.cases.jenike_sweep import CALIBRATION_CHART, CHECK, SHAPE_CHART
from siloflow.model.cost import RunEstimate

@dataclass(frozen=True)
class Group:
    """One validation group: the runs it makes and the groups whose runs its rows also draw on.

    Attributes
    ----------
    kind : str
        The case kind whose runs it makes.
    roles : tuple of str, optional
        The roles of that kind's runs it makes (:func:`siloflow.model.cases.run_roles`); None: all of them.
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
#: compared against it); the blending study reads the flat-bottom silo's base runs, whose settled fills it starts from.
GROUPS: dict[str, Group] = {
    "calibration": Group("jenike", (CALIBRATION_CHART,)),
    "calibration_shapes": Group("jenike", (SHAPE_CHART,)),
    "calibration_checks": Group("jenike", (CHECK,), reads=("calibration", "calibration_shapes")),
    "silo": Group("silo_flat", (REFERENCE,)),
    "silo_series": Group("silo_flat", (VARIANT,), reads=("silo",)),
    # its flow patterns start from the flat-bottom silo's settled fills (silo_recirculation.assembly: silo_flat)
    "blending": Group("silo_recirculation", reads=("silo",)),
    "blender": Group("blender"),
}

#: The longest a group (or a part of one) may take on :data:`PART_CORES` cores (s): a working session.
GROUP_BUDGET_S = 2.5 * 3600.0
#: The core time the whole validation tier may take, recorded on :data:`PART_CORES` cores (CPU s).
TIER_BUDGET_CORE_S = 60.0 * 3600.0

#: The share of the budget a part is filled to by its estimated wall time: with the validation configuration's rates per
#: case kind, a group's estimate is within about a tenth of its recorded time (the record's page sets them side by
#: side), and the budget holds for the measured times.
PART_FILL = 0.9

#: The cores the budget is for, a laptop's: the parts of a group are the same whatever the cores of the machine at
#: hand, so that a group begun on one machine can be finished on another.
PART_CORES = 2

#: A group's status against the record (:func:`group_status`).
COMPLETE, STALE, MISSING = "complete", "stale", "missing"


def group_of(kind: str, role: str) -> str:
    """The group that makes a run of case kind ``kind`` with ``role`` (:func:`siloflow.model.cases.run_roles`)."""
    for name, group in GROUPS.items():
        if group.makes(kind, role):
            return name
    raise KeyError(f"no validation group makes {role!r} runs of kind {kind!r}; the groups are {', '.join(GROUPS)}")


def assign(estimates: Sequence[RunEstimate], roles: Mapping[str, str]) -> dict[str, list[RunEstimate]]:
    """The runs each group makes: ``{group: [estimate]}`` in :data:`GROUPS` order.

    Parameters
    ----------
    estimates : sequence of RunEstimate
        A configuration's run estimates (:func:`siloflow.engines.planning.config_estimates`).
    roles : mapping
        ``{run id: role}`` of every run (:func:`siloflow.model.cases.run_roles`).
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


def check_reads(name: str, status: Mapping[str, str], parts: Mapping[str, Sequence["Part"]] | None = None) -> None:
    """Refuse (ValueError) to run group ``name`` before the groups it reads are complete in the record (``status``
    of :func:`group_status`): Snakemake would make their runs too, past the group's budget. The message names what
    to run first, part by part for a group in parts (``parts`` from :func:`split_groups`)."""
    waiting = [other for other in GROUPS[name].reads if status.get(other, COMPLETE) != COMPLETE]
    if waiting:
        names = [part.name for other in waiting for part in (parts or {}).get(other, ())] or waiting
        raise ValueError(f"validation group {name!r} compares against the runs of {', '.join(waiting)}, whose record is "
                         f"{' and '.join(status[other] for other in waiting)}: run "
                         f"{' then '.join(f'make validate GROUP={other}' for other in names)} first")


def makespan(core_seconds: Iterable[float], cores: int) -> float:
    """Wall time of independent single-core jobs on ``cores`` cores, the longest started first (s).

    Snakemake starts the longest runs first (:func:`siloflow.engines.planning.run_priorities`); each job goes to the core
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
class Part:
    """A part of a validation group: the runs one `make validate GROUP=<name>` makes, or carries on (a run longer
    than a part runs over several, :attr:`time_slice`).

    Attributes
    ----------
    name : str
        What `make validate GROUP=` takes: the group's name when the group is one part, else ``<group>_<k>``.
    group : str
        The group it belongs to.
    positions : tuple of int
        Its runs, as positions in the group's runs (:func:`assign`'s order, which is the configuration's): positions,
        not run ids, so that a part still names its runs when a silo's run ids are known only after the calibration.
    """

    name: str
    group: str
    positions: tuple[int, ...]
    #: ``(j, k)`` for runs longer than a part on their own: this part is the j-th of the k consecutive parts that run
    #: them, each stopping them at its deadline and the next resuming them from their restart files; None otherwise
    time_slice: tuple[int, int] | None = None

    def runs(self, members: Sequence):
        """The part's runs among ``members``, the group's runs in :func:`assign`'s order (estimates or run ids)."""
        return [members[i] for i in self.positions]


def _longest_first(members: Sequence[RunEstimate]) -> list[int]:
    """Positions of ``members``, the most core time first (ties by run id)."""
    return sorted(range(len(members)),
                  key=lambda i: (-members[i].wall_time_s * members[i].mpi_ranks, members[i].run_id))


def _side_by_side(members: Sequence[RunEstimate], order: Sequence[int], cores: int,
                  budget_s: float) -> list[list[int]]:
    """The runs longer than ``budget_s`` on their own (positions in ``order``), gathered side by side while the
    ``cores`` hold their ranks: each list runs through the same consecutive time-sliced parts."""
    long = [i for i in order if members[i].wall_time_s > budget_s]
    gathered: list[list[int]] = []
    while long:
        chosen, used = [], 0
        for i in list(long):
            ranks = min(members[i].mpi_ranks, cores)
            if not chosen or used + ranks <= cores:
                chosen.append(i)
                used += ranks
                long.remove(i)
        gathered.append(chosen)
    return gathered


def lone_runs(made: Mapping[str, Sequence[RunEstimate]], cores: int = PART_CORES,
              budget_s: float = PART_FILL * GROUP_BUDGET_S) -> dict[str, int]:
    """The runs that would leave cores idle through the time-sliced parts of their group, with the MPI ranks that
    use them: ``{run id: ranks}``, the cores shared out among the runs side by side (:func:`split`).

    A run longer than a part, with no other such run of its group beside it, holds one core of the part's two for
    all its parts; on two ranks it finishes sooner (`make bench-assembly` measures 1 rank against 2 on the tier's
    largest assembly). A run already on as many ranks as its share is left out.
    """
    wider: dict[str, int] = {}
    for members in made.values():
        for chosen in _side_by_side(members, _longest_first(members), cores, budget_s):
            share = cores // len(chosen)
            wider.update({members[i].run_id: share for i in chosen if members[i].mpi_ranks < share})
    return wider


def split(group: str, members: Sequence[RunEstimate], cores: int = PART_CORES,
          budget_s: float = PART_FILL * GROUP_BUDGET_S) -> list[Part]:
    """A group's runs in parts that each take at most ``budget_s`` on ``cores`` cores (by default
    :data:`PART_FILL` of :data:`GROUP_BUDGET_S`, so that the measured times stay within the budget).

    First-fit decreasing: the runs, the longest first, each go into the first part whose wall time
    (:func:`runs_wall_time`) stays within the budget with it, else into a new part. The parts depend only on the
    estimates, so the same configuration always gives the same parts. Runs longer than the budget on their own run
    side by side, as many as the cores hold, over as many consecutive parts as the longest of them needs (time slices:
    each part stops them at its deadline, the next resumes them from their restart files); these parts come first.

    Parameters
    ----------
    group : str
        The group's name (the parts are ``<group>_1``, ``<group>_2``, ...; a group in one part keeps its name).
    members : sequence of RunEstimate
        The group's runs (:func:`assign`).
    cores : int
        The cores of the budget.
    budget_s : float
        The longest a part may take by its estimate (s).

    Returns
    -------
    list of Part
        In order of their longest run; none for a group without runs.
    """
    order = _longest_first(members)
    sliced = [(chosen, math.ceil(max(members[i].wall_time_s for i in chosen) / budget_s))
              for chosen in _side_by_side(members, order, cores, budget_s)]
    bins: list[list[int]] = []
    for i in (i for i in order if members[i].wall_time_s <= budget_s):
        fits = (b for b in bins
                if runs_wall_time(((members[j].wall_time_s, members[j].mpi_ranks) for j in (*b, i)), cores) <= budget_s)
        target = next(fits, None)
        if target is None:
            bins.append([i])
        else:
            target.append(i)
    parts = [(tuple(sorted(chosen)), (j, slices)) for chosen, slices in sliced for j in range(1, slices + 1)]
    parts += [(tuple(sorted(b)), None) for b in bins]
    if len(parts) == 1:
        return [Part(group, group, parts[0][0])]
    return [Part(f"{group}_{k}", group, positions, time_slice)
            for k, (positions, time_slice) in enumerate(parts, start=1)]


def split_groups(made: Mapping[str, Sequence[RunEstimate]], cores: int = PART_CORES) -> dict[str, list[Part]]:
    """``{group: [Part]}`` of every group that makes a run (:func:`split` of each group of :func:`assign`)."""
    return {name: split(name, members, cores) for name, members in made.items() if members}


def find_part(name: str, parts: Mapping[str, Sequence[Part]]) -> Part:
    """The part `make validate GROUP=<name>` names; a ValueError that says what to run instead for an unknown name or
    a group that is split into parts."""
    for group_parts in parts.values():
        for part in group_parts:
            if part.name == name:
                return part
    if name in parts:
        names = [part.name for part in parts[name]]
        raise ValueError(f"validation group {name!r} takes longer than {PART_FILL * GROUP_BUDGET_S / 3600:g} h on "
                         f"{PART_CORES} cores by its estimate, so it runs in {len(names)} parts: "
                         f"{' then '.join(f'make validate GROUP={n}' for n in names)} (the part that makes its last run "
                         f"writes its record)")
    known = [part.name for group_parts in parts.values() for part in group_parts]
    raise ValueError(f"unknown validation group {name!r}; this configuration's groups and parts are {', '.join(known)}")


def part_of_runs(parts: Mapping[str, Sequence[Part]], runs: Mapping[str, Sequence[str]]) -> dict[str, str]:
    """``{run id: part name}`` from the parts and each group's run ids in :func:`assign`'s order (``runs``)."""
    return {run: part.name for name, group_parts in parts.items() for part in group_parts
            for run in part.runs(runs[name])}


def group_of_part(name: str) -> str:
    """The group a part name (or a group name) belongs to."""
    if name in GROUPS:
        return name
    group, _, k = name.rpartition("_")
    if group in GROUPS and k.isdigit():
        return group
    raise ValueError(f"{name!r} names no validation group or part of one; the groups are {', '.join(GROUPS)}")


def finished_groups(planned: Mapping[str, set[str]], done: set[str]) -> list[str]:
    """The groups whose every run behind their rows (:func:`planned_runs`) is in ``done`` (the runs that have finished
    in the working directory), in :data:`GROUPS` order: the groups whose record can be written."""
    return [name for name in GROUPS if name in planned and planned[name] <= done]


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


def _cost(name: str, members: Sequence[RunEstimate], cores: int) -> GroupCost:
    wall = runs_wall_time(((e.wall_time_s, e.mpi_ranks) for e in members), cores)
    return GroupCost(name, len(members), math.fsum(e.core_seconds for e in members), wall, wall > GROUP_BUDGET_S)


def group_costs(made: Mapping[str, Sequence[RunEstimate]], cores: int) -> list[GroupCost]:
    """The cost of each group of the runs it makes (:func:`assign`) on ``cores`` cores; a run on several MPI ranks
    takes that many cores for its wall time."""
    return [_cost(name, members, cores) for name, members in made.items()]


def _slice_cost(part: Part, members: Sequence[RunEstimate], cores: int, budget_s: float) -> GroupCost:
    """The cost of one time slice of runs longer than a part: the part's budget of wall time, or what the runs have
    left in the last slice, and the core time their cores spend in it."""
    j, _ = part.time_slice
    runs = part.runs(members)
    left = [max(0.0, e.wall_time_s - (j - 1) * budget_s) for e in runs]
    spent = [min(budget_s, wall) for wall in left]
    wall = max(spent)
    core_seconds = math.fsum(s * e.mpi_ranks for s, e in zip(spent, runs))
    return GroupCost(part.name, len(runs), core_seconds, wall, wall > GROUP_BUDGET_S)


def part_costs(parts: Mapping[str, Sequence[Part]], made: Mapping[str, Sequence[RunEstimate]],
               cores: int, budget_s: float = PART_FILL * GROUP_BUDGET_S) -> dict[str, list[GroupCost]]:
    """``{group: [cost of each part]}`` on ``cores`` cores of the groups split into several parts (``parts`` from
    :func:`split_groups`, ``made`` the groups' runs in the same order, possibly estimated with another cost model); a
    time slice of runs longer than a part costs its share of them (``budget_s`` of wall time at most)."""
    return {name: [_slice_cost(part, made[name], cores, budget_s) if part.time_slice
                   else _cost(part.name, part.runs(made[name]), cores) for part in group_parts]
            for name, group_parts in parts.items() if len(group_parts) > 1}


def planned_runs(made: Mapping[str, Sequence[RunEstimate]]) -> dict[str, set[str]]:
    """The run ids behind each group's rows (:func:`assign`'s runs it makes and those of the groups it reads):
    ``{group: {run id}}`` of the groups that make a run in this configuration (a silo without a front-wall series
    has no series group)."""
    own = {name: {estimate.run_id for estimate in members} for name, members in made.items()}
    return {name: own[name].union(*(own.get(other, set()) for other in GROUPS[name].reads))
            for name in own if own[name]}


def group_status(planned: Mapping[str, set[str]], recorded: Mapping[str, set[str]],
                 other_code: Iterable[str] = ()) -> dict[str, str]:
    """Each group's status in the record against the plan and the row code.

    Parameters
    ----------
    planned : mapping
        ``{group: {run id}}`` the configuration plans (:func:`planned_runs`).
    recorded : mapping
        ``{group: {run id}}`` of the runs behind the record's rows (its provenance); a group absent or empty has no
        record.
    other_code : iterable of str
        The recorded groups whose rows were written by other row code than today's.

    Returns
    -------
    dict
        ``{group: status}`` for every group of ``planned``: :data:`MISSING` without a record, :data:`COMPLETE` when
        the record's runs are exactly those planned and its rows were written by today's row code, else
        :data:`STALE` (a run changed, was added or left out, or the row code changed).
    """
    status, changed = {}, set(other_code)
    for name, runs in planned.items():
        held = set(recorded.get(name, ()))
        status[name] = MISSING if not held else COMPLETE if held == set(runs) and name not in changed else STALE
    return status


STATUS_IDS_SHOWN = 4
"""How many run ids a status line names of the runs that differ from the plan, before it counts the rest."""


def _first_ids(run_ids: Sequence[str]) -> str:
    """The first :data:`STATUS_IDS_SHOWN` of ``run_ids`` and how many more, so that a group whose every run changed
    (a changed parameter renames them all) keeps a line a reader takes in."""
    shown = ", ".join(run_ids[:STATUS_IDS_SHOWN]) or "none"
    more = len(run_ids) - STATUS_IDS_SHOWN
    return f"{shown} and {more} more" if more > 0 else shown


def status_lines(planned: Mapping[str, set[str]], recorded: Mapping[str, set[str]],
                 other_code: Mapping[str, bool] | None = None) -> list[str]:
    """`make validate-status`'s lines: per group, its status, the runs that differ from the plan and whether its rows
    were written by other row code (``other_code``: ``{group: whether its record keeps what re-derives its rows}``)."""
    lines = []
    other_code = dict(other_code or {})
    for name, status in group_status(planned, recorded, other_code).items():
        held, runs = set(recorded.get(name, ())), set(planned[name])
        line = f"{name:18s} {status:9s} {len(held & runs)} of {len(runs)} planned runs recorded"
        if status == STALE and held != runs:
            gone, new = sorted(held - runs), sorted(runs - held)
            line += (f"; recorded but no longer planned: {_first_ids(gone)}; planned but not recorded: "
                     f"{_first_ids(new)}")
        if name in other_code and held:
            line += ("; its rows were written by other row code: `siloflow record rederive --group "
                     f"{name}` derives them again from the products its record keeps" if other_code[name] else
                     "; its rows were written by other row code and its record keeps no products to derive them "
                     f"from: `make validate GROUP={name}` records it again")
        lines.append(line)
    return lines


def cost_lines(costs: Sequence[GroupCost], cores: int, parts: Mapping[str, Sequence[GroupCost]] | None = None) -> list[str]:
    """`make estimate`'s lines on the groups: each group's runs, core time and wall time on ``cores`` cores (the
    groups that make no run of the configuration left out), and under a group split into parts (``parts`` from
    :func:`part_costs`) each part, the name `make validate GROUP=` takes."""
    parts = parts or {}
    lines = [f"Validation groups (make validate GROUP=<name>) on {cores} core(s); a group whose estimate exceeds "
             f"{PART_FILL * GROUP_BUDGET_S / 3600:g} h on {PART_CORES} cores ({PART_FILL:.0%} of the "
             f"{GROUP_BUDGET_S / 3600:g} h budget) runs in parts:"]
    for cost in (cost for cost in costs if cost.runs):
        split_into = parts.get(cost.name, ())
        flag = (f"  in {len(split_into)} parts" if split_into else
                "  OVER BUDGET: split it" if cost.over_budget else "")
        lines.append(f"  {cost.name:22s} {cost.runs:3d} runs  {cost.core_seconds / 3600:6.2f} core-h  "
                     f"{cost.wall_time_s / 3600:5.2f} h wall{flag}")
        for part in split_into:
            over = "  OVER BUDGET" if part.over_budget else ""
            lines.append(f"    {part.name:20s} {part.runs:3d} runs  {part.core_seconds / 3600:6.2f} core-h  "
                         f"{part.wall_time_s / 3600:5.2f} h wall{over}")
    return lines
