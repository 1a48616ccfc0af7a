"""The results tree, defined once: where each case's runs live and what a run directory holds.

The workflow's rules, the run planning (estimates, disk checks) and the tests all build paths here::

    results/<case root>/<run id>/        (each case kind's root is in its registry entry, siloflow.model.cases.kinds)
        deck/            the engine's input files; deck/case.json (the neutral case summary) is written last
        run.json         the typed run record (siloflow.model.record), written last, only when the run passed its checks
        logs/            one log per workflow step, and the run step's timing (logs/run_benchmark.tsv)
        metrics/ fields/ plots/ tracks.npz ...   analysis products
        failed_attempts/ output of unfinished earlier attempts, moved aside, never deleted

The engine's own files (dumps, logs, restart files) also live in the run directory, under names only the engine knows.

Runs siloflow did not make (a user's own engine input, configured by name in ``<case>.existing_runs``) stay in their
own folders, which siloflow only reads; their analysis products go to ``results/existing_runs/<case root>/<name>/``
(``metrics/ fields/ plots/ logs/``, as a run directory's).
"""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath

from siloflow.model.cases.kinds import case_kind

__all__ = ["RESULTS", "CASE_SUMMARY", "EXISTING_RUNS", "EXISTING_RUN_WILDCARD", "RUN_BENCHMARK", "RUN_PROVENANCE",
           "RUN_RECORD", "READ_PRODUCTS", "SILO_ROW_PRODUCTS", "CALIBRATION_DIR", "CALIBRATED_PARAMETERS",
           "BAYESIAN_DIR", "CROSS_ENGINE_DIR", "SUMMARY_DIR", "VALIDATION_RECORD", "REPOSITORY_RECORD", "VERIFICATION_DIR", "case_root", "existing_run_dir", "existing_run_path", "run_dir",
           "run_path", "write_text_atomic"]

#: The results folder, relative to the working directory of the workflow.
RESULTS = "results"

#: The neutral case summary an engine writes last into ``deck/`` (the product of a deck step).
CASE_SUMMARY = "deck/case.json"
#: The typed run record (the product of a run step).
RUN_RECORD = "run.json"
#: Snakemake's benchmark of a run step: its wall time (column ``s``) and memory.
RUN_BENCHMARK = "logs/run_benchmark.tsv"
#: Each attempt of a run step: its start, the commit of the code and the engine's version (siloflow.engines.provenance).
RUN_PROVENANCE = "logs/run_provenance.json"

#: The products across runs, each in its folder under :data:`RESULTS`: the calibration (tables, charts, the chosen
#: parameters), the summary (the validation table, the report's summary page, the validation record), the DEM
#: verification suite and the cross-engine check.
CALIBRATION_DIR = f"{RESULTS}/calibration"
SUMMARY_DIR = f"{RESULTS}/summary"
VERIFICATION_DIR = f"{RESULTS}/verification"
CROSS_ENGINE_DIR = f"{RESULTS}/cross_engine"
#: The joint Bayesian calibration: ``<engine>/iteration_<k>/`` (design, posterior), ``<engine>/runs/<run id>/``,
#: ``<engine>/predictive/`` and ``<engine>/`` (the final posterior, its plots and the comparison with the chart).
BAYESIAN_DIR = f"{CALIBRATION_DIR}/bayesian"

#: The calibration's chosen parameters, which a silo run with calibrated parameters reads.
CALIBRATED_PARAMETERS = f"{CALIBRATION_DIR}/parameters.yaml"

#: Each validation group's record as the pipeline writes it (``<group>/``), before `make validate` copies it into
#: the repository's ``docs/validation/``.
VALIDATION_RECORD = f"{SUMMARY_DIR}/record"
#: Where `make validate` keeps the record in the repository (relative to its top), the Makefile's VALIDATION_RECORD.
REPOSITORY_RECORD = "docs/validation"

#: The products of a flat-bottom silo run its validation rows are read from, by the name the rows call them.
SILO_ROW_PRODUCTS = {"case": CASE_SUMMARY, "flow": "metrics/flow.json", "fields": "metrics/fields.json",
                     "balance": "metrics/fill_balance.json", "janssen": "metrics/janssen.csv",
                     "kinematic": "metrics/kinematic.csv", "boundary": "metrics/flow_channel_boundary.csv"}

#: The products of a run that another validation group reads (its rows, its record, the analyses across runs behind
#: them), by case kind: the record of a group that others read keeps them, so that a later `make validate GROUP=`
#: on another machine restores them instead of making those runs again.
READ_PRODUCTS = {
    "jenike": ("metrics/bulk_friction.json", RUN_RECORD, RUN_BENCHMARK),
    "silo_flat": (*SILO_ROW_PRODUCTS.values(), "fields/depth_averaged.npz", RUN_RECORD, RUN_BENCHMARK),
}

#: The wildcard rules use for a run id.
RUN_WILDCARD = "{run}"

#: Folder, under :data:`RESULTS`, of the analyses of runs siloflow did not make.
EXISTING_RUNS = "existing_runs"
#: The wildcard rules use for the name of a run siloflow did not make.
EXISTING_RUN_WILDCARD = "{existing}"


def case_root(case: str, results: str = RESULTS) -> str:
    """``results/<case root>``: the folder that holds every run of case kind ``case`` (its registry entry's
    :attr:`~siloflow.model.cases.kinds.CaseKind.results_root`)."""
    return str(PurePosixPath(results) / case_kind(case).results_root)


def run_dir(case: str, run: str = RUN_WILDCARD, results: str = RESULTS) -> str:
    """The directory of run ``run`` of case ``case`` (with the default ``{run}``: the rules' wildcard pattern)."""
    return f"{case_root(case, results)}/{run}"


def run_path(case: str, relative: str, run: str = RUN_WILDCARD, results: str = RESULTS) -> str:
    """A file of a run: ``run_path("silo_flat", "metrics/flow.csv")`` is ``results/silo_flat/{run}/metrics/flow.csv``."""
    if relative.startswith("/") or ".." in PurePosixPath(relative).parts:
        raise ValueError(f"run paths are relative and stay inside the run directory, got {relative!r}")
    return f"{run_dir(case, run, results)}/{relative}"


def existing_run_dir(case: str, name: str = EXISTING_RUN_WILDCARD, results: str = RESULTS) -> str:
    """The folder of the analysis of run ``name`` siloflow did not make, of case ``case``:
    ``results/existing_runs/<case root>/<name>`` (with the default ``{existing}``: the rules' wildcard pattern)."""
    return str(PurePosixPath(results) / EXISTING_RUNS / case_kind(case).results_root / name)


def existing_run_path(case: str, relative: str, name: str = EXISTING_RUN_WILDCARD, results: str = RESULTS) -> str:
    """A product of the analysis of a run siloflow did not make: ``existing_run_path("silo_flat", "metrics/flow.csv")``
    is ``results/existing_runs/silo_flat/{existing}/metrics/flow.csv``."""
    if relative.startswith("/") or ".." in PurePosixPath(relative).parts:
        raise ValueError(f"paths of an existing run's analysis are relative and stay inside its folder, "
                         f"got {relative!r}")
    return f"{existing_run_dir(case, name, results)}/{relative}"


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a ``.partial`` file and a rename, so that a reader (or a killed run) never
    sees half of it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    partial.write_text(text, encoding="utf-8")
    os.replace(partial, path)
