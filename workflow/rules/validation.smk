# The validation table: the study's comparisons from this configuration's runs as one table (CSV and a report
# page), each row with its uncertainty and whether the scale shows its physics. It reads the products of every
# stage and runs no engine; config/validation.yaml (`make validate`) is the scale at which the rows are shown.

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


def validation_inputs(wildcards):
    base = run_ids("silo_flat")[0]
    inputs = {
        "bulk": f"{CALIBRATION}/bulk_friction.csv",
        "parameters": f"{CALIBRATION}/parameters.yaml",
        "janssen": run_path("silo_flat", "metrics/janssen.csv", base),
        "kinematic": run_path("silo_flat", "metrics/kinematic.csv", base),
        "boundary": run_path("silo_flat", "metrics/flow_channel_boundary.csv", base),
        "recirculation_cases": [run_path(RECIRCULATION, CASE_SUMMARY, run) for run in recirculation_runs()],
        "recirculation_summaries": [run_path(RECIRCULATION, "metrics/blending.json", run) for run in recirculation_runs()],
        "recirculation_rtds": [run_path(RECIRCULATION, "metrics/rtd.csv", run) for run in recirculation_runs()],
        "blender": [run_path("blender", "metrics/blender.json", run) for run in blender_runs()],
        "blender_cases": [run_path("blender", CASE_SUMMARY, run) for run in blender_runs()],
    }
    for key, name in SILO_FILES.items():
        inputs[f"silo_{key}"] = [run_path("silo_flat", name, run) for _, run in validation_silo_runs()]
    return inputs


rule validation_table:
    input:
        unpack(validation_inputs),
    output:
        table=f"{VALIDATION}/validation.csv",
        page=report(f"{VALIDATION}/validation.html", caption="../report/validation.rst", category="0 Summary",
                    labels={"figure": "validation table"}),
    params:
        criteria=config["validation"],
        cell_diameter=config["jenike"]["cell"]["inner_diameter"],
        shapes={shape: config["particle_models"][shape] for shape in config["jenike"]["sweep"]["shapes"]},
        density=config["materials"][config["jenike"]["particle_material"]]["density"],
        base_restitution=config["jenike"]["sweep"]["restitution"],
        lid=config["jenike"]["lid"],
        profile_height=config["silo_flat"]["parametric"]["profile_height"],
        labels=lambda wildcards: [label for label, _ in validation_silo_runs()],
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
            [target for kind in _kinds for target in KIND_TARGETS[kind]()],
