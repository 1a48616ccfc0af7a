# Planar flat-bottom silo (batch discharge): deck -> LIGGGHTS run -> flow metrics.

wildcard_constraints:
    run="[A-Za-z0-9_.-]+",


rule silo_deck:
    input:
        parameters=calibrated_parameters_file,
    output:
        deck=f"{RESULTS}/silo_flat/{{run}}/deck/in.liggghts",
        case=f"{RESULTS}/silo_flat/{{run}}/deck/case.json",
    params:
        defining=lambda wildcards: silo_case_for_run(silo_config(), wildcards.run).defining_parameters,
    log:
        f"{RESULTS}/silo_flat/{{run}}/logs/deck.log",
    script:
        "../scripts/silo_deck.py"


rule silo_run:
    input:
        deck=rules.silo_deck.output.deck,
        case=rules.silo_deck.output.case,
        parameters=calibrated_parameters_file,
    output:
        record=f"{RESULTS}/silo_flat/{{run}}/run.json",
    params:
        engine=config["engine"],
    resources:
        tasks=config["engine"]["mpi_ranks"],
    threads: config["engine"]["mpi_ranks"]
    # the longest job: start it first so the short calibration runs fill the other cores meanwhile
    priority: 10
    log:
        f"{RESULTS}/silo_flat/{{run}}/logs/run.log",
    script:
        "../scripts/silo_run.py"


rule silo_metrics:
    input:
        record=rules.silo_run.output.record,
        case=rules.silo_deck.output.case,
    output:
        table=f"{RESULTS}/silo_flat/{{run}}/metrics/flow.csv",
        history=f"{RESULTS}/silo_flat/{{run}}/metrics/discharge.csv",
        summary=f"{RESULTS}/silo_flat/{{run}}/metrics/flow.json",
        plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/discharge.png", caption="../report/silo_discharge.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "discharge"}),
    params:
        analysis=lambda wildcards: {
            "steady_window": config["silo_flat"]["steady_window"],
            "beverloo": config["silo_flat"]["beverloo"],
        },
    log:
        f"{RESULTS}/silo_flat/{{run}}/logs/metrics.log",
    script:
        "../scripts/silo_metrics.py"


rule silo_fields:
    input:
        record=rules.silo_run.output.record,
        case=rules.silo_deck.output.case,
        flow=rules.silo_metrics.output.summary,
    output:
        pvd=f"{RESULTS}/silo_flat/{{run}}/fields/fields.pvd",
        arrays=f"{RESULTS}/silo_flat/{{run}}/fields/averaged.npz",
        profiles=f"{RESULTS}/silo_flat/{{run}}/metrics/profiles.csv",
        instantaneous=f"{RESULTS}/silo_flat/{{run}}/metrics/profiles_instantaneous.csv",
        boundaries=f"{RESULTS}/silo_flat/{{run}}/metrics/flow_channel_boundary.csv",
        kinematic=f"{RESULTS}/silo_flat/{{run}}/metrics/kinematic.csv",
        centreline=f"{RESULTS}/silo_flat/{{run}}/metrics/centreline_velocity.csv",
        janssen=f"{RESULTS}/silo_flat/{{run}}/metrics/janssen.csv",
        summary=f"{RESULTS}/silo_flat/{{run}}/metrics/fields.json",
        profile_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/profiles.png", caption="../report/silo_profiles.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "velocity profiles"}),
        contour_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/vz_contour.png", caption="../report/silo_contour.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "v_z field"}),
        kinematic_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/kinematic_B.png", caption="../report/silo_kinematic_b.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "kinematic B"}),
        kinematic_u_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/kinematic_u.png", caption="../report/silo_kinematic_u.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "kinematic u"}),
        centreline_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/centreline_velocity.png", caption="../report/silo_centreline.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "centreline"}),
        janssen_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/janssen.png", caption="../report/silo_janssen.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "Janssen"}),
        force_chain_plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/force_chains.png", caption="../report/silo_force_chains.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "force chains"}),
    params:
        settings=lambda wildcards: config["silo_flat"]["fields"],
    log:
        f"{RESULTS}/silo_flat/{{run}}/logs/fields.log",
    script:
        "../scripts/silo_fields.py"


rule silo_measured_comparison:
    input:
        fields=rules.silo_fields.output.arrays,
        measured=lambda wildcards: config["silo_flat"]["fields"]["measured_profiles"],
    output:
        table=f"{RESULTS}/silo_flat/{{run}}/metrics/measured_comparison.csv",
        plot=report(f"{RESULTS}/silo_flat/{{run}}/plots/measured_comparison.png", caption="../report/silo_measured.rst", category="2 Silo validation", subcategory="{run}", labels={"figure": "measured"}),
    params:
        plane=config["silo_flat"]["fields"]["measured_plane"],
    log:
        f"{RESULTS}/silo_flat/{{run}}/logs/measured_comparison.log",
    script:
        "../scripts/silo_measured_comparison.py"


def _study_runs(wildcards):
    return parametric_studies()[wildcards.study]


rule silo_parametric:
    input:
        flows=lambda wildcards: [f"{silo_dir(run)}/metrics/flow.json" for _, run in _study_runs(wildcards)],
        fields=lambda wildcards: [f"{silo_dir(run)}/fields/averaged.npz" for _, run in _study_runs(wildcards)],
    output:
        table=f"{RESULTS}/silo_flat/parametric/{{study}}.csv",
        plot=report(f"{RESULTS}/silo_flat/parametric/{{study}}.png", caption="../report/silo_parametric.rst", category="2 Silo validation", subcategory="Parametric studies", labels={"figure": "{study}"}),
    params:
        labels=lambda wildcards: [label for label, _ in _study_runs(wildcards)],
        runs=lambda wildcards: [run for _, run in _study_runs(wildcards)],
        profile_height=config["silo_flat"]["parametric"]["profile_height"],
    log:
        f"{RESULTS}/silo_flat/parametric/logs/{{study}}.log",
    script:
        "../scripts/silo_parametric.py"
