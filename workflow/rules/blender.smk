# Multi-flow blender: deck -> LIGGGHTS run -> steady depth-averaged fields -> profiles, pathlines, RTD and blending
# modes per configuration; a comparison of the configurations; gravity scaling when several factors are run.


rule blender_deck:
    output:
        deck=f"{RESULTS}/blender/{{run}}/deck/in.liggghts",
        case=f"{RESULTS}/blender/{{run}}/deck/case.json",
    params:
        defining=lambda wildcards: blender_case_for_run(config, wildcards.run).defining_parameters,
    log:
        f"{RESULTS}/blender/{{run}}/logs/deck.log",
    script:
        "../scripts/blender_deck.py"


rule blender_run:
    input:
        deck=rules.blender_deck.output.deck,
        case=rules.blender_deck.output.case,
    output:
        record=f"{RESULTS}/blender/{{run}}/run.json",
    params:
        engine=config["engine"],
    resources:
        tasks=config["engine"]["mpi_ranks"],
    threads: config["engine"]["mpi_ranks"]
    # long runs: start them early
    priority: 4
    log:
        f"{RESULTS}/blender/{{run}}/logs/run.log",
    script:
        "../scripts/blender_run.py"


rule blender_fields:
    input:
        record=rules.blender_run.output.record,
        case=rules.blender_deck.output.case,
    output:
        fields=f"{RESULTS}/blender/{{run}}/fields/fields.npz",
        flow=f"{RESULTS}/blender/{{run}}/metrics/flow.json",
    params:
        bin_size=config["blender"]["bin_size"],
    log:
        f"{RESULTS}/blender/{{run}}/logs/fields.log",
    script:
        "../scripts/blender_fields.py"


rule blender_analysis:
    input:
        fields=rules.blender_fields.output.fields,
        flow=rules.blender_fields.output.flow,
        case=rules.blender_deck.output.case,
    output:
        summary=f"{RESULTS}/blender/{{run}}/metrics/blender.json",
        profiles=f"{RESULTS}/blender/{{run}}/metrics/profiles.csv",
        residence=f"{RESULTS}/blender/{{run}}/metrics/residence_across_width.csv",
        rtd=f"{RESULTS}/blender/{{run}}/metrics/rtd.csv",
        vrr=f"{RESULTS}/blender/{{run}}/metrics/vrr_period.csv",
        profiles_plot=report(f"{RESULTS}/blender/{{run}}/plots/profiles.png", caption="../report/blender_profiles.rst", category="4 Blender", subcategory="{run}", labels={"figure": "profiles"}),
        distribution_plot=report(f"{RESULTS}/blender/{{run}}/plots/insert_velocities.png", caption="../report/blender_insert.rst", category="4 Blender", subcategory="{run}", labels={"figure": "insert velocities"}),
        fcb_plot=report(f"{RESULTS}/blender/{{run}}/plots/flow_channel.png", caption="../report/blender_fcb.rst", category="4 Blender", subcategory="{run}", labels={"figure": "flow channel"}),
        pathlines_plot=report(f"{RESULTS}/blender/{{run}}/plots/pathlines.png", caption="../report/blender_pathlines.rst", category="4 Blender", subcategory="{run}", labels={"figure": "pathlines"}),
        rtd_plot=report(f"{RESULTS}/blender/{{run}}/plots/rtd.png", caption="../report/blender_rtd.rst", category="4 Blender", subcategory="{run}", labels={"figure": "RTD"}),
        discontinuous_plot=report(f"{RESULTS}/blender/{{run}}/plots/discontinuous.png", caption="../report/blender_discontinuous.rst", category="4 Blender", subcategory="{run}", labels={"figure": "discontinuous"}),
        vrr_plot=report(f"{RESULTS}/blender/{{run}}/plots/vrr_period.png", caption="../report/blender_vrr.rst", category="4 Blender", subcategory="{run}", labels={"figure": "VRR vs period"}),
    params:
        blender=config["blender"],
    log:
        f"{RESULTS}/blender/{{run}}/logs/analysis.log",
    script:
        "../scripts/blender_analysis.py"


rule blender_comparison:
    input:
        summaries=lambda wildcards: [f"{blender_dir(run)}/metrics/blender.json" for run in blender_runs()],
    output:
        table=f"{RESULTS}/blender/comparison/configurations.csv",
        markdown=f"{RESULTS}/blender/comparison/configurations.md",
        plot=report(f"{RESULTS}/blender/comparison/configurations.png", caption="../report/blender_comparison.rst", category="4 Blender", subcategory="Comparison", labels={"figure": "configurations"}),
        rtd_plot=report(f"{RESULTS}/blender/comparison/rtd.png", caption="../report/blender_comparison_rtd.rst", category="4 Blender", subcategory="Comparison", labels={"figure": "RTDs"}),
    params:
        runs=lambda wildcards: blender_runs(),
        blender=config["blender"],
    log:
        f"{RESULTS}/blender/comparison/comparison.log",
    script:
        "../scripts/blender_comparison.py"


rule blender_gravity:
    input:
        summaries=lambda wildcards: [f"{blender_dir(run)}/metrics/blender.json" for run in blender_runs()],
    output:
        table=f"{RESULTS}/blender/gravity/scaling.csv",
        plot=report(f"{RESULTS}/blender/gravity/scaling.png", caption="../report/blender_gravity.rst", category="4 Blender", subcategory="Gravity scaling", labels={"figure": "gravity"}),
    params:
        runs=lambda wildcards: blender_runs(),
    log:
        f"{RESULTS}/blender/gravity/gravity.log",
    script:
        "../scripts/blender_gravity.py"


rule blender_all:
    input:
        blender_targets,
