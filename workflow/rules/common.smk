# Shared set-up: validate the configuration first thing and derive the runs it defines.

import sys
from pathlib import Path

sys.path.insert(0, workflow.basedir)

from calibration.parameters import calibrated_config
from engines.config import ConfigError, validate_config
from engines.estimates import InsufficientDiskSpace, format_bytes
from engines.planning import config_estimates, ensure_disk_space
from engines.cases.blender import blender_case_for_run, blender_cases
from engines.cases.silo_recirculation import recirculation_case_for_run, recirculation_cases
from engines.cases.silo_flat import build_silo_case, parametric_variants, silo_case_for_run, silo_cases

try:
    # In place, so that scripts see the defaults through snakemake.config too.
    config.update(validate_config(config))
except ConfigError as error:
    raise WorkflowError(f"Invalid configuration: {error}") from None

RESULTS = "results"

try:
    # Geometry and sizing errors surface before anything runs, whatever the parameter source.
    silo_cases(config)
except ValueError as error:
    raise WorkflowError(f"Invalid silo_flat configuration: {error}") from None
try:
    recirculation_cases(config)
except ValueError as error:
    raise WorkflowError(f"Invalid blending configuration: {error}") from None
try:
    blender_cases(config)
except (ValueError, KeyError) as error:
    raise WorkflowError(f"Invalid blender configuration: {error}") from None


def check_disk_for_pending_runs():
    """Refuse to start when the runs still to do would not fit on the disk of results/ (estimates.disk_check)."""
    if not config["estimates"]["disk_check"]:
        return
    try:
        margin = ensure_disk_space(config_estimates(config), RESULTS)
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


def silo_dir(run_id):
    return f"{RESULTS}/silo_flat/{run_id}"


def silo_flat_targets(wildcards=None):
    return [
        path
        for run_id in silo_cases(silo_config())
        for path in (
            f"{silo_dir(run_id)}/metrics/flow.csv",
            f"{silo_dir(run_id)}/plots/discharge.png",
            f"{silo_dir(run_id)}/fields/fields.pvd",
            f"{silo_dir(run_id)}/metrics/profiles.csv",
            f"{silo_dir(run_id)}/plots/profiles.png",
            *measured_comparison_targets(run_id),
        )
    ]


def measured_comparison_targets(run_id):
    if config["silo_flat"]["fields"]["measured_profiles"] is None:
        return []
    return [f"{silo_dir(run_id)}/metrics/measured_comparison.csv", f"{silo_dir(run_id)}/plots/measured_comparison.png"]


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
        path
        for study in parametric_studies()
        for path in (f"{RESULTS}/silo_flat/parametric/{study}.csv", f"{RESULTS}/silo_flat/parametric/{study}.png")
    ]


def blending_dir(run_id):
    return f"{RESULTS}/blending/{run_id}"


def blending_runs(role="blending"):
    """Run ids of the recirculation runs with the given role (the blending study or the thin verification silo)."""
    return [run for run, case in recirculation_cases(config).items() if case.role == role]


def blending_targets(wildcards=None):
    runs = blending_runs()
    targets = [
        f"{blending_dir(run)}/{name}"
        for run in runs
        for name in ("metrics/blending.json", "plots/concentration.png", "plots/vrr.png", "plots/rtd.png",
                     "plots/lti.png", "plots/vrr_period.png", "plots/recirculation_model.png", "plots/snapshots")
    ]
    if runs:
        targets += [f"{RESULTS}/blending/summary/blending.csv", f"{RESULTS}/blending/summary/vrr.png"]
    targets += [
        f"{blending_dir(run)}/verification/{name}"
        for run in blending_runs("verification")
        for name in ("verification.json", "paths.png", "residence_times.png")
    ]
    return targets


def blender_dir(run_id):
    return f"{RESULTS}/blender/{run_id}"


def blender_runs():
    """Run ids of the blender runs (configurations x gravity factors)."""
    return list(blender_cases(config))


def blender_targets(wildcards=None):
    runs = blender_runs()
    targets = [
        f"{blender_dir(run)}/{name}"
        for run in runs
        for name in ("metrics/blender.json", "plots/profiles.png", "plots/insert_velocities.png",
                     "plots/flow_channel.png", "plots/pathlines.png", "plots/rtd.png", "plots/discontinuous.png",
                     "plots/vrr_period.png")
    ]
    if runs:
        targets += [f"{RESULTS}/blender/comparison/{name}"
                    for name in ("configurations.csv", "configurations.md", "configurations.png", "rtd.png")]
    if len(config["blender"]["gravity_factors"]) > 1:
        targets += [f"{RESULTS}/blender/gravity/scaling.csv", f"{RESULTS}/blender/gravity/scaling.png"]
    return targets


def print_result_locations():
    for path in [*calibration_targets(), *silo_flat_targets(), *parametric_targets(), *blending_targets(),
                 *blender_targets()]:
        print(f"siloflow result: {Path(path).resolve()}")
