# The validation table: the study's comparisons from this configuration's runs as one table (CSV and a report
# page), each row with its uncertainty and whether the scale shows its physics. It reads the products of every
# stage and runs no engine; config/validation.yaml (`make validate`) is the scale at which the rows are shown.

from engines.layout import VALIDATION_RECORD
from engines.validation_groups import GROUPS

VALIDATION = f"{RESULTS}/summary"
SILO_FILES = {"case": CASE_SUMMARY, "flow": "metrics/flow.json", "fields": "metrics/fields.json",
              "balance": "metrics/fill_balance.json"}


def validation_silo_runs():
    """``[(label, run id)]``: the base silo run first, then the front-wall friction series (labels mu_fw=<value>)."""
    base = run_ids("silo_flat")[0]
    series = parametric_studies().get("front_back_friction", [])
    return [(front_wall_label(), base)] + [(label, run) for label, run in series if label != "base"]


def front_wall_label():
    """The base run's label in the front-wall series: its particle-front wall sliding friction."""
    silo = config["silo_flat"]
    pair = sorted([silo["particle_material"], silo["wall_materials"]["front_back"]])
    contact = next(c for c in silo_config()["contacts"] if sorted(c["materials"]) == pair)
    return f"mu_fw={contact['sliding_friction']:g}"


def group_rows_inputs(group):
    """The products each group's rows are read from (an input function of the group)."""

    def inputs(wildcards):
        if group == "calibration":
            return {"bulk": f"{CALIBRATION}/bulk_friction.csv", "parameters": f"{CALIBRATION}/parameters.yaml"}
        if group == "silo":
            base = run_ids("silo_flat")[0]
            found = {
                "janssen": run_path("silo_flat", "metrics/janssen.csv", base),
                "kinematic": run_path("silo_flat", "metrics/kinematic.csv", base),
                "boundary": run_path("silo_flat", "metrics/flow_channel_boundary.csv", base),
            }
            for key, name in SILO_FILES.items():
                found[f"silo_{key}"] = [run_path("silo_flat", name, run) for _, run in validation_silo_runs()]
            return found
        if group == "blending":
            runs = recirculation_runs()
            return {"cases": [run_path(RECIRCULATION, CASE_SUMMARY, run) for run in runs],
                    "summaries": [run_path(RECIRCULATION, "metrics/blending.json", run) for run in runs],
                    "rtds": [run_path(RECIRCULATION, "metrics/rtd.csv", run) for run in runs]}
        return {"summaries": [run_path("blender", "metrics/blender.json", run) for run in blender_runs()],
                "cases": [run_path("blender", CASE_SUMMARY, run) for run in blender_runs()]}

    return inputs


#: The groups whose rows this configuration makes: a group without runs (a study switched off) has none.
ROW_GROUPS = [group for group, kinds in GROUPS.items() if any(CASES[kind] for kind in kinds)]


for _group in ROW_GROUPS:

    rule:
        name:
            f"validation_rows_{_group}"
        input:
            unpack(group_rows_inputs(_group)),
        output:
            rows=f"{VALIDATION}/rows/{_group}.csv",
        params:
            group=_group,
            criteria=config["validation"],
            cell_diameter=config["jenike"]["cell"]["inner_diameter"],
            shapes={shape: config["particle_models"][shape] for shape in config["jenike"]["sweep"]["shapes"]},
            density=config["materials"][config["jenike"]["particle_material"]]["density"],
            base_restitution=config["jenike"]["sweep"]["restitution"],
            lid=config["jenike"]["lid"],
            profile_height=config["silo_flat"]["parametric"]["profile_height"],
            labels=lambda wildcards: [label for label, _ in validation_silo_runs()],
        log:
            f"{VALIDATION}/rows/{_group}.log",
        script:
            "../scripts/validation_rows.py"


rule validation_table:
    input:
        rows=[f"{VALIDATION}/rows/{group}.csv" for group in ROW_GROUPS],
    output:
        table=f"{VALIDATION}/validation.csv",
        page=report(f"{VALIDATION}/validation.html", caption="../report/validation.rst", category="0 Summary",
                    labels={"figure": "validation table"}),
    log:
        f"{VALIDATION}/validation.log",
    script:
        "../scripts/validation_table.py"


# The validation tier in groups (engines.validation_groups): `make validate GROUP=<name>` asks for the products of one
# group's case kinds, here their targets per kind.
KIND_TARGETS = {
    "jenike": calibration_targets,
    "silo_flat": lambda: [*silo_flat_targets(), *parametric_targets()],
    RECIRCULATION: recirculation_targets,
    "blender": blender_targets,
}

for _group, _kinds in GROUPS.items():

    rule:
        name:
            f"validate_{_group}"
        input:
            # input functions: the flat-bottom silo's runs are known only after the calibration when it uses
            # calibrated parameters
            lambda wildcards, kinds=_kinds: [target for kind in kinds for target in KIND_TARGETS[kind]()],
            [f"{VALIDATION_RECORD}/{_group}/{name}" for name in ("runs.csv", "table.csv")] if _group in ROW_GROUPS else [],


def record_plots(group):
    """``{name in the record: plot}`` a reader needs to judge a group's rows: calibration charts, the base silo's
    profiles and Janssen comparison with the front-wall series, VRR against Nr, the blender's passage velocities
    and gravity series."""
    if group == "calibration":
        plots = {f"{name}.png": f"{CALIBRATION}/charts/{name}.png" for name in calibration_chart_names()}
        plots.update({"lid_comparison.png": path for path in lid_comparison_targets() if path.endswith(".png")})
        return plots
    if group == "silo":
        base = run_ids("silo_flat")[0]
        plots = {f"{name}.png": run_path("silo_flat", f"plots/{name}.png", base) for name in ("profiles", "janssen")}
        plots.update({f"{study}.png": f"{case_root('silo_flat')}/parametric/{study}.png" for study in parametric_studies()})
        return plots
    if group == "blending":
        return {"vrr.png": f"{case_root(RECIRCULATION)}/summary/vrr.png"}
    plots = {f"insert_velocities_{cases('blender')[run].configuration}_g{cases('blender')[run].gravity_factor:g}.png":
             run_path("blender", "plots/insert_velocities.png", run) for run in blender_runs()}
    if len(config["blender"]["gravity_factors"]) > 1:
        plots["gravity_scaling.png"] = f"{case_root('blender')}/gravity/scaling.png"
    return plots


for _group in ROW_GROUPS:

    rule:
        name:
            f"validation_record_{_group}"
        input:
            # input functions, as above: the runs of a calibrated silo are known after the calibration
            rows=f"{VALIDATION}/rows/{_group}.csv",
            records=lambda wildcards, kinds=GROUPS[_group]: [run_path(kind, RUN_RECORD, run) for kind in kinds
                                                             for run in run_ids(kind)],
            benchmarks=lambda wildcards, kinds=GROUPS[_group]: [run_path(kind, RUN_BENCHMARK, run) for kind in kinds
                                                                for run in run_ids(kind)],
            plots=lambda wildcards, group=_group: list(record_plots(group).values()),
        output:
            runs=f"{VALIDATION_RECORD}/{_group}/runs.csv",
            table=f"{VALIDATION_RECORD}/{_group}/table.csv",
        params:
            plot_names=lambda wildcards, group=_group: list(record_plots(group)),
            seeds=lambda wildcards, kinds=GROUPS[_group]: {run: list(case.seeds) for kind in kinds
                                                           for run, case in cases(kind).items()},
        log:
            f"{VALIDATION_RECORD}/{_group}.log",
        script:
            "../scripts/validation_record.py"
