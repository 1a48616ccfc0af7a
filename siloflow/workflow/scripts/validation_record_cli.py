"""Command line of the validation record: `make validate-status`, the record's copy into the repository and its page,
and `make validate GROUP=<name>`'s check. An adapter of the workflow layer (it joins the planner and the record's
analysis): ``python siloflow/workflow/scripts/validation_record_cli.py <command> ...``.

``status CONFIG RECORD_DIR`` prints, per group, whether the record in ``RECORD_DIR`` (``docs/validation``) is
complete, stale or missing against the runs ``CONFIG`` plans (:func:`siloflow.engines.validation_groups.group_status`);
``publish WORKDIR RECORD_DIR [GROUP]`` copies the records a `make validate` wrote in ``WORKDIR`` into ``RECORD_DIR``;
``page CONFIG FULL_SCALE_CONFIG RECORD_DIR`` writes ``RECORD_DIR/README.md`` from the record
(:func:`siloflow.analysis.studies.validation.record.record_page`); ``check GROUP CONFIG RECORD_DIR`` refuses, before anything
runs, an unknown group or part, a group that runs in parts (naming them), one whose rows compare against a group
not yet complete in the record, or a configuration whose plots are not PNG, which the record keeps
(``plots.format``); ``restore GROUP CONFIG RECORD_DIR WORKDIR`` checks as ``check`` does, then copies into WORKDIR
the products of the runs of the groups GROUP reads that their records keep and WORKDIR lacks (so that a group reads
the runs another session made instead of making them again); ``finished CONFIG WORKDIR [GROUP]`` prints the groups
(of GROUP's only) whose every run has finished in WORKDIR, whose record `make validate` then writes.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Sequence

from siloflow.analysis.io.tables import write_text
from siloflow.analysis.io.validation_record import (PRODUCTS, check_plot_format, read_group_record, read_record, restore_products,
                                           write_group_record)
from siloflow.analysis.studies.validation.record import record_page, run_wall_time
from siloflow.engines.config import load_config
from siloflow.engines.layout import RESULTS, RUN_RECORD, VALIDATION_RECORD
from siloflow.engines.planning import config_estimates, group_runs, run_directory
from siloflow.engines.validation_groups import (GROUPS, MISSING, STALE, check_group, check_reads, find_part, finished_groups,
                                       group_costs, group_of_part, group_status, planned_runs, runs_wall_time,
                                       split_groups, status_lines)

#: The record's page, in its folder.
RECORD_PAGE = "README.md"


def _run_ids(record: dict) -> dict[str, set[str]]:
    """``{group: {run id}}`` of a record read with :func:`siloflow.analysis.io.validation_record.read_record`."""
    return {name: {run["run_id"] for run in group.runs} for name, group in record.items()}


def recorded_runs(record_dir: str | Path) -> dict[str, set[str]]:
    """``{group: {run id}}`` from each group's provenance (``<record_dir>/<group>/runs.csv``); a group without the
    file is absent."""
    return _run_ids(read_record(record_dir, GROUPS))


def publish(workdir: str | Path, record_dir: str | Path, groups: Sequence[str]) -> list[str]:
    """Copy the records the pipeline wrote under ``workdir`` (:data:`siloflow.engines.layout.VALIDATION_RECORD`) of
    ``groups`` into ``record_dir``, each replacing that group's previous record; returns the groups copied (a group
    the pipeline has not recorded is left as it is)."""
    copied = []
    for name in groups:
        source = Path(workdir) / VALIDATION_RECORD / name
        if (source / "runs.csv").is_file():
            record = read_group_record(source)
            write_group_record(Path(record_dir) / name, record.rows, record.runs,
                               {plot: source / plot for plot in record.plots},
                               {product: source / PRODUCTS / product for product in record.products})
            copied.append(name)
    return copied


def measured_wall_times(record: dict, cores: int) -> dict[str, dict[str, float]]:
    """``{group: {part: s}}``: the wall time of the runs each part of each recorded group makes (the ``group`` column
    of its runs names the part), from their measured times, on ``cores`` cores
    (:func:`siloflow.engines.validation_groups.runs_wall_time`); the runs a group reads from another group are not its own."""
    walls = {}
    for name, group in record.items():
        made: dict[str, list] = {}
        for run in group.runs:
            if group_of_part(run["group"]) == name:
                made.setdefault(run["group"], []).append((run_wall_time(run), int(run["cores"])))
        walls[name] = {part: runs_wall_time(runs, cores) for part, runs in sorted(made.items())}
    return walls


def _plan(config_path: str, record: bool = False) -> tuple[list, dict[str, list]]:
    """A configuration's run estimates and the runs each group makes of them (:func:`siloflow.engines.planning.group_runs`).
    With ``record``, the configuration is to write the record from: refused (ValueError) when its plots are not in the
    record's format (:func:`siloflow.analysis.io.validation_record.check_plot_format`)."""
    config = load_config(config_path)
    if record:
        check_plot_format(config["plots"]["format"])
    estimates = config_estimates(config)
    return estimates, group_runs(config, estimates)


def _planned(config_path: str) -> dict[str, set[str]]:
    return planned_runs(_plan(config_path)[1])


def _check(name: str, made: dict[str, list], record_dir: str | Path) -> None:
    parts = split_groups(made)
    check_reads(find_part(name, parts).group, group_status(planned_runs(made), recorded_runs(record_dir)), parts)


def check(name: str, config_path: str, record_dir: str | Path) -> None:
    """`make validate GROUP=<name>`'s check before anything runs: ``name`` is a group or a part of one that
    ``config_path`` plans, its plots are in the record's format, and the groups its rows compare against are complete
    in the record (ValueError)."""
    _check(name, _plan(config_path, record=True)[1], record_dir)


def restore(name: str, config_path: str, record_dir: str | Path, workdir: str | Path) -> dict[str, int]:
    """:func:`check` group or part ``name``, then copy into ``workdir`` the products of the runs of the groups it
    reads that their records in ``record_dir`` keep and ``workdir`` lacks
    (:func:`siloflow.analysis.io.validation_record.restore_products`). Returns ``{group read: files copied}``."""
    made = _plan(config_path, record=True)[1]
    _check(name, made, record_dir)
    reads = GROUPS[group_of_part(name)].reads
    restored = {other: len(restore_products(Path(record_dir) / other, workdir)) for other in reads}
    results = Path(workdir) / RESULTS
    absent = [e.run_id for other in reads for e in made[other] if not (run_directory(results, e) / RUN_RECORD).is_file()]
    if absent:
        parts = split_groups(made)
        again = [part.name for other in reads for part in parts.get(other, ())]
        raise ValueError(f"{len(absent)} runs of {', '.join(reads)} that {name!r} compares against are neither in "
                         f"{results} nor kept by their record in {record_dir} (a record written before records kept "
                         f"the products of their runs): run {' then '.join(f'make validate GROUP={p}' for p in again)} "
                         f"on this machine first")
    return restored


def finished(config_path: str, workdir: str | Path, name: str | None = None) -> tuple[list[str], list[str]]:
    """The groups whose record can be written now, and what the others still wait for.

    Parameters
    ----------
    config_path : str
        The configuration.
    workdir : path
        The working directory of `make validate` (its ``results/`` holds the runs).
    name : str, optional
        A group or part (`make validate GROUP=<name>`): only its group is considered.

    Returns
    -------
    groups : list of str
        The groups every run behind whose rows has finished in ``workdir`` (its run record written).
    waiting : list of str
        For each other group considered, a line saying how many of its runs are still to make.
    """
    estimates, made = _plan(config_path)
    planned = planned_runs(made)
    results = Path(workdir) / RESULTS
    done = {e.run_id for e in estimates if (run_directory(results, e) / RUN_RECORD).is_file()}
    if name is not None:
        planned = {group: runs for group, runs in planned.items() if group == group_of_part(name)}
    ready = finished_groups(planned, done)
    waiting = [f"{group}: {len(planned[group] - done)} of {len(planned[group])} runs behind its rows still to make; "
               f"its record is written by the `make validate GROUP=` that makes the last"
               for group in planned if group not in ready]
    return ready, waiting


def page(config_path: str, full_scale_path: str, record_dir: str | Path, cores: int = 2) -> str:
    """The record's page for the record under ``record_dir``, judged against ``config_path``'s plan, with each
    group's measured wall time on ``cores`` cores, its parts and its cost at the scale of ``full_scale_path``."""
    made = _plan(config_path)[1]
    record = read_record(record_dir, GROUPS)
    status = group_status(planned_runs(made), _run_ids(record))
    parts = {name: [part.name for part in group_parts] for name, group_parts in split_groups(made).items()}
    full_scale = {cost.name: cost.core_seconds for cost in group_costs(_plan(full_scale_path)[1], cores=1)}
    return record_page(record, status, {name: full_scale.get(name, math.nan) for name in GROUPS},
                       measured_wall_times(record, cores), cores, config_path, full_scale_path, parts)


def main(argv: Sequence[str] | None = None) -> int:
    """Command line; returns 0 when every group is complete (status) or the group exists (check), 1 when a group is
    stale or missing, 2 on a usage error."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) == 4 and argv[0] == "check":
        try:
            check(argv[1], argv[2], argv[3])
        except ValueError as error:
            print(f"siloflow: {error}", file=sys.stderr)
            return 2
        return 0
    if len(argv) == 5 and argv[0] == "restore":
        try:
            restored = restore(*argv[1:])
        except ValueError as error:
            print(f"siloflow: {error}", file=sys.stderr)
            return 2
        for other, count in restored.items():
            print(f"siloflow: {count} products of the runs of {other} restored from {argv[3]}/{other} into {argv[4]}")
        return 0
    if len(argv) in (3, 4) and argv[0] == "finished":
        try:
            ready, waiting = finished(argv[1], argv[2], argv[3] if len(argv) == 4 else None)
        except ValueError as error:
            print(f"siloflow: {error}", file=sys.stderr)
            return 2
        for line in waiting:
            print(f"siloflow: {line}", file=sys.stderr)
        print(" ".join(ready))
        return 0
    if len(argv) == 3 and argv[0] == "status":
        planned = _planned(argv[1])
        recorded = recorded_runs(argv[2])
        print(f"The validation record in {argv[2]} against the runs {argv[1]} plans:")
        print("\n".join(status_lines(planned, recorded)))
        return 1 if {STALE, MISSING} & set(group_status(planned, recorded).values()) else 0
    if len(argv) in (3, 4) and argv[0] == "publish":
        try:
            groups = [check_group(argv[3])] if len(argv) == 4 else list(GROUPS)
        except ValueError as error:
            print(f"siloflow: {error}", file=sys.stderr)
            return 2
        copied = publish(argv[1], argv[2], groups)
        print(f"validation record of {', '.join(copied) or 'no group'} copied into {argv[2]}")
        return 0
    if len(argv) == 4 and argv[0] == "page":
        path = write_text(Path(argv[3]) / RECORD_PAGE, page(argv[1], argv[2], argv[3]))
        print(f"siloflow result: {path.resolve()}")
        return 0
    print("usage: validation_record_cli.py status CONFIG RECORD_DIR | publish WORKDIR RECORD_DIR [GROUP] | "
          "page CONFIG FULL_SCALE_CONFIG RECORD_DIR | check GROUP CONFIG RECORD_DIR | "
          "restore GROUP CONFIG RECORD_DIR WORKDIR | finished CONFIG WORKDIR [GROUP]",
          file=sys.stderr)
    return 2


if __name__ == "__main__":
    raise SystemExit(main())
