"""The engine-neutral case model: every case siloflow can run, as plain data built from validated configuration.

:data:`CASE_BUILDERS` is the one list of case kinds: each maps a validated configuration to its runs, keyed by run
id. The workflow, the run planning and the tests all take the cases from here.
"""

from __future__ import annotations

import copy

from model.cases.blender import blender_cases
from model.cases.jenike import jenike_cases
from model.cases.jenike_sweep import point_role
from model.cases.silo_flat import silo_cases
from model.cases.silo_recirculation import recirculation_cases

__all__ = ["CASE_BUILDERS", "REFERENCE", "VARIANT", "case_for_run", "cases_of", "reference_runs", "run_roles"]

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


def _replicates(config: dict, case: str) -> tuple[int, int]:
    """``(N, M)``: runs of every configuration and of the reference configuration (M >= N)."""
    section = config.get(case, {}) if case in REPLICATED_CASES else {}
    replicates = section.get("replicates", 1)
    return replicates, max(replicates, section.get("reference_replicates", 1))


def _reseeded(config: dict, case: str, offset: int) -> dict:
    """The runs of ``case`` with its section's seed raised by ``offset``, in the builder's order."""
    reseeded = copy.deepcopy(config)
    reseeded[case]["seed"] += offset
    return CASE_BUILDERS[case](reseeded)


def cases_of(config: dict, case: str) -> dict:
    """The runs of case kind ``case`` a validated configuration defines, keyed by run id.

    With ``replicates: N`` (N >= 2) in the case's section, every run is there N times, with the section's seed
    plus 0, 1, ..., N - 1 (distinct engine seeds, so distinct run ids); the first replicate is the run that
    ``replicates: 1`` gives, so raising N keeps the runs already done. With ``reference_replicates: M`` only the
    reference configuration (:func:`reference_runs`) is there ``max(N, M)`` times, so that a comparison of
    configurations knows the spread between seeds at the cost of M - N runs.
    """
    return _runs_and_reference(config, case)[0]


def _runs_and_reference(config: dict, case: str) -> tuple[dict, list[str]]:
    """The runs of :func:`cases_of` and the run ids of :func:`reference_runs`, from one build of each seed."""
    if case not in CASE_BUILDERS:
        raise KeyError(f"unknown case {case!r}; the cases are {', '.join(CASE_BUILDERS)}")
    runs = CASE_BUILDERS[case](config)
    # the builders list the reference configuration first
    reference = list(runs)[:1]
    replicates, seeds = _replicates(config, case)
    for offset in range(1, seeds):
        others = _reseeded(config, case, offset)
        first = next(iter(others))
        reference.append(first)
        runs.update(others if offset < replicates else {first: others[first]})
    return runs, reference


def reference_runs(config: dict, case: str) -> list[str]:
    """Run ids of the reference configuration of case kind ``case``, one per seed: the first run its builder
    defines (the base flat-bottom silo, the first flow pattern, the first blender configuration at the lowest
    gravity factor, the first Jenike sweep point), then its reseeded replicates (:func:`cases_of`)."""
    return _runs_and_reference(config, case)[1]


#: The roles of the runs of a silo-type case kind (:func:`run_roles`): the reference configuration's or another's.
REFERENCE, VARIANT = "reference", "variant"


def run_roles(config: dict, case: str) -> dict[str, str]:
    """``{run id: role}`` of the runs of case kind ``case``: a Jenike run's sweep role
    (:data:`model.cases.jenike_sweep.ROLES`: the calibration shape's charts, another shape's, or a check), any
    other run :data:`REFERENCE` when it is one of :func:`reference_runs` and :data:`VARIANT` otherwise."""
    runs, reference = _runs_and_reference(config, case)
    if case == "jenike":
        return {run: point_role(job.sweep_point, config["jenike"]["sweep"]["restitution"],
                                config["calibration"]["shape"]) for run, job in runs.items()}
    return {run: REFERENCE if run in reference else VARIANT for run in runs}


def case_for_run(config: dict, case: str, run: str):
    """The case of run id ``run``; the error names the runs the configuration does define."""
    runs = cases_of(config, case)
    if run not in runs:
        raise KeyError(f"{case} run '{run}' is not defined by this configuration; it defines: {', '.join(sorted(runs))}")
    return runs[run]
