# Blending in the recirculating flat-bottom silo: engine inputs -> engine run -> clump tracks -> direct measurement,
# RTDs and LTI predictions per flow pattern; the one-particle-thick verification of the Eulerian RTD; a summary.


def recirculation_runs(role="blending"):
    """Run ids of the recirculating-silo runs with the given role (the blending study or the thin verification silo)."""
    return [run for run, case in cases(RECIRCULATION).items() if case.role == role]


def shortcut_measured():
    """Whether the blending runs go on past where the study's shortcut stops, so that it can be measured on them."""
    blending = config[RECIRCULATION]
    return blending["recirculations"] > blending["tracer"]["start_recirculations"] + blending["shortcut"]["residence_times"]


def recirculation_targets(wildcards=None, runs=None):
    """The products of the recirculating silo's runs (``runs``: those of these run ids, without the summary across
    runs; all with the summary when None)."""
    blending = among(recirculation_runs(), runs)
    targets = [
        run_path(RECIRCULATION, name, run)
        for run in blending
        for name in ("metrics/blending.json",
                     *(plot_file(f"plots/{plot}") for plot in ("concentration", "vrr", "rtd", "lti", "vrr_period",
                                                               "recirculation_model")),
                     "plots/snapshots")
    ]
    # a run that starts from the flat-bottom silo's assembly has that run's settled fill and balance
    targets += [run_path(RECIRCULATION, "metrics/fill_balance.json", run) for run in blending
                if run in settled_runs(RECIRCULATION)]
    if shortcut_measured():
        targets += [run_path(RECIRCULATION, name, run) for run in blending
                    for name in ("metrics/shortcut.csv", plot_file("plots/shortcut"))]
    if runs is None and blending:
        targets += [f"{case_root(RECIRCULATION)}/summary/blending.csv", plot_file(f"{case_root(RECIRCULATION)}/summary/vrr")]
    verification = among(recirculation_runs("verification"), runs)
    targets += [
        run_path(RECIRCULATION, f"verification/{name}", run)
        for run in verification
        for name in ("verification.json", plot_file("paths"), plot_file("residence_times"))
    ]
    targets += [run_path(RECIRCULATION, "metrics/fill_balance.json", run) for run in verification]
    return targets


CASE_TARGETS[RECIRCULATION] = recirculation_targets


def recirculation_assembly(wildcards):
    """The record of the flat-bottom silo run whose settled fill a blending run starts from (its folder keeps the
    fill); none for a run that pours its own."""
    assembly = cases(RECIRCULATION)[wildcards.run].assembly
    return run_path("silo_flat", RUN_RECORD, run=assembly.run_id) if assembly is not None else []


rule silo_recirculation_deck:
    input:
        assembly=recirculation_assembly,
    output:
        case=deck_rule_output(RECIRCULATION),
    params:
        kind=RECIRCULATION,
        case=typed_case(RECIRCULATION),
        defining=lambda wildcards: cases(RECIRCULATION)[wildcards.run].defining_parameters,
    # as the run it feeds: Snakemake does not pass a priority on to a job's inputs, and the run can only start
    # once its deck is written
    priority: RUN_PRIORITY.get("silo_recirculation", 0)
    log:
        run_path(RECIRCULATION, "logs/deck.log"),
    script:
        "../scripts/case_deck.py"


rule silo_recirculation_run:
    input:
        case=rules.silo_recirculation_deck.output.case,
    output:
        record=run_rule_output(RECIRCULATION),
    params:
        kind=RECIRCULATION,
        case=typed_case(RECIRCULATION),
        engine=config["engine"],
    resources:
        tasks=mpi_ranks,
    threads: mpi_ranks
    priority: RUN_PRIORITY.get("silo_recirculation", 0)
    log:
        run_path(RECIRCULATION, "logs/run.log"),
    benchmark:
        run_benchmark(RECIRCULATION),
    script:
        "../scripts/case_run.py"


rule silo_recirculation_tracks:
    input:
        record=rules.silo_recirculation_run.output.record,
        case=rules.silo_recirculation_deck.output.case,
    output:
        tracks=f"{run_dir(RECIRCULATION)}/tracks.npz",
    params:
        on_damaged=config["dumps"]["on_damaged"],
    log:
        f"{run_dir(RECIRCULATION)}/logs/tracks.log",
    script:
        "../scripts/silo_recirculation_tracks.py"


rule silo_recirculation_analysis:
    input:
        case=rules.silo_recirculation_deck.output.case,
        tracks=rules.silo_recirculation_tracks.output.tracks,
    output:
        summary=f"{run_dir(RECIRCULATION)}/metrics/blending.json",
        concentration=f"{run_dir(RECIRCULATION)}/metrics/concentration.csv",
        vrr=f"{run_dir(RECIRCULATION)}/metrics/vrr.csv",
        rtd=f"{run_dir(RECIRCULATION)}/metrics/rtd.csv",
        vrr_period=f"{run_dir(RECIRCULATION)}/metrics/vrr_period.csv",
        model=f"{run_dir(RECIRCULATION)}/metrics/recirculation_model.csv",
        concentration_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/concentration"), caption="../report/silo_recirculation_concentration.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "concentration"}),
        vrr_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/vrr"), caption="../report/silo_recirculation_vrr.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "VRR"}),
        rtd_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/rtd"), caption="../report/silo_recirculation_rtd.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "RTD"}),
        lti_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/lti"), caption="../report/silo_recirculation_lti.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "LTI"}),
        vrr_period_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/vrr_period"), caption="../report/silo_recirculation_vrr_period.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "VRR vs period"}),
        model_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/recirculation_model"), caption="../report/silo_recirculation_model.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "recirculation model"}),
        snapshots=report(directory(f"{run_dir(RECIRCULATION)}/plots/snapshots"), patterns=[plot_file("{layout}")],
                         caption="../report/silo_recirculation_snapshots.rst", category="3 Recirculating silo", subcategory="{run}",
                         labels={"figure": "snapshots {layout}"}),
        per_layout=directory(f"{run_dir(RECIRCULATION)}/plots/layouts"),
    params:
        case=typed_case(RECIRCULATION),
        # of the plots in plots/snapshots/ and plots/layouts/, which the script names
        plot_format=PLOT_FORMAT,
        blending=lambda wildcards: {key: config[RECIRCULATION][key] for key in
                                    ("layouts", "lti", "concentration_window", "concentration_window_target_vrr", "tracer",
                                     "eulerian", "snapshots", "bulk_density_slab")},
    log:
        f"{run_dir(RECIRCULATION)}/logs/analysis.log",
    script:
        "../scripts/silo_recirculation_analysis.py"


rule silo_recirculation_shortcut:
    input:
        case=rules.silo_recirculation_deck.output.case,
        tracks=rules.silo_recirculation_tracks.output.tracks,
    output:
        table=report(f"{run_dir(RECIRCULATION)}/metrics/shortcut.csv", caption="../report/silo_recirculation_shortcut.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "shortcut table"}),
        plot=report(plot_file(f"{run_dir(RECIRCULATION)}/plots/shortcut"), caption="../report/silo_recirculation_shortcut.rst", category="3 Recirculating silo", subcategory="{run}", labels={"figure": "shortcut"}),
    params:
        case=typed_case(RECIRCULATION),
        blending=lambda wildcards: {key: config[RECIRCULATION][key] for key in
                                    ("layouts", "lti", "concentration_window", "concentration_window_target_vrr", "tracer",
                                     "shortcut")},
    log:
        f"{run_dir(RECIRCULATION)}/logs/shortcut.log",
    script:
        "../scripts/silo_recirculation_shortcut.py"


rule silo_recirculation_verification:
    input:
        case=rules.silo_recirculation_deck.output.case,
        tracks=rules.silo_recirculation_tracks.output.tracks,
    output:
        table=f"{run_dir(RECIRCULATION)}/verification/residence_times.csv",
        summary=f"{run_dir(RECIRCULATION)}/verification/verification.json",
        paths_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/verification/paths"), caption="../report/silo_recirculation_paths.rst", category="3 Recirculating silo", subcategory="Verification", labels={"figure": "paths"}),
        residence_plot=report(plot_file(f"{run_dir(RECIRCULATION)}/verification/residence_times"), caption="../report/silo_recirculation_residence.rst", category="3 Recirculating silo", subcategory="Verification", labels={"figure": "residence times"}),
    params:
        case=typed_case(RECIRCULATION),
        blending=lambda wildcards: {key: config[RECIRCULATION][key] for key in ("verification", "tracer", "eulerian")},
    log:
        f"{run_dir(RECIRCULATION)}/logs/verification.log",
    script:
        "../scripts/silo_recirculation_verification.py"


rule silo_recirculation_summary:
    input:
        summaries=lambda wildcards: [f"{run_dir(RECIRCULATION, run)}/metrics/blending.json" for run in recirculation_runs()],
        vrr=lambda wildcards: [f"{run_dir(RECIRCULATION, run)}/metrics/vrr.csv" for run in recirculation_runs()],
    output:
        table=f"{case_root(RECIRCULATION)}/summary/blending.csv",
        vrr_plot=report(plot_file(f"{case_root(RECIRCULATION)}/summary/vrr"), caption="../report/silo_recirculation_summary.rst", category="3 Recirculating silo", subcategory="Summary", labels={"figure": "VRR all"}),
    params:
        runs=lambda wildcards: recirculation_runs(),
        validation=config["validation"],
    log:
        f"{case_root(RECIRCULATION)}/summary/summary.log",
    script:
        "../scripts/silo_recirculation_summary.py"


rule silo_recirculation_all:
    input:
        # the kind's products as the workflow knows them at the end (ParaView's included)
        lambda wildcards: CASE_TARGETS[RECIRCULATION](wildcards),
