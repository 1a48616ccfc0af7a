# Planar flat-bottom silo (batch discharge): deck -> LIGGGHTS run -> flow metrics.

wildcard_constraints:
    run="[A-Za-z0-9_.-]+",


def silo_flat_targets(wildcards=None, runs=None):
    """The products of the flat-bottom silo's runs (``runs``: its run ids, all when None)."""
    return [
        run_path("silo_flat", name, run)
        for run in (run_ids("silo_flat") if runs is None else runs)
        for name in ("metrics/flow.csv", plot_file("plots/discharge"), "fields/fields.pvd", "metrics/profiles.csv",
                     plot_file("plots/profiles"), "metrics/fill_balance.json", *measured_comparison_names(),
                     *piv_names())
    ]


def piv_names():
    names = []
    if config["silo_flat"]["piv"]["enabled"]:
        names += ["metrics/piv_accuracy.csv", plot_file("plots/piv_accuracy")]
    if MEASURED_PIV_FILES:
        names += ["metrics/piv_comparison.csv", plot_file("plots/piv_comparison")]
    return names


def measured_comparison_names():
    if config["silo_flat"]["fields"]["measured_profiles"] is None:
        return []
    return ["metrics/measured_comparison.csv", plot_file("plots/measured_comparison")]


def parametric_studies():
    """``{study: [(label, run id), ...]}`` of the configured parametric silo studies, base run first."""
    base = silo_config()
    base_run = build_silo_case(base).run_id
    return {
        study: [("base", base_run)] + [(label, build_silo_case(variant).run_id) for label, variant in runs]
        for study, runs in parametric_variants(base).items()
    }


def parametric_targets(wildcards=None):
    folder = f"{case_root('silo_flat')}/parametric"
    return [path for study in parametric_studies() for path in (f"{folder}/{study}.csv", plot_file(f"{folder}/{study}"))]


def posterior_draw_targets(wildcards=None):
    if not config["silo_flat"]["posterior_draws"]:
        return []
    return [f"{case_root('silo_flat')}/posterior_draws/{name}" for name in ("runs.csv", "spread.csv", "summary.json",
                                                                            plot_file("draws"))]


def silo_flat_products(wildcards=None, runs=None):
    """The flat-bottom silo's products: its runs' (``runs``: these run ids only), with the parametric studies and the
    runs at the posterior's draws when all."""
    return silo_flat_targets(runs=runs) + (parametric_targets() + posterior_draw_targets() if runs is None else [])


CASE_TARGETS["silo_flat"] = silo_flat_products


rule silo_deck:
    input:
        parameters=calibrated_parameters_file,
    output:
        case=deck_rule_output("silo_flat"),
    params:
        kind="silo_flat",
        case=typed_case("silo_flat"),
        defining=lambda wildcards: cases("silo_flat")[wildcards.run].defining_parameters,
    # as the run it feeds: Snakemake does not pass a priority on to a job's inputs, and the run can only start
    # once its deck is written
    priority: RUN_PRIORITY.get("silo_flat", 0)
    log:
        run_path("silo_flat", "logs/deck.log"),
    script:
        "../scripts/case_deck.py"


rule silo_run:
    input:
        case=rules.silo_deck.output.case,
        parameters=calibrated_parameters_file,
    output:
        record=run_rule_output("silo_flat"),
    params:
        kind="silo_flat",
        case=typed_case("silo_flat"),
        engine=config["engine"],
    resources:
        tasks=mpi_ranks,
    threads: mpi_ranks
    priority: RUN_PRIORITY.get("silo_flat", 0)
    log:
        run_path("silo_flat", "logs/run.log"),
    benchmark:
        run_benchmark("silo_flat"),
    script:
        "../scripts/case_run.py"


rule silo_metrics:
    input:
        case=rules.silo_deck.output.case,
        record=rules.silo_run.output.record,
    output:
        table=f"{run_dir('silo_flat')}/metrics/flow.csv",
        history=f"{run_dir('silo_flat')}/metrics/discharge.csv",
        summary=f"{run_dir('silo_flat')}/metrics/flow.json",
        plot=report(plot_file(f"{run_dir('silo_flat')}/plots/discharge"), caption="../report/silo_discharge.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "discharge"}),
    params:
        case=typed_case("silo_flat"),
        analysis=lambda wildcards: {
            "steady_window": config["silo_flat"]["steady_window"],
            "beverloo": config["silo_flat"]["beverloo"],
        },
        on_damaged=config["dumps"]["on_damaged"],
    log:
        f"{run_dir('silo_flat')}/logs/metrics.log",
    script:
        "../scripts/silo_metrics.py"


rule silo_fields:
    input:
        case=rules.silo_deck.output.case,
        record=rules.silo_run.output.record,
        flow=rules.silo_metrics.output.summary,
    output:
        pvd=f"{run_dir('silo_flat')}/fields/fields.pvd",
        arrays=f"{run_dir('silo_flat')}/fields/averaged.npz",
        profiles=f"{run_dir('silo_flat')}/metrics/profiles.csv",
        instantaneous=f"{run_dir('silo_flat')}/metrics/profiles_instantaneous.csv",
        boundaries=f"{run_dir('silo_flat')}/metrics/flow_channel_boundary.csv",
        kinematic=f"{run_dir('silo_flat')}/metrics/kinematic.csv",
        centreline=f"{run_dir('silo_flat')}/metrics/centreline_velocity.csv",
        janssen=f"{run_dir('silo_flat')}/metrics/janssen.csv",
        summary=f"{run_dir('silo_flat')}/metrics/fields.json",
        profile_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/profiles"), caption="../report/silo_profiles.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "velocity profiles"}),
        contour_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/vz_contour"), caption="../report/silo_contour.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "v_z field"}),
        kinematic_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/kinematic_B"), caption="../report/silo_kinematic_b.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "kinematic B"}),
        kinematic_u_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/kinematic_u"), caption="../report/silo_kinematic_u.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "kinematic u"}),
        centreline_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/centreline_velocity"), caption="../report/silo_centreline.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "centreline"}),
        janssen_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/janssen"), caption="../report/silo_janssen.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "Janssen"}),
        force_chain_plot=report(plot_file(f"{run_dir('silo_flat')}/plots/force_chains"), caption="../report/silo_force_chains.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "force chains"}),
    params:
        case=typed_case("silo_flat"),
        settings=lambda wildcards: config["silo_flat"]["fields"],
        on_damaged=config["dumps"]["on_damaged"],
    log:
        f"{run_dir('silo_flat')}/logs/fields.log",
    script:
        "../scripts/silo_fields.py"


rule silo_piv_synthetic:
    input:
        case=rules.silo_deck.output.case,
        record=rules.silo_run.output.record,
    output:
        table=f"{run_dir('silo_flat')}/metrics/piv_accuracy.csv",
        profiles=f"{run_dir('silo_flat')}/metrics/piv_accuracy_profiles.csv",
        plot=report(plot_file(f"{run_dir('silo_flat')}/plots/piv_accuracy"), caption="../report/silo_piv_accuracy.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "PIV accuracy"}),
    params:
        case=typed_case("silo_flat"),
        piv=config["silo_flat"]["piv"],
        heights=config["silo_flat"]["fields"]["profile_heights"],
        on_damaged=config["dumps"]["on_damaged"],
    log:
        f"{run_dir('silo_flat')}/logs/piv_synthetic.log",
    script:
        "../scripts/silo_piv_synthetic.py"


rule silo_piv_compare:
    input:
        case=rules.silo_deck.output.case,
        record=rules.silo_run.output.record,
        profiles=rules.silo_piv_synthetic.output.profiles,
        measured=lambda wildcards: [str(p) for p in MEASURED_PIV_FILES],
    output:
        table=f"{run_dir('silo_flat')}/metrics/piv_comparison.csv",
        plot=report(plot_file(f"{run_dir('silo_flat')}/plots/piv_comparison"), caption="../report/silo_piv_comparison.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "PIV comparison"}),
    params:
        case=typed_case("silo_flat"),
        piv=config["silo_flat"]["piv"],
        heights=config["silo_flat"]["fields"]["profile_heights"],
        on_damaged=config["dumps"]["on_damaged"],
    log:
        f"{run_dir('silo_flat')}/logs/piv_compare.log",
    script:
        "../scripts/silo_piv_compare.py"


rule silo_measured_comparison:
    input:
        fields=rules.silo_fields.output.arrays,
        measured=lambda wildcards: config["silo_flat"]["fields"]["measured_profiles"],
    output:
        table=f"{run_dir('silo_flat')}/metrics/measured_comparison.csv",
        plot=report(plot_file(f"{run_dir('silo_flat')}/plots/measured_comparison"), caption="../report/silo_measured.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "measured"}),
    params:
        plane=config["silo_flat"]["fields"]["measured_plane"],
    log:
        f"{run_dir('silo_flat')}/logs/measured_comparison.log",
    script:
        "../scripts/silo_measured_comparison.py"


rule silo_depth_averaged:
    input:
        arrays=rules.silo_fields.output.arrays,
    output:
        arrays=f"{run_dir('silo_flat')}/fields/depth_averaged.npz",
    log:
        f"{run_dir('silo_flat')}/logs/depth_averaged.log",
    script:
        "../scripts/silo_depth_averaged.py"


def _study_runs(wildcards):
    return parametric_studies()[wildcards.study]


rule silo_parametric:
    input:
        flows=lambda wildcards: [run_path("silo_flat", "metrics/flow.json", run) for _, run in _study_runs(wildcards)],
        fields=lambda wildcards: [run_path("silo_flat", "fields/depth_averaged.npz", run) for _, run in _study_runs(wildcards)],
    output:
        table=f"{case_root('silo_flat')}/parametric/{{study}}.csv",
        plot=report(plot_file(f"{case_root('silo_flat')}/parametric/{{study}}"), caption="../report/silo_parametric.rst", category="2 Silo validation", subcategory="Parametric studies", labels={"figure": "{study}"}),
    params:
        labels=lambda wildcards: [label for label, _ in _study_runs(wildcards)],
        runs=lambda wildcards: [run for _, run in _study_runs(wildcards)],
        profile_height=config["silo_flat"]["parametric"]["profile_height"],
    log:
        f"{case_root('silo_flat')}/parametric/logs/{{study}}.log",
    script:
        "../scripts/silo_parametric.py"


rule silo_posterior_draws:
    input:
        parameters=calibrated_parameters_file,
        draws=lambda wildcards: checkpoints.bayes_parameters.get(engine=engine_kind(config, "silo_flat")).output.draws,
        flows=lambda wildcards: [run_path("silo_flat", "metrics/flow.json", run) for _, run in posterior_draw_runs()],
        janssen=lambda wildcards: [run_path("silo_flat", "metrics/janssen.csv", run) for _, run in posterior_draw_runs()],
    output:
        table=f"{case_root('silo_flat')}/posterior_draws/runs.csv",
        spread=report(f"{case_root('silo_flat')}/posterior_draws/spread.csv", caption="../report/silo_posterior_draws.rst", category="2 Silo validation", subcategory="Calibration uncertainty", labels={"figure": "calibration error bars"}),
        summary=f"{case_root('silo_flat')}/posterior_draws/summary.json",
        plot=report(plot_file(f"{case_root('silo_flat')}/posterior_draws/draws"), caption="../report/silo_posterior_draws.rst", category="2 Silo validation", subcategory="Calibration uncertainty", labels={"figure": "runs at posterior draws"}),
    params:
        labels=lambda wildcards: [label for label, _ in posterior_draw_runs()],
        runs=lambda wildcards: [run for _, run in posterior_draw_runs()],
        engine=engine_kind(config, "silo_flat"),
    log:
        f"{case_root('silo_flat')}/posterior_draws/logs/draws.log",
    script:
        "../scripts/silo_posterior_draws.py"
