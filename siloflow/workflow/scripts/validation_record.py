"""Snakemake adapter: one validation group's record (its rows, the provenance of its runs, its plots, the products its
rows are computed from and what re-derives them), which `make validate GROUP=<name>` then copies into
docs/validation/<group>/."""

from datetime import datetime, timezone
from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.io.validation_products import row_code_digest
from siloflow.analysis.io.validation_record import benchmark_wall_time, read_validation_rows, write_group_record
from siloflow.analysis.studies.validation.record import provenance_row
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to
from siloflow.engines.provenance import code_commit, read_attempts

with logged_to(snakemake.log[0]) as log:
    inputs, params = snakemake.input, snakemake.params
    writer, versions, runs = code_commit(snakemake.scriptdir), {}, []
    for record_path, benchmark in zip(inputs.records, inputs.benchmarks):
        record = read_run_record(record_path)
        run_dir = Path(record_path).parent
        attempts = read_attempts(run_dir)
        if attempts:
            commit, version = attempts[-1]["commit"], attempts[-1]["engine_version"]
        else:
            # a run made before its attempts were noted: the engine installed now, the code unknown
            if record.engine not in versions:
                versions[record.engine] = engine_named(record.engine).installed_version()
            commit, version = f"unknown (recorded by {writer})", versions[record.engine]
        finished = datetime.fromtimestamp(Path(record_path).stat().st_mtime, tz=timezone.utc).date().isoformat()
        runs.append(provenance_row(record, params.made_by[record.run_id], version, params.seeds[record.run_id], commit,
                                   benchmark_wall_time(benchmark), engine_named(record.engine).earlier_attempt_seconds(run_dir),
                                   finished, len(attempts) or None))
    derivation = {**params.derivation, "row_code": row_code_digest(), "written_by": writer}
    directory = write_group_record(Path(snakemake.output.runs).parent, read_validation_rows(inputs.rows), runs,
                                   dict(zip(params.plot_names, inputs.plots)),
                                   {path: path for path in inputs.products}, derivation)
    log.info("record of %d runs in %s (written by %s), with %d products", len(runs), directory, writer,
             len(inputs.products))
