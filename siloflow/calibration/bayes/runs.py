"""The Jenike runs of a Bayesian calibration's parameter sets on one engine, and their bulk friction angles as the
arrays an iteration takes.

A design is a list of parameter sets, ``{"theta": [...], "replicate": k}``; :func:`with_runs` adds each set's Jenike
points and run ids (``{"points": {test: point}, "runs": {test: run id}}``), which the design file keeps, so that the
workflow and :func:`observations` find a set's runs without building cases again.
"""

from __future__ import annotations

import copy
from typing import Mapping, Sequence

import numpy as np

from siloflow.calibration.bayes.joint import Calibration, points_of_set
from siloflow.model.cases.jenike import JenikeCase, build_jenike_case

__all__ = ["cases_of_sets", "completed_sets", "engine_config", "failed_runs", "observations", "with_runs"]


def engine_config(config: Mapping, engine: str) -> dict:
    """A copy of the validated ``config`` whose Jenike runs run on ``engine``."""
    changed = copy.deepcopy(dict(config))
    changed["jenike"]["engine"] = engine
    return changed


def with_runs(config: Mapping, calibration: Calibration, sets: Sequence[Mapping], engine: str) -> list[dict]:
    """The sets with their Jenike points and run ids on ``engine``."""
    on_engine = engine_config(config, engine)
    found = []
    for chosen in sets:
        points = points_of_set(calibration, chosen["theta"], chosen["replicate"])
        runs = {point["test"]: build_jenike_case(on_engine, point).run_id for point in points}
        found.append({**chosen, "points": {point["test"]: point for point in points}, "runs": runs})
    return found


def cases_of_sets(config: Mapping, engine: str, sets: Sequence[Mapping]) -> dict[str, JenikeCase]:
    """``{run id: case}`` of the runs of ``sets`` (as :func:`with_runs` wrote them) on ``engine``."""
    on_engine = engine_config(config, engine)
    cases = {}
    for chosen in sets:
        for test, point in chosen["points"].items():
            case = build_jenike_case(on_engine, point)
            if case.run_id != chosen["runs"][test]:
                raise ValueError(f"the design's run {chosen['runs'][test]} is {case.run_id} with this configuration: "
                                 "the configuration changed since the design was written")
            cases[case.run_id] = case
    return cases


def failed_runs(sets: Sequence[Mapping], summaries: Mapping[str, Mapping]) -> list[dict]:
    """The runs of ``sets`` that failed (their summary says ``failed``): set, test, run id and the engine's error."""
    return [{"theta": list(chosen["theta"]), "replicate": chosen["replicate"], "test": test, "run_id": run,
             "error": summaries[run]["error"]}
            for chosen in sets for test, run in chosen["runs"].items() if summaries[run].get("failed")]


def completed_sets(sets: Sequence[Mapping], summaries: Mapping[str, Mapping]) -> list[Mapping]:
    """The sets all of whose runs completed (a set with a failed run is left out of the posterior)."""
    return [chosen for chosen in sets if not any(summaries[run].get("failed") for run in chosen["runs"].values())]


def observations(calibration: Calibration, sets: Sequence[Mapping],
                 summaries: Mapping[str, Mapping]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(theta (n, d), angles (n, k), errors (n, k))`` of the sets: each test's bulk friction angle and its standard
    error (deg), from the runs' bulk friction summaries (``metrics/bulk_friction.json``) by run id.

    Raises
    ------
    ValueError
        Naming a run that failed (take :func:`completed_sets` first).
    """
    failed = failed_runs(sets, summaries)
    if failed:
        raise ValueError(f"the run {failed[0]['run_id']} failed: {failed[0]['error']}")
    theta = np.array([chosen["theta"] for chosen in sets], dtype=float)
    angles = np.array([[summaries[chosen["runs"][test]]["bulk_friction_angle_deg"] for test in calibration.tests]
                       for chosen in sets], dtype=float)
    errors = np.array([[summaries[chosen["runs"][test]]["bulk_friction_angle_deg_error"] for test in calibration.tests]
                       for chosen in sets], dtype=float)
    return theta, angles, errors
