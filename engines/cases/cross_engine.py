"""The cross-engine check's runs: the flat-bottom silo of ``silo_flat``, made small by the keys of ``cross_engine``,
on each of two engines with several seeds (the spread over the seeds is what a difference between engines is
measured against)."""

from __future__ import annotations

import copy

from engines.cases.silo_flat import SiloCase, build_silo_case

__all__ = ["SIZE_KEYS", "cross_engine_cases"]

#: The ``cross_engine`` keys that replace those of ``silo_flat``.
SIZE_KEYS = ("width", "fill_height", "outlet_width", "discharge_time")


def cross_engine_cases(config: dict) -> dict[str, dict[str, SiloCase]]:
    """``{engine: {run id: case}}`` of a validated configuration: ``cross_engine.seeds`` runs per engine, seeds
    ``silo_flat.seed`` + 0, 1, ...; the runs of the engines differ in nothing else (the engine enters the run id)."""
    section = config["cross_engine"]
    cases: dict[str, dict[str, SiloCase]] = {}
    for engine in section["engines"]:
        cases[engine] = {}
        for offset in range(section["seeds"]):
            run_config = copy.deepcopy(config)
            silo = run_config["silo_flat"]
            silo.update({key: section[key] for key in SIZE_KEYS})
            silo.update({"engine": engine, "seed": config["silo_flat"]["seed"] + offset})
            case = build_silo_case(run_config)
            cases[engine][case.run_id] = case
    return cases
