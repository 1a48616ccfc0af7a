"""One engine run of one case, from a validated configuration to its checked run record.

The workflow's deck and run steps call these two functions: they build the case the configuration defines for a
run id (:mod:`model.cases`), pick the engine that runs it (:mod:`engines.interface`) and, before a run, check the
disk and log what it will cost (:mod:`engines.planning`).
"""

from __future__ import annotations

import logging
from pathlib import Path

from model.record import RunRecord
from model.cases import case_for_run
from model.cases.common import engine_kind
from engines.estimates import estimate_case
from engines.interface import EngineOptions, engine_for
from engines.planning import cost_model, preflight

__all__ = ["render_run", "run_case"]


def render_run(config: dict, case_kind: str, run: str, run_dir: str | Path) -> Path:
    """Write the engine inputs of run ``run`` of ``case_kind`` into ``<run_dir>/deck/``; returns ``deck/case.json``."""
    case = case_for_run(config, case_kind, run)
    summary = engine_for(config, case_kind).write_inputs(case, run_dir)
    logging.getLogger("siloflow").info("%s inputs of %s run %s written; case summary %s",
                                       engine_kind(config, case_kind), case_kind, run, summary)
    return summary


def run_case(config: dict, case_kind: str, run: str, run_dir: str | Path) -> RunRecord:
    """Run the rendered inputs of run ``run`` of ``case_kind`` on its engine, after checking the disk and logging the
    estimate; returns the run record (also written as ``<run_dir>/run.json``)."""
    case = case_for_run(config, case_kind, run)
    kind = engine_kind(config, case_kind)
    options = EngineOptions.from_config(config, kind)
    logging.getLogger("siloflow").info(preflight(config, estimate_case(case, options.mpi_ranks, cost_model(config)), run_dir))
    return engine_for(config, case_kind).run(case, run_dir, options)
