# Shared set-up: check the configuration first thing (siloflow.engines.preflight: validate it, build every case it defines,
# let each case's engine accept it, find the engines and read the files it names, or refuse it naming the key) before
# anything runs, and derive the targets from the one results layout.

from pathlib import Path

import yaml

from siloflow.analysis.io.measured_inputs import MeasuredInputError, check_measured_inputs
from siloflow.calibration.parameters import CALIBRATED_SOURCES, calibrated_config, posterior_draw_configs
from siloflow.model.cases.common import engine_kind
from siloflow.model.cases import cases_of
from siloflow.model.cases.kinds import CASE_KINDS
from siloflow.model.cases.silo_flat import build_silo_case, parametric_variants
from siloflow.model.cases.silo_recirculation import SECTION as RECIRCULATION
from siloflow.engines.preflight import PreflightError, preflight
from siloflow.engines.estimates import InsufficientDiskSpace, format_bytes
from siloflow.model.cases.cross_engine import cross_engine_cases, cross_engine_jenike_cases
from siloflow.model.cases.verification import verification_cases
from siloflow.engines.interface import ENGINE_KINDS, CaseNotSupported, engine_for, engine_named
from siloflow.engines.layout import (CALIBRATED_PARAMETERS, CALIBRATION_DIR, CASE_SUMMARY, CROSS_ENGINE_DIR, RESULTS, RUN_BENCHMARK,
                            RUN_RECORD, SUMMARY_DIR, VERIFICATION_DIR, case_root, run_dir, run_path)
from siloflow.engines.planning import ensure_disk_space, group_runs as planned_group_runs, run_priorities, run_ranks

# Snakemake has read the config files already, through YTE when a file asks for it (Snakemake has no switch to refuse
# that); siloflow.engines.preflight reads them again as plain data, so that such a file, a repeated key or a YAML 1.1 boolean
# word stops the workflow here, then validates the configuration, builds every case, finds the engines' programs and
# the runs siloflow did not make; siloflow.analysis.io.measured_inputs then reads the measured files it names. All before anything
# runs.
try:
    PREFLIGHT = preflight(config, workflow.configfiles)
    #: The measured PIV files, read and checked with the measured profiles; empty for no comparison.
    MEASURED_PIV_FILES = check_measured_inputs(PREFLIGHT.config["silo_flat"])
except (PreflightError, MeasuredInputError) as error:
    raise WorkflowError(str(error)) from None
# In place, so that scripts see the defaults through snakemake.config too.
config.update(PREFLIGHT.config)

#: The format of every plot the workflow writes, its file name suffix (plots.format: png, pdf or svg); the writer
#: (siloflow.analysis.io.plots.save_figure) takes the format from the suffix.
PLOT_FORMAT = config["plots"]["format"]


def plot_file(stem):
    """The plot ``stem`` (its path without a suffix; wildcards allowed) in the configured format (plots.format)."""
    return f"{stem}.{PLOT_FORMAT}"


#: Every case the validated configuration defines (the flat-bottom silo's as configured, before calibration).
CASES = PREFLIGHT.cases

#: Snakemake priority of each case kind's engine runs, longest estimated run first, so that both cores stay busy to
#: the end (the Jenike runs, short, fill in).
#: The estimate of every run, made once: the priorities below and the disk check at the start read it.
ESTIMATES = PREFLIGHT.estimates
RUN_PRIORITY = run_priorities(ESTIMATES)
#: The runs each validation group makes, as its parts run them (validation.smk splits them into parts).
PLANNED_GROUP_RUNS = planned_group_runs(config, ESTIMATES)
#: MPI ranks of each run: the configuration's (engine.mpi_ranks), or both of a part's cores for a run alone through
#: its parts (siloflow.engines.planning.group_runs).
RUN_RANKS = run_ranks(PLANNED_GROUP_RUNS)


def mpi_ranks(wildcards):
    """MPI ranks of an engine run step (its threads; the run script starts its engine on them)."""
    return RUN_RANKS.get(wildcards.run, config["engine"]["mpi_ranks"])


#: Each case kind's products, ``{kind: targets(wildcards=None, runs=None)}``: its rule file adds its own. With ``runs``
#: (run ids) the products of those runs on their own; without, of every run and the analyses across them.
CASE_TARGETS = {}


#: The flat-bottom silo's runs with calibrated parameters, built once per version of the calibration's choice:
#: ``{version: (cases, [(label, run id)] of the posterior mean and draws)}``.
_CALIBRATED_CASES = {}


def _calibrated_silo():
    """The silo's runs with calibrated parameters, and its runs at the posterior mean and draws
    (``silo_flat.posterior_draws``; none without), built once per version of the calibration's files."""
    path = calibrated_parameters_file()
    version = (path, Path(path).stat().st_mtime_ns)
    if version not in _CALIBRATED_CASES:
        silo = silo_config()
        calibrated = cases_of(silo, "silo_flat")
        labelled = []
        if config["silo_flat"]["posterior_draws"]:
            # the draws are written beside the posterior mean, by the same checkpoint
            draws = checkpoints.bayes_parameters.get(engine=engine_kind(config, "silo_flat")).output.draws
            drawn = [(label, build_silo_case(c)) for label, c in
                     posterior_draw_configs(config, yaml.safe_load(Path(draws).read_text(encoding="utf-8")))]
            calibrated.update({case.run_id: case for _, case in drawn})
            labelled = [("posterior mean", build_silo_case(silo).run_id),
                        *((label, case.run_id) for label, case in drawn)]
        _CALIBRATED_CASES[version] = (calibrated, labelled)
    return _CALIBRATED_CASES[version]


def cases(kind):
    """The runs of case ``kind``: the flat-bottom silo's with calibrated parameters applied when asked for (the only
    place they are applied)."""
    if kind == "silo_flat" and uses_calibrated_parameters():
        return _calibrated_silo()[0]
    return CASES[kind]


def posterior_draw_runs():
    """``[(label, run id)]`` of the silo at the posterior mean then at each posterior draw (``silo_flat.posterior_draws``)."""
    return _calibrated_silo()[1]


def typed_case(kind):
    """A deck or run job's case, as built when the workflow was parsed: the job builds none. Snakemake hands it to
    the script as it is; it stays out of the rerun check (Snakemake compares only plain values), where the run id and
    the ``defining`` parameters stand for it."""
    def case(wildcards):
        return cases(kind)[wildcards.run]
    return case


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
    return config["silo_flat"]["parameters"] in CALIBRATED_SOURCES


def calibrated_parameters_file(wildcards=None):
    """The calibration's parameters.yaml when the silo uses it (waits for its checkpoint), else nothing: the chart
    inversion's, or the Bayesian posterior's on the silo's engine."""
    if not uses_calibrated_parameters():
        return []
    if config["silo_flat"]["parameters"] == "bayesian":
        return checkpoints.bayes_parameters.get(engine=engine_kind(config, "silo_flat")).output.parameters
    return checkpoints.calibration_parameters.get().output.parameters


def silo_config():
    """The configuration of the silo runs, with calibrated parameters applied when asked for."""
    if not uses_calibrated_parameters():
        return config
    return calibrated_config(config, calibrated_parameters_file())


def run_ids(kind):
    """Run ids of case ``kind`` (the flat-bottom silo's with calibrated parameters applied when asked for)."""
    return list(cases(kind))


def settled_runs(kind):
    """Run ids of case ``kind`` that pour and settle their own fill (not those that start from another run's, whose
    settled fill is that run's)."""
    return [run for run, case in cases(kind).items() if getattr(case, "assembly", None) is None]


def settled_fill_record(kind):
    """The input function of a step that reads a run's settled fill: the record of the run that settled it, the run's
    own or, for a run that starts from another run's settled fill (its ``assembly``), that run's."""
    def record(wildcards):
        assembly = getattr(cases(kind)[wildcards.run], "assembly", None)
        if assembly is None:
            return run_path(kind, RUN_RECORD, run=wildcards.run)
        return run_path("silo_flat", RUN_RECORD, run=assembly.run_id)
    return record


def among(found, runs):
    """The run ids of ``found`` that are in ``runs`` (all of them when ``runs`` is None), in ``found``'s order."""
    return list(found) if runs is None else [run for run in found if run in runs]


def print_result_locations():
    """Where the products of the runs are, those that exist: a call for one target (``bayesian_calibration``, a
    validation group) makes only some of them."""
    for path in [*(path for targets in CASE_TARGETS.values() for path in targets()), *existing_runs_targets()]:
        if Path(path).exists():
            print(f"siloflow result: {Path(path).resolve()}")


# The deck and run steps of every case: the engine writes deck/case.json last, and run.json last of a run.
def deck_rule_output(kind):
    return run_path(kind, CASE_SUMMARY)


def run_rule_output(kind):
    return run_path(kind, RUN_RECORD)


def run_benchmark(kind):
    """Snakemake's timing of a run step (wall time, memory): the validation record's provenance reads it."""
    return run_path(kind, RUN_BENCHMARK)
