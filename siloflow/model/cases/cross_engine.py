"""The cross-engine check's runs, on each of two engines with several seeds (the spread over the seeds is what a
difference between engines is measured against): the flat-bottom silo of ``silo_flat`` made small by the keys of
``cross_engine``, and Jenike points (``cross_engine.jenike.points``) in the cell of ``jenike`` made small by the keys
of ``cross_engine.jenike``."""

from __future__ import annotations

import copy

from siloflow.model.cases.jenike import JenikeCase, build_jenike_case
from siloflow.model.cases.silo_flat import SiloCase, build_silo_case

__all__ = ["JENIKE_CELL_KEYS", "SIZE_KEYS", "cross_engine_cases", "cross_engine_jenike_cases"]

#: The ``cross_engine`` keys that replace those of ``silo_flat``.
SIZE_KEYS = ("width", "fill_height", "outlet_width", "discharge_time")
#: The ``cross_engine.jenike`` keys that replace those of ``jenike.cell``.
JENIKE_CELL_KEYS = ("inner_diameter", "bottom_ring_height", "shear_ring_height")


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


def jenike_point_label(point: dict) -> str:
    """How the table names a Jenike point: its test, sliding and rolling friction."""
    test = "internal" if point["test"] == "internal" else f"wall ({point['test']})"
    return f"bulk friction, {test}, mu = {point['sliding_friction']:g}, mu_r = {point['rolling_friction']:g}"


def cross_engine_jenike_cases(config: dict) -> dict[str, dict[str, tuple[str, JenikeCase]]]:
    """``{engine: {run id: (point label, case)}}``: each point of ``cross_engine.jenike.points`` (shape, restitution
    and rotation of ``jenike.sweep``), ``cross_engine.seeds`` runs per engine with seeds ``jenike.seed`` + 0, 1, ...

    Raises
    ------
    ValueError
        Naming the point, when its cell cannot be built (e.g. a wall material that is not defined).
    """
    section = config["cross_engine"]
    small = section["jenike"]
    sweep = config["jenike"]["sweep"]
    cases: dict[str, dict[str, tuple[str, JenikeCase]]] = {}
    for engine in section["engines"]:
        cases[engine] = {}
        for point in small["points"]:
            full = {"shape": sweep["shapes"][0], "test": point["test"], "sliding_friction": point["sliding_friction"],
                    "rolling_friction": point["rolling_friction"], "restitution": sweep["restitution"],
                    "rotation_blocked": sweep["rotation_blocked"]}
            for offset in range(section["seeds"]):
                run_config = copy.deepcopy(config)
                jenike = run_config["jenike"]
                jenike["cell"].update({key: small[key] for key in JENIKE_CELL_KEYS})
                jenike["fill"]["settle_time"] = small["settle_time"]
                jenike["consolidation"]["time"] = small["consolidation_time"]
                jenike["shear"]["displacement"] = small["shear_displacement"]
                jenike.update({"engine": engine, "seed": config["jenike"]["seed"] + offset})
                try:
                    case = build_jenike_case(run_config, full)
                except ValueError as error:
                    raise ValueError(f"cross_engine.jenike.points {point}: {error}") from None
                cases[engine][case.run_id] = (jenike_point_label(full), case)
    return cases
