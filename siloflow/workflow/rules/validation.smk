# The validation table: the study's comparisons from this configuration's runs as one table (CSV and a report
# page), each row with its uncertainty and whether the scale shows its physics. It reads the products of every
# stage and runs no engine; config/validation.yaml (`make validate`) is the scale at which the rows are shown.

from siloflow.analysis.io.validation_record import RECORD_PLOT_FORMAT, check_plot_format
from siloflow.model.cases import REFERENCE, VARIANT, run_roles
from siloflow.model.cases.jenike_sweep import CALIBRATION_CHART, CHECK, SHAPE_CHART
from siloflow.engines.layout import READ_PRODUCTS, SILO_ROW_PRODUCTS, SUMMARY_DIR, VALIDATION_RECORD
from siloflow.engines.validation_groups import GROUPS, part_of_runs, split_groups



def roles(kind):
    """``{run id: role}`` of case ``kind``'s runs (the flat-bottom silo's with calibrated parameters applied when asked
    for)."""
    return run_roles(silo_config() if kind == "silo_flat" else config, kind)


def references(kind):
    """Run ids of the reference configuration of a silo-type case ``kind``, one per seed, in seed order."""
    return [run for run, role in roles(kind).items() if role == REFERENCE]


def group_made(group):
    """Run ids a validation group makes."""
    spec = GROUPS[group]
    if spec.roles is None:
        return run_ids(spec.kind)
    role = roles(spec.kind)
    return [run for run in run_ids(spec.kind) if spec.makes(spec.kind, role[run])]


def group_runs(group):
    """Run ids behind a validation group's rows: those it makes, then those of the groups it reads."""
    return [*group_made(group), *(run for other in GROUPS[group].reads for run in group_made(other))]


def front_wall_labels():
    """``{run id: label}`` of the front-wall friction series: the base run's seeds by their particle-front wall
    sliding friction (mu_fw=<value>), the variants by their study label."""
    silo = config["silo_flat"]
    pair = sorted([silo["particle_material"], silo["wall_materials"]["front_back"]])
    contact = next(c for c in silo_config()["contacts"] if sorted(c["materials"]) == pair)
    labels = {run: f"mu_fw={contact['sliding_friction']:g}" for run in references("silo_flat")}
    labels.update({run: label for label, run in parametric_studies().get("front_back_friction", []) if label != "base"})
    return labels


def group_rows_inputs(group):
    """The products a group's rows are read from (an input function of the group)."""

    def inputs(wildcards):
        kind = GROUPS[group].kind
        if kind == "jenike":
            found = {"summaries": [run_path("jenike", "metrics/bulk_friction.json", run) for run in group_runs(group)]}
            if CALIBRATION_CHART in GROUPS[group].roles:
                found["parameters"] = CALIBRATED_PARAMETERS
            return found
        if kind == "silo_flat":
            labels = front_wall_labels()
            runs = [run for run in group_runs(group) if run in labels]
            return {key: [run_path("silo_flat", name, run) for run in runs] for key, name in SILO_ROW_PRODUCTS.items()}
        if kind == RECIRCULATION:
            runs = recirculation_runs()
            return {"cases": [run_path(RECIRCULATION, CASE_SUMMARY, run) for run in runs],
                    "summaries": [run_path(RECIRCULATION, "metrics/blending.json", run) for run in runs],
                    "rtds": [run_path(RECIRCULATION, "metrics/rtd.csv", run) for run in runs]}
        return {"summaries": [run_path("blender", "metrics/blender.json", run) for run in blender_runs()],
                "cases": [run_path("blender", CASE_SUMMARY, run) for run in blender_runs()]}

    return inputs


def group_rows_params(group):
    """The configuration a group's rows use (siloflow.analysis.studies.validation.group_rows.group_rows): the keys of
    its case kind only, with the run ids of the reference configuration's seeds and, for the front-wall series, each
    run's label."""
    kind = GROUPS[group].kind
    params = {"group": group, "reference": [] if kind == "jenike" else references(kind)}
    if kind == "jenike":
        jenike, targets = config["jenike"], config["calibration"]
        # the rows each role's group judges: the curves of its charts, the coefficients read from the calibration
        # shape's, the checks against the charts
        sections = {CALIBRATION_CHART: ("curves", "calibrated"), SHAPE_CHART: ("curves",), CHECK: ("comparisons",)}
        params.update(sections=[section for role in GROUPS[group].roles for section in sections[role]],
                      base_restitution=jenike["sweep"]["restitution"], lid=jenike["lid"],
                      shear_velocity=jenike["shear"]["velocity"],
                      targets={test: [angle - targets["tolerance_deg"], angle + targets["tolerance_deg"]]
                               for test, angle in targets["targets_deg"].items()})
    elif kind == "silo_flat":
        params.update(profile_height=config["silo_flat"]["parametric"]["profile_height"],
                      labels=front_wall_labels() if group == "silo_series" else {})
    return params


rule validation_silo_profiles:
    input:
        fields=lambda wildcards: [run_path("silo_flat", "fields/depth_averaged.npz", run) for run in references("silo_flat")],
        kinematic=lambda wildcards: [run_path("silo_flat", "metrics/kinematic.csv", run) for run in references("silo_flat")],
        summaries=lambda wildcards: [run_path("silo_flat", "metrics/fields.json", run) for run in references("silo_flat")],
    output:
        plot=plot_file(f"{SUMMARY_DIR}/figures/silo_profiles"),
    params:
        heights=config["silo_flat"]["fields"]["profile_heights"],
    log:
        f"{SUMMARY_DIR}/figures/logs/silo_profiles.log",
    script:
        "../scripts/silo_seed_profiles.py"


rule validation_silo_janssen:
    input:
        janssen=lambda wildcards: [run_path("silo_flat", "metrics/janssen.csv", run)
                                   for run in references("silo_flat")],
    output:
        plot=plot_file(f"{SUMMARY_DIR}/figures/silo_janssen"),
    log:
        f"{SUMMARY_DIR}/figures/logs/silo_janssen.log",
    script:
        "../scripts/silo_seed_janssen.py"


def makes_runs(spec):
    """Whether a group makes any run of this configuration."""
    role = run_roles(config, spec.kind)
    return any(spec.makes(spec.kind, role[run]) for run in CASES[spec.kind])


#: The groups whose rows this configuration makes: a group without runs (a study switched off, a silo without a
#: front-wall series) has none.
ROW_GROUPS = [group for group, spec in GROUPS.items() if makes_runs(spec)]


for _group in ROW_GROUPS:

    rule:
        name:
            f"validation_rows_{_group}"
        input:
            unpack(group_rows_inputs(_group)),
        output:
            rows=f"{SUMMARY_DIR}/rows/{_group}.csv",
        params:
            kind=GROUPS[_group].kind,
            # a function: the calibrated silo's run ids are known after the calibration
            rows=lambda wildcards, group=_group: group_rows_params(group),
        log:
            f"{SUMMARY_DIR}/rows/{_group}.log",
        script:
            "../scripts/validation_rows.py"


rule validation_table:
    input:
        rows=[f"{SUMMARY_DIR}/rows/{group}.csv" for group in ROW_GROUPS],
    output:
        table=f"{SUMMARY_DIR}/validation.csv",
        page=report(f"{SUMMARY_DIR}/validation.html", caption="../report/validation.rst", category="0 Summary",
                    labels={"figure": "validation table"}),
    log:
        f"{SUMMARY_DIR}/validation.log",
    script:
        "../scripts/validation_table.py"


# The validation tier in groups (siloflow.engines.validation_groups): `make validate GROUP=<name>` asks for the products of the
# runs one group makes, with its record; a group too long for one session runs in parts, each asking for the products
# of its runs only (the Makefile then writes the group's record once its last run has finished).
def run_targets(kind, runs):
    """The products of each of ``runs`` of case ``kind`` on its own (the products across runs come with the record)."""
    return CASE_TARGETS[kind](runs=runs)


def group_targets(group):
    """The products of the runs a group makes and of the analyses across them: the Jenike runs' with the charts, the
    calibrated parameters and the lid comparison; the flat-bottom silo's with the parametric studies of the series;
    every other kind's as a whole."""
    spec, made = GROUPS[group], group_made(group)
    if spec.kind == "jenike":
        parameters = [CALIBRATED_PARAMETERS] if spec.makes(spec.kind, CALIBRATION_CHART) else []
        return [*run_targets("jenike", made), *record_plots(group).values(), *parameters]
    if spec.kind == "silo_flat":
        return [*run_targets("silo_flat", made), *(parametric_targets() if made and spec.makes(spec.kind, VARIANT) else [])]
    return CASE_TARGETS[spec.kind]()

#: Each group's parts, from the configuration's own cost estimates (siloflow.engines.validation_groups.split).
PARTS = split_groups(PLANNED_GROUP_RUNS)


def part_runs(part):
    """Run ids a part of a group makes."""
    return part.runs(group_made(part.group))


def made_by(group):
    """``{run id: the group or part that makes it}`` of the runs behind a group's rows."""
    names = (group, *GROUPS[group].reads)
    return part_of_runs({name: PARTS[name] for name in names if name in PARTS}, {name: group_made(name) for name in names})


for _group in GROUPS:

    rule:
        name:
            f"validate_{_group}"
        input:
            # input functions: the flat-bottom silo's runs are known only after the calibration when it uses
            # calibrated parameters
            lambda wildcards, group=_group: group_targets(group),
            [f"{VALIDATION_RECORD}/{_group}/{name}" for name in ("runs.csv", "table.csv")] if _group in ROW_GROUPS else [],


for _part in (part for group_parts in PARTS.values() if len(group_parts) > 1 for part in group_parts):

    rule:
        name:
            f"validate_{_part.name}"
        input:
            lambda wildcards, part=_part: run_targets(GROUPS[part.group].kind, part_runs(part)),


def record_plots(group):
    """``{name in the record: plot}`` a reader needs to judge a group's rows: calibration charts, the base silo's
    seeds' profiles and B and their stresses beside Janssen's, and the front-wall series, VRR against Nr, the
    blender's passage velocities and gravity series. The record keeps PNG plots
    (siloflow.analysis.io.validation_record): with another plots.format a group's record is refused here, before
    anything runs."""
    try:
        check_plot_format(PLOT_FORMAT)
    except ValueError as error:
        raise WorkflowError(str(error)) from None
    return {f"{name}.{RECORD_PLOT_FORMAT}": plot for name, plot in record_plot_sources(group).items()}


def record_plot_sources(group):
    """:func:`record_plots` by name in the record without its suffix."""
    kind = GROUPS[group].kind
    if kind == "jenike":
        plots = {name: plot_file(f"{CALIBRATION_DIR}/charts/{name}") for name in calibration_chart_names(group_made(group))}
        if GROUPS[group].makes(kind, CHECK):
            plots.update({"lid_comparison": path for path in lid_comparison_targets() if path.endswith(f".{PLOT_FORMAT}")})
        return plots
    if kind == "silo_flat":
        plots = {}
        if GROUPS[group].makes(kind, REFERENCE):
            # the reference seeds' profiles and stresses, combined as the rows combine them
            plots.update(profiles=plot_file(f"{SUMMARY_DIR}/figures/silo_profiles"),
                         janssen=plot_file(f"{SUMMARY_DIR}/figures/silo_janssen"))
        if GROUPS[group].makes(kind, VARIANT):
            plots.update({study: plot_file(f"{case_root('silo_flat')}/parametric/{study}") for study in parametric_studies()})
        return plots
    if kind == RECIRCULATION:
        return {"vrr": plot_file(f"{case_root(RECIRCULATION)}/summary/vrr")}
    plots = {f"insert_velocities_{cases('blender')[run].configuration}_g{cases('blender')[run].gravity_factor:g}":
             run_path("blender", plot_file("plots/insert_velocities"), run) for run in blender_runs()}
    if len(config["blender"]["gravity_factors"]) > 1:
        plots["gravity_scaling"] = plot_file(f"{case_root('blender')}/gravity/scaling")
    return plots


#: The groups whose runs another group's rows read.
READ_GROUPS = {other for spec in GROUPS.values() for other in spec.reads}


def read_products(group):
    """The products of the runs a group makes that another group reads (siloflow.engines.layout.READ_PRODUCTS), which its
    record keeps; none when no group reads it."""
    if group not in READ_GROUPS:
        return []
    kind = GROUPS[group].kind
    return [run_path(kind, name, run) for run in group_made(group) for name in READ_PRODUCTS[kind]]


def derivation(group):
    """What re-derives a group's rows from the products its record keeps: its case kind, the configuration keys its
    rows use and its products by name, as paths in the working directory."""
    inputs = group_rows_inputs(group)(None)
    return {"kind": GROUPS[group].kind, "params": group_rows_params(group),
            "inputs": {key: [paths] if isinstance(paths, str) else list(paths) for key, paths in inputs.items()}}


def kept_products(group):
    """The products a group's record keeps: those of its runs another group reads, and every product its rows are
    computed from (siloflow.analysis.io.validation_products), so that its rows can be derived again without a run."""
    rows = [path for paths in derivation(group)["inputs"].values() for path in paths]
    return list(dict.fromkeys([*read_products(group), *rows]))


for _group in ROW_GROUPS:

    rule:
        name:
            f"validation_record_{_group}"
        input:
            # input functions, as above: the runs of a calibrated silo are known after the calibration
            rows=f"{SUMMARY_DIR}/rows/{_group}.csv",
            records=lambda wildcards, group=_group: [run_path(GROUPS[group].kind, RUN_RECORD, run)
                                                     for run in group_runs(group)],
            benchmarks=lambda wildcards, group=_group: [run_path(GROUPS[group].kind, RUN_BENCHMARK, run)
                                                        for run in group_runs(group)],
            plots=lambda wildcards, group=_group: list(record_plots(group).values()),
            products=lambda wildcards, group=_group: kept_products(group),
        output:
            runs=f"{VALIDATION_RECORD}/{_group}/runs.csv",
            table=f"{VALIDATION_RECORD}/{_group}/table.csv",
        params:
            plot_names=lambda wildcards, group=_group: list(record_plots(group)),
            seeds=lambda wildcards, group=_group: {run: list(case.seeds) for run, case in
                                                   cases(GROUPS[group].kind).items()},
            made_by=lambda wildcards, group=_group: made_by(group),
            derivation=lambda wildcards, group=_group: derivation(group),
        log:
            f"{VALIDATION_RECORD}/{_group}.log",
        script:
            "../scripts/validation_record.py"
