"""``siloflow record``: the validation record in ``docs/validation/``, against the runs a configuration plans.

``status`` prints, per group, whether the record is complete, stale or missing against the runs ``--config``
(default ``config/validation.yaml``) plans (:func:`siloflow.engines.validation_groups.group_status`); ``publish``
copies the records a validation run wrote in ``--directory`` into the record; ``page`` writes the record's page
(``README.md``) from the record (:func:`siloflow.analysis.studies.validation.record.record_page`); ``check --group``
refuses, before anything runs, an unknown group or part, a group that runs in parts (naming them), one whose rows
compare against a group not yet complete in the record, or a configuration whose plots are not PNG, which the record
keeps (``plots.format``); ``restore --group`` checks as ``check`` does, then copies into ``--directory`` the products
of the runs of the groups it reads that their records keep and the folder lacks (so that a group reads the runs
another session made instead of making them again); ``finished`` prints the groups (of ``--group``'s only) whose
every run has finished in ``--directory``, whose record ``make validate`` then writes; ``rederive`` derives a group's
rows again from the products its record keeps, with today's row code (no run).
"""

from __future__ import annotations

import argparse
import math
import sys
from itertools import zip_longest
from pathlib import Path
from typing import Sequence

from siloflow.analysis.io.tables import write_text
from siloflow.analysis.io.validation_products import read_group_products, row_code_digest
from siloflow.analysis.io.validation_record import (PRODUCTS, check_plot_format, read_group_record, read_hypothesis_records,
                                           read_record, restore_products, write_group_record)
from siloflow.analysis.studies.validation.group_rows import UNMADE, judged_rows
from siloflow.analysis.studies.validation.findings import FINDINGS
from siloflow.analysis.studies.validation.record import earlier_attempt_times, record_page, run_wall_time
from siloflow.analysis.studies.validation.scale import FINDING_SCALES, scale_verdict
from siloflow.calibration.table import point_table
from siloflow.engines.config import load_config
from siloflow.engines.hypotheses import HYPOTHESES
from siloflow.engines.layout import RESULTS, RUN_RECORD, VALIDATION_RECORD
from siloflow.engines.planning import config_estimates, group_runs, run_directory
from siloflow.engines.validation_groups import (GROUP_BUDGET_S, GROUPS, MISSING, STALE, TIER_BUDGET_CORE_S, check_group,
                                       check_reads, find_part, finished_groups, group_costs, group_of_part,
                                       group_status, planned_runs, runs_wall_time, split_groups, status_lines)

#: The record's page, in its folder.
RECORD_PAGE = "README.md"


def _run_ids(record: dict) -> dict[str, set[str]]:
    """``{group: {run id}}`` of a record read with :func:`siloflow.analysis.io.validation_record.read_record`."""
    return {name: {run["run_id"] for run in group.runs} for name, group in record.items()}


def other_row_code(record: dict) -> dict[str, bool]:
    """``{group: whether its record keeps what re-derives its rows}`` of the recorded groups whose rows were written by
    other row code than today's (:func:`siloflow.analysis.io.validation_products.row_code_digest`)."""
    today = row_code_digest()
    return {name: group.derivation is not None for name, group in record.items()
            if (group.derivation or {}).get("row_code") != today}


def rederive(config_path: str, record_dir: str | Path, groups: Sequence[str]) -> dict[str, int]:
    """Derive again the rows of each of ``groups`` from the products its record keeps, with today's row code and
    ``config_path``'s ``validation`` section and dimensions, and write them into its record (its runs, plots and
    products unchanged). A product is looked for in the group's own record, then in those of the groups it reads.
    Returns ``{group: rows}``; refuses (ValueError) a group whose record keeps no derivation or lacks a product, or
    whose recorded runs are not those ``config_path`` plans (its dimensions are not theirs)."""
    config = load_config(config_path)
    record_dir = Path(record_dir)
    planned = planned_runs(group_runs(config, config_estimates(config)))
    written = {}
    for name in groups:
        group = read_group_record(record_dir / name) if (record_dir / name / "runs.csv").is_file() else None
        if group is None or group.derivation is None:
            raise ValueError(f"{name}: its record keeps no derivation (written before records kept one): "
                             f"`make validate GROUP={name}` records it again")
        # a row's scale verdict is judged on the configuration's dimensions: only those of the runs it comes from
        recorded = {run["run_id"] for run in group.runs}
        if recorded != planned.get(name, set()):
            raise ValueError(f"{name}: its recorded runs are not those {config_path} plans, so their rows cannot be "
                             f"judged on its dimensions: `make validate GROUP={name}` records it again")
        derivation = group.derivation
        places = [record_dir / other / PRODUCTS for other in (name, *GROUPS[name].reads)]

        def found(path: str) -> Path:
            for place in places:
                if (place / path).is_file():
                    return place / path
            raise ValueError(f"{name}: product {path} is in none of the records of {', '.join((name, *GROUPS[name].reads))}")

        kind = derivation["kind"]
        inputs = {key: [found(path) for path in paths] for key, paths in derivation["inputs"].items()}
        data = read_group_products(kind, inputs)
        if kind == "jenike":
            data["points"] = point_table(data["summaries"])
        rows = judged_rows(kind, data, derivation["params"], config["validation"],
                           lambda finding, as_study: scale_verdict(finding, kind, config, as_study))
        write_group_record(record_dir / name, rows, group.runs, {plot: record_dir / name / plot for plot in group.plots},
                           {product: record_dir / name / PRODUCTS / product for product in group.products},
                           {**derivation, "row_code": row_code_digest()})
        written[name] = len(rows)
    return written


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
                               {product: source / PRODUCTS / product for product in record.products},
                               record.derivation)
            copied.append(name)
    return copied


def measured_wall_times(record: dict, cores: int, sliced: frozenset[str] = frozenset()) -> dict[str, dict[str, float]]:
    """``{group: {part: s}}``: the wall time of each `make validate GROUP=` call of each recorded group, on ``cores``
    cores (:func:`siloflow.engines.validation_groups.runs_wall_time`); the runs a group reads from another group are
    not its own.

    A run's ``group`` column names the part that finished it, which counts the run over all its attempts (one
    interrupted and run again inside its part took the part that long). A run of ``sliced``, longer than a part and
    carried on over several (:attr:`siloflow.engines.validation_groups.Part.time_slice`), counts only its last
    attempt there: its earlier attempts ran in earlier calls, each listed as ``<group> earlier attempt <k>``, the
    longest k-th earlier attempt of the group's sliced runs (they run side by side from their first part, so their
    k-th attempts share a call).
    """
    walls = {}
    for name, group in record.items():
        made: dict[str, list] = {}
        earlier = []
        for run in group.runs:
            if group_of_part(run["group"]) != name:
                continue
            if run["run_id"] in sliced:
                made.setdefault(run["group"], []).append((float(run["wall_time_s"]), int(run["cores"])))
                earlier.append(earlier_attempt_times(run))
            else:
                made.setdefault(run["group"], []).append((run_wall_time(run), int(run["cores"])))
        walls[name] = {part: runs_wall_time(runs, cores) for part, runs in sorted(made.items())}
        calls = [max(times) for times in zip_longest(*earlier, fillvalue=0.0)]
        walls[name].update({f"{name} earlier attempt {k}": seconds for k, seconds in enumerate(calls, 1)})
    return walls


def sliced_runs(made: dict[str, list]) -> frozenset[str]:
    """Run ids that a configuration's plan carries over several parts (each longer than a part on its own)."""
    return frozenset(made[part.group][position].run_id for group_parts in split_groups(made).values()
                     for part in group_parts if part.time_slice is not None for position in part.positions)


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
    group's measured wall time on ``cores`` cores beside its estimate, its parts and its cost at the scale of
    ``full_scale_path``."""
    config = load_config(config_path)
    made = group_runs(config, config_estimates(config))
    estimated = {estimate.run_id: estimate.core_seconds for runs in made.values() for estimate in runs}
    # the dimensions alone: whether each row computes its quantity as the study defines it is the row's to say
    verdicts = {finding.id: scale_verdict(finding.id, FINDING_SCALES[finding.id].kind, config, True)
                for finding in FINDINGS}
    record = read_record(record_dir, GROUPS)
    status = group_status(planned_runs(made), _run_ids(record), other_row_code(record))
    parts = {name: [part.name for part in group_parts] for name, group_parts in split_groups(made).items()}
    full_scale = {cost.name: cost.core_seconds for cost in group_costs(_plan(full_scale_path)[1], cores=1)}
    return record_page(record, status, {name: full_scale.get(name, math.nan) for name in GROUPS},
                       measured_wall_times(record, cores, sliced_runs(made)), cores, config_path, full_scale_path,
                       parts, estimated,
                       verdicts, UNMADE, {cost.name: cost.core_seconds for cost in group_costs(made, cores=1)},
                       read_hypothesis_records(record_dir), {name: h.findings for name, h in HYPOTHESES.items()},
                       (TIER_BUDGET_CORE_S, GROUP_BUDGET_S))


#: The configurations and the record the commands take by default, relative to the working directory.
VALIDATION_CONFIG, FULL_SCALE_CONFIG, RECORD_DIR = "config/validation.yaml", "config/thesis.yaml", "docs/validation"


class RecordError(ValueError):
    """A record command's refusal; its message is the one line the user reads."""


def _config(args: argparse.Namespace) -> str:
    files = args.config or [VALIDATION_CONFIG]
    if len(files) != 1:
        raise RecordError("the record is judged against one configuration: give --config once")
    if not Path(files[0]).is_file():
        raise RecordError(f"config file {files[0]!r}: no such file")
    return files[0]


def _status(args: argparse.Namespace) -> int:
    config = _config(args)
    try:
        planned, recorded = _planned(config), recorded_runs(args.record)
    except ValueError as error:
        raise RecordError(str(error)) from None
    other = other_row_code(read_record(args.record, GROUPS))
    print(f"The validation record in {args.record} against the runs {config} plans and today's row code:")
    print("\n".join(status_lines(planned, recorded, other)))
    print("\n".join(hypothesis_lines(read_hypothesis_records(args.record))))
    return 1 if {STALE, MISSING} & set(group_status(planned, recorded, other).values()) else 0


def hypothesis_lines(recorded: Sequence[dict]) -> list[str]:
    """`make validate-status`'s lines on the measured hypotheses (:data:`siloflow.engines.hypotheses.HYPOTHESES`):
    each recorded one with its date and its rows, each other one with the command that records it."""
    lines = ["Measured hypotheses (make hypothesis NAME=<name>):"]
    for name, hypothesis in HYPOTHESES.items():
        rows = [row for row in recorded if row["hypothesis"] == name]
        lines.append(f"{name:22s} recorded {rows[0]['date']}: {len(rows)} rows of {', '.join(hypothesis.findings)}"
                     if rows else f"{name:22s} not recorded: make hypothesis NAME={name}")
    return lines


def _rederive(args: argparse.Namespace) -> int:
    try:
        groups = [check_group(args.group)] if args.group else [
            name for name, derivable in other_row_code(read_record(args.record, GROUPS)).items() if derivable]
        written = rederive(_config(args), args.record, groups)
    except ValueError as error:
        raise RecordError(str(error)) from None
    for name, count in written.items():
        print(f"siloflow: {count} rows of {name} derived again from the products its record keeps")
    if not written:
        print("siloflow: no group's rows to derive again")
    return 0


def _publish(args: argparse.Namespace) -> int:
    try:
        groups = [check_group(args.group)] if args.group else list(GROUPS)
    except ValueError as error:
        raise RecordError(str(error)) from None
    copied = publish(args.directory, args.record, groups)
    print(f"validation record of {', '.join(copied) or 'no group'} copied into {args.record}")
    return 0


def _page(args: argparse.Namespace) -> int:
    config = _config(args)
    if not Path(args.full_scale).is_file():
        raise RecordError(f"config file {args.full_scale!r}: no such file")
    path = write_text(Path(args.record) / RECORD_PAGE, page(config, args.full_scale, args.record, args.cores))
    print(f"siloflow result: {path.resolve()}")
    return 0


def _check_command(args: argparse.Namespace) -> int:
    try:
        check(args.group, _config(args), args.record)
    except ValueError as error:
        raise RecordError(str(error)) from None
    return 0


def _restore(args: argparse.Namespace) -> int:
    try:
        restored = restore(args.group, _config(args), args.record, args.directory)
    except ValueError as error:
        raise RecordError(str(error)) from None
    for other, count in restored.items():
        print(f"siloflow: {count} products of the runs of {other} restored from {args.record}/{other} into "
              f"{args.directory}")
    return 0


def _finished(args: argparse.Namespace) -> int:
    try:
        ready, waiting = finished(_config(args), args.directory, args.group)
    except ValueError as error:
        raise RecordError(str(error)) from None
    for line in waiting:
        print(f"siloflow: {line}", file=sys.stderr)
    print(" ".join(ready))
    return 0


def add_parser(commands, common) -> None:
    """Add ``record`` and its commands to the command line's subcommands; ``common`` adds --config, --cores and
    --directory to a parser."""
    parser = commands.add_parser("record", help="the validation record: status, publish, page, check, restore, "
                                 "finished, rederive", description=__doc__.split("\n\n")[0].strip('"'))
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True, parser_class=type(parser))
    working = "the validation run's working folder (its results/ holds the runs; default: the current folder)"
    for name, handler, help_text, group in (
            ("status", _status, "whether each group's record is complete, stale or missing (exit 1 if any is not "
                                "complete)", None),
            ("publish", _publish, "copy the records a validation run wrote into the record", "optional"),
            ("page", _page, "write the record's page (README.md) from the record", None),
            ("check", _check_command, "refuse a group that cannot run now, before anything runs", "required"),
            ("restore", _restore, "check a group, then restore the runs it reads from the record", "required"),
            ("finished", _finished, "print the groups whose every run has finished", "optional"),
            ("rederive", _rederive, "derive a group's rows again from the products its record keeps (default: "
                                    "every group whose rows other row code wrote and whose record can)", "optional")):
        sub = verbs.add_parser(name, help=help_text, description=help_text[0].upper() + help_text[1:] + ".")
        common(sub, working)
        sub.add_argument("--record", default=RECORD_DIR, metavar="DIR",
                         help=f"the record's folder (default: {RECORD_DIR})")
        if name == "page":
            sub.add_argument("--full-scale", default=FULL_SCALE_CONFIG, metavar="FILE",
                             help=f"the full-scale configuration the page quotes costs of (default: {FULL_SCALE_CONFIG})")
        if group:
            sub.add_argument("--group", required=group == "required", metavar="NAME",
                             help="a group of the record or a part of one (silo_1, ...)")
        sub.set_defaults(handler=handler)
