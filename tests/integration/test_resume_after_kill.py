"""`make run` after a SIGKILL: the next call removes the killed run's stale Snakemake lock and completes, without a
manual `snakemake --unlock`; a second call while a run is live is refused and leaves that run's locks alone.

A small pipeline `make run` runs whole: the small silo (about 650 clumps) on LIGGGHTS without PIV, one tiny Jenike
shear test, and no blending study, blender or verification. The README's run command starts it in its own session;
once an engine job runs, the session is frozen where it is (SIGSTOP), a second `make run` is refused, then the whole
session is killed with SIGKILL and the same `make run` is called again.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from tests.repo import REPO_ROOT
from tests.conftest import NO_BLENDER, NO_BLENDING, NO_VERIFICATION, SMALL_SILO, TINY_JENIKE_SWEEP, require_liggghts

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(90)]


CONFIG = {
    "silo_flat": SMALL_SILO,
    "jenike": TINY_JENIKE_SWEEP,
    "silo_recirculation": NO_BLENDING,
    "blender": NO_BLENDER,
    "verification": NO_VERIFICATION,
}


def _make_run(config: Path, workdir: Path) -> list[str]:
    """The README's `make run`, for this configuration and working directory, at low priority (another engine job may
    share the machine). Its install step is taken as done (``-o install``): it reinstalls the editable package with
    pip, which would pull the package from under the job scripts of tests running beside this one, and the package
    is installed (this test imports it)."""
    return ["nice", "-n", "10", "make", "--no-print-directory", "-C", str(REPO_ROOT), "-o", "install", "run",
            f"CONFIG={config}", f"RUN_DIR={workdir}", f"PYTHON={sys.executable}", "CORES=2"]


def _environment() -> dict:
    # a `make test` above pytest must not hand its jobserver to these make calls
    return {key: value for key, value in os.environ.items() if key not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}


def _session_processes(session: int) -> list[int]:
    """Live (not zombie) processes of a session."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rpartition(")")[2].split()
        except OSError:
            continue
        if fields[0] != "Z" and int(fields[3]) == session:
            found.append(int(entry.name))
    return found


def _signal_session(session: int, number: int) -> None:
    """Send signal ``number`` to every live process of a session."""
    for pid in _session_processes(session):
        try:
            os.kill(pid, number)
        except ProcessLookupError:
            pass  # ended between the listing and the signal


def _lock_files(workdir: Path) -> dict[str, str]:
    locks = workdir / ".snakemake" / "locks"
    return {path.name: path.read_text() for path in sorted(locks.iterdir())} if locks.is_dir() else {}


@pytest.fixture(scope="module")
def killed_and_resumed(tmp_path_factory):
    """Run, refuse a second run, kill, run again; yields what each step saw."""
    require_liggghts()
    workdir = tmp_path_factory.mktemp("killed_run").resolve()
    config = workdir / "tiny.yaml"
    config.write_text(yaml.safe_dump(CONFIG))
    seen = {"workdir": workdir}
    with open(workdir / "killed_make.log", "w") as killed_output:
        killed = subprocess.Popen(_make_run(config, workdir), stdout=killed_output, stderr=subprocess.STDOUT,
                                  stdin=subprocess.DEVNULL, env=_environment(), start_new_session=True)
    try:
        # an engine job is running once a run step has opened its log and Snakemake holds its locks
        deadline = time.monotonic() + 600
        while killed.poll() is None and time.monotonic() < deadline and not (
                list((workdir / "results").glob("**/logs/run.log")) and _lock_files(workdir)):
            time.sleep(0.5)
        # Frozen where it is, the run stays live, holding its locks, however long the second call takes to reach
        # its launcher: on a loaded machine the small pipeline could otherwise finish before that.
        _signal_session(killed.pid, signal.SIGSTOP)
        assert killed.poll() is None, (workdir / "killed_make.log").read_text()[-3000:]
        seen["locks_while_live"] = _lock_files(workdir)
        assert seen["locks_while_live"], "no engine job within 10 minutes"
        seen["second"] = subprocess.run(_make_run(config, workdir), capture_output=True, text=True,
                                        stdin=subprocess.DEVNULL, env=_environment(), check=False, timeout=300)
        seen["locks_after_refusal"] = _lock_files(workdir)
        seen["alive_after_refusal"] = killed.poll() is None
    finally:
        os.killpg(killed.pid, signal.SIGKILL)
        # a process of the session outside its group (none is expected) carries on as it would have unfrozen, so
        # that the check for left-over processes below sees it
        _signal_session(killed.pid, signal.SIGCONT)
        killed.wait()
    # the engine dies with its group; wait until nothing of the session is left before looking at the directory
    deadline = time.monotonic() + 30
    while _session_processes(killed.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    seen["left_over"] = _session_processes(killed.pid)
    seen["locks_after_kill"] = _lock_files(workdir)
    seen["report_after_kill"] = (workdir / "results" / "report.html").exists()
    seen["resumed"] = subprocess.run(_make_run(config, workdir), capture_output=True, text=True,
                                     stdin=subprocess.DEVNULL, env=_environment(), check=False, timeout=1200)
    yield seen


def test_a_second_run_while_one_is_live_is_refused_and_leaves_its_locks_alone(killed_and_resumed):
    seen = killed_and_resumed
    second = seen["second"]
    assert second.returncode != 0
    assert f"another siloflow run is live in {seen['workdir']}" in second.stderr, second.stderr[-3000:]
    assert "Snakemake locks were left alone" in second.stderr
    assert "removed a stale Snakemake lock" not in second.stdout + second.stderr
    assert seen["locks_after_refusal"] == seen["locks_while_live"]
    assert seen["alive_after_refusal"]


def test_the_killed_run_left_stale_locks(killed_and_resumed):
    seen = killed_and_resumed
    assert seen["left_over"] == []
    assert seen["locks_after_kill"], "SIGKILL left no Snakemake lock: nothing for the next run to remove"
    assert not seen["report_after_kill"], "the run finished before it was killed"


def test_make_run_after_the_kill_completes_without_a_manual_unlock(killed_and_resumed):
    seen = killed_and_resumed
    resumed, workdir = seen["resumed"], seen["workdir"]
    output = resumed.stdout + resumed.stderr
    assert resumed.returncode == 0, output[-5000:]
    assert f"removed a stale Snakemake lock ({len(seen['locks_after_kill'])} lock files) that a killed run left in " \
           f"{workdir}" in output
    assert _lock_files(workdir) == {}
    assert (workdir / "results" / "summary" / "summary.html").is_file()
    assert (workdir / "results" / "report.html").is_file()
    assert list((workdir / "results" / "silo_flat").glob("*/run.json"))
