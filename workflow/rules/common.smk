# Shared set-up: validate the configuration first thing and derive the runs it defines.

import sys
from pathlib import Path

sys.path.insert(0, workflow.basedir)

from engines.config import ConfigError, validate_config
from engines.silo import silo_cases

try:
    # In place, so that scripts see the defaults through snakemake.config too.
    config.update(validate_config(config))
except ConfigError as error:
    raise WorkflowError(f"Invalid configuration: {error}") from None

RESULTS = "results"

try:
    SILO_CASES = silo_cases(config)
except ValueError as error:
    raise WorkflowError(f"Invalid silo_flat configuration: {error}") from None


def silo_dir(run_id):
    return f"{RESULTS}/silo_flat/{run_id}"


def silo_flat_targets():
    return [
        path
        for run_id in SILO_CASES
        for path in (f"{silo_dir(run_id)}/metrics/flow.csv", f"{silo_dir(run_id)}/plots/discharge.png")
    ]


def print_result_locations():
    for path in silo_flat_targets():
        print(f"siloflow result: {Path(path).resolve()}")
