"""The Snakemake launcher (siloflow.engines.workflow_lock): it holds an flock for the whole run, refuses while another run is
live, removes a killed run's stale locks with the run's own workflow arguments, and passes on Snakemake's exit code.

Snakemake is replaced by a small script that records its arguments; no engine and no Snakemake run.
"""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from tests.repo import REPO_ROOT
from siloflow.cli.main import main
from siloflow.engines.workflow_lock import (
    LAUNCHER_LOCK,
    LiveRunError,
    acquire_launcher_lock,
    is_snakemake_command,
    launch,
    live_snakemake_processes,
    stale_lock_files,
    unlock_command,
    working_directory,
)

# Records its arguments (one JSON line each call) and behaves as Snakemake would for the launcher: --unlock removes
# the lock files; the exit codes come from the environment.
FAKE_SNAKEMAKE = textwrap.dedent("""
    import json, os, pathlib, signal, sys, time
    arguments = sys.argv[1:]
    with open(os.environ["FAKE_SNAKEMAKE_LOG"], "a") as log:
        log.write(json.dumps(arguments) + "\\n")
    directory = pathlib.Path(arguments[arguments.index("--directory") + 1])
    if "--unlock" in arguments:
        for lock in (directory / ".snakemake" / "locks").glob("*"):
            lock.unlink()
        sys.exit(int(os.environ.get("FAKE_UNLOCK_EXIT", "0")))
    if os.environ.get("FAKE_PID_FILE"):
        # written whole and then renamed, so that a reader never sees the file empty
        pid_file = pathlib.Path(os.environ["FAKE_PID_FILE"])
        pid_file.with_suffix(".partial").write_text(str(os.getpid()))
        pid_file.with_suffix(".partial").replace(pid_file)
    time.sleep(float(os.environ.get("FAKE_SLEEP", "0")))
    if os.environ.get("FAKE_SIGNAL"):
        os.kill(os.getpid(), int(os.environ["FAKE_SIGNAL"]))
    sys.exit(int(os.environ.get("FAKE_RUN_EXIT", "0")))
""")


@pytest.fixture
def fake_snakemake(tmp_path, monkeypatch):
    """(command that starts the fake Snakemake, function returning the argument lists it was called with)."""
    script = tmp_path / "fake_snakemake.py"
    script.write_text(FAKE_SNAKEMAKE)
    log = tmp_path / "calls.jsonl"
    monkeypatch.setenv("FAKE_SNAKEMAKE_LOG", str(log))

    def calls():
        return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []

    return [sys.executable, str(script)], calls


@pytest.fixture
def empty_proc(tmp_path):
    """A proc file system without processes, so that the machine's own Snakemake runs play no part."""
    proc = tmp_path / "proc"
    proc.mkdir()
    return proc


def _run_arguments(workdir: Path) -> list[str]:
    return ["--snakefile", str(REPO_ROOT / "Snakefile"), "--directory", str(workdir), "--configfile",
            str(workdir / "tiny.yaml"), "--cores", "2", "--rerun-incomplete", "--rerun-triggers", "mtime", "params",
            "input"]


def _stale_locks(workdir: Path) -> list[Path]:
    locks = workdir / ".snakemake" / "locks"
    locks.mkdir(parents=True)
    paths = [locks / "0.input.lock", locks / "0.output.lock"]
    for path in paths:
        path.write_text(f"{workdir}/results/x\n")
    return paths


def test_the_working_directory_is_the_directory_option_else_the_current_one(tmp_path):
    assert working_directory(["--cores", "2"], cwd=tmp_path) == tmp_path.resolve()
    assert working_directory(["--directory", "run", "--cores", "2"], cwd=tmp_path) == (tmp_path / "run").resolve()
    assert working_directory(["-d", str(tmp_path / "a")], cwd="/") == (tmp_path / "a").resolve()
    assert working_directory([f"--directory={tmp_path / 'b'}"], cwd="/") == (tmp_path / "b").resolve()


def test_the_unlock_command_repeats_the_workflow_directory_and_configuration_only():
    arguments = ["all", "--cores", "2", "--snakefile", "/repo/Snakefile", "-d", "/run", "--configfile", "a.yaml",
                 "b.yaml", "--rerun-incomplete", "--config", "x=1", "y=2", "--rerun-triggers", "mtime", "params",
                 "--configfiles=c.yaml"]
    assert unlock_command(arguments, snakemake=["snakemake"]) == [
        "snakemake", "--unlock", "--snakefile", "/repo/Snakefile", "-d", "/run", "--configfile", "a.yaml", "b.yaml",
        "--config", "x=1", "y=2", "--configfiles", "c.yaml"]
    # a single-valued option takes one word: what follows it is a target, not part of the workflow arguments
    assert unlock_command(["-s", "Snakefile", "target"], snakemake=["sm"]) == ["sm", "--unlock", "-s", "Snakefile"]
    assert unlock_command(["--cores", "1"])[-1] == "--unlock"
    assert unlock_command([])[:3] == [sys.executable, "-m", "snakemake"]


def test_the_launcher_lock_is_refused_while_held_and_names_the_directory_and_holder(tmp_path):
    held = acquire_launcher_lock(tmp_path)
    try:
        assert (tmp_path / ".snakemake" / LAUNCHER_LOCK).read_text() == f"{os.getpid()}\n"
        with pytest.raises(LiveRunError, match="another siloflow run is live") as refused:
            acquire_launcher_lock(tmp_path)
        assert str(tmp_path) in str(refused.value) and f"by process {os.getpid()}" in str(refused.value)
        # the refused attempt leaves the holder's pid in place
        assert (tmp_path / ".snakemake" / LAUNCHER_LOCK).read_text() == f"{os.getpid()}\n"
    finally:
        held.close()
    acquire_launcher_lock(tmp_path).close()


def test_the_launcher_lock_is_free_once_its_holder_is_killed_with_sigkill(tmp_path):
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from siloflow.engines.workflow_lock import acquire_launcher_lock; "
                               "lock = acquire_launcher_lock(sys.argv[1]); print('held', flush=True); time.sleep(60)",
         str(tmp_path)],
        cwd=REPO_ROOT, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(LiveRunError):
            acquire_launcher_lock(tmp_path)
    finally:
        holder.kill()
        holder.wait()
    acquire_launcher_lock(tmp_path).close()


def test_stale_lock_files_are_the_files_in_snakemakes_lock_folder(tmp_path):
    assert stale_lock_files(tmp_path) == []
    (tmp_path / ".snakemake" / "locks").mkdir(parents=True)
    assert stale_lock_files(tmp_path) == []
    paths = _stale_locks(tmp_path / "w")
    assert stale_lock_files(tmp_path / "w") == paths


@pytest.mark.parametrize("argv, expected", [
    (["/usr/bin/python3", "-m", "snakemake", "--cores", "2"], True),
    (["python3", "-u", "-msnakemake", "-n"], True),
    (["/usr/local/bin/python3.11", "/usr/local/bin/snakemake", "--cores", "2"], True),
    (["snakemake", "-n"], True),
    (["nice", "-n", "19", "python", "-m", "snakemake"], True),
    (["python", "-m", "snakemake.cli"], True),
    (["python", "-m", "siloflow.engines.workflow_lock", "--snakefile", "/repo/Snakefile", "--directory", "/run"], False),
    (["python", "-m", "snakemake_executor_plugin_slurm"], False),
    (["liggghts", "-in", "in.case"], False),
    ([], False),
])
def test_snakemake_command_lines_are_recognised(argv, expected):
    assert is_snakemake_command(argv) is expected


def _fake_process(proc: Path, pid: int, argv: list[str], cwd: Path) -> None:
    entry = proc / str(pid)
    entry.mkdir()
    (entry / "cmdline").write_bytes(b"\0".join(word.encode() for word in argv) + b"\0")
    (entry / "cwd").symlink_to(cwd)


def test_live_snakemake_processes_are_those_working_in_the_directory(tmp_path, empty_proc):
    workdir, elsewhere = tmp_path / "run", tmp_path / "other"
    workdir.mkdir()
    elsewhere.mkdir()
    _fake_process(empty_proc, 40, ["python3", "-m", "snakemake", "--cores", "2"], workdir)
    _fake_process(empty_proc, 41, ["python3", "-m", "snakemake", "--cores", "2"], elsewhere)
    _fake_process(empty_proc, 42, ["liggghts", "-in", "in.case"], workdir)
    _fake_process(empty_proc, 43, ["snakemake"], workdir)
    (empty_proc / "44").mkdir()  # a process that ended while the folder was read
    (empty_proc / "self").mkdir()
    assert live_snakemake_processes(workdir, empty_proc) == [40, 43]
    assert live_snakemake_processes(workdir, empty_proc, exclude=(43,)) == [40]
    assert live_snakemake_processes(tmp_path / "none", empty_proc) == []


def test_a_live_snakemake_started_by_hand_is_found_in_the_real_proc(tmp_path):
    # argv[0] "snakemake", working in tmp_path: what /proc shows of `snakemake ...` started there by hand
    process = subprocess.Popen(["bash", "-c", "exec -a snakemake sleep 60"], cwd=tmp_path)
    try:
        deadline = time.monotonic() + 10
        while process.pid not in live_snakemake_processes(tmp_path) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert live_snakemake_processes(tmp_path) == [process.pid]
    finally:
        process.kill()
        process.wait()
    assert live_snakemake_processes(tmp_path) == []


def test_a_run_without_stale_locks_starts_snakemake_once_and_returns_its_exit_code(tmp_path, fake_snakemake,
                                                                                   empty_proc, monkeypatch):
    command, calls = fake_snakemake
    monkeypatch.setenv("FAKE_RUN_EXIT", "3")
    stream = io.StringIO()
    assert launch(_run_arguments(tmp_path), snakemake=command, proc=empty_proc, stream=stream) == 3
    assert calls() == [_run_arguments(tmp_path)]
    assert stream.getvalue() == ""
    # the lock is released when the run ends
    acquire_launcher_lock(tmp_path).close()


def test_stale_locks_are_removed_with_the_runs_own_arguments_before_the_run(tmp_path, fake_snakemake, empty_proc):
    command, calls = fake_snakemake
    _stale_locks(tmp_path)
    stream = io.StringIO()
    assert launch(_run_arguments(tmp_path), snakemake=command, proc=empty_proc, stream=stream) == 0
    assert calls() == [
        ["--unlock", "--snakefile", str(REPO_ROOT / "Snakefile"), "--directory", str(tmp_path), "--configfile",
         str(tmp_path / "tiny.yaml")],
        _run_arguments(tmp_path),
    ]
    assert stream.getvalue() == (f"siloflow: removed a stale Snakemake lock (2 lock files) that a killed run left in "
                                 f"{tmp_path.resolve()}\n")
    assert stale_lock_files(tmp_path) == []


def test_a_failed_unlock_stops_before_the_run(tmp_path, fake_snakemake, empty_proc, monkeypatch):
    command, calls = fake_snakemake
    _stale_locks(tmp_path)
    monkeypatch.setenv("FAKE_UNLOCK_EXIT", "1")
    stream = io.StringIO()
    assert launch(_run_arguments(tmp_path), snakemake=command, proc=empty_proc, stream=stream) == 1
    assert [call[0] for call in calls()] == ["--unlock"]
    assert "removing the stale Snakemake lock" in stream.getvalue() and "failed" in stream.getvalue()


def test_a_live_launcher_is_never_unlocked(tmp_path, fake_snakemake, empty_proc):
    command, calls = fake_snakemake
    locks = _stale_locks(tmp_path)
    held = acquire_launcher_lock(tmp_path)
    try:
        with pytest.raises(LiveRunError, match="another siloflow run is live"):
            launch(_run_arguments(tmp_path), snakemake=command, proc=empty_proc)
    finally:
        held.close()
    assert calls() == []
    assert stale_lock_files(tmp_path) == locks
    assert all(path.read_text() == f"{tmp_path}/results/x\n" for path in locks)


def test_a_live_snakemake_started_by_hand_is_never_unlocked(tmp_path, fake_snakemake, empty_proc):
    command, calls = fake_snakemake
    locks = _stale_locks(tmp_path)
    _fake_process(empty_proc, 4242, ["/usr/bin/python3", "/usr/bin/snakemake", "--cores", "2"], tmp_path)
    with pytest.raises(LiveRunError, match="outside this launcher .process 4242."):
        launch(_run_arguments(tmp_path), snakemake=command, proc=empty_proc)
    assert calls() == []
    assert stale_lock_files(tmp_path) == locks
    # the refusal releases the launcher's lock
    acquire_launcher_lock(tmp_path).close()


def test_a_snakemake_ended_by_a_signal_exits_as_a_shell_reports_it(tmp_path, fake_snakemake, empty_proc,
                                                                   monkeypatch):
    command, _ = fake_snakemake
    monkeypatch.setenv("FAKE_SIGNAL", str(int(signal.SIGTERM)))
    assert launch(_run_arguments(tmp_path), snakemake=command, proc=empty_proc) == 128 + signal.SIGTERM


def test_snakemake_keeps_the_directory_locked_when_the_launcher_alone_is_killed(tmp_path, fake_snakemake,
                                                                                monkeypatch):
    command, _ = fake_snakemake
    pid_file = tmp_path / "snakemake.pid"
    monkeypatch.setenv("FAKE_PID_FILE", str(pid_file))
    monkeypatch.setenv("FAKE_SLEEP", "60")
    launcher = subprocess.Popen(
        [sys.executable, "-c", "import json, sys; from siloflow.engines.workflow_lock import launch; "
                               "launch(json.loads(sys.argv[1]), snakemake=json.loads(sys.argv[2]), proc=sys.argv[3])",
         json.dumps(_run_arguments(tmp_path)), json.dumps(command), str(tmp_path)],
        cwd=REPO_ROOT)
    deadline = time.monotonic() + 20
    while not pid_file.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert pid_file.exists(), "the fake Snakemake did not start within 20 s"
    snakemake_pid = int(pid_file.read_text())
    try:
        launcher.kill()
        launcher.wait()
        with pytest.raises(LiveRunError):
            acquire_launcher_lock(tmp_path)
    finally:
        os.kill(snakemake_pid, signal.SIGKILL)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        try:
            acquire_launcher_lock(tmp_path).close()
            break
        except LiveRunError:
            time.sleep(0.05)
    else:
        pytest.fail("the lock stayed held after Snakemake was killed")


def test_the_command_line_refuses_a_live_run_with_a_message_and_a_retry_exit_code(tmp_path, capsys):
    held = acquire_launcher_lock(tmp_path)
    try:
        assert main(["run", "--config", str(REPO_ROOT / "config" / "config.yaml"), "--directory", str(tmp_path),
                     "--cores", "1"]) == 75
    finally:
        held.close()
    err = capsys.readouterr().err
    assert err.startswith(f"siloflow run: another siloflow run is live in {tmp_path.resolve()} ")
    assert len(err.splitlines()) == 1
