"""The ``siloflow`` command: run a configuration's workflow, check it, estimate it, render its engine inputs, say
what a results folder holds, and keep the validation record.

Every command takes ``--config`` (repeatable: later files layer over earlier ones, as Snakemake's ``--configfile``
does) and ``--cores``. A usage error, a missing file or a configuration the schema refuses is answered in one line on
standard error with exit code 2, before anything runs; a run that another launcher holds answers with exit code 75.
The make targets of the clone call these commands.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Sequence

from siloflow.cli import record
from siloflow.cli.hypothesis import PAIR, record_hypothesis
from siloflow.engines.config import PACKAGE_ROOT, ConfigError, layered_config, validate_config
from siloflow.engines.config_yaml import ConfigFileError
from siloflow.engines.deadline import DEADLINE_VARIABLE
from siloflow.engines.estimates import format_bytes, total_dump_bytes
from siloflow.engines.hypotheses import HYPOTHESES, hypothesis_directory, hypothesis_named
from siloflow.engines.layout import RESULTS
from siloflow.engines.planning import estimate_report
from siloflow.engines.preflight import Preflight, PreflightError, preflight
from siloflow.engines.results_status import results_status, scan_results, status_lines
from siloflow.engines.runs import render_run
from siloflow.engines.validation_groups import GROUP_BUDGET_S, PART_FILL
from siloflow.engines.workflow_lock import LiveRunError, launch
from siloflow.model.cases.kinds import configured_kinds

#: The configuration a command takes when ``--config`` is not given, relative to the working directory.
DEFAULT_CONFIG = "config/config.yaml"
#: The report ``siloflow run`` writes, relative to the working directory (``--directory``).
DEFAULT_REPORT = f"{RESULTS}/report.html"
#: The package's workflow and its own profile (the rerun policy: package data, so that an installed siloflow runs).
SNAKEFILE = PACKAGE_ROOT / "workflow" / "Snakefile"
WORKFLOW_PROFILE = PACKAGE_ROOT / "workflow" / "profiles" / "default"
#: Exit codes: a usage error or refused input, and a run that is live in the same folder (EX_TEMPFAIL).
USAGE_ERROR, LIVE_RUN = 2, 75


class UsageError(Exception):
    """What a command refuses before it does anything; its message is the one line the user reads."""


class _Parser(argparse.ArgumentParser):
    """argparse with its errors in one line: the usage it would print is one ``--help`` away."""

    def error(self, message: str):
        self.exit(USAGE_ERROR, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _cores(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"takes a whole number of cores >= 1, got {text!r}")
    return int(text)


def _common(parser: argparse.ArgumentParser, directory_help: str) -> None:
    parser.add_argument("--config", action="append", metavar="FILE",
                        help=f"configuration file (default: {DEFAULT_CONFIG}); give it again to layer another file "
                             "over it, e.g. --config config/config.yaml --config config/checks.yaml")
    parser.add_argument("--cores", type=_cores, default=2, metavar="N", help="cores to use or plan for (default: 2)")
    parser.add_argument("--directory", default=".", metavar="DIR", help=directory_help)


def _config_files(args: argparse.Namespace) -> list[Path]:
    files = [Path(name) for name in (args.config or [DEFAULT_CONFIG])]
    for path in files:
        if not path.is_file():
            raise UsageError(f"config file {str(path)!r}: no such file" if not path.exists()
                             else f"config file {str(path)!r} is not a file")
    return files


def _directory(args: argparse.Namespace, must_exist: bool = False) -> Path:
    directory = Path(args.directory)
    if directory.exists() and not directory.is_dir():
        raise UsageError(f"--directory {args.directory!r} is not a folder")
    if must_exist and not directory.is_dir():
        raise UsageError(f"--directory {args.directory!r}: no such folder")
    return directory


def _checked(files: Sequence[Path], directory: Path) -> Preflight:
    """The workflow's own check of the configuration (:func:`siloflow.engines.preflight.preflight`), with the
    configuration's relative paths (PIV files, existing runs) taken from ``directory`` as the workflow takes them."""
    absolute = [path.resolve() for path in files]
    try:
        raw = layered_config(absolute)
    except ConfigError as error:
        raise UsageError(f"invalid configuration: {error}") from None  # the message names the file
    previous = Path.cwd()
    os.chdir(directory if directory.is_dir() else previous)
    try:
        return preflight(raw, absolute)
    except PreflightError as error:
        raise UsageError(f"{_label(files)}: {error}") from None
    finally:
        os.chdir(previous)


def _validated(files: Sequence[Path]) -> dict:
    """The configuration validated against the schema, defaults filled, without the workflow's other checks (the
    engines need not be installed to plan a run for another machine)."""
    try:
        raw = layered_config([path.resolve() for path in files])
    except ConfigError as error:
        raise UsageError(f"invalid configuration: {error}") from None  # the message names the file
    try:
        return validate_config(raw)
    except ConfigError as error:
        raise UsageError(f"{_label(files)}: invalid configuration: {error}") from None


def _label(files: Sequence[Path]) -> str:
    return " + ".join(str(path) for path in files)


# ---------------------------------------------------------------------------------------------------------- commands


def check(args: argparse.Namespace) -> int:
    """Validate a configuration and plan it: nothing runs."""
    files = _config_files(args)
    checked = _checked(files, _directory(args))
    by_kind: dict[str, int] = {}
    for estimate in checked.estimates:
        by_kind[estimate.kind] = by_kind.get(estimate.kind, 0) + 1
    core_hours = sum(estimate.core_seconds for estimate in checked.estimates) / 3600.0
    runs = ", ".join(f"{kind} {count}" for kind, count in by_kind.items())
    print(f"{_label(files)}: valid. {len(checked.estimates)} engine runs ({runs}); about {core_hours:.3g} core-hours "
          f"({core_hours / args.cores:.3g} h on {args.cores} cores if every core is busy) and "
          f"{format_bytes(total_dump_bytes(checked.estimates))} of dumps. Nothing was run; `siloflow estimate` gives each run's cost.")
    return 0


def estimate(args: argparse.Namespace) -> int:
    """Print the cost of every run of a configuration, and measured against estimated for its finished runs."""
    files = _config_files(args)
    directory = _directory(args)
    config = _validated(files)
    try:
        report = estimate_report(config, _label(files), directory / RESULTS, args.cores)
    except ValueError as error:  # a configuration whose runs cannot be planned
        raise UsageError(f"invalid configuration: {error}") from None
    print(report)
    return 0


def render(args: argparse.Namespace) -> int:
    """Write the engine inputs of every run of a configuration without running them."""
    files = _config_files(args)
    output = Path(args.output)
    if output.exists() and (not output.is_dir() or any(output.iterdir())):
        raise UsageError(f"--output {args.output!r} exists and is not an empty folder; siloflow writes inputs into a "
                         "new or empty folder only, so that nothing there is overwritten")
    checked = _checked(files, _directory(args))
    written = 0
    for kind, cases in checked.cases.items():
        for run_id, case in cases.items():
            summary = render_run(checked.config, kind, case, output / kind / run_id)
            print(f"siloflow inputs: {summary.parent}")
            written += 1
    print(f"{written} runs' engine inputs written under {output}/ (the flat-bottom silo's as configured, before "
          f"any calibration replaces its parameters)")
    return 0


def status(args: argparse.Namespace) -> int:
    """Say what a results folder holds for a configuration: finished, unfinished and planned runs, run folders it no
    longer plans, and whether the report is stale."""
    files = _config_files(args)
    directory = _directory(args, must_exist=True)
    checked = _checked(files, directory)
    results = directory / RESULTS
    listing = scan_results(results, configured_kinds(), directory / DEFAULT_REPORT)
    print(f"{results}/ against {_label(files)}:")
    print("\n".join(status_lines(results_status(checked.estimates, listing), str(results))))
    return 0


def snakemake_arguments(files: Sequence[Path], directory: Path, cores: int, targets: Sequence[str],
                        extra: Sequence[str]) -> list[str]:
    """Snakemake's arguments for the package's workflow: the targets first (``--configfile`` takes every word after
    it), then the workflow, its profile, the working directory, the configuration files and the cores."""
    return [*targets, "--snakefile", str(SNAKEFILE), "--workflow-profile", str(WORKFLOW_PROFILE),
            "--directory", str(directory.resolve()), "--cores", str(cores), *extra,
            "--configfile", *(str(path.resolve()) for path in files)]


def run(args: argparse.Namespace) -> int:
    """Run the workflow of a configuration (resuming what an interrupted run left), then write its report."""
    files = _config_files(args)
    directory = _directory(args)
    _checked(files, directory)
    directory.mkdir(parents=True, exist_ok=True)
    extra = [*(["--keep-going"] if args.keep_going else []), *(["--dry-run"] if args.dry_run else [])]
    if args.part_deadline:
        # the run steps Snakemake starts inherit it (siloflow.engines.deadline)
        os.environ[DEADLINE_VARIABLE] = repr(time.time() + PART_FILL * GROUP_BUDGET_S)
    code = launch(snakemake_arguments(files, directory, args.cores, args.target, extra))
    if code != 0 or args.no_report or args.dry_run:
        return code
    report = Path(args.report) if args.report else directory / DEFAULT_REPORT
    return launch(snakemake_arguments(files, directory, args.cores, args.target,
                                      ["--report", str(report.resolve())]))


def hypothesis(args: argparse.Namespace) -> int:
    """Run a measured hypothesis's pair (its base, then its variant) to their validation rows, the engine runs of both
    stopped at one validation part's deadline from the call's start (the next call carries them on), and record the
    comparison once both are made."""
    try:
        chosen = hypothesis_named(args.name)
    except ValueError as error:
        raise UsageError(str(error)) from None
    directory = hypothesis_directory(chosen.name, _directory(args))
    members = dict(zip(PAIR, (chosen.base_files(), chosen.variant_files())))
    for member, files in members.items():  # both checked before anything runs
        for path in files:
            if not path.is_file():
                raise UsageError(f"hypothesis {chosen.name!r}: its {member}'s configuration {str(path)!r} is missing; "
                                 "run it from the clone's top folder")
        # as `siloflow run` checks its --directory: relative paths from the member's folder once it exists
        _checked(files, directory / member)
    os.environ[DEADLINE_VARIABLE] = repr(time.time() + PART_FILL * GROUP_BUDGET_S)
    for member, files in members.items():
        (directory / member).mkdir(parents=True, exist_ok=True)
        code = launch(snakemake_arguments(files, directory / member, args.cores, [f"validation_rows_{chosen.group}"],
                                          ["--keep-going", *(["--dry-run"] if args.dry_run else [])]))
        if code != 0:
            print(f"siloflow hypothesis: the {member} of {chosen.name} stopped (exit {code}); "
                  f"`make hypothesis NAME={chosen.name}` carries it on from its restart files", file=sys.stderr)
            return code
    if args.dry_run:
        return 0
    try:
        path = record_hypothesis(chosen, directory, Path(args.record))
    except ValueError as error:
        raise UsageError(str(error)) from None
    print(f"siloflow result: {path.resolve()}")
    return 0


# ------------------------------------------------------------------------------------------------------------ parser


def parser() -> argparse.ArgumentParser:
    """The command line's parser: one subcommand per job."""
    top = _Parser(prog="siloflow", description="DEM calibration, validation and blending of pellets in silos, from "
                  "config files to plots (LIGGGHTS and YADE through Snakemake).")
    top.add_argument("--version", action="version", version=f"siloflow {_version()}")
    commands = top.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    in_folder = "working folder: results/ and Snakemake's state go there (default: the current folder)"

    sub = commands.add_parser("run", help="run a configuration's workflow, then write its report",
                              description="Run the workflow of a configuration on real engines, resuming what an "
                                          "interrupted run left, then write the report (results/report.html).")
    _common(sub, in_folder)
    sub.add_argument("--target", action="append", default=[], metavar="RULE",
                     help="a workflow target to make instead of the whole pipeline (repeatable), e.g. "
                          "bayesian_calibration or validate_silo")
    sub.add_argument("--report", metavar="FILE", help=f"where the report goes (default: DIR/{DEFAULT_REPORT})")
    sub.add_argument("--no-report", action="store_true", help="run only, write no report")
    sub.add_argument("--keep-going", action="store_true", help="go on with independent runs when one fails")
    sub.add_argument("--dry-run", action="store_true", help="print what would run, run nothing")
    sub.add_argument("--part-deadline", action="store_true",
                     help=f"stop the engine runs {PART_FILL * GROUP_BUDGET_S / 3600:g} h from now, a validation "
                          "part's time; a stopped run carries on from its restart files the next time")
    sub.set_defaults(handler=run)

    sub = commands.add_parser("check", help="validate a configuration and plan it; nothing runs",
                              description="Validate a configuration as the workflow does before anything runs (the "
                                          "schema, every case it builds, the engines it needs, the files it names) "
                                          "and plan its runs.")
    _common(sub, "folder the configuration's relative paths start from (default: the current folder)")
    sub.set_defaults(handler=check)

    sub = commands.add_parser("estimate", help="print the cost of every run of a configuration",
                              description="Print particle counts, steps, CPU and wall time and disk of every run of a "
                                          "configuration, each validation group's cost and, for finished runs, "
                                          "estimated against measured CPU time.")
    _common(sub, in_folder)
    sub.set_defaults(handler=estimate)

    sub = commands.add_parser("render", help="write the engine inputs of a configuration without running them",
                              description="Write the engine inputs (decks and scripts) of every run of a "
                                          "configuration into OUTPUT/<case kind>/<run id>/deck/, running nothing.")
    _common(sub, "folder the configuration's relative paths start from (default: the current folder)")
    sub.add_argument("--output", required=True, metavar="OUTPUT", help="a new or empty folder")
    sub.set_defaults(handler=render)

    sub = commands.add_parser("status", help="say what a results folder holds and what is stale",
                              description="Say, for a configuration, which of its runs have finished in a working "
                                          "folder, which are unfinished or still to do, which run folders it no "
                                          "longer plans, and whether the report is older than its runs.")
    _common(sub, in_folder)
    sub.set_defaults(handler=status)

    sub = commands.add_parser("hypothesis", help="run a measured hypothesis's pair and record where it moves the "
                                                 "findings",
                              description="Run a measured hypothesis of the validation record (a reduced case and the "
                                          "same with one change) to its validation rows, then record, per row, whether "
                                          "the change moves the figure towards the study: "
                                          "docs/validation/hypotheses/NAME.csv. Each call stops its engine runs "
                                          f"{PART_FILL * GROUP_BUDGET_S / 3600:g} h after it starts; the next carries "
                                          "them on. The hypotheses: " + ", ".join(HYPOTHESES) + ".")
    sub.add_argument("name", metavar="NAME", help="the hypothesis: " + ", ".join(HYPOTHESES))
    sub.add_argument("--cores", type=_cores, default=2, metavar="N", help="cores to use (default: 2)")
    sub.add_argument("--directory", default=".", metavar="DIR",
                     help="working folder: the pair runs in DIR/results/hypotheses/NAME/ (default: the current folder)")
    sub.add_argument("--record", default=record.RECORD_DIR, metavar="DIR",
                     help=f"the validation record's folder (default: {record.RECORD_DIR})")
    sub.add_argument("--dry-run", action="store_true", help="print what the pair would run, run and record nothing")
    sub.set_defaults(handler=hypothesis)

    record.add_parser(commands, _common)
    return top


def _version() -> str:
    try:
        return version("siloflow")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "unknown"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns its exit code."""
    try:
        args = parser().parse_args(argv)
    except SystemExit as exit:  # --help, --version and usage errors end here, with argparse's code
        return exit.code if isinstance(exit.code, int) else USAGE_ERROR
    if args.command is None:
        parser().print_help(sys.stderr)
        return USAGE_ERROR
    try:
        return args.handler(args)
    except (UsageError, record.RecordError, ConfigFileError, ConfigError) as error:
        print(f"siloflow {args.command}: {error}", file=sys.stderr)
        return USAGE_ERROR
    except LiveRunError as error:
        print(f"siloflow {args.command}: {error}", file=sys.stderr)
        return LIVE_RUN
