# Multi-flow blender: engine inputs -> engine run -> steady depth-averaged fields -> profiles, pathlines, RTD and blending
# modes per configuration; a comparison of the configurations; gravity scaling when several factors are run.


def blender_runs():
    """Run ids of the blender runs (configurations x gravity factors)."""
    return run_ids("blender")


def blender_targets(wildcards=None, runs=None):
    """The products of the blender's runs (``runs``: those of these run ids, without the comparisons across runs;
    all with the comparisons when None)."""
    chosen = among(blender_runs(), runs)
    targets = [
        run_path("blender", name, run)
        for run in chosen
        for name in ("metrics/blender.json", "metrics/fill_balance.json",
                     *(plot_file(f"plots/{plot}") for plot in ("profiles", "insert_velocities", "flow_channel",
                                                               "pathlines", "rtd", "discontinuous", "vrr_period")))
    ]
    if runs is not None:
        return targets
    if chosen:
        targets += [f"{case_root('blender')}/comparison/{name}"
                    for name in ("configurations.csv", "significance.csv", "configurations.md", plot_file("configurations"),
                                 plot_file("rtd"))]
    if len(config["blender"]["gravity_factors"]) > 1:
        targets += [f"{case_root('blender')}/gravity/scaling.csv", plot_file(f"{case_root('blender')}/gravity/scaling")]
    return targets


CASE_TARGETS["blender"] = blender_targets


rule blender_deck:
    output:
        case=deck_rule_output("blender"),
    params:
        kind="blender",
        case=typed_case("blender"),
        defining=lambda wildcards: cases("blender")[wildcards.run].defining_parameters,
    # as the run it feeds: Snakemake does not pass a priority on to a job's inputs, and the run can only start
    # once its deck is written
    priority: RUN_PRIORITY.get("blender", 0)
    log:
        run_path("blender", "logs/deck.log"),
    script:
        "../scripts/case_deck.py"


rule blender_run:
    input:
        case=rules.blender_deck.output.case,
    output:
        record=run_rule_output("blender"),
    params:
        kind="blender",
        case=typed_case("blender"),
        engine=config["engine"],
    resources:
        tasks=mpi_ranks,
    threads: mpi_ranks
    priority: RUN_PRIORITY.get("blender", 0)
    log:
        run_path("blender", "logs/run.log"),
    benchmark:
        run_benchmark("blender"),
    script:
        "../scripts/case_run.py"


rule blender_fields:
    input:
        case=rules.blender_deck.output.case,
        record=rules.blender_run.output.record,
    output:
        fields=f"{run_dir('blender')}/fields/fields.npz",
        flow=f"{run_dir('blender')}/metrics/flow.json",
        # each frame of the steady window: the series whose batch means give the passage velocities' errors
        frames=f"{run_dir('blender')}/fields/steady_frames.npz",
        # the same of the layer at the front and back walls: what the study's PIV sees
        wall_layer=f"{run_dir('blender')}/fields/wall_layer.npz",
    params:
        case=typed_case("blender"),
        bin_size=config["blender"]["bin_size"],
        on_damaged=config["dumps"]["on_damaged"],
    log:
        f"{run_dir('blender')}/logs/fields.log",
    script:
        "../scripts/blender_fields.py"


rule blender_analysis:
    input:
        fields=rules.blender_fields.output.fields,
        flow=rules.blender_fields.output.flow,
        frames=rules.blender_fields.output.frames,
        wall_layer=rules.blender_fields.output.wall_layer,
        case=rules.blender_deck.output.case,
    output:
        summary=f"{run_dir('blender')}/metrics/blender.json",
        profiles=f"{run_dir('blender')}/metrics/profiles.csv",
        residence=f"{run_dir('blender')}/metrics/residence_across_width.csv",
        rtd=f"{run_dir('blender')}/metrics/rtd.csv",
        vrr=f"{run_dir('blender')}/metrics/vrr_period.csv",
        profiles_plot=report(plot_file(f"{run_dir('blender')}/plots/profiles"), caption="../report/blender_profiles.rst", category="4 Blender", subcategory="{run}", labels={"figure": "profiles"}),
        distribution_plot=report(plot_file(f"{run_dir('blender')}/plots/insert_velocities"), caption="../report/blender_insert.rst", category="4 Blender", subcategory="{run}", labels={"figure": "insert velocities"}),
        fcb_plot=report(plot_file(f"{run_dir('blender')}/plots/flow_channel"), caption="../report/blender_fcb.rst", category="4 Blender", subcategory="{run}", labels={"figure": "flow channel"}),
        pathlines_plot=report(plot_file(f"{run_dir('blender')}/plots/pathlines"), caption="../report/blender_pathlines.rst", category="4 Blender", subcategory="{run}", labels={"figure": "pathlines"}),
        rtd_plot=report(plot_file(f"{run_dir('blender')}/plots/rtd"), caption="../report/blender_rtd.rst", category="4 Blender", subcategory="{run}", labels={"figure": "RTD"}),
        discontinuous_plot=report(plot_file(f"{run_dir('blender')}/plots/discontinuous"), caption="../report/blender_discontinuous.rst", category="4 Blender", subcategory="{run}", labels={"figure": "discontinuous"}),
        vrr_plot=report(plot_file(f"{run_dir('blender')}/plots/vrr_period"), caption="../report/blender_vrr.rst", category="4 Blender", subcategory="{run}", labels={"figure": "VRR vs period"}),
    params:
        case=typed_case("blender"),
        blender=lambda wildcards: {key: config["blender"][key] for key in (
            "bin_size", "fill_height", "profile_heights_above", "pathlines", "rtd", "discontinuous", "continuous")},
        validation=config["validation"],
    log:
        f"{run_dir('blender')}/logs/analysis.log",
    script:
        "../scripts/blender_analysis.py"


rule blender_comparison:
    input:
        summaries=lambda wildcards: [f"{run_dir('blender', run)}/metrics/blender.json" for run in blender_runs()],
    output:
        table=f"{case_root('blender')}/comparison/configurations.csv",
        markdown=f"{case_root('blender')}/comparison/configurations.md",
        significance=f"{case_root('blender')}/comparison/significance.csv",
        plot=report(plot_file(f"{case_root('blender')}/comparison/configurations"), caption="../report/blender_comparison.rst", category="4 Blender", subcategory="Comparison", labels={"figure": "configurations"}),
        rtd_plot=report(plot_file(f"{case_root('blender')}/comparison/rtd"), caption="../report/blender_comparison_rtd.rst", category="4 Blender", subcategory="Comparison", labels={"figure": "RTDs"}),
    params:
        runs=lambda wildcards: blender_runs(),
        tolerance=config["blender"]["discontinuous"]["tolerance"],
    log:
        f"{case_root('blender')}/comparison/comparison.log",
    script:
        "../scripts/blender_comparison.py"


rule blender_gravity:
    input:
        summaries=lambda wildcards: [f"{run_dir('blender', run)}/metrics/blender.json" for run in blender_runs()],
    output:
        table=f"{case_root('blender')}/gravity/scaling.csv",
        plot=report(plot_file(f"{case_root('blender')}/gravity/scaling"), caption="../report/blender_gravity.rst", category="4 Blender", subcategory="Gravity scaling", labels={"figure": "gravity"}),
    params:
        runs=lambda wildcards: blender_runs(),
    log:
        f"{case_root('blender')}/gravity/gravity.log",
    script:
        "../scripts/blender_gravity.py"


rule blender_all:
    input:
        # the kind's products as the workflow knows them at the end (ParaView's included)
        lambda wildcards: CASE_TARGETS["blender"](wildcards),
