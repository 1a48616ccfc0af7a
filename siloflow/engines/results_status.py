"""What a results folder holds for a configuration: each planned run finished, unfinished or still to do, the run
folders the configuration no longer plans, and whether the report is older than the runs it shows.

A run's id hashes every parameter that defines it (:mod:`siloflow.engines.layout`), so a run whose parameters changed
is a new run: its old folder is no longer planned. Such folders are listed as "not planned", never removed (another
configuration may still use them). The classification (:func:`results_status`) works on names and times;
:func:`scan_results` reads them off the disk.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping

from siloflow.engines.layout import CASE_SUMMARY, RUN_RECORD, case_root
from siloflow.model.cost import RunEstimate

#: A run's states, in the order the status lists them.
FINISHED, UNFINISHED, TO_DO = "finished", "unfinished", "to do"


@dataclass(frozen=True)
class FolderListing:
    """What a results folder holds, as :func:`scan_results` reads it.

    Attributes
    ----------
    folders : mapping
        ``{case kind: {run folder name}}``: the folders under each kind's case root.
    records : mapping
        ``{(case kind, run id): modification time of its run record (s since the epoch)}``: the finished runs.
    report_time : float or None
        Modification time of the report (s since the epoch); None when there is none.
    """

    folders: Mapping[str, set[str]] = field(default_factory=dict)
    records: Mapping[tuple[str, str], float] = field(default_factory=dict)
    report_time: float | None = None


@dataclass(frozen=True)
class ResultsStatus:
    """The status of a results folder against a configuration's plan.

    Attributes
    ----------
    states : dict
        ``{case kind: {state: [run id, ...]}}`` with the states :data:`FINISHED`, :data:`UNFINISHED` (its folder
        exists, its run record does not: the next run resumes it) and :data:`TO_DO`, each list in plan order.
    not_planned : dict
        ``{case kind: [folder name, ...]}``: run folders the configuration does not plan, sorted.
    report_stale : bool or None
        True when a finished run's record is newer than the report, False when the report is newer than every
        record; None when there is no report.
    """

    states: dict
    not_planned: dict
    report_stale: bool | None

    def counts(self) -> dict[str, int]:
        """How many runs are in each state, over every case kind."""
        return {state: sum(len(by_state[state]) for by_state in self.states.values())
                for state in (FINISHED, UNFINISHED, TO_DO)}


def results_status(estimates: Iterable[RunEstimate], listing: FolderListing) -> ResultsStatus:
    """Classify the planned runs of ``estimates`` by what ``listing`` holds.

    Parameters
    ----------
    estimates : iterable of RunEstimate
        Every run the configuration plans (:func:`siloflow.engines.planning.config_estimates`).
    listing : FolderListing
        What the results folder holds.

    Returns
    -------
    ResultsStatus
    """
    states: dict[str, dict[str, list[str]]] = {}
    planned: dict[str, set[str]] = {}
    for estimate in estimates:
        kind, run = estimate.kind, estimate.run_id
        planned.setdefault(kind, set()).add(run)
        by_state = states.setdefault(kind, {FINISHED: [], UNFINISHED: [], TO_DO: []})
        if (kind, run) in listing.records:
            by_state[FINISHED].append(run)
        elif run in listing.folders.get(kind, set()):
            by_state[UNFINISHED].append(run)
        else:
            by_state[TO_DO].append(run)
    not_planned = {kind: sorted(names - planned.get(kind, set()))
                   for kind, names in listing.folders.items() if names - planned.get(kind, set())}
    finished_times = [time for (kind, run), time in listing.records.items() if run in planned.get(kind, set())]
    if listing.report_time is None:
        stale = None
    else:
        stale = any(time > listing.report_time for time in finished_times)
    return ResultsStatus(states=states, not_planned=not_planned, report_stale=stale)


def status_lines(status: ResultsStatus, results: str) -> list[str]:
    """The status as the command line prints it: a line per case kind, the folders not planned and the report."""
    lines = []
    for kind, by_state in status.states.items():
        parts = [f"{len(runs)} {state}" for state, runs in by_state.items() if runs]
        lines.append(f"{kind}: {', '.join(parts)}")
        lines += [f"  unfinished (the next run resumes it): {run}" for run in by_state[UNFINISHED]]
    for kind, names in status.not_planned.items():
        lines.append(f"{kind}: {len(names)} folder(s) this configuration does not plan (another configuration's, or "
                     f"runs whose parameters have changed since; kept): {', '.join(names)}")
    counts = status.counts()
    lines.append(f"in all: {counts[FINISHED]} finished, {counts[UNFINISHED]} unfinished, {counts[TO_DO]} to do, "
                 f"under {results}/")
    if status.report_stale is None:
        lines.append("report: none yet")
    elif status.report_stale:
        lines.append("report: stale (older than a finished run it shows); `siloflow run` writes it again")
    else:
        lines.append("report: up to date with the finished runs")
    return lines


def scan_results(results: str | Path, kinds: Iterable[str], report: str | Path) -> FolderListing:
    """Read what ``results`` holds for the case kinds ``kinds``: their run folders (those holding inputs or a run
    record), the run records' times and the report's time."""
    folders, records = {}, {}
    for kind in kinds:
        root = Path(case_root(kind, str(results)))
        # a run's folder holds its inputs (deck/) or its record; a case root also holds the case's own tables
        deck = Path(CASE_SUMMARY).parent.name
        names = {path.name for path in root.iterdir()
                 if (path / deck).is_dir() or (path / RUN_RECORD).is_file()} if root.is_dir() else set()
        folders[kind] = names
        for name in names:
            record = root / name / RUN_RECORD
            if record.is_file():
                records[(kind, name)] = record.stat().st_mtime
    report = Path(report)
    return FolderListing(folders=folders, records=records,
                         report_time=report.stat().st_mtime if report.is_file() else None)
