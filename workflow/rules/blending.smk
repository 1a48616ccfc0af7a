# Blending in the recirculating flat-bottom silo: deck -> LIGGGHTS run -> clump tracks -> direct measurement,
# RTDs and LTI predictions per flow pattern; the one-particle-thick verification of the Eulerian RTD; a summary.


rule blending_deck:
    output:
        deck=f"{RESULTS}/blending/{{run}}/deck/in.liggghts",
        case=f"{RESULTS}/blending/{{run}}/deck/case.json",
    params:
        defining=lambda wildcards: recirculation_case_for_run(config, wildcards.run).defining_parameters,
    log:
        f"{RESULTS}/blending/{{run}}/logs/deck.log",
    script:
        "../scripts/blending_deck.py"


rule blending_run:
    input:
        deck=rules.blending_deck.output.deck,
        case=rules.blending_deck.output.case,
    output:
        record=f"{RESULTS}/blending/{{run}}/run.json",
    params:
        engine=config["engine"],
    resources:
        tasks=config["engine"]["mpi_ranks"],
    threads: config["engine"]["mpi_ranks"]
    # long runs: start them early, after the batch silo
    priority: 5
    log:
        f"{RESULTS}/blending/{{run}}/logs/run.log",
    script:
        "../scripts/blending_run.py"


rule blending_tracks:
    input:
        record=rules.blending_run.output.record,
        case=rules.blending_deck.output.case,
    output:
        tracks=f"{RESULTS}/blending/{{run}}/tracks.npz",
    log:
        f"{RESULTS}/blending/{{run}}/logs/tracks.log",
    script:
        "../scripts/blending_tracks.py"


rule blending_analysis:
    input:
        tracks=rules.blending_tracks.output.tracks,
        case=rules.blending_deck.output.case,
    output:
        summary=f"{RESULTS}/blending/{{run}}/metrics/blending.json",
        concentration=f"{RESULTS}/blending/{{run}}/metrics/concentration.csv",
        vrr=f"{RESULTS}/blending/{{run}}/metrics/vrr.csv",
        rtd=f"{RESULTS}/blending/{{run}}/metrics/rtd.csv",
        vrr_period=f"{RESULTS}/blending/{{run}}/metrics/vrr_period.csv",
        model=f"{RESULTS}/blending/{{run}}/metrics/recirculation_model.csv",
        concentration_plot=report(f"{RESULTS}/blending/{{run}}/plots/concentration.png", caption="../report/blending_concentration.rst", category="3 Blending", subcategory="{run}", labels={"figure": "concentration"}),
        vrr_plot=report(f"{RESULTS}/blending/{{run}}/plots/vrr.png", caption="../report/blending_vrr.rst", category="3 Blending", subcategory="{run}", labels={"figure": "VRR"}),
        rtd_plot=report(f"{RESULTS}/blending/{{run}}/plots/rtd.png", caption="../report/blending_rtd.rst", category="3 Blending", subcategory="{run}", labels={"figure": "RTD"}),
        lti_plot=report(f"{RESULTS}/blending/{{run}}/plots/lti.png", caption="../report/blending_lti.rst", category="3 Blending", subcategory="{run}", labels={"figure": "LTI"}),
        vrr_period_plot=report(f"{RESULTS}/blending/{{run}}/plots/vrr_period.png", caption="../report/blending_vrr_period.rst", category="3 Blending", subcategory="{run}", labels={"figure": "VRR vs period"}),
        model_plot=report(f"{RESULTS}/blending/{{run}}/plots/recirculation_model.png", caption="../report/blending_model.rst", category="3 Blending", subcategory="{run}", labels={"figure": "recirculation model"}),
        snapshots=report(directory(f"{RESULTS}/blending/{{run}}/plots/snapshots"), patterns=["{layout}.png"],
                         caption="../report/blending_snapshots.rst", category="3 Blending", subcategory="{run}",
                         labels={"figure": "snapshots {layout}"}),
        per_layout=directory(f"{RESULTS}/blending/{{run}}/plots/layouts"),
    params:
        blending=config["blending"],
    log:
        f"{RESULTS}/blending/{{run}}/logs/analysis.log",
    script:
        "../scripts/blending_analysis.py"


rule blending_verification:
    input:
        tracks=rules.blending_tracks.output.tracks,
        case=rules.blending_deck.output.case,
    output:
        table=f"{RESULTS}/blending/{{run}}/verification/residence_times.csv",
        summary=f"{RESULTS}/blending/{{run}}/verification/verification.json",
        paths_plot=report(f"{RESULTS}/blending/{{run}}/verification/paths.png", caption="../report/blending_paths.rst", category="3 Blending", subcategory="Verification", labels={"figure": "paths"}),
        residence_plot=report(f"{RESULTS}/blending/{{run}}/verification/residence_times.png", caption="../report/blending_residence.rst", category="3 Blending", subcategory="Verification", labels={"figure": "residence times"}),
    params:
        blending=config["blending"],
    log:
        f"{RESULTS}/blending/{{run}}/logs/verification.log",
    script:
        "../scripts/blending_verification.py"


rule blending_summary:
    input:
        summaries=lambda wildcards: [f"{blending_dir(run)}/metrics/blending.json" for run in blending_runs()],
        vrr=lambda wildcards: [f"{blending_dir(run)}/metrics/vrr.csv" for run in blending_runs()],
    output:
        table=f"{RESULTS}/blending/summary/blending.csv",
        vrr_plot=report(f"{RESULTS}/blending/summary/vrr.png", caption="../report/blending_summary.rst", category="3 Blending", subcategory="Summary", labels={"figure": "VRR all"}),
    params:
        runs=lambda wildcards: blending_runs(),
    log:
        f"{RESULTS}/blending/summary/summary.log",
    script:
        "../scripts/blending_summary.py"


rule blending_all:
    input:
        blending_targets,
