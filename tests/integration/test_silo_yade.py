"""YADE runs the micro silo (about 350 two-sphere clumps, 20 mm of fill) through the engine interface: fill, settle,
open, discharge. The run is SIGKILLed, once after its pour has written two snapshots and once after its discharge has,
and resumed by the next call in that stage; no socket listens while it runs; its frames, wall forces and settled fill
read back into the neutral objects and the analysis works on them unchanged (flow rate, force balance).
"""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from siloflow.model.frames import clumps_from_frame
from siloflow.analysis.numerics.force_balance import settled_fill_balance
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.engines.config import load_config_file, validate_config
from siloflow.engines.interface import EngineOptions, EngineRunError, engine_for
from siloflow.engines.deadline import PartDeadline
from siloflow.engines.yade.run import attempt_logs, restart_files
from tests.stopped_runs import deadline_once, killable, started_log
from tests.conftest import DEFAULT_CONFIG, MICRO_SILO, require_yade
from tests.paraview_checks import check_paraview_folder, write_engine_paraview_files

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(90)]


def listening_inodes() -> set[str]:
    """Socket inodes in LISTEN state (TCP and TCP6: state 0A in /proc/net/tcp*)."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table, encoding="ascii") as handle:
            next(handle)
            for line in handle:
                fields = line.split()
                if fields[3] == "0A":
                    found.add(fields[9])
    return found


def socket_inodes(pid: int) -> set[str]:
    """The socket inodes process ``pid`` holds open."""
    found = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            found.add(target[len("socket:["):-1])
    return found


def script_processes(run_dir: Path) -> list[int]:
    """Processes running the run's script (their working directory is the run directory)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if Path(os.readlink(entry / "cwd")) == run_dir and "deck/run.py" in (entry / "cmdline").read_text():
                found.append(int(entry.name))
        except OSError:
            continue
    return found


@pytest.fixture(scope="module", params=["fill", "discharge"])
def micro_run(request, tmp_path_factory):
    require_yade()
    raw = load_config_file(DEFAULT_CONFIG)
    raw["silo_flat"] = {**raw["silo_flat"], **MICRO_SILO}
    config = validate_config(raw)
    case = build_silo_case(config)
    engine = engine_for(config, "silo_flat")
    stage = request.param
    run_dir = (tmp_path_factory.mktemp(f"yade_killed_in_{stage}") / case.run_id).resolve()
    engine.write_inputs(case, run_dir)
    failure = []
    first = threading.Thread(target=lambda: failure.append(_expect_failure(engine, case, run_dir)))
    first.start()
    listening_while_running = None
    deadline = time.monotonic() + 900
    # on until it can be killed in its stage and has been seen running (the sockets looked at)
    while ((not killable(run_dir, stage, "log.yade", restart_files) or listening_while_running is None)
           and first.is_alive() and time.monotonic() < deadline):
        pids = script_processes(run_dir)
        log = run_dir / "log.yade"
        # YADE is imported and the scene runs once the script reports progress
        if pids and listening_while_running is None and log.exists() and "SILOFLOW progress" in log.read_text():
            listening_while_running = {pid: socket_inodes(pid) & listening_inodes() for pid in pids}
        time.sleep(0.2)
    assert first.is_alive(), f"the run went past its {stage} before it could be killed there"
    assert killable(run_dir, stage, "log.yade", restart_files), f"no two snapshots in its {stage} within 15 minutes"
    for pid in script_processes(run_dir):
        os.kill(pid, signal.SIGKILL)
    first.join()
    if stage == "fill":
        # a validation part's deadline falls while the resumed run goes on: it stops there, and neither goes back
        # to an older snapshot nor runs on past the deadline
        with pytest.raises(PartDeadline), deadline_once(started_log(run_dir / "resume1.log.yade"), case.run_id):
            engine.run(case, run_dir, EngineOptions())
        assert [path.name for path in attempt_logs(run_dir)] == ["log.yade", "resume1.log.yade"]
        assert "SILOFLOW discharged" not in (run_dir / "resume1.log.yade").read_text()
    record = engine.run(case, run_dir, EngineOptions())
    return case, engine, run_dir, record, listening_while_running, failure, stage


def _expect_failure(engine, case, run_dir):
    try:
        engine.run(case, run_dir, EngineOptions())
    except EngineRunError as error:
        return str(error)
    return None


def test_no_socket_listens_while_yade_runs(micro_run):
    _, _, _, _, listening, _, _ = micro_run
    assert listening, "the script's process was not seen running"
    assert all(inodes == set() for inodes in listening.values()), listening


def test_the_killed_run_failed_and_resumed_from_a_snapshot(micro_run):
    case, _, run_dir, record, _, failure, stage = micro_run
    assert failure and failure[0] is not None and "exit code -9" in failure[0]
    # a run killed in its pour was stopped once more by a part's deadline (the fixture)
    assert record.resumed_attempts == (2 if stage == "fill" else 1)
    resumed_logs = [path.read_text() for path in attempt_logs(run_dir)[1:]]
    assert "SILOFLOW resumed" in resumed_logs[-1]
    # a pour resumed goes on inserting where it stopped, from the random state its snapshot kept (the fill ends in
    # the first resumption or, where the part's deadline came first, in the next)
    assert any("SILOFLOW filled" in text for text in resumed_logs) == (stage == "fill")
    assert record.stage("fill")["clumps"] == case.fill.n_clumps
    assert not (run_dir / "restart").exists()  # snapshots only serve resumption


def test_the_silo_filled_settled_and_discharged(micro_run):
    case, engine, run_dir, record, _, _, _ = micro_run
    assert record.engine == "yade" and record.n_clumps == case.fill.n_clumps
    assert record.stage("settle")["ke_per_clump"] < case.settle_threshold
    frames = engine.read_frames(run_dir, record)
    assert len(frames) == record.n_frames
    steps = [frame.step for frame in frames]
    assert steps == sorted(set(steps))  # the resumed attempt rewrote, never duplicated, the frames after its snapshot
    clumps = [clumps_from_frame(frame) for frame in frames]
    # every clump carries the exact mass of the union of its spheres
    assert np.allclose(clumps[0].mass, case.particle.mass, rtol=1e-12)
    assert len(clumps[0].clump_id) == case.fill.n_clumps
    assert len(clumps[-1].clump_id) < 0.9 * case.fill.n_clumps  # clumps left through the outlet


def test_wall_forces_span_the_run_and_the_settled_fill_balances(micro_run):
    case, engine, run_dir, record, _, _, _ = micro_run
    history = engine.wall_forces(run_dir, record)
    assert set(history.walls) == {"wall_left", "wall_right", "wall_front", "wall_back", "floor_left", "floor_right",
                                  "outlet_gate"}
    assert np.all(np.diff(history.time) > 0)
    assert history.time[-1] == pytest.approx(record.stage("discharge")["time"], abs=case.dump_every * case.timestep)
    settled = engine.settled_fill(run_dir, record)
    assert [s.frame.step for s in settled] == [settled[0].frame.step, settled[0].frame.step + 1]
    balance = settled_fill_balance(settled, [0.2 * case.fill_height], case.gravity)
    assert balance.weight == pytest.approx(record.n_clumps * case.particle.mass * case.gravity, rel=1e-9)
    # walls + floor carry the weight (the fill is at rest)
    assert balance.support_ratio == pytest.approx(1.0, abs=0.01)
    assert sum(balance.wall_support.values()) / balance.weight == pytest.approx(balance.support_ratio, abs=1e-6)


def test_the_yade_run_opens_in_paraview_on_its_simulated_clock(micro_run, tmp_path):
    case, engine, run_dir, record, _, _, _ = micro_run
    frames = write_engine_paraview_files("silo_flat", case, engine, run_dir, record)
    check_paraview_folder(run_dir, frames, fields=False, workdir=tmp_path)
