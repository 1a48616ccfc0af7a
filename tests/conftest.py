"""Shared fixtures: a validated configuration and tiny silo settings for engine runs."""

from __future__ import annotations

import copy
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

# The tests draw headless, as the workflow does (the Snakefile sets the same): no library module of siloflow chooses a
# backend. Set before anything imports matplotlib, which reads it then; the pipelines the tests start inherit it.
os.environ.setdefault("MPLBACKEND", "Agg")

import pytest

from siloflow.cli.main import main
from siloflow.engines.config import load_config_file, validate_config
from tests.repo import REPO_ROOT
from siloflow.model.cases import cases_of
from siloflow.engines.interface import EngineOptions, engine_for, engine_named

DEFAULT_CONFIG = REPO_ROOT / "config" / "config.yaml"

# The tiny fills of the tests that check other stages pour fast (a gentle pour would take several times longer):
# no limit on the stream's momentum flux, and a force balance that only refuses a fill far from rest. The fill's
# physics (gentle pour, force balance) is checked by tests/integration/test_fill_balance_liggghts.py.
FAST_POUR = {"zone_width_fraction": 0.6, "zone_height": 0.03, "insertion_velocity": 2.0, "momentum_flux_ratio": 100.0,
             "balance_tolerance": {"support": 0.5, "plane": 1.0}}

# The tiny fills settle to 1.67e-4 of the two-sphere clump's m g d (6.0e-7 J), 1e-10 J per clump: a little looser than
# the default 1e-4, as the short tests need no more rest than their force balance tolerates.
TINY_SETTLE = {"kinetic_energy_ratio": 1.67e-4, "max_time": 1.0}

# The silos and blenders of the tests step at the demo tier's 0.2 of the Rayleigh time (config/config.yaml); a pipeline
# run in a temporary directory would otherwise take the schema's 0.1. The physics tests whose bounds compare two
# estimates of one figure on the tiny cases (the fill's force balance, Little's law, the gravity scaling) read runs at
# the study's 0.1, at which those bounds were measured; the ones that compare a run with its own rerun (two MPI ranks,
# a resumed run, measured PIV of the same run) hold at either step.
STAGE_TIMESTEP_FRACTION = 0.2

# A silo small enough for a real LIGGGHTS run in well under a minute (~1,400 two-sphere clumps), with an
# outlet of about 7 clump diameters so that it flows without arching.
TINY_SILO = {
    "width": 0.08,
    "depth": 0.012,
    "fill_height": 0.04,
    "outlet_width": 0.024,
    "fill": FAST_POUR,
    "settle": TINY_SETTLE,
    "timestep_fraction": STAGE_TIMESTEP_FRACTION,
    "discharge_time": 0.6,
    # the fill is only 40 mm high: profiles low enough to stay inside it during the steady discharge
    "fields": {"profile_heights": [0.01, 0.02, 0.03]},
}


# A silo small enough for YADE's integration tests (about 350 clumps; YADE integrates them 5-8 times slower than
# LIGGGHTS on this case): fill, settle, open, and 0.3 s of discharge.
MICRO_SILO = {
    "width": 0.04,
    "depth": 0.012,
    "fill_height": 0.02,
    "outlet_width": 0.016,
    "fill": FAST_POUR,
    "settle": TINY_SETTLE,
    "timestep_fraction": STAGE_TIMESTEP_FRACTION,
    "discharge_time": 0.3,
    "fields": {"profile_heights": [0.005, 0.01]},
    "engine": "yade",
}

# A small silo on LIGGGHTS (about 650 clumps, half a minute of one core) for the pipelines whose tests read no silo
# figure (the calibrated silo, the workflow lock): deep enough for the fields step's Janssen comparison, which the micro
# silo's 20 mm fill leaves without a row; no synthetic PIV.
SMALL_SILO = {**MICRO_SILO, "engine": "liggghts", "width": 0.05, "fill_height": 0.03,
              "fields": {"profile_heights": [0.01, 0.02]}, "piv": {"enabled": False}}


# A tiny recirculating silo (about 1,000 clumps, Nr about 4 in 1.8 s) and a thin one (about 400 clumps).
TINY_BLENDING = {
    "width": 0.06,
    "depth": 0.012,
    "fill_height": 0.04,
    "outlet_width": 0.02,
    "channel_length": 0.04,
    "recirculations": 3.0,
    "timestep_fraction": STAGE_TIMESTEP_FRACTION,
    "flow_patterns": ["semi_mass_flow"],
    "concentration_window": 0.1,
    "snapshots": [0, 0.5, 1, 2],
    "tracer": {"start_recirculations": 0.5, "bins": 15},
    "lti": {"period_fractions": [0.2, 0.5, 1.0, 2.0], "passes": 6},
    "verification": {"width": 0.06, "depth": 0.0045, "fill_height": 0.04, "recirculations": 3.0,
                     "bin_sizes": [0.005, 0.01, 0.015]},
}

# The calibration stage is part of every workflow run: pipelines that test other stages run one tiny shear test in the
# default 40 mm cell (a 30 mm cell's levelled sample puts 1.025 of its weight on the walls and floor, outside 1 %),
# settled, consolidated and sheared in about two thirds of the time of the calibration's tiny cell
# (test_calibration_pipeline.py): at sliding friction 0.3 and rolling friction 0.1 it gave bulk friction
# 0.593 +- 0.009 against 0.581 +- 0.009, and its levelled sample's support 0.9998 against 0.9996.
TINY_JENIKE_SWEEP = {
    "cell": {"inner_diameter": 0.04, "bottom_ring_height": 0.008, "shear_ring_height": 0.01, "plate_size": 0.07},
    "fill": {"settle_time": 0.05},
    "consolidation": {"time": 0.03},
    "shear": {"velocity": 0.06, "displacement": 0.003},
    "sweep": {"tests": ["internal"], "sliding_friction": [0.3], "rolling_friction": [0.1], "lid_comparison": False,
              "diagnostics": "none"},
}

# Pipelines that test other stages leave the blending study and the blender out.
NO_BLENDING = {"enabled": False}
NO_BLENDER = {"enabled": False}
#: the verification suite has its own test (test_verification_suite.py); the other stages' pipelines leave it out
NO_VERIFICATION = {"enabled": False}

# A tiny blender (about 2,000 two-sphere clumps, one layer deep): a 150 mm hopper with no tube and an insert given
# by its plate end points, wide enough (passages of 7 clump sizes and more) to flow without arching; continuous
# discharge at gravity factors 1 and 4.
TINY_BLENDER = {
    "configurations": ["tiny"],
    "inserts": {"tiny": {"inlet": [0.045, 0.1223], "outlet": [0.03, 0.08]}},
    "timestep_fraction": 0.1,   # the study's step, at which the physics tier's gravity scaling was measured
    "width": 0.15,
    "depth": 0.0045,
    "vertical_height": 0.16,
    "outlet_width": 0.024,
    "fill_height": 0.14,
    "wall_thickness": 0.002,
    "tube_width": 0.0,
    "fill_zone_width_fraction": 0.6,
    "discharge": {"mode": "continuous", "time": 0.8, "steady_window": [0.3, 0.8], "profile_windows": 2},
    "gravity_factors": [1.0, 4.0],
    "bin_size": 0.005,
    "profile_heights_above": [0.01],
    "pathlines": {"release_height": 0.13, "spacing": 0.0075, "integration_step": 0.001, "max_time": 100.0},
    "continuous": {"period_fractions": [0.2, 0.5, 1.0, 2.0], "comparison_fractions": [0.5, 1.0]},
}


class RunsOnDemand(dict):
    """Engine runs of a test module by name: ``make(name)`` runs one. The names in ``ahead`` (the fast tier's) are made
    up front, two side by side; any other (a physics tier's) on first use, so that a tier makes only what it reads."""

    def __init__(self, make, ahead=()):
        super().__init__()
        self.make = make
        with ThreadPoolExecutor(max_workers=2) as pool:
            futures = {name: pool.submit(make, name) for name in ahead}
            self.update({name: future.result() for name, future in futures.items()})

    def __missing__(self, name):
        self[name] = self.make(name)
        return self[name]


def pytest_collection_modifyitems(config, items):
    """The longest modules first, so that `make test`'s workers (xdist hands out whole files, in this order, with
    ``--no-loadscope-reorder``) finish together: a module marked ``core_seconds(n)`` costs about n seconds of one
    core; unmarked modules (the unit tests) fill in at the end. The sort is stable: a module's tests keep their
    order."""

    def cost(item) -> float:
        marker = item.get_closest_marker("core_seconds")
        return marker.args[0] if marker else 0.0

    items.sort(key=cost, reverse=True)


@pytest.fixture
def raw_default_config() -> dict:
    """The default configuration file as read, before validation."""
    return load_config_file(DEFAULT_CONFIG)


@pytest.fixture
def default_config(raw_default_config) -> dict:
    """The default configuration, validated and with defaults filled."""
    return validate_config(raw_default_config)


@pytest.fixture
def tiny_config(raw_default_config) -> dict:
    """A validated configuration of the tiny silo."""
    raw = copy.deepcopy(raw_default_config)
    raw["silo_flat"] = {**raw["silo_flat"], **copy.deepcopy(TINY_SILO)}
    return validate_config(raw)


def run_snakemake(workdir, *arguments: str, targets=()) -> subprocess.CompletedProcess:
    """Run the repository's workflow in ``workdir``; targets go first, since --configfile takes every word after it."""
    return subprocess.run(
        [sys.executable, "-m", "snakemake", *targets, "-s", str(REPO_ROOT / "Snakefile"), "--directory", str(workdir),
         *arguments],
        capture_output=True,
        text=True,
        check=False,
    )


def record_main(words: list[str]) -> int:
    """``siloflow record WORDS...`` run in this process; returns its exit code."""
    return main(["record", *words])


def liggghts():
    """The LIGGGHTS engine, through the registry (the integration tests run it only through the interface)."""
    require_liggghts()
    return engine_named("liggghts")


def require_yade():
    """Fail loudly when YADE is missing: its integration tests must run the real engine. `make test` installs it
    (Debian package yade, without recommends)."""
    if not Path("/usr/lib/x86_64-linux-gnu/yade-double/py/yade").is_dir():
        pytest.fail("YADE is not installed: run `make test`, which installs the Debian package yade")


def require_liggghts():
    """Fail loudly when the engine is missing: integration tests must run the real LIGGGHTS, never pass
    without it. `make test` installs it (Debian package liggghts)."""
    if shutil.which("liggghts") is None:
        pytest.fail("LIGGGHTS is not installed: run `make test`, which installs the Debian package liggghts")


def run_first_case(config: dict, kind: str, root: Path):
    """Render and run the first case of kind ``kind`` of a validated configuration on its engine, in
    ``root/<run id>``; returns (case, engine, run directory, run record)."""
    case = next(iter(cases_of(config, kind).values()))
    engine = engine_for(config, kind)
    run_dir = root / case.run_id
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions.from_config(config, engine.name))
    return case, engine, run_dir, record
