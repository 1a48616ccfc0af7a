"""One engine run of one case, from a validated configuration to its checked run record.

The workflow's deck and run steps call these two functions with the case the workflow built when it was parsed
(:mod:`siloflow.model.cases`; neither builds one): they pick the engine that runs it (:mod:`siloflow.engines.interface`) and, before a
run, check the disk and log what it will cost (:mod:`siloflow.engines.planning`).
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.kinds import kind_of_case
from siloflow.model.cases.common import engine_kind
from siloflow.engines.estimates import estimate_case
from siloflow.engines.interface import EngineOptions, engine_for
from siloflow.engines.planning import cost_model, preflight

__all__ = ["render_run", "run_case"]


def _check_kind(case_kind: str, case) -> None:
    if kind_of_case(case).name != case_kind:
        raise TypeError(f"a {type(case).__name__} is no {case_kind} case")


def render_run(config: dict, case_kind: str, case, run_dir: str | Path, assembly_dir: str | Path | None = None) -> Path:
    """Write the engine inputs of ``case`` (a run of ``case_kind`` of the validated ``config``) into
    ``<run_dir>/deck/``, with the settled fill of the run in ``assembly_dir`` where the case starts from one
    (:meth:`siloflow.engines.interface.Engine.place_assembly`); returns ``deck/case.json``."""
    _check_kind(case_kind, case)
    run = case.run_id
    summary = engine_for(config, case_kind).write_inputs(case, run_dir, assembly_dir)
    logging.getLogger("siloflow").info("%s inputs of %s run %s written; case summary %s",
                                       engine_kind(config, case_kind), case_kind, run, summary)
    return summary


def run_case(config: dict, case_kind: str, case, run_dir: str | Path, mpi_ranks: int | None = None) -> RunRecord:
    """Run the rendered inputs of ``case`` (a run of ``case_kind`` of the validated ``config``) on its engine, after
    checking the disk and logging the estimate; returns the run record (also written as ``<run_dir>/run.json``).
    ``mpi_ranks``: the ranks the workflow gives the run (its step's threads), instead of ``engine.mpi_ranks``."""
    _check_kind(case_kind, case)
    kind = engine_kind(config, case_kind)
    options = EngineOptions.from_config(config, kind)
    if mpi_ranks is not None:
        options = dataclasses.replace(options, mpi_ranks=mpi_ranks)
    logging.getLogger("siloflow").info(preflight(config, estimate_case(case, options.mpi_ranks, cost_model(config)), run_dir))
    return engine_for(config, case_kind).run(case, run_dir, options)
