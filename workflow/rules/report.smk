# The report: one summary page with the figures of merit of every stage. `snakemake --report results/report.html`
# (run by `make run`) collects it with every plot the rules mark with report(), each with its caption.


rule report_summary:
    input:
        parameters=f"{RESULTS}/calibration/parameters.yaml",
        flows=lambda wildcards: [f"{silo_dir(run)}/metrics/flow.json" for run in silo_cases(silo_config())],
        measured=lambda wildcards: [path for run in silo_cases(silo_config()) for path in measured_comparison_targets(run)
                                    if path.endswith(".csv")],
        blending=lambda wildcards: [f"{RESULTS}/blending/summary/blending.csv"] if blending_runs() else [],
        blender=lambda wildcards: [f"{RESULTS}/blender/comparison/configurations.csv"] if blender_runs() else [],
    output:
        page=report(f"{RESULTS}/summary/summary.html", caption="../report/summary.rst", category="0 Summary",
                    labels={"figure": "figures of merit"}),
    log:
        f"{RESULTS}/summary/summary.log",
    script:
        "../scripts/report_summary.py"
