"""Design of the calibration sweep: the Jenike shear-cell runs a configuration asks for.

A sweep point is a plain dict (it keys the run and travels through Snakemake unchanged)::

    {"shape": "sphere2", "test": "internal" | <wall material>, "sliding_friction": 0.3,
     "rolling_friction": 0.1, "restitution": 0.1, "rotation_blocked": False}

with ``"lid"`` on the lid comparison's points, ``"replicate"`` (>= 1, added to the seed) on the reference point's
extra seeds, ``"shear_velocity"`` (m/s) on its shear-speed study and ``"pour": "own_friction"`` (:data:`OWN_POUR`) on the
points of the pour variant.
"""

from __future__ import annotations

from typing import Mapping

from siloflow.model.cases.config_checks import ConfigError, require, require_subset

INTERNAL = "internal"

#: The pour of a sample: as ``jenike.fill`` configures it, or at the test's own particle friction (the variant of
#: ``jenike.sweep.own_pour_variant``, a critically consolidated sample).
CONFIGURED_POUR, OWN_POUR = "configured", "own_friction"
POURS = (CONFIGURED_POUR, OWN_POUR)


def configured_pour(row) -> bool:
    """Whether a calibration table row's sample was poured as ``jenike.fill`` configures, not by the pour variant (a
    table written before the variant has no ``pour`` column: every row was)."""
    return row.get("pour", CONFIGURED_POUR) in ("", CONFIGURED_POUR)

#: The role of a sweep point (:func:`point_role`): a point of the calibration shape's charts, of another shape's
#: charts, or of a check against a chart (rotation blocked, the other lid, another restitution or shear speed, another
#: seed).
CALIBRATION_CHART, SHAPE_CHART, CHECK = "calibration_chart", "shape_chart", "check"
ROLES = (CALIBRATION_CHART, SHAPE_CHART, CHECK)


def middle_sliding_friction(sweep: dict) -> float:
    """The middle of the sweep's sliding frictions (the upper middle of an even count): the point of the restitution
    study, the reference point and the diagnostics."""
    return float(sorted(sweep["sliding_friction"])[len(sweep["sliding_friction"]) // 2])


def other_lid(lid: str) -> str:
    """The lid a comparison runs against: servo for rigid and rigid for servo."""
    return "servo" if lid == "rigid" else "rigid"


def sweep_points(sweep: dict, lid: str = "rigid", pour_friction: float | None = None) -> list[dict]:
    """Expand the ``jenike.sweep`` section into the list of distinct sweep points.

    The grid is every shape x test x sliding friction x rolling friction at the base restitution (wall tests only
    for the shapes of ``wall_test_shapes``, null: all). The
    restitution sensitivity adds, per shape and test, the middle sliding friction at the first rolling
    friction for each extra restitution; the rotation-blocked reference adds every sliding friction at the
    first rolling friction with particle rotation blocked. The lid comparison adds, per shape, the internal
    test at every sliding friction and the first rolling friction with the other lid (key ``"lid"``).
    These three studies go to the shapes of ``sensitivity_shapes`` and (the first two) the tests of
    ``sensitivity_tests`` (null: all). Duplicates are dropped, order is
    stable. With ``reference_replicates: M`` the reference point (:func:`reference_point`) and each other shape's
    (:func:`replicated_points`) run M times: the copies carry ``"replicate": 1 ... M - 1``, which the case adds to
    its seed, so that every chart carries the spread between seeds of a point of its own. The shear-speed study runs
    the reference point at each velocity of ``shear_velocity_sensitivity`` (key ``"shear_velocity"``, m/s). The pour
    variant (``own_pour_variant``) pours the sensitivity shapes' internal test, if a sensitivity test, at each sliding
    friction and the first rolling friction at that particle friction (key ``"pour"``: :data:`OWN_POUR`), except where that
    friction is the configured pour's: there the variant is the chart's own point.

    Parameters
    ----------
    sweep : dict
        The validated ``jenike.sweep`` configuration section.
    lid : str
        The configured lid (``jenike.lid``); the comparison uses the other one.
    pour_friction : float or None
        The configured pour's particle friction (``jenike.fill.sliding_friction``, -); None pours every sample at its
        own friction already, and the sweep has no pour variant.

    Returns
    -------
    list of dict
        Sweep points (friction coefficients and restitution are dimensionless).
    """
    sliding = list(sweep["sliding_friction"])
    rolling = list(sweep["rolling_friction"])
    base_restitution = sweep["restitution"]
    points: list[dict] = []

    def add(shape, test, mu, mu_r, restitution, blocked=False):
        point = {
            "shape": shape,
            "test": test,
            "sliding_friction": float(mu),
            "rolling_friction": float(mu_r),
            "restitution": float(restitution),
            "rotation_blocked": bool(blocked),
        }
        if point not in points:
            points.append(point)

    wall_test_shapes = sweep.get("wall_test_shapes") or sweep["shapes"]
    sensitivity_shapes = sweep.get("sensitivity_shapes") or sweep["shapes"]
    sensitivity_tests = sweep.get("sensitivity_tests") or sweep["tests"]
    for shape in sweep["shapes"]:
        tests = [test for test in sweep["tests"] if test == INTERNAL or shape in wall_test_shapes]
        for test in tests:
            for mu_r in rolling:
                for mu in sliding:
                    add(shape, test, mu, mu_r, base_restitution)
            if shape not in sensitivity_shapes or test not in sensitivity_tests:
                continue
            middle = middle_sliding_friction(sweep)
            for restitution in sweep["restitution_sensitivity"]:
                add(shape, test, middle, rolling[0], restitution)
            if sweep["rotation_blocked"]:
                for mu in sliding:
                    add(shape, test, mu, rolling[0], base_restitution, blocked=True)
            if sweep.get("own_pour_variant") and pour_friction is not None and test == INTERNAL:
                for mu in sliding:
                    if mu != pour_friction:
                        points.append({"shape": shape, "test": test, "sliding_friction": float(mu),
                                       "rolling_friction": float(rolling[0]), "restitution": float(base_restitution),
                                       "rotation_blocked": False, "pour": OWN_POUR})
        if sweep["lid_comparison"] and INTERNAL in sweep["tests"] and shape in sensitivity_shapes:
            for mu in sliding:
                point = {
                    "shape": shape,
                    "test": INTERNAL,
                    "sliding_friction": float(mu),
                    "rolling_friction": float(rolling[0]),
                    "restitution": float(base_restitution),
                    "rotation_blocked": False,
                    "lid": other_lid(lid),
                }
                if point not in points:
                    points.append(point)
    for replicated in replicated_points(sweep, points):
        points += [{**replicated, "replicate": k} for k in range(1, sweep.get("reference_replicates", 1))]
    reference = reference_point(sweep)
    if reference is not None and reference in points:
        points += [{**reference, "shear_velocity": float(v)} for v in sweep.get("shear_velocity_sensitivity", [])]
    return points


def replicated_points(sweep: dict, points: list[dict]) -> list[dict]:
    """The points of ``points`` that run ``reference_replicates`` times: the reference point (:func:`reference_point`)
    and, for every other shape, the same point of its own (its first sensitivity test, else its first test, at the
    middle sliding friction, the first rolling friction and the base restitution), so that each shape's charts carry
    a spread between seeds of their own."""
    reference = reference_point(sweep)
    chosen = [reference] if reference is not None and reference in points else []
    tests = sweep.get("sensitivity_tests") or sweep["tests"]
    for shape in sweep["shapes"]:
        if any(point["shape"] == shape for point in chosen):
            continue
        test = next((test for test in tests if test in sweep["tests"]), sweep["tests"][0])
        point = {"shape": shape, "test": test, "sliding_friction": middle_sliding_friction(sweep),
                 "rolling_friction": float(sweep["rolling_friction"][0]), "restitution": float(sweep["restitution"]),
                 "rotation_blocked": False}
        if point in points:
            chosen.append(point)
    return chosen


def reference_point(sweep: dict) -> dict | None:
    """The sweep point whose seeds give the spread between seeds of every comparison of the sweep: the first
    sensitivity shape's first sensitivity test at the middle sliding friction, the first rolling friction and the
    base restitution (the point the restitution study also runs); None without a sensitivity shape."""
    shapes = sweep.get("sensitivity_shapes") or sweep["shapes"]
    tests = sweep.get("sensitivity_tests") or sweep["tests"]
    if not shapes or not tests:
        return None
    return {"shape": shapes[0], "test": tests[0],
            "sliding_friction": middle_sliding_friction(sweep),
            "rolling_friction": float(sweep["rolling_friction"][0]), "restitution": float(sweep["restitution"]),
            "rotation_blocked": False}


def is_chart_point(point: dict, base_restitution: float) -> bool:
    """Whether a sweep point belongs on a calibration chart: base restitution, rotation free, the configured lid,
    shear velocity and pour, the first seed."""
    return (point["restitution"] == base_restitution and not point["rotation_blocked"]
            and not {"lid", "shear_velocity", "replicate", "pour"} & set(point))


def point_role(point: dict, base_restitution: float, calibration_shape: str) -> str:
    """The role of a sweep point (:data:`ROLES`): a chart point of ``calibration_shape`` or of another shape, or a
    check."""
    if "replicate" in point:
        # a replicate belongs to the chart of the point it repeats: its seeds give that chart's spread
        point = {key: value for key, value in point.items() if key != "replicate"}
    if not is_chart_point(point, base_restitution):
        return CHECK
    return CALIBRATION_CHART if point["shape"] == calibration_shape else SHAPE_CHART


def diagnostic_points(points: list[dict], sweep: dict, lid: str) -> list[dict]:
    """The chart points that get contact and rotation diagnostics (``jenike.sweep.diagnostics``).

    Only rigid-lid runs record wall contacts, so a servo ``lid`` gives none.
    """
    if sweep["diagnostics"] == "none" or lid != "rigid":
        return []
    chart = [p for p in points if is_chart_point(p, sweep["restitution"])]
    if sweep["diagnostics"] == "all":
        return chart
    return [p for p in chart if p["sliding_friction"] == middle_sliding_friction(sweep)]


def jenike_run_role(config: Mapping, case) -> str:
    """The role (:data:`ROLES`) of a Jenike run of a validated configuration: its sweep point's."""
    return point_role(case.sweep_point, config["jenike"]["sweep"]["restitution"], config["calibration"]["shape"])


def check_jenike_config(config: Mapping, contact_pairs: Mapping) -> None:
    """The Jenike cell's own checks: its materials, shapes and tests are defined and every pair it brings into contact
    has contact parameters; its sensitivity and wall-test picks are among the sweep's; the calibration's shape and
    rolling friction are points of the sweep."""
    materials = config["materials"]
    jenike = config["jenike"]
    sweep = jenike["sweep"]
    particle = jenike["particle_material"]
    for key in ("particle_material", "ring_material", "lid_material"):
        require(jenike[key], materials, f"jenike.{key}", "material")
    if "density" not in materials[particle]:
        raise ConfigError(f"config key 'materials.{particle}.density': the particle material needs a density")
    for index, shape in enumerate(sweep["shapes"]):
        require(shape, config["particle_models"], f"jenike.sweep.shapes[{index}]", "particle model")
    for key in ("wall_test_shapes", "sensitivity_shapes"):
        require_subset(sweep[key], sweep["shapes"], f"jenike.sweep.{key}", "jenike.sweep.shapes")
    require_subset(sweep["sensitivity_tests"], sweep["tests"], "jenike.sweep.sensitivity_tests", "jenike.sweep.tests")
    wall_tests = []
    for index, test in enumerate(sweep["tests"]):
        if test != "internal":
            require(test, materials, f"jenike.sweep.tests[{index}]", "test ('internal' or a wall material)")
            wall_tests.append(test)
    for material in sorted({particle, jenike["ring_material"], jenike["lid_material"], *wall_tests}):
        if frozenset((particle, material)) not in contact_pairs:
            raise ConfigError(
                f"config key 'contacts': no contact parameters for the pair [{particle}, {material}] used by jenike"
            )
    if sweep["own_pour_variant"] and jenike["fill"]["sliding_friction"] is None:
        raise ConfigError("config key 'jenike.sweep.own_pour_variant': needs jenike.fill.sliding_friction set; with "
                          "null every sample is poured at its own particle friction already")
    calibration = config["calibration"]
    if calibration["shape"] not in sweep["shapes"]:
        raise ConfigError(
            f"config key 'calibration.shape': '{calibration['shape']}' is not among jenike.sweep.shapes "
            f"{sweep['shapes']}"
        )
    if calibration["rolling_friction"] not in sweep["rolling_friction"]:
        raise ConfigError(
            f"config key 'calibration.rolling_friction': {calibration['rolling_friction']} is not among "
            f"jenike.sweep.rolling_friction {sweep['rolling_friction']}"
        )
