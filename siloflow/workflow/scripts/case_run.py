"""Snakemake adapter: run the rendered inputs of one run of any case on its engine and check it (run.json last), from
the case the workflow built; each attempt first notes the code's commit and the engine's version in the run's folder.
Under a validation part's deadline (siloflow.engines.deadline) the engine stops when the part's time is up."""

import os
from pathlib import Path

from siloflow.engines.deadline import deadline_from, until
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to
from siloflow.engines.provenance import code_commit, note_attempt
from siloflow.engines.runs import run_case
from siloflow.model.cases.common import engine_kind

with logged_to(snakemake.log[0]):
    run_dir = Path(snakemake.output.record).parent
    engine = engine_kind(snakemake.config, snakemake.params.kind)
    note_attempt(run_dir, engine, engine_named(engine).installed_version(), code_commit(snakemake.scriptdir))
    with until(deadline_from(os.environ), f"{snakemake.params.kind} run {run_dir.name}"):
        # the step's threads are its MPI ranks (the workflow's mpi_ranks: a run alone in its parts takes both cores)
        run_case(snakemake.config, snakemake.params.kind, snakemake.params.case, run_dir, snakemake.threads)
