# The cross-engine check (`snakemake cross_engine`): the small flat-bottom silo of `cross_engine` on two engines,
# `cross_engine.seeds` runs each; each run's filling bulk density, steady flow rate and centreline velocity, and one
# table of the engines' means and spreads and their difference in standard errors.

CROSS_ENGINE_DIR = f"{RESULTS}/cross_engine"
CROSS_ENGINE_RUNS = cross_engine_cases(config)

CROSS_ENGINE_EXPLANATION = (
    "Each engine's mean and standard deviation over its seeds, and the difference of the means in units of its "
    "standard error. Where they differ: the rolling resistance (LIGGGHTS' constant directional torque against YADE's "
    "elastic-plastic moment, alike once rolling is fully mobilised) and the sphere-wall contact (YADE takes R* = r/2 "
    "for a sphere on a wall: a softer wall contact; see the verification table). The Jenike points are not compared "
    "yet: YADE has no shear-cell script."
)


def cross_engine_records():
    return [f"{CROSS_ENGINE_DIR}/{engine}/{run}/{RUN_RECORD}" for engine, runs in CROSS_ENGINE_RUNS.items()
            for run in runs]


rule cross_engine_run:
    output:
        record=f"{CROSS_ENGINE_DIR}/{{engine}}/{{run}}/{RUN_RECORD}",
    wildcard_constraints:
        engine="|".join(ENGINE_KINDS),
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


rule cross_engine_table:
    input:
        metrics=[record.replace(RUN_RECORD, "metrics/cross_engine.json") for record in cross_engine_records()],
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
