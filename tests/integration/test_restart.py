"""A run killed with SIGKILL resumes from its newest restart file on the next workflow call, in the stage it was
killed in; a validation part's deadline stops a resumed run where it is, and the next call resumes it again.

The tiny silo (about 1,400 clumps) runs killed (the whole process group: Snakemake, the script and LIGGGHTS) once
during its pour, after it has written two restart files, and once during its discharge, after two restart files past
the opening of its outlet. The killed workflow is unlocked and called again; it resumes. In `make test-physics` the
tiny silo also runs uninterrupted, and each resumed run ends with the same clumps and flow rate within noise.
"""

from __future__ import annotations

import csv
import math
import os
import signal
import subprocess
import sys
import time

import pytest
import yaml

from siloflow.model.record import read_run_record
from siloflow.engines.config import load_config_file, validate_config
from tests.repo import REPO_ROOT
from siloflow.engines.layout import run_dir as layout_run_dir, run_path
from siloflow.engines.deadline import PartDeadline
from siloflow.engines.interface import EngineOptions, engine_for
from siloflow.engines.liggghts.run import attempt_logs, restart_files
from siloflow.model.cases.silo_flat import build_silo_case
from tests.stopped_runs import deadline_once, killable, started_log
from tests.conftest import NO_BLENDER, NO_BLENDING, TINY_SILO, require_liggghts, run_snakemake

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(160)]

CONFIG = {"silo_flat": TINY_SILO, "silo_recirculation": NO_BLENDING, "blender": NO_BLENDER}


def _snakemake_command(workdir, config_path, target):
    return [sys.executable, "-m", "snakemake", target, "-s", str(REPO_ROOT / "Snakefile"), "--directory",
            str(workdir), "--cores", "1", "--configfile", str(config_path)]


def _config() -> dict:
    raw = load_config_file(REPO_ROOT / "config" / "config.yaml")
    raw["silo_flat"] = {**raw["silo_flat"], **TINY_SILO}
    return validate_config(raw)


def _run_id() -> str:
    return build_silo_case(_config()).run_id


def _workdir(tmp_path_factory, name):
    workdir = tmp_path_factory.mktemp(name)
    (workdir / "tiny.yaml").write_text(yaml.safe_dump(CONFIG))
    return workdir


@pytest.fixture(scope="module", params=["fill", "discharge"])
def killed_and_resumed(request, tmp_path_factory):
    """The tiny silo's workflow killed during its pour or its discharge, unlocked and called again; yields the stage
    and the run directory."""
    require_liggghts()
    stage = request.param
    run_id = _run_id()
    target = run_path("silo_flat", "metrics/flow.csv", run_id)
    workdir = _workdir(tmp_path_factory, f"killed_in_{stage}")
    killed = subprocess.Popen(_snakemake_command(workdir, workdir / "tiny.yaml", target),
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    run_dir = workdir / layout_run_dir("silo_flat", run_id)
    deadline = time.monotonic() + 600
    while (not killable(run_dir, stage, "log.liggghts", restart_files) and killed.poll() is None
           and time.monotonic() < deadline):
        time.sleep(0.2)
    assert killed.poll() is None, f"the run went past its {stage} before it could be killed there"
    assert killable(run_dir, stage, "log.liggghts", restart_files), f"no two restart files in its {stage} in 10 minutes"
    os.killpg(killed.pid, signal.SIGKILL)
    killed.wait()
    # let the orphaned engine die with its group before looking at the run directory
    time.sleep(1.0)
    assert not (run_dir / "run.json").exists()
    unlock = run_snakemake(workdir, "--unlock", "--configfile", str(workdir / "tiny.yaml"))
    assert unlock.returncode == 0, unlock.stdout[-2000:] + unlock.stderr[-2000:]
    if stage == "fill":
        # a validation part's deadline falls while the resumed run pours: the run stops there, and it neither goes
        # back to an older restart file nor runs on past the deadline (the engine called directly, so that the
        # deadline counts from the resumption, not from the workflow's start)
        config = _config()
        with pytest.raises(PartDeadline), deadline_once(started_log(run_dir / "resume1.log.liggghts"), run_id):
            engine_for(config, "silo_flat").run(build_silo_case(config), run_dir, EngineOptions())
        assert [path.name for path in attempt_logs(run_dir)] == ["log.liggghts", "resume1.log.liggghts"]
        stopped = (run_dir / "resume1.log.liggghts").read_text()
        assert "SILOFLOW discharged" not in stopped and not (run_dir / "run.json").exists()
    resumed = run_snakemake(workdir, "--cores", "1", "--rerun-incomplete", "--configfile",
                            str(workdir / "tiny.yaml"), targets=[target])
    assert resumed.returncode == 0, resumed.stdout[-3000:] + resumed.stderr[-3000:]
    # the resumption that completed the run: the engine's own log where the deadline stopped the first one early
    completed = attempt_logs(run_dir)[-1] if stage == "fill" else run_dir / "logs" / "run.log"
    yield stage, run_dir, completed.read_text()


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    """The tiny silo's workflow run through once; yields the run directory."""
    require_liggghts()
    run_id = _run_id()
    workdir = _workdir(tmp_path_factory, "uninterrupted")
    result = run_snakemake(workdir, "--cores", "1", "--configfile", str(workdir / "tiny.yaml"),
                           targets=[run_path("silo_flat", "metrics/flow.csv", run_id)])
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    yield workdir / layout_run_dir("silo_flat", run_id)


def test_the_killed_run_resumes_from_its_restart_file_in_the_stage_it_was_killed_in(killed_and_resumed):
    stage, run_dir, log = killed_and_resumed
    if stage == "fill":
        # the resumed deck pours again: it defines the pour before its first run
        assert "fix pour all insert/rate/region" in log, log[-2000:]
    else:
        assert "from restart file restart/state_" in log and f" in its {stage}" in log, log[-2000:]
    record = read_run_record(run_dir / "run.json")
    # a run killed in its pour was stopped once more by a part's deadline (the fixture)
    assert record.resumed_attempts == (2 if stage == "fill" else 1)
    resumed_logs = [path.read_text() for path in attempt_logs(run_dir)[1:]]
    assert "SILOFLOW resumed" in resumed_logs[-1]
    # a pour resumed goes on inserting where it stopped: the fill holds the case's clumps, no more
    assert record.stage("fill")["clumps"] == record.n_clumps
    # (the fill ends in the first resumption or, where the part's deadline came first, in the next)
    assert any("SILOFLOW filled" in text for text in resumed_logs) == (stage == "fill")
    # the markers' times are the steps' (LIGGGHTS starts its clock again at zero in a resumed attempt)
    assert record.open_time_s == pytest.approx(record.open_step * record.timestep_s, rel=1e-12)
    # restart files only serve resumption; a finished run has none left
    assert not (run_dir / "restart").exists()


@pytest.mark.physics  # a second run of the tiny silo, uninterrupted
def test_resumed_and_uninterrupted_runs_agree(killed_and_resumed, uninterrupted):
    (_, resumed_dir, _), uninterrupted_dir = killed_and_resumed, uninterrupted
    resumed = read_run_record(resumed_dir / "run.json")
    uninterrupted = read_run_record(uninterrupted_dir / "run.json")
    assert resumed.stage("fill")["clumps"] == uninterrupted.stage("fill")["clumps"] == resumed.n_clumps
    assert resumed.n_frames == uninterrupted.n_frames
    # the same discharge, from wherever the outlet opened (a fill resumed settles in its own number of checks)
    assert (resumed.stage("discharge")["step"] - resumed.open_step
            == uninterrupted.stage("discharge")["step"] - uninterrupted.open_step)
    (a,) = csv.DictReader((resumed_dir / "metrics" / "flow.csv").open())
    (b,) = csv.DictReader((uninterrupted_dir / "metrics" / "flow.csv").open())
    rate_a, rate_b = float(a["mass_flow_rate_kg_s"]), float(b["mass_flow_rate_kg_s"])
    # After the restart the trajectories part (the engine rebuilds its neighbour lists in another order), so the
    # two runs differ like two realisations: counting noise of the clumps discharged in the steady window,
    # rate / sqrt(N), for each run.
    clump_mass = float(b["initial_mass_kg"]) / float(b["n_clumps"])
    window = float(b["steady_window_end_s"]) - float(b["steady_window_start_s"])
    counted = rate_b * window / clump_mass
    noise = 3.0 * math.sqrt(2.0) * rate_b / math.sqrt(counted)
    print(f"flow rate resumed {rate_a:.5g} kg/s, uninterrupted {rate_b:.5g} kg/s, 3 sigma of counting noise "
          f"{noise:.2g} kg/s ({counted:.0f} clumps in the window); clumps left {resumed.stage('discharge')['clumps']:.0f} "
          f"and {uninterrupted.stage('discharge')['clumps']:.0f}")
    assert abs(rate_a - rate_b) <= noise
    assert abs(resumed.stage("discharge")["clumps"] - uninterrupted.stage("discharge")["clumps"]) <= 0.05 * resumed.n_clumps
