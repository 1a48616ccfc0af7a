"""Start Snakemake in a working directory that a killed run may have left locked, and never unlock a live run.

:func:`launch` runs ``python -m snakemake <snakemake arguments...>`` (``siloflow run`` calls it, and so ``make run``
and ``make validate``). Snakemake marks the files a run works on in ``.snakemake/locks/``
and removes the marks when it ends; a Snakemake killed with SIGKILL cannot, and every later call in that directory
fails with "Directory cannot be locked" until ``snakemake --unlock``. Unlocking by hand is only safe when no
Snakemake is still running there, which the user has to know. The launcher decides it instead:

1. It takes an exclusive, non-blocking :func:`fcntl.flock` on ``.snakemake/siloflow.launcher.lock`` in the working
   directory and holds it until Snakemake ends. The kernel drops an flock when the last process holding its file
   dies, by SIGKILL too, so a held flock means a live launcher (or its Snakemake, which inherits the lock's file
   descriptor). When another process holds it, the launcher refuses (:class:`LiveRunError`) and touches nothing.
2. It looks in ``/proc`` for any Snakemake process whose working directory is this one (a run started by hand, or
   a job process of a Snakemake that was killed alone), and refuses when it finds one.
3. Only then, when ``.snakemake/locks/`` holds lock files, they are stale: it runs ``snakemake --unlock`` with the
   run's ``--snakefile``, ``--directory``, ``--configfile`` and ``--config`` arguments and says so in one line.
4. It runs Snakemake with the given arguments as a child process and exits with its exit code. A refusal exits
   with 75 (EX_TEMPFAIL: the same call succeeds once the live run has ended) and names the directory.

Only runs started through the launcher are protected by the flock; a Snakemake started by hand is recognised by
step 2 only while it runs as ``snakemake ...`` or ``python -m snakemake ...`` in this process namespace and its
``/proc`` entry is readable. A Snakemake that starts by hand between step 2 and the unlock is not seen. Engine
processes orphaned by a Snakemake killed alone are not Snakemake processes and are not seen either; killing the
whole process group (as a terminal or a batch system does) leaves none.

Examples
--------
>>> working_directory(["--cores", "2", "--directory", "/tmp/run"], cwd="/work")
PosixPath('/tmp/run')
>>> unlock_command(["--cores", "2", "-s", "Snakefile", "--configfile", "a.yaml", "b.yaml", "--rerun-incomplete"],
...                snakemake=["snakemake"])
['snakemake', '--unlock', '-s', 'Snakefile', '--configfile', 'a.yaml', 'b.yaml']
"""

from __future__ import annotations

import errno
import fcntl
import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import IO, Sequence

__all__ = [
    "LAUNCHER_LOCK",
    "LiveRunError",
    "acquire_launcher_lock",
    "is_snakemake_command",
    "launch",
    "live_snakemake_processes",
    "stale_lock_files",
    "unlock_command",
    "working_directory",
]

#: The launcher's flock file, inside the working directory's ``.snakemake/``.
LAUNCHER_LOCK = "siloflow.launcher.lock"

#: How Snakemake is started: the interpreter that runs the launcher, so that both see the same packages.
SNAKEMAKE = (sys.executable, "-m", "snakemake")

#: Snakemake options that choose the workflow and its configuration: ``--unlock`` must parse the same workflow, and
#: the Snakefile validates the configuration while it is parsed. Each maps to whether it takes several values.
WORKFLOW_OPTIONS = {
    "--snakefile": False, "-s": False,
    "--directory": False, "-d": False,
    "--configfile": True, "--configfiles": True,
    "--config": True, "-C": True,
}

#: Signals the launcher passes on to Snakemake. SIGINT is not among them: a terminal sends it to the whole
#: foreground process group, Snakemake included, and a second SIGINT would cut Snakemake's own clean-up short.
FORWARDED_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


class LiveRunError(RuntimeError):
    """Another Snakemake run is live in the working directory: nothing may be unlocked or started there."""


def working_directory(arguments: Sequence[str], cwd: str | os.PathLike | None = None) -> Path:
    """The directory Snakemake will work in: the value of ``--directory``/``-d``, else ``cwd``.

    Parameters
    ----------
    arguments
        Snakemake's command-line arguments.
    cwd
        The directory relative paths start from; the launcher's working directory when None.

    Returns
    -------
    Path
        The absolute working directory (symbolic links resolved, so that it compares with ``/proc/<pid>/cwd``).
    """
    base = Path(cwd) if cwd is not None else Path.cwd()
    directory = base
    for option, values in _workflow_arguments(arguments):
        if option in ("--directory", "-d") and values:
            directory = base / values[0]
    return Path(os.path.realpath(directory))


def _workflow_arguments(arguments: Sequence[str]) -> list[tuple[str, list[str]]]:
    """The workflow options of :data:`WORKFLOW_OPTIONS` among ``arguments`` as (option, values), in order.

    A value is any word up to the next one that starts with ``-``, as Snakemake reads an option of several values;
    ``--option=value`` counts as one value.
    """
    found = []
    index = 0
    while index < len(arguments):
        word = arguments[index]
        index += 1
        option, equals, value = word.partition("=")
        if option not in WORKFLOW_OPTIONS or (equals and not option.startswith("--")):
            continue
        if equals:
            found.append((option, [value]))
            continue
        values = []
        while index < len(arguments) and not arguments[index].startswith("-"):
            values.append(arguments[index])
            index += 1
            if not WORKFLOW_OPTIONS[option]:
                break
        found.append((option, values))
    return found


def unlock_command(arguments: Sequence[str], snakemake: Sequence[str] = SNAKEMAKE) -> list[str]:
    """The ``snakemake --unlock`` command for the workflow, directory and configuration of a run.

    Parameters
    ----------
    arguments
        The run's Snakemake arguments.
    snakemake
        The command that starts Snakemake.

    Returns
    -------
    list of str
        ``snakemake --unlock`` followed by the run's ``--snakefile``, ``--directory``, ``--configfile`` and
        ``--config`` options with their values, in the run's order; every other option (cores, targets, reruns)
        is left out.
    """
    command = [*snakemake, "--unlock"]
    for option, values in _workflow_arguments(arguments):
        command += [option, *values]
    return command


def stale_lock_files(directory: str | os.PathLike) -> list[Path]:
    """The lock files in ``<directory>/.snakemake/locks/``, sorted (none when the folder does not exist).

    Called while the launcher holds its flock and no Snakemake runs in ``directory``, so they are stale.
    """
    locks = Path(directory) / ".snakemake" / "locks"
    if not locks.is_dir():
        return []
    return sorted(path for path in locks.iterdir() if path.is_file())


def acquire_launcher_lock(directory: str | os.PathLike) -> IO[str]:
    """Take the launcher's exclusive flock in ``directory`` and return its open file (the lock lives as long as it).

    Parameters
    ----------
    directory
        The working directory; its ``.snakemake/`` is created when missing.

    Returns
    -------
    file object
        The lock file, opened, locked and holding this process's id (for the message of a refused launcher).

    Raises
    ------
    LiveRunError
        When another process holds the lock: a launcher, or its Snakemake, is live in ``directory``.
    """
    folder = Path(directory) / ".snakemake"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / LAUNCHER_LOCK
    # "a+" neither truncates (the holder's pid stays readable for the refusal) nor fails when the file is missing.
    handle = open(path, "a+", encoding="utf-8")
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as error:
        if error.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            handle.close()
            raise
        handle.seek(0)
        holder = handle.read().strip()
        handle.close()
        raise LiveRunError(
            f"another siloflow run is live in {directory} ({path} is locked"
            f"{f' by process {holder}' if holder else ''}); wait for it to end, or stop it, and call again. "
            f"Its Snakemake locks were left alone.") from None
    handle.seek(0)
    handle.truncate()
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    return handle


def is_snakemake_command(argv: Sequence[str]) -> bool:
    """Whether a command line is a Snakemake process: ``snakemake ...``, ``python .../snakemake ...`` or
    ``python -m snakemake[.submodule] ...``, also behind a wrapper such as ``nice``.

    A word counts when its file name is exactly ``snakemake`` (so ``Snakefile`` or ``snakemake-executor-plugin``
    do not) or when it follows ``-m`` and names the snakemake package. Seeing Snakemake where there is none only
    makes the launcher refuse, which is the safe side.
    """
    for index, word in enumerate(argv):
        if os.path.basename(word) == "snakemake":
            return True
        if word == "-m" and index + 1 < len(argv) and argv[index + 1].split(".")[0] == "snakemake":
            return True
        if word.startswith("-m") and word[2:].split(".")[0] == "snakemake":
            return True
    return False


def live_snakemake_processes(directory: str | os.PathLike, proc: str | os.PathLike = "/proc",
                             exclude: Sequence[int] = ()) -> list[int]:
    """Process ids of the Snakemake processes whose working directory is ``directory``.

    Parameters
    ----------
    directory
        The working directory of the run.
    proc
        The proc file system (a folder of ``<pid>/cmdline`` files and ``<pid>/cwd`` links).
    exclude
        Process ids left out (the launcher's own).

    Returns
    -------
    list of int
        Sorted process ids. Processes whose entries cannot be read (ended meanwhile, or another user's) are left
        out; a zombie has an empty command line and counts as ended.
    """
    target = os.path.realpath(directory)
    found = []
    for entry in Path(proc).iterdir():
        if not entry.name.isdigit() or int(entry.name) in exclude:
            continue
        try:
            argv = [word for word in (entry / "cmdline").read_bytes().decode(errors="replace").split("\0") if word]
            if not is_snakemake_command(argv):
                continue
            cwd = os.readlink(entry / "cwd")
        except OSError:
            continue
        if os.path.realpath(cwd) == target:
            found.append(int(entry.name))
    return sorted(found)


def launch(arguments: Sequence[str], snakemake: Sequence[str] = SNAKEMAKE, proc: str | os.PathLike = "/proc",
           stream: IO[str] | None = None) -> int:
    """Run Snakemake with ``arguments`` under the launcher's lock, unlocking a killed run's stale locks first.

    Parameters
    ----------
    arguments
        Snakemake's command-line arguments.
    snakemake
        The command that starts Snakemake.
    proc
        The proc file system searched for Snakemake processes started by hand.
    stream
        Where the launcher's own lines go; standard error when None.

    Returns
    -------
    int
        Snakemake's exit code (128 + the signal number when a signal ended it), or the unlock's when that failed.

    Raises
    ------
    LiveRunError
        When another run is live in the working directory (nothing was unlocked or started).
    """
    stream = stream if stream is not None else sys.stderr
    directory = working_directory(arguments)
    lock = acquire_launcher_lock(directory)
    try:
        others = live_snakemake_processes(directory, proc, exclude=(os.getpid(),))
        if others:
            raise LiveRunError(
                f"Snakemake is running in {directory} outside this launcher (process {', '.join(map(str, others))}); "
                f"wait for it to end, or stop it, and call again. Its Snakemake locks were left alone.")
        stale = stale_lock_files(directory)
        if stale:
            unlocked = subprocess.run(unlock_command(arguments, snakemake), stdin=subprocess.DEVNULL, check=False)
            if unlocked.returncode != 0:
                print(f"siloflow: removing the stale Snakemake lock in {directory} failed "
                      f"(snakemake --unlock exited with {unlocked.returncode})", file=stream, flush=True)
                return unlocked.returncode
            print(f"siloflow: removed a stale Snakemake lock ({len(stale)} lock files) that a killed run left in "
                  f"{directory}", file=stream, flush=True)
        return _run_child([*snakemake, *arguments], lock.fileno())
    finally:
        lock.close()


def _run_child(command: list[str], lock_fd: int) -> int:
    """Run ``command`` with the launcher's lock descriptor inherited, pass on SIGTERM and SIGHUP, and return its
    exit code (128 + signal number when a signal ended it, as a shell reports it)."""
    child: list[subprocess.Popen] = []

    def forward(signum, _frame):
        if child:
            child[0].send_signal(signum)

    def ignore(_signum, _frame):
        pass

    # Python handlers, not SIG_IGN: an ignored signal stays ignored across exec (Snakemake could then not be
    # interrupted), a handler is reset to the default there.
    previous = {signum: signal.signal(signum, forward) for signum in FORWARDED_SIGNALS}
    previous[signal.SIGINT] = signal.signal(signal.SIGINT, ignore)
    try:
        # Snakemake inherits the lock, so that the directory stays locked while it lives even if the launcher is
        # killed alone.
        child.append(subprocess.Popen(command, pass_fds=(lock_fd,)))
        returncode = child[0].wait()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    return 128 - returncode if returncode < 0 else returncode
