"""``siloflow hypothesis NAME``: the record of a measured hypothesis (:mod:`siloflow.engines.hypotheses`) from its pair
of runs.

The command (in :mod:`siloflow.cli.main`) runs the base and the variant to their validation rows; this module reads
the two rows files, compares them (:func:`siloflow.analysis.studies.validation.hypothesis.compare_rows`) and writes
the hypothesis's record, ``docs/validation/hypotheses/<name>.csv``, with the pair's cost and the code that ran its runs.
"""

from __future__ import annotations

import math
from datetime import date
from pathlib import Path

from siloflow.analysis.io.validation_record import (HYPOTHESES_DIR, benchmark_wall_time, read_validation_rows,
                                                    write_hypothesis_record)
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.analysis.studies.validation.hypothesis import compare_rows
from siloflow.engines.config import layered_config, validate_config
from siloflow.engines.hypotheses import Hypothesis
from siloflow.engines.interface import engine_named
from siloflow.engines.layout import RESULTS, RUN_BENCHMARK, RUN_RECORD, SUMMARY_DIR
from siloflow.engines.provenance import read_attempts
from siloflow.model.record import read_run_record

__all__ = ["PAIR", "rows_file", "pair_core_seconds", "pair_commits", "configured_numbers", "record_hypothesis"]

#: The pair's runs, each in its own working folder under the hypothesis's.
PAIR = ("base", "variant")


def rows_file(hypothesis: Hypothesis, directory: Path, member: str) -> Path:
    """The validation rows of ``member`` (base or variant) of the pair run in ``directory``."""
    return directory / member / SUMMARY_DIR / "rows" / f"{hypothesis.group}.csv"


def _pair_runs(directory: Path) -> list[Path]:
    """The folders of the pair's engine runs (those whose run step Snakemake timed), base first."""
    return [benchmark.parent.parent for member in PAIR
            for benchmark in sorted((directory / member / RESULTS).rglob(RUN_BENCHMARK))]


def pair_core_seconds(directory: Path) -> float:
    """Core time of the pair's engine runs (CPU s): each finished run's time over all its attempts (its run step's
    Snakemake benchmark, the last attempt, plus the attempts before it from the engine's own log, as the groups'
    records count them) times its MPI ranks, over every run under ``directory``."""
    total = []
    for run_dir in _pair_runs(directory):
        wall = benchmark_wall_time(run_dir / RUN_BENCHMARK)
        if not (run_dir / RUN_RECORD).is_file():
            total.append(wall)  # a step that made no run record: one core
            continue
        record = read_run_record(run_dir / RUN_RECORD)
        total.append((wall + engine_named(record.engine).earlier_attempts_seconds(run_dir)) * record.mpi_ranks)
    return math.fsum(total)


def pair_commits(directory: Path) -> str:
    """The commits of siloflow's code that ran the pair's runs (each run's last attempt, as its provenance notes it:
    :mod:`siloflow.engines.provenance`), each once, in order; ``unknown`` for a run that noted none."""
    commits = [attempts[-1]["commit"] if (attempts := read_attempts(run_dir)) else "unknown"
               for run_dir in _pair_runs(directory)]
    return " ".join(dict.fromkeys(commits)) or "unknown"


def configured_numbers(config: dict) -> dict[str, tuple[float, float]]:
    """``{part id: (x, x)}`` of the finding parts whose number is the configuration's (:attr:`Part.configured`, a
    dotted key such as ``calibration.targets_deg.aluminium``), where ``config`` gives it: the point a move towards the
    study heads for."""
    numbers = {}
    for part in PARTS.values():
        if not part.configured:
            continue
        value = config
        for key in part.configured.split("."):
            value = value.get(key) if isinstance(value, dict) else None
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            numbers[part.id] = (float(value), float(value))
    return numbers


def record_hypothesis(hypothesis: Hypothesis, directory: Path, record_dir: Path, root: Path = Path(".")) -> Path:
    """Compare the pair run in ``directory`` and write the hypothesis's record under ``record_dir``; returns its path.
    The configured numbers some parts are judged against are the base's, its files under the clone ``root``.

    Raises
    ------
    FileNotFoundError
        When a member's rows are missing (its run has not finished), naming the file.
    ValueError
        When the two members do not judge the same rows (:func:`compare_rows`).
    """
    files = {member: rows_file(hypothesis, directory, member) for member in PAIR}
    for member, path in files.items():
        if not path.is_file():
            raise FileNotFoundError(f"hypothesis {hypothesis.name!r}: the {member}'s rows {path} are not made yet; "
                                    f"`make hypothesis NAME={hypothesis.name}` carries its runs on")
    base_config = validate_config(layered_config(hypothesis.base_files(root)))
    rows = compare_rows(hypothesis.name, hypothesis.statement, hypothesis.change, hypothesis.findings,
                        read_validation_rows(files["base"]), read_validation_rows(files["variant"]),
                        configured_numbers(base_config))
    provenance = {"core_hours": pair_core_seconds(directory) / 3600.0, "commit": pair_commits(directory),
                  "date": date.today().isoformat()}
    return write_hypothesis_record(Path(record_dir) / HYPOTHESES_DIR / f"{hypothesis.name}.csv",
                                   [{**row, **provenance} for row in rows])
