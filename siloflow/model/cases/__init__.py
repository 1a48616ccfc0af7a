"""The engine-neutral case model: every case siloflow can run, as plain data built from validated configuration.

The case kinds are registered in :mod:`siloflow.model.cases.kinds`, each with the builder that maps a validated configuration
to its runs; :func:`cases_of` adds the replicates a section asks for. The workflow, the run planning and the tests
all take the runs from here.
"""

from __future__ import annotations

import copy

from siloflow.model.cases.kinds import case_kind

__all__ = ["REFERENCE", "VARIANT", "case_for_run", "cases_of", "reference_runs", "run_roles"]


def _replicates(config: dict, case: str) -> tuple[int, int]:
    """``(N, M)``: runs of every configuration and of the reference configuration (M >= N); 1 for a kind whose
    section has no replicates (the Jenike sweep's uncertainty is the band of friction values that reproduce the
    target within its tolerance)."""
    section = config.get(case, {}) if case_kind(case).replicated else {}
    replicates = section.get("replicates", 1)
    return replicates, max(replicates, section.get("reference_replicates", 1))


def _reseeded(config: dict, case: str, offset: int) -> dict:
    """The runs of ``case`` with its section's seed raised by ``offset``, in the builder's order."""
    reseeded = copy.deepcopy(config)
    reseeded[case]["seed"] += offset
    return case_kind(case).build(reseeded)


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
    kind = case_kind(case)
    if kind.build is None:
        raise KeyError(f"case kind {case!r} has no config section; its runs are not built from a configuration")
    runs = kind.build(config)
    if not runs:
        # a case switched off (its ``enabled: false``) has no reference to reseed
        return runs, []
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
    """``{run id: role}`` of the runs of case kind ``case``: the role its kind gives it (a Jenike run's sweep role,
    :data:`siloflow.model.cases.jenike_sweep.ROLES`: the calibration shape's charts, another shape's, or a check), for other
    kinds :data:`REFERENCE` when it is one of :func:`reference_runs` and :data:`VARIANT` otherwise."""
    runs, reference = _runs_and_reference(config, case)
    role = case_kind(case).run_role
    if role is not None:
        return {run: role(config, job) for run, job in runs.items()}
    return {run: REFERENCE if run in reference else VARIANT for run in runs}


def case_for_run(config: dict, case: str, run: str):
    """The case of run id ``run``; the error names the runs the configuration does define."""
    runs = cases_of(config, case)
    if run not in runs:
        raise KeyError(f"{case} run '{run}' is not defined by this configuration; it defines: {', '.join(sorted(runs))}")
    return runs[run]
