# Shared set-up: check the configuration first thing (engines.preflight: validate it, build every case it defines,
# let each case's engine accept it, find the engines and read the files it names, or refuse it naming the key) before
# anything runs, and derive the targets from the one results layout.

import sys
from pathlib import Path

sys.path.insert(0, workflow.basedir)

from analysis.io.measured_inputs import MeasuredInputError, check_measured_inputs
from calibration.parameters import calibrated_config
from model.cases import CASE_BUILDERS, cases_of
from model.cases.silo_flat import build_silo_case, parametric_variants
from model.cases.silo_recirculation import SECTION as RECIRCULATION
from engines.preflight import PreflightError, preflight
from engines.estimates import InsufficientDiskSpace, format_bytes
from model.cases.cross_engine import cross_engine_cases, cross_engine_jenike_cases
from model.cases.verification import verification_cases
from engines.interface import ENGINE_KINDS, CaseNotSupported, engine_for, engine_named
from engines.layout import (CALIBRATED_PARAMETERS, CALIBRATION_DIR, CASE_SUMMARY, CROSS_ENGINE_DIR, RESULTS, RUN_BENCHMARK,
                            RUN_RECORD, SUMMARY_DIR, VERIFICATION_DIR, case_root, run_dir, run_path)
from engines.planning import ensure_disk_space, run_priorities

# Snakemake has read the config files already, through YTE when a file asks for it (Snakemake has no switch to refuse
# that); engines.preflight reads them again as plain data, so that such a file, a repeated key or a YAML 1.1 boolean
# word stops the workflow here, then validates the configuration, builds every case, finds the engines' programs and
# the runs siloflow did not make; analysis.io.measured_inputs then reads the measured files it names. All before anything
# runs.
try:
    PREFLIGHT = preflight(config, workflow.configfiles)
    #: The measured PIV files, read and checked with the measured profiles; empty for no comparison.
    MEASURED_PIV_FILES = check_measured_inputs(PREFLIGHT.config["silo_flat"])
except (PreflightError, MeasuredInputError) as error:
    raise WorkflowError(str(error)) from None
# In place, so that scripts see the defaults through snakemake.config too.
config.update(PREFLIGHT.config)

#: Every case the validated configuration defines (the flat-bottom silo's as configured, before calibration).
CASES = PREFLIGHT.cases

#: Snakemake priority of each case kind's engine runs, longest estimated run first, so that both cores stay busy to
#: the end (the Jenike runs, short, fill in).
#: The estimate of every run, made once: the priorities below and the disk check at the start read it.
ESTIMATES = PREFLIGHT.estimates
RUN_PRIORITY = run_priorities(ESTIMATES)


def cases(kind):
    """The runs of case ``kind``: the flat-bottom silo's with calibrated parameters applied when asked for."""
    if kind == "silo_flat" and uses_calibrated_parameters():
        return cases_of(silo_config(), kind)
    return CASES[kind]


def check_disk_for_pending_runs():
    """Refuse to start when the runs still to do would not fit on the disk of results/ (estimates.disk_check)."""
    if not config["estimates"]["disk_check"]:
        return
    try:
        margin = ensure_disk_space(ESTIMATES, RESULTS)
    except InsufficientDiskSpace as error:
        raise WorkflowError(f"Not enough disk space: {error}") from None
    print(f"siloflow: the runs still to do fit on the disk of {RESULTS}/ ({format_bytes(margin)} to spare)")


def uses_calibrated_parameters():
    return config["silo_flat"]["parameters"] == "calibrated"


def calibrated_parameters_file(wildcards=None):
    """The calibration's parameters.yaml when the silo uses it (waits for the checkpoint), else nothing."""
    if not uses_calibrated_parameters():
        return []
    return checkpoints.calibration_parameters.get().output.parameters


def silo_config():
    """The configuration of the silo runs, with calibrated parameters applied when asked for."""
    if not uses_calibrated_parameters():
        return config
    return calibrated_config(config, calibrated_parameters_file())


def run_ids(kind):
    """Run ids of case ``kind`` (the flat-bottom silo's with calibrated parameters applied when asked for)."""
    return list(cases(kind))


def silo_flat_targets(wildcards=None, runs=None):
    """The products of the flat-bottom silo's runs (``runs``: its run ids, all when None)."""
    return [
        run_path("silo_flat", name, run)
        for run in (run_ids("silo_flat") if runs is None else runs)
        for name in ("metrics/flow.csv", "plots/discharge.png", "fields/fields.pvd", "metrics/profiles.csv",
                     "plots/profiles.png", "metrics/fill_balance.json", *measured_comparison_names(),
                     *piv_names())
    ]


def piv_names():
    names = []
    if config["silo_flat"]["piv"]["enabled"]:
        names += ["metrics/piv_accuracy.csv", "plots/piv_accuracy.png"]
    if MEASURED_PIV_FILES:
        names += ["metrics/piv_comparison.csv", "plots/piv_comparison.png"]
    return names


def measured_comparison_names():
    if config["silo_flat"]["fields"]["measured_profiles"] is None:
        return []
    return ["metrics/measured_comparison.csv", "plots/measured_comparison.png"]


def parametric_studies():
    """``{study: [(label, run id), ...]}`` of the configured parametric silo studies, base run first."""
    base = silo_config()
    base_run = build_silo_case(base).run_id
    return {
        study: [("base", base_run)] + [(label, build_silo_case(variant).run_id) for label, variant in runs]
        for study, runs in parametric_variants(base).items()
    }


def parametric_targets(wildcards=None):
    return [
        f"{case_root('silo_flat')}/parametric/{study}.{ext}" for study in parametric_studies() for ext in ("csv", "png")
    ]


def recirculation_runs(role="blending"):
    """Run ids of the recirculating-silo runs with the given role (the blending study or the thin verification silo)."""
    return [run for run, case in cases(RECIRCULATION).items() if case.role == role]


def shortcut_measured():
    """Whether the blending runs go on past where the study's shortcut stops, so that it can be measured on them."""
    blending = config[RECIRCULATION]
    return blending["recirculations"] > blending["tracer"]["start_recirculations"] + blending["shortcut"]["residence_times"]


def among(found, runs):
    """The run ids of ``found`` that are in ``runs`` (all of them when ``runs`` is None), in ``found``'s order."""
    return list(found) if runs is None else [run for run in found if run in runs]


def recirculation_targets(wildcards=None, runs=None):
    """The products of the recirculating silo's runs (``runs``: those of these run ids, without the summary across
    runs; all with the summary when None)."""
    blending = among(recirculation_runs(), runs)
    targets = [
        run_path(RECIRCULATION, name, run)
        for run in blending
        for name in ("metrics/blending.json", "metrics/fill_balance.json", "plots/concentration.png", "plots/vrr.png",
                     "plots/rtd.png", "plots/lti.png", "plots/vrr_period.png", "plots/recirculation_model.png",
                     "plots/snapshots")
    ]
    if shortcut_measured():
        targets += [run_path(RECIRCULATION, name, run) for run in blending for name in ("metrics/shortcut.csv", "plots/shortcut.png")]
    if runs is None and blending:
        targets += [f"{case_root(RECIRCULATION)}/summary/blending.csv", f"{case_root(RECIRCULATION)}/summary/vrr.png"]
    verification = among(recirculation_runs("verification"), runs)
    targets += [
        run_path(RECIRCULATION, f"verification/{name}", run)
        for run in verification
        for name in ("verification.json", "paths.png", "residence_times.png")
    ]
    targets += [run_path(RECIRCULATION, "metrics/fill_balance.json", run) for run in verification]
    return targets


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
        for name in ("metrics/blender.json", "metrics/fill_balance.json", "plots/profiles.png",
                     "plots/insert_velocities.png", "plots/flow_channel.png", "plots/pathlines.png", "plots/rtd.png",
                     "plots/discontinuous.png", "plots/vrr_period.png")
    ]
    if runs is not None:
        return targets
    if chosen:
        targets += [f"{case_root('blender')}/comparison/{name}"
                    for name in ("configurations.csv", "significance.csv", "configurations.md", "configurations.png", "rtd.png")]
    if len(config["blender"]["gravity_factors"]) > 1:
        targets += [f"{case_root('blender')}/gravity/scaling.csv", f"{case_root('blender')}/gravity/scaling.png"]
    return targets


def print_result_locations():
    for path in [*calibration_targets(), *silo_flat_targets(), *existing_runs_targets(), *parametric_targets(),
                 *recirculation_targets(), *blender_targets()]:
        print(f"siloflow result: {Path(path).resolve()}")


# The deck and run steps of every case: the engine writes deck/case.json last, and run.json last of a run.
def deck_rule_output(kind):
    return run_path(kind, CASE_SUMMARY)


def run_rule_output(kind):
    return run_path(kind, RUN_RECORD)


def run_benchmark(kind):
    """Snakemake's timing of a run step (wall time, memory): the validation record's provenance reads it."""
    return run_path(kind, RUN_BENCHMARK)
