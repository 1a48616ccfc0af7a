"""The engine-neutral case model: every case siloflow can run, as plain data built from validated configuration.

:data:`CASE_BUILDERS` is the one list of case kinds: each maps a validated configuration to its runs, keyed by run
id. The workflow, the run planning and the tests all take the cases from here.
"""

from __future__ import annotations

from engines.cases.blender import blender_cases
from engines.cases.jenike import jenike_cases
from engines.cases.silo_flat import silo_cases
from engines.cases.silo_recirculation import recirculation_cases

__all__ = ["CASE_BUILDERS", "case_for_run", "cases_of"]

#: Case kind -> function of a validated configuration returning its runs ``{run id: case}``.
CASE_BUILDERS = {
    "jenike": jenike_cases,
    "silo_flat": silo_cases,
    "silo_recirculation": recirculation_cases,
    "blender": blender_cases,
}


def cases_of(config: dict, case: str) -> dict:
    """The runs of case kind ``case`` a validated configuration defines, keyed by run id."""
    if case not in CASE_BUILDERS:
        raise KeyError(f"unknown case {case!r}; the cases are {', '.join(CASE_BUILDERS)}")
    return CASE_BUILDERS[case](config)


def case_for_run(config: dict, case: str, run: str):
    """The case of run id ``run``; the error names the runs the configuration does define."""
    runs = cases_of(config, case)
    if run not in runs:
        raise KeyError(f"{case} run '{run}' is not defined by this configuration; it defines: {', '.join(sorted(runs))}")
    return runs[run]
