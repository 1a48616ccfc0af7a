# siloflow: DEM calibration, validation and blending of pellets in silos.
# Thin entry point: validate the config, include one rule file per stage, declare the final targets.

import os

from snakemake.utils import min_version

# Plots are drawn headless: the jobs' scripts inherit this (no siloflow module chooses a matplotlib backend).
os.environ.setdefault("MPLBACKEND", "Agg")

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"


# One rule file per case kind, as its registry entry names it (model.cases.kinds); each adds its products to
# CASE_TARGETS.
for _kind in CASE_KINDS.values():
    if _kind.rules is not None:

        include: f"workflow/rules/{_kind.rules}"


include: "workflow/rules/existing_runs.smk"
include: "workflow/rules/bayesian_calibration.smk"
include: "workflow/rules/fill_balance.smk"
include: "workflow/rules/paraview.smk"
include: "workflow/rules/validation.smk"
include: "workflow/rules/verification.smk"
include: "workflow/rules/cross_engine.smk"
include: "workflow/rules/report.smk"


rule all:
    input:
        *CASE_TARGETS.values(),
        existing_runs_targets,
        f"{RESULTS}/summary/summary.html",
        f"{RESULTS}/summary/validation.csv",
        verification_targets(),
    default_target: True


onstart:
    check_disk_for_pending_runs()


onsuccess:
    print_result_locations()
