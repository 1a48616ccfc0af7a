"""A validation part's deadline: read from the environment, it stops an engine run in progress (the child process
too) or refuses to start one once the part's time is up."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from siloflow.engines.deadline import DEADLINE_VARIABLE, PartDeadline, deadline_from, until
from siloflow.engines.interface import EngineRunError
from siloflow.engines.progress import run_with_progress


class _NoParser:
    def feed(self, text):
        return []


def test_the_deadline_is_read_from_the_environment():
    assert deadline_from({}) is None and deadline_from({DEADLINE_VARIABLE: ""}) is None
    assert deadline_from({DEADLINE_VARIABLE: "1700000000.5"}) == 1700000000.5
    for bad in ("soon", "nan", "inf"):
        with pytest.raises(ValueError, match=DEADLINE_VARIABLE):
            deadline_from({DEADLINE_VARIABLE: bad})


def test_a_run_after_the_deadline_does_not_start():
    started = []
    with pytest.raises(PartDeadline, match="silo_flat run r1: the validation part's time is up"):
        with until(100.0, "silo_flat run r1", clock=lambda: 100.0):
            started.append(True)
    assert not started and issubclass(PartDeadline, EngineRunError)


def test_without_a_deadline_the_body_runs_as_is():
    with until(None, "run"):
        done = True
    assert done


def test_the_deadline_stops_an_engine_in_progress_and_its_process(tmp_path):
    command = [sys.executable, "-c", "import time; print('started', flush=True); time.sleep(60)"]
    begin = time.monotonic()
    captured = {}

    def spawn(*args, **kwargs):
        captured["process"] = original(*args, **kwargs)
        return captured["process"]

    original = subprocess.Popen
    subprocess.Popen = spawn
    try:
        with pytest.raises(PartDeadline):
            with until(time.time() + 1.0, "jenike run r2"):
                run_with_progress(command, tmp_path, tmp_path / "out.txt", {}, _NoParser(), None, 30.0, 0.1)
    finally:
        subprocess.Popen = original
    assert time.monotonic() - begin < 20.0
    # the engine is gone with its job, and the alarm is cleared
    assert captured["process"].poll() is not None
    time.sleep(1.2)


def test_a_stop_signal_to_the_run_step_stops_its_engine_too(tmp_path):
    # the run step in a process of its own, as Snakemake runs a script: SIGTERM to it must not leave the engine running
    step = (
        "import subprocess, sys\n"
        "from siloflow.engines.progress import run_with_progress\n"
        "class P:\n"
        "    def feed(self, text): return []\n"
        "original = subprocess.Popen\n"
        "def spawn(*args, **kwargs):\n"
        "    process = original(*args, **kwargs)\n"
        "    print(process.pid, flush=True)\n"
        "    return process\n"
        "subprocess.Popen = spawn\n"
        f"run_with_progress([sys.executable, '-c', 'import time; time.sleep(60)'], {str(tmp_path)!r}, "
        f"{str(tmp_path / 'out.txt')!r}, {{}}, P(), None, 30.0, 0.1)\n"
    )
    runner = subprocess.Popen([sys.executable, "-c", step], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    engine_pid = int(runner.stdout.readline())
    time.sleep(0.5)
    runner.terminate()
    _, error = runner.communicate(timeout=40)
    assert runner.returncode != 0 and "Terminated: stopped by SIGTERM" in error
    # the engine is gone: signal 0 to its pid finds no process (it was the runner's child, reaped with it)
    time.sleep(0.2)
    with pytest.raises(ProcessLookupError):
        os.kill(engine_pid, 0)
