# The report: one summary page with the figures of merit of every stage. `snakemake --report results/report.html`
# (run by `make run`) collects it with every plot the rules mark with report(), each with its caption.


rule report_summary:
    input:
        parameters=CALIBRATED_PARAMETERS,
        flows=lambda wildcards: [run_path("silo_flat", "metrics/flow.json", run) for run in run_ids("silo_flat")],
        measured=lambda wildcards: [run_path("silo_flat", name, run) for run in run_ids("silo_flat")
                                    for name in measured_comparison_names() if name.endswith(".csv")],
        blending=lambda wildcards: [f"{case_root(RECIRCULATION)}/summary/blending.csv"] if recirculation_runs() else [],
        blender=lambda wildcards: [f"{case_root('blender')}/comparison/configurations.csv"] if blender_runs() else [],
        blender_differences=lambda wildcards: [f"{case_root('blender')}/comparison/significance.csv"] if blender_runs() else [],
        balances=lambda wildcards: [run_path(kind, "metrics/fill_balance.json", run)
                                    for kind in FILL_BALANCE_CASES for run in settled_runs(kind)],
        validation=rules.validation_table.output.table,
    output:
        page=report(f"{SUMMARY_DIR}/summary.html", caption="../report/summary.rst", category="0 Summary",
                    labels={"figure": "figures of merit"}),
    log:
        f"{SUMMARY_DIR}/summary.log",
    script:
        "../scripts/report_summary.py"
