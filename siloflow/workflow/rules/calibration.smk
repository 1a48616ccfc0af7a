# Calibration: Jenike shear-cell sweep -> bulk friction per point -> table, charts -> chosen parameters.

from siloflow.model.cases.jenike_sweep import diagnostic_points, is_chart_point

JENIKE_CASES = cases("jenike")


def jenike_point(run):
    """The sweep point of a Jenike run, with the lid, shear velocity (m/s) and pour it ran with."""
    return JENIKE_CASES[run].summary_point


def _on_chart(case):
    return is_chart_point(case.sweep_point, config["jenike"]["sweep"]["restitution"])


def calibration_chart_names(runs=None):
    """``<shape>_<test>`` of each calibration chart the sweep runs (of ``runs``' points only, run ids, when given)."""
    chosen = JENIKE_CASES if runs is None else {run: JENIKE_CASES[run] for run in runs}
    return list(dict.fromkeys(f"{case.point['shape']}_{case.point['test']}" for case in chosen.values()
                              if _on_chart(case)))


def chart_runs(chart):
    """The runs of one calibration chart (``<shape>_<test>``): its chart points."""
    return [run for run, case in JENIKE_CASES.items()
            if _on_chart(case) and f"{case.point['shape']}_{case.point['test']}" == chart]


def summaries_of(runs):
    return [run_path("jenike", "metrics/bulk_friction.json", run) for run in runs]


def lid_comparison_runs():
    """The runs the lid comparison pairs: the internal tests at the base restitution, rotation free, with either lid
    at the configured shear speed and first seed."""
    base = config["jenike"]["sweep"]["restitution"]
    return [run for run, case in JENIKE_CASES.items()
            if case.point["test"] == "internal" and is_chart_point({k: v for k, v in case.sweep_point.items()
                                                                    if k != "lid"}, base)]


def calibration_shape_runs():
    """The chart points of the calibration shape: what the calibrated parameters are read from."""
    return [run for run, case in JENIKE_CASES.items() if _on_chart(case)
            and case.point["shape"] == config["calibration"]["shape"]]


def lid_comparison_targets():
    sweep = config["jenike"]["sweep"]
    if not (sweep["lid_comparison"] and "internal" in sweep["tests"]):
        return []
    return [f"{CALIBRATION_DIR}/lid_comparison.csv", plot_file(f"{CALIBRATION_DIR}/charts/lid_comparison")]


def diagnostic_targets(runs=None):
    """The diagnostic plots of the runs (``runs``: run ids, all when None) whose points get diagnostics."""
    points = diagnostic_points([case.sweep_point for case in JENIKE_CASES.values()], config["jenike"]["sweep"],
                               config["jenike"]["lid"])
    chosen = [run for run in (JENIKE_CASES if runs is None else runs) if JENIKE_CASES[run].sweep_point in points]
    return [run_path("jenike", plot_file(f"plots/{name}"), run) for run in chosen for name in ("mobilised_friction", "angular_velocity")]


def calibration_targets(wildcards=None, runs=None):
    """The calibration's products: of ``runs`` (Jenike run ids) on their own, or of every run with the table, the
    charts, the chosen parameters and the lid comparison."""
    if runs is not None:
        return [*(run_path("jenike", name, run) for run in runs
                  for name in ("metrics/bulk_friction.json", "metrics/fill_balance.json", plot_file("plots/forces"))),
                *diagnostic_targets(runs)]
    return [
        *diagnostic_targets(),
        *[run_path("jenike", plot_file("plots/forces"), run) for run in JENIKE_CASES],
        f"{CALIBRATION_DIR}/bulk_friction.csv",
        CALIBRATED_PARAMETERS,
        *[plot_file(f"{CALIBRATION_DIR}/charts/{name}") for name in calibration_chart_names()],
        *lid_comparison_targets(),
        *[run_path("jenike", "metrics/fill_balance.json", run) for run in JENIKE_CASES],
    ]


CASE_TARGETS["jenike"] = calibration_targets


rule jenike_deck:
    output:
        case=deck_rule_output("jenike"),
    params:
        kind="jenike",
        case=typed_case("jenike"),
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
        kind="jenike",
        case=typed_case("jenike"),
        engine=config["engine"],
    resources:
        tasks=mpi_ranks,
    threads: mpi_ranks
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
    params:
        point=lambda wildcards: jenike_point(wildcards.run),
    log:
        run_path("jenike", "logs/friction.log"),
    script:
        "../scripts/jenike_shear_test.py"


# apart from the bulk friction: a validation group that reads another group's runs gets their bulk friction from
# that group's record, which keeps no plot of them
rule jenike_forces_plot:
    input:
        record=rules.jenike_run.output.record,
        case=rules.jenike_deck.output.case,
    output:
        plot=report(run_path("jenike", plot_file("plots/forces")), caption="../report/jenike_forces.rst", category="1 Calibration", subcategory="Shear tests", labels={"figure": "{run}"}),
    params:
        point=lambda wildcards: jenike_point(wildcards.run),
    log:
        run_path("jenike", "logs/forces_plot.log"),
    script:
        "../scripts/jenike_shear_test.py"


rule calibration_table:
    input:
        summaries=[run_path("jenike", "metrics/bulk_friction.json", run) for run in sorted(JENIKE_CASES)],
    output:
        table=f"{CALIBRATION_DIR}/bulk_friction.csv",
    log:
        f"{CALIBRATION_DIR}/logs/table.log",
    script:
        "../scripts/calibration_table.py"


rule calibration_chart:
    input:
        summaries=lambda wildcards: summaries_of(chart_runs(wildcards.chart)),
    output:
        chart=report(plot_file(f"{CALIBRATION_DIR}/charts/{{chart}}"), caption="../report/calibration_chart.rst",
                     category="1 Calibration", subcategory="Charts", labels={"figure": "{chart}"}),
    wildcard_constraints:
        chart="|".join(calibration_chart_names()) or "no chart",
    params:
        calibration=config["calibration"],
        base_restitution=config["jenike"]["sweep"]["restitution"],
        shear_velocity=config["jenike"]["shear"]["velocity"],
        lid=config["jenike"]["lid"],
        validation=config["validation"],
    log:
        f"{CALIBRATION_DIR}/logs/chart_{{chart}}.log",
    script:
        "../scripts/calibration_charts.py"


checkpoint calibration_parameters:
    input:
        summaries=summaries_of(calibration_shape_runs()),
    output:
        parameters=CALIBRATED_PARAMETERS,
    params:
        calibration=config["calibration"],
        base_restitution=config["jenike"]["sweep"]["restitution"],
        shear_velocity=config["jenike"]["shear"]["velocity"],
        lid=config["jenike"]["lid"],
    log:
        f"{CALIBRATION_DIR}/logs/parameters.log",
    script:
        "../scripts/calibration_parameters.py"


rule lid_comparison:
    input:
        summaries=summaries_of(lid_comparison_runs()),
    output:
        table=f"{CALIBRATION_DIR}/lid_comparison.csv",
        plot=report(plot_file(f"{CALIBRATION_DIR}/charts/lid_comparison"), caption="../report/lid_comparison.rst", category="1 Calibration", subcategory="Charts", labels={"figure": "lid comparison"}),
    params:
        base_restitution=config["jenike"]["sweep"]["restitution"],
        shear_velocity=config["jenike"]["shear"]["velocity"],
    log:
        f"{CALIBRATION_DIR}/logs/lid_comparison.log",
    script:
        "../scripts/lid_comparison.py"


rule jenike_diagnostics:
    input:
        case=rules.jenike_deck.output.case,
        record=rules.jenike_run.output.record,
    output:
        friction=report(run_path("jenike", plot_file("plots/mobilised_friction")), caption="../report/mobilised_friction.rst", category="1 Calibration", subcategory="Diagnostics", labels={"figure": "{run}"}),
        rotation=report(run_path("jenike", plot_file("plots/angular_velocity")), caption="../report/angular_velocity.rst", category="1 Calibration", subcategory="Diagnostics", labels={"figure": "{run}"}),
        summary=run_path("jenike", "metrics/diagnostics.json"),
    params:
        case=typed_case("jenike"),
    log:
        run_path("jenike", "logs/diagnostics.log"),
    script:
        "../scripts/jenike_diagnostics.py"
