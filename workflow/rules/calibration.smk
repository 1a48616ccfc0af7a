# Calibration: Jenike shear-cell sweep -> bulk friction per point -> table, charts -> chosen parameters.

from calibration.sweep import diagnostic_points, sweep_points
from engines.cases.jenike import build_jenike_case


def _jenike_points():
    points = {}
    for point in sweep_points(config["jenike"]["sweep"], lid=config["jenike"]["lid"]):
        try:
            case = build_jenike_case(config, point)
        except ValueError as error:
            raise WorkflowError(f"Invalid jenike configuration for sweep point {point}: {error}") from None
        points[case.run_id] = point
    return points


JENIKE_POINTS = _jenike_points()
CALIBRATION = f"{RESULTS}/calibration"


def jenike_dir(run_id):
    return f"{CALIBRATION}/runs/{run_id}"


def calibration_chart_names():
    sweep = config["jenike"]["sweep"]
    return [f"{shape}_{test}" for shape in sweep["shapes"] for test in sweep["tests"]]


def lid_comparison_targets():
    sweep = config["jenike"]["sweep"]
    if not (sweep["lid_comparison"] and "internal" in sweep["tests"]):
        return []
    return [f"{CALIBRATION}/lid_comparison.csv", f"{CALIBRATION}/charts/lid_comparison.png"]


def diagnostic_targets():
    points = diagnostic_points(list(JENIKE_POINTS.values()), config["jenike"]["sweep"], config["jenike"]["lid"])
    chosen = [run_id for run_id, point in JENIKE_POINTS.items() if point in points]
    return [f"{jenike_dir(run_id)}/plots/{name}.png" for run_id in chosen for name in ("mobilised_friction", "angular_velocity")]


def calibration_targets():
    return [
        *diagnostic_targets(),
        f"{CALIBRATION}/bulk_friction.csv",
        f"{CALIBRATION}/parameters.yaml",
        *[f"{CALIBRATION}/charts/{name}.png" for name in calibration_chart_names()],
        *lid_comparison_targets(),
    ]


rule jenike_deck:
    output:
        deck=f"{CALIBRATION}/runs/{{point}}/deck/in.liggghts",
        case=f"{CALIBRATION}/runs/{{point}}/deck/case.json",
    params:
        point=lambda wildcards: JENIKE_POINTS[wildcards.point],
    log:
        f"{CALIBRATION}/runs/{{point}}/logs/deck.log",
    script:
        "../scripts/jenike_deck.py"


rule jenike_run:
    input:
        deck=rules.jenike_deck.output.deck,
    output:
        record=f"{CALIBRATION}/runs/{{point}}/run.json",
    params:
        point=lambda wildcards: JENIKE_POINTS[wildcards.point],
        engine=config["engine"],
    resources:
        tasks=config["engine"]["mpi_ranks"],
    threads: config["engine"]["mpi_ranks"]
    log:
        f"{CALIBRATION}/runs/{{point}}/logs/run.log",
    script:
        "../scripts/jenike_run.py"


rule jenike_friction:
    input:
        record=rules.jenike_run.output.record,
        case=rules.jenike_deck.output.case,
    output:
        summary=f"{CALIBRATION}/runs/{{point}}/metrics/bulk_friction.json",
        plot=report(f"{CALIBRATION}/runs/{{point}}/plots/forces.png", caption="../report/jenike_forces.rst", category="1 Calibration", subcategory="Shear tests", labels={"figure": "{point}"}),
    params:
        point=lambda wildcards: JENIKE_POINTS[wildcards.point],
        lid=config["jenike"]["lid"],
    log:
        f"{CALIBRATION}/runs/{{point}}/logs/friction.log",
    script:
        "../scripts/jenike_friction.py"


rule calibration_table:
    input:
        summaries=expand(f"{CALIBRATION}/runs/{{point}}/metrics/bulk_friction.json", point=sorted(JENIKE_POINTS)),
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
    log:
        f"{CALIBRATION}/logs/lid_comparison.log",
    script:
        "../scripts/lid_comparison.py"


rule jenike_diagnostics:
    input:
        record=rules.jenike_run.output.record,
        case=rules.jenike_deck.output.case,
    output:
        friction=report(f"{CALIBRATION}/runs/{{point}}/plots/mobilised_friction.png", caption="../report/mobilised_friction.rst", category="1 Calibration", subcategory="Diagnostics", labels={"figure": "{point}"}),
        rotation=report(f"{CALIBRATION}/runs/{{point}}/plots/angular_velocity.png", caption="../report/angular_velocity.rst", category="1 Calibration", subcategory="Diagnostics", labels={"figure": "{point}"}),
        summary=f"{CALIBRATION}/runs/{{point}}/metrics/diagnostics.json",
    log:
        f"{CALIBRATION}/runs/{{point}}/logs/diagnostics.log",
    script:
        "../scripts/jenike_diagnostics.py"
