"""The engine-neutral case model: every case siloflow can run, as plain data built from validated configuration.

:data:`CASE_BUILDERS` is the one list of case kinds: each maps a validated configuration to its runs, keyed by run
id. The workflow, the run planning and the tests all take the cases from here.
"""

from __future__ import annotations

import copy

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


#: The case kinds whose section has ``replicates`` (the Jenike sweep is not replicated: its calibration's
#: uncertainty is the band of friction values that reproduce the target within its tolerance).
REPLICATED_CASES = ("silo_flat", "silo_recirculation", "blender")


def cases_of(config: dict, case: str) -> dict:
    """The runs of case kind ``case`` a validated configuration defines, keyed by run id.

    With ``replicates: N`` (N >= 2) in the case's section, every run is there N times, with the section's seed
    plus 0, 1, ..., N - 1 (distinct engine seeds, so distinct run ids); the first replicate is the run that
    ``replicates: 1`` gives, so raising N keeps the runs already done.
    """
    if case not in CASE_BUILDERS:
        raise KeyError(f"unknown case {case!r}; the cases are {', '.join(CASE_BUILDERS)}")
    runs = CASE_BUILDERS[case](config)
    replicates = config.get(case, {}).get("replicates", 1) if case in REPLICATED_CASES else 1
    for offset in range(1, replicates):
        reseeded = copy.deepcopy(config)
        reseeded[case]["seed"] += offset
        runs.update(CASE_BUILDERS[case](reseeded))
    return runs


def case_for_run(config: dict, case: str, run: str):
    """The case of run id ``run``; the error names the runs the configuration does define."""
    runs = cases_of(config, case)
    if run not in runs:
        raise KeyError(f"{case} run '{run}' is not defined by this configuration; it defines: {', '.join(sorted(runs))}")
    return runs[run]
