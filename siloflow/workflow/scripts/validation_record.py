"""Snakemake adapter: one validation group's record (its rows, the provenance of its runs, its plots), which `make
validate GROUP=<name>` then copies into docs/validation/<group>/."""

import subprocess
from datetime import datetime, timezone
from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.io.validation_record import benchmark_wall_time, read_validation_rows, write_group_record
from siloflow.analysis.studies.validation.record import provenance_row
from siloflow.engines.interface import engine_named
from siloflow.engines.layout import REPOSITORY_RECORD
from siloflow.engines.logs import logged_to


def _commit() -> str:
    """The commit of the code that writes the record, ``-dirty`` with uncommitted changes to anything but the record
    kept in the repository (which `make validate` rewrites group by group); ``unknown`` outside git."""
    where = Path(snakemake.scriptdir)
    head = subprocess.run(["git", "-C", str(where), "rev-parse", "HEAD"], capture_output=True, text=True, check=False)
    if head.returncode != 0:
        return "unknown"
    dirty = subprocess.run(["git", "-C", str(where), "status", "--porcelain", "--untracked-files=no", "--", ":/",
                            f":(top,exclude){REPOSITORY_RECORD}"],
                           capture_output=True, text=True, check=False).stdout.strip()
    return head.stdout.strip() + ("-dirty" if dirty else "")


with logged_to(snakemake.log[0]) as log:
    inputs, params = snakemake.input, snakemake.params
    commit, versions, runs = _commit(), {}, []
    for record_path, benchmark in zip(inputs.records, inputs.benchmarks):
        record = read_run_record(record_path)
        if record.engine not in versions:
            versions[record.engine] = engine_named(record.engine).installed_version()
        finished = datetime.fromtimestamp(Path(record_path).stat().st_mtime, tz=timezone.utc).date().isoformat()
        runs.append(provenance_row(record, params.made_by[record.run_id], versions[record.engine],
                                   params.seeds[record.run_id], commit, benchmark_wall_time(benchmark),
                                   engine_named(record.engine).earlier_attempts_seconds(Path(record_path).parent), finished))
    directory = write_group_record(Path(snakemake.output.runs).parent, read_validation_rows(inputs.rows), runs,
                                   dict(zip(params.plot_names, inputs.plots)),
                                   {path: path for path in inputs.products})
    log.info("record of %d runs in %s (code %s), with %d products other groups read", len(runs), directory, commit,
             len(inputs.products))
