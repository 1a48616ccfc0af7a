# The joint Bayesian calibration (`snakemake bayesian_calibration`, calibration.bayesian): per engine, a space-filling
# first design of parameter sets, each run as one Jenike test per target; then per iteration the posterior on
# Gaussian-process surrogates of the runs and the next sets where it has mass, until it stops moving or the budget is
# spent; then runs at posterior draws (the predictive check), the posterior's report and the chart's answer beside it.

import json

from siloflow.calibration.bayes.joint import calibration_of, first_design, twin_sets
from siloflow.calibration.bayes.runs import cases_of_sets, with_runs
from siloflow.engines.layout import BAYESIAN_DIR

BAYES = calibration_of(config)
BAYES_SETTINGS = config["calibration"]["bayesian"]
# The first set's runs on each engine, built and accepted by the engine now: a cell or an engine limit fails here.
try:
    for _engine in BAYES_SETTINGS["engines"]:
        for _case in cases_of_sets(config, _engine, with_runs(config, BAYES, first_design(BAYES)[:1], _engine)).values():
            engine_named(_engine).check_case(_case)
except (CaseNotSupported, ValueError) as error:
    raise WorkflowError(f"The Bayesian calibration's runs cannot be built or run on their engines: {error}") from None


#: The twin experiment's runs at the known parameters, per engine (calibration.bayesian.twin): its targets.
BAYES_TWIN = BAYES_SETTINGS["twin"]["enabled"]
TWIN_SETS = {engine: with_runs(config, BAYES, twin_sets(BAYES), engine) if BAYES_TWIN else []
             for engine in BAYES_SETTINGS["engines"]}


def bayes_folder(engine="{engine}"):
    return f"{BAYESIAN_DIR}/{engine}"


def bayes_iteration_file(name, engine="{engine}", iteration="{iteration}"):
    return f"{bayes_folder(engine)}/iteration_{iteration}/{name}"


def bayes_run_file(name, engine="{engine}", run="{run}"):
    return f"{bayes_folder(engine)}/runs/{run}/{name}"


#: Each design file as read, by path and version: the DAG asks for the same designs once per job.
_DESIGNS = {}


def read_design(path):
    version = (str(path), Path(path).stat().st_mtime_ns)
    if version not in _DESIGNS:
        _DESIGNS[version] = json.loads(Path(path).read_text())
    return _DESIGNS[version]


def bayes_design(engine, iteration):
    """The sets of iteration ``iteration``'s design on ``engine`` (waits for its checkpoint)."""
    return read_design(checkpoints.bayes_design.get(engine=engine, iteration=str(iteration)).output.design)


def bayes_sets_upto(engine, iteration):
    return [chosen for k in range(int(iteration) + 1) for chosen in bayes_design(engine, k)["sets"]]


def bayes_summaries(sets, engine):
    return sorted({bayes_run_file("metrics/bulk_friction.json", engine, run) for chosen in sets
                   for run in chosen["runs"].values()})


def bayes_case(engine, run):
    """The case of a run of a design written on ``engine`` (its iterations' and the predictive check's) or of the twin
    experiment's truth."""
    designs = [read_design(path)["sets"] for path in sorted(Path(bayes_folder(engine)).glob("*/design.json"))]
    for found in (TWIN_SETS.get(engine, []), *designs):
        sets = [chosen for chosen in found if run in chosen["runs"].values()]
        if sets:
            return cases_of_sets(config, engine, sets[:1])[run]
    raise WorkflowError(f"no design of the Bayesian calibration on {engine} has the run {run}")


def bayes_final_iteration(engine):
    """The last iteration with a posterior: the one before the first design that stopped."""
    iteration = 1
    while not bayes_design(engine, iteration)["stopped"]:
        iteration += 1
    return iteration - 1


def bayes_targets(wildcards):
    """The twin experiment's targets, made by the engine at the truth; none when the targets are measured ones."""
    return [f"{bayes_folder(wildcards.engine)}/twin/targets.json"] if BAYES_TWIN else []


rule bayes_twin_targets:
    input:
        summaries=lambda wildcards: bayes_summaries(TWIN_SETS[wildcards.engine], wildcards.engine),
    output:
        targets=f"{bayes_folder()}/twin/targets.json",
    params:
        sets=lambda wildcards: TWIN_SETS[wildcards.engine],
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
    log:
        f"{bayes_folder()}/twin/logs/targets.log",
    script:
        "../scripts/bayes_twin_targets.py"


def bayes_previous(wildcards):
    """An iteration's design reads the previous iteration's posterior and every design before it."""
    iteration = int(wildcards.iteration)
    if iteration == 0:
        return []
    return [bayes_iteration_file(name, wildcards.engine, iteration - 1) for name in ("posterior.json", "posterior.npz")] + [
        bayes_iteration_file("design.json", wildcards.engine, k) for k in range(iteration)]


checkpoint bayes_design:
    input:
        previous=bayes_previous,
    output:
        design=bayes_iteration_file("design.json"),
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        iteration="[0-9]+",
    log:
        bayes_iteration_file("logs/design.log"),
    script:
        "../scripts/bayes_design.py"


# A run that fails (an unstable corner of the prior box) does not stop the calibration: its outcome says so, its
# set is left out of the posterior and named in posterior.json; the engine's files stay for inspection.
rule bayes_run:
    output:
        outcome=bayes_run_file("outcome.json"),
    params:
        case=lambda wildcards: bayes_case(wildcards.engine, wildcards.run),
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        run="[^/]+",
    resources:
        tasks=config["engine"]["mpi_ranks"],
    threads: config["engine"]["mpi_ranks"]
    log:
        bayes_run_file("logs/run.log"),
    benchmark:
        bayes_run_file(RUN_BENCHMARK)
    script:
        "../scripts/bayes_run.py"


rule bayes_friction:
    input:
        outcome=bayes_run_file("outcome.json"),
    output:
        summary=bayes_run_file("metrics/bulk_friction.json"),
    params:
        point=lambda wildcards: bayes_case(wildcards.engine, wildcards.run).summary_point,
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        run="[^/]+",
    log:
        bayes_run_file("logs/friction.log"),
    script:
        "../scripts/bayes_friction.py"


rule bayes_posterior:
    input:
        designs=lambda wildcards: [bayes_iteration_file("design.json", wildcards.engine, k)
                                   for k in range(int(wildcards.iteration) + 1)],
        summaries=lambda wildcards: bayes_summaries(bayes_sets_upto(wildcards.engine, wildcards.iteration),
                                                    wildcards.engine),
        previous=lambda wildcards: [] if int(wildcards.iteration) == 0 else [
            bayes_iteration_file(name, wildcards.engine, int(wildcards.iteration) - 1)
            for name in ("posterior.npz", "posterior.json")],
        targets=bayes_targets,
    output:
        samples=bayes_iteration_file("posterior.npz"),
        summary=bayes_iteration_file("posterior.json"),
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        iteration="[0-9]+",
    log:
        bayes_iteration_file("logs/posterior.log"),
    script:
        "../scripts/bayes_posterior.py"


checkpoint bayes_predictive_design:
    input:
        samples=lambda wildcards: bayes_iteration_file("posterior.npz", wildcards.engine,
                                                       bayes_final_iteration(wildcards.engine)),
    output:
        design=f"{bayes_folder()}/predictive/design.json",
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
    log:
        f"{bayes_folder()}/predictive/logs/design.log",
    script:
        "../scripts/bayes_predictive_design.py"


def bayes_predictive_sets(engine):
    return read_design(checkpoints.bayes_predictive_design.get(engine=engine).output.design)["sets"]


rule bayes_report:
    input:
        summary=lambda wildcards: bayes_iteration_file("posterior.json", wildcards.engine,
                                                       bayes_final_iteration(wildcards.engine)),
        samples=lambda wildcards: bayes_iteration_file("posterior.npz", wildcards.engine,
                                                       bayes_final_iteration(wildcards.engine)),
        designs=lambda wildcards: [bayes_iteration_file("design.json", wildcards.engine, k)
                                   for k in range(bayes_final_iteration(wildcards.engine) + 1)],
        runs=lambda wildcards: bayes_summaries(bayes_sets_upto(wildcards.engine, bayes_final_iteration(wildcards.engine)),
                                               wildcards.engine),
        predictive_design=f"{bayes_folder()}/predictive/design.json",
        predictive=lambda wildcards: bayes_summaries(bayes_predictive_sets(wildcards.engine), wildcards.engine),
        chart=[CALIBRATED_PARAMETERS] if BAYES_SETTINGS["compare_with_chart"] else [],
        targets=bayes_targets,
    output:
        posterior=f"{bayes_folder()}/posterior.json",
        intervals=report(f"{bayes_folder()}/intervals.csv", caption="../report/bayes_intervals.rst",
                         category="1 Calibration", subcategory="Bayesian", labels={"figure": "intervals {engine}"}),
        predictive=report(f"{bayes_folder()}/predictive.csv", caption="../report/bayes_predictive.rst",
                          category="1 Calibration", subcategory="Bayesian", labels={"figure": "predictive table {engine}"}),
        ridge=report(f"{bayes_folder()}/ridge.csv", caption="../report/bayes_ridge.rst", category="1 Calibration",
                     subcategory="Bayesian", labels={"figure": "ridge {engine}"}),
        comparison=report(f"{bayes_folder()}/chart_comparison.csv", caption="../report/bayes_chart.rst",
                          category="1 Calibration", subcategory="Bayesian", labels={"figure": "chart beside posterior {engine}"}),
        twin=report(f"{bayes_folder()}/twin.csv", caption="../report/bayes_twin.rst", category="1 Calibration",
                    subcategory="Bayesian", labels={"figure": "twin experiment {engine}"}),
        corner=report(plot_file(f"{bayes_folder()}/corner"), caption="../report/bayes_corner.rst", category="1 Calibration",
                      subcategory="Bayesian", labels={"figure": "posterior {engine}"}),
        predictive_plot=report(plot_file(f"{bayes_folder()}/predictive"), caption="../report/bayes_predictive.rst",
                               category="1 Calibration", subcategory="Bayesian",
                               labels={"figure": "predictive check {engine}"}),
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
    log:
        f"{bayes_folder()}/logs/report.log",
    script:
        "../scripts/bayes_report.py"


checkpoint bayes_parameters:
    input:
        posterior=f"{bayes_folder()}/posterior.json",
        predictive_design=f"{bayes_folder()}/predictive/design.json",
    output:
        parameters=f"{bayes_folder()}/parameters.yaml",
        draws=f"{bayes_folder()}/draws.yaml",
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
    log:
        f"{bayes_folder()}/logs/parameters.log",
    script:
        "../scripts/bayes_parameters.py"


rule bayesian_calibration:
    input:
        posteriors=[f"{bayes_folder(engine)}/posterior.json" for engine in BAYES_SETTINGS["engines"]],
    output:
        table=f"{BAYESIAN_DIR}/engines.csv",
    params:
        engines=BAYES_SETTINGS["engines"],
    log:
        f"{BAYESIAN_DIR}/logs/engines.log",
    script:
        "../scripts/bayes_engines.py"
