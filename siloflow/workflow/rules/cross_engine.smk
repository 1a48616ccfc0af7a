# The cross-engine check (`snakemake cross_engine`): the small flat-bottom silo of `cross_engine` and the Jenike points
# of `cross_engine.jenike` on two engines, `cross_engine.seeds` runs each; each silo run's filling bulk density, steady
# flow rate and centreline velocity, each Jenike run's bulk friction, and one table of the engines' means and spreads
# and their difference in standard errors.

CROSS_ENGINE_RUNS = cross_engine_cases(config)
try:
    CROSS_ENGINE_JENIKE_RUNS = cross_engine_jenike_cases(config)
    for _engine, _runs in CROSS_ENGINE_JENIKE_RUNS.items():
        for _label, _case in _runs.values():
            engine_named(_engine).check_case(_case)
    for _engine, _runs in CROSS_ENGINE_RUNS.items():
        for _case in _runs.values():
            engine_named(_engine).check_case(_case)
except (CaseNotSupported, ValueError) as error:
    raise WorkflowError(f"The cross-engine runs cannot be built or run on their engines: {error}") from None

CROSS_ENGINE_EXPLANATION = (
    "Each engine's mean and standard deviation over its seeds, and the difference of the means in units of its "
    "standard error. Where they differ: YADE's scripts have no tangential dashpot (with clumps it went unstable at "
    "the study's restitution; the flowing silo then loses less energy), its rolling resistance is an elastic-plastic "
    "moment (LIGGGHTS': constant directional torque, alike once rolling is fully mobilised) capped 1.5 times higher "
    "on a mesh wall, and its sphere-wall contact is softer (R* = r/2; see the verification table)."
)


def cross_engine_records():
    return [f"{CROSS_ENGINE_DIR}/{engine}/{run}/{RUN_RECORD}" for engine, runs in CROSS_ENGINE_RUNS.items()
            for run in runs]


def cross_engine_jenike_records():
    return [f"{CROSS_ENGINE_DIR}/jenike/{engine}/{run}/{RUN_RECORD}"
            for engine, runs in CROSS_ENGINE_JENIKE_RUNS.items() for run in runs]


rule cross_engine_run:
    output:
        record=f"{CROSS_ENGINE_DIR}/{{engine}}/{{run}}/{RUN_RECORD}",
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        run="[^/]+",
    log:
        f"{CROSS_ENGINE_DIR}/{{engine}}/{{run}}/logs/run.log",
    script:
        "../scripts/cross_engine_run.py"


rule cross_engine_metrics:
    input:
        record=f"{CROSS_ENGINE_DIR}/{{engine}}/{{run}}/{RUN_RECORD}",
    output:
        metrics=f"{CROSS_ENGINE_DIR}/{{engine}}/{{run}}/metrics/cross_engine.json",
    params:
        profile_height_fraction=config["cross_engine"]["profile_height_fraction"],
    log:
        f"{CROSS_ENGINE_DIR}/{{engine}}/{{run}}/logs/metrics.log",
    script:
        "../scripts/cross_engine_metrics.py"


rule cross_engine_jenike_run:
    output:
        record=f"{CROSS_ENGINE_DIR}/jenike/{{engine}}/{{run}}/{RUN_RECORD}",
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        run="[^/]+",
    log:
        f"{CROSS_ENGINE_DIR}/jenike/{{engine}}/{{run}}/logs/run.log",
    script:
        "../scripts/cross_engine_jenike_run.py"


rule cross_engine_jenike_friction:
    input:
        record=f"{CROSS_ENGINE_DIR}/jenike/{{engine}}/{{run}}/{RUN_RECORD}",
    output:
        metrics=f"{CROSS_ENGINE_DIR}/jenike/{{engine}}/{{run}}/metrics/bulk_friction.json",
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
        run="[^/]+",
    params:
        point=lambda wildcards: CROSS_ENGINE_JENIKE_RUNS[wildcards.engine][wildcards.run][0],
    log:
        f"{CROSS_ENGINE_DIR}/jenike/{{engine}}/{{run}}/logs/friction.log",
    script:
        "../scripts/cross_engine_jenike_friction.py"


rule cross_engine_table:
    input:
        metrics=[record.replace(RUN_RECORD, "metrics/cross_engine.json") for record in cross_engine_records()],
        jenike=[record.replace(RUN_RECORD, "metrics/bulk_friction.json") for record in cross_engine_jenike_records()],
    output:
        table=f"{CROSS_ENGINE_DIR}/cross_engine.csv",
        page=report(f"{CROSS_ENGINE_DIR}/cross_engine.html", caption="../report/cross_engine.rst",
                    category="0 Summary", labels={"figure": "cross-engine table"}),
    params:
        engines=config["cross_engine"]["engines"],
        explanation=CROSS_ENGINE_EXPLANATION,
    log:
        f"{CROSS_ENGINE_DIR}/logs/cross_engine_table.log",
    script:
        "../scripts/cross_engine_table.py"


rule cross_engine:
    input:
        rules.cross_engine_table.output.table,
