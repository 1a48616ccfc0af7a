# Calibration: Jenike shear-cell sweep -> bulk friction per point -> table, charts -> chosen parameters.

from calibration.sweep import diagnostic_points

JENIKE_CASES = cases("jenike")
CALIBRATION = f"{RESULTS}/calibration"


def jenike_point(run):
    """The sweep point of a Jenike run, with the lid and shear velocity (m/s) it ran with."""
    case = JENIKE_CASES[run]
    return {**case.point, "lid": case.lid_kind, "shear_velocity": case.shear_velocity}


def calibration_chart_names():
    sweep = config["jenike"]["sweep"]
    return [f"{shape}_{test}" for shape in sweep["shapes"] for test in sweep["tests"]]


def lid_comparison_targets():
    sweep = config["jenike"]["sweep"]
    if not (sweep["lid_comparison"] and "internal" in sweep["tests"]):
        return []
    return [f"{CALIBRATION}/lid_comparison.csv", f"{CALIBRATION}/charts/lid_comparison.png"]


def _sweep_point(run):
    """The point as the sweep designed it (the lid and shear velocity only where they differ from the configured)."""
    point = dict(JENIKE_CASES[run].point)
    if JENIKE_CASES[run].lid_kind != config["jenike"]["lid"]:
        point["lid"] = JENIKE_CASES[run].lid_kind
    if JENIKE_CASES[run].shear_velocity != config["jenike"]["shear"]["velocity"]:
        point["shear_velocity"] = JENIKE_CASES[run].shear_velocity
    return point


def diagnostic_targets():
    points = diagnostic_points([_sweep_point(run) for run in JENIKE_CASES], config["jenike"]["sweep"], config["jenike"]["lid"])
    chosen = [run for run in JENIKE_CASES if _sweep_point(run) in points]
    return [run_path("jenike", f"plots/{name}.png", run) for run in chosen for name in ("mobilised_friction", "angular_velocity")]


def calibration_targets():
    return [
        *diagnostic_targets(),
        f"{CALIBRATION}/bulk_friction.csv",
        f"{CALIBRATION}/parameters.yaml",
        *[f"{CALIBRATION}/charts/{name}.png" for name in calibration_chart_names()],
        *lid_comparison_targets(),
        *[run_path("jenike", "metrics/fill_balance.json", run) for run in JENIKE_CASES],
    ]


rule jenike_deck:
    output:
        case=deck_rule_output("jenike"),
    params:
        case="jenike",
        defining=lambda wildcards: JENIKE_CASES[wildcards.run].defining_parameters,
    log:
        run_path("jenike", "logs/deck.log"),
    script:
        "../scripts/case_deck.py"


rule jenike_run:
    input:
        case=rules.jenike_deck.output.case,
    output:
        record=run_rule_output("jenike"),
    params:
        case="jenike",
        engine=config["engine"],
    resources:
        tasks=config["engine"]["mpi_ranks"],
    threads: config["engine"]["mpi_ranks"]
    log:
        run_path("jenike", "logs/run.log"),
    benchmark:
        run_benchmark("jenike"),
    script:
        "../scripts/case_run.py"


rule jenike_friction:
    input:
        record=rules.jenike_run.output.record,
        case=rules.jenike_deck.output.case,
    output:
        summary=run_path("jenike", "metrics/bulk_friction.json"),
        plot=report(run_path("jenike", "plots/forces.png"), caption="../report/jenike_forces.rst", category="1 Calibration", subcategory="Shear tests", labels={"figure": "{run}"}),
    params:
        point=lambda wildcards: jenike_point(wildcards.run),
    log:
        run_path("jenike", "logs/friction.log"),
    script:
        "../scripts/jenike_friction.py"


rule calibration_table:
    input:
        summaries=[run_path("jenike", "metrics/bulk_friction.json", run) for run in sorted(JENIKE_CASES)],
    output:
        table=f"{CALIBRATION}/bulk_friction.csv",
    log:
        f"{CALIBRATION}/logs/table.log",
    script:
        "../scripts/calibration_table.py"


rule calibration_charts:
    input:
        table=rules.calibration_table.output.table,
    output:
        charts=[
            report(f"{CALIBRATION}/charts/{name}.png", caption="../report/calibration_chart.rst",
                   category="1 Calibration", subcategory="Charts", labels={"figure": name})
            for name in calibration_chart_names()
        ],
    params:
        calibration=config["calibration"],
        base_restitution=config["jenike"]["sweep"]["restitution"],
        shear_velocity=config["jenike"]["shear"]["velocity"],
        lid=config["jenike"]["lid"],
    log:
        f"{CALIBRATION}/logs/charts.log",
    script:
        "../scripts/calibration_charts.py"


checkpoint calibration_parameters:
    input:
        table=rules.calibration_table.output.table,
    output:
        parameters=f"{CALIBRATION}/parameters.yaml",
    params:
        calibration=config["calibration"],
        base_restitution=config["jenike"]["sweep"]["restitution"],
        shear_velocity=config["jenike"]["shear"]["velocity"],
        lid=config["jenike"]["lid"],
    log:
        f"{CALIBRATION}/logs/parameters.log",
    script:
        "../scripts/calibration_parameters.py"


rule lid_comparison:
    input:
        table=rules.calibration_table.output.table,
    output:
        table=f"{CALIBRATION}/lid_comparison.csv",
        plot=report(f"{CALIBRATION}/charts/lid_comparison.png", caption="../report/lid_comparison.rst", category="1 Calibration", subcategory="Charts", labels={"figure": "lid comparison"}),
    params:
        base_restitution=config["jenike"]["sweep"]["restitution"],
        shear_velocity=config["jenike"]["shear"]["velocity"],
    log:
        f"{CALIBRATION}/logs/lid_comparison.log",
    script:
        "../scripts/lid_comparison.py"


rule jenike_diagnostics:
    input:
        record=rules.jenike_run.output.record,
        case=rules.jenike_deck.output.case,
    output:
        friction=report(run_path("jenike", "plots/mobilised_friction.png"), caption="../report/mobilised_friction.rst", category="1 Calibration", subcategory="Diagnostics", labels={"figure": "{run}"}),
        rotation=report(run_path("jenike", "plots/angular_velocity.png"), caption="../report/angular_velocity.rst", category="1 Calibration", subcategory="Diagnostics", labels={"figure": "{run}"}),
        summary=run_path("jenike", "metrics/diagnostics.json"),
    log:
        run_path("jenike", "logs/diagnostics.log"),
    script:
        "../scripts/jenike_diagnostics.py"
