"""Progress of a running simulation, whatever the engine: the progress line and the monitor that reports it.

An engine's own parser reads its screen output (it knows the format); this module only needs from it the latest
sample (simulated time and clump count, :class:`Sample`) and the current stage name, through the small
:class:`ScreenParser` protocol. :class:`ProgressMonitor` follows the growing screen-output file, feeds it to the
parser and reports :class:`Progress` lines to the rule's log and, when given one, to the terminal.

Several runs may share one terminal: Snakemake starts each ``script:`` job as a ``python`` subprocess that inherits
Snakemake's stderr, so two engine runs at once write to the same terminal. A progress line is therefore never
rewritten in place (two jobs rewriting one line leave neither legible): every report is one complete line that
names its run, written with a single ``write`` call ending in a newline, at most once per reporting interval plus
once at the end. Python's ``sys.__stderr__`` is write-through (one ``write`` is one ``write(2)`` system call), and
the kernel keeps one such call whole: a pipe write of at most ``PIPE_BUF`` (4096) bytes is atomic, and the tty
driver serialises writers per call. So lines of parallel jobs may alternate but never mix within a line.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import signal
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable, Iterator, Protocol, TextIO

from siloflow.engines.estimates import format_duration


class Sample(Protocol):
    """What progress needs from one line of an engine's output.

    Attributes
    ----------
    time : float
        Simulated time since the start of the run (s).
    clumps : float or None
        Clumps in the simulation (-); None when the engine does not report them.
    """

    @property
    def time(self) -> float: ...

    @property
    def clumps(self) -> float | None: ...


class ScreenParser(Protocol):
    """Incremental parser of an engine's screen output, as :class:`ProgressMonitor` drives it.

    ``feed`` takes text in chunks of any size (a chunk may end inside a line), ``flush`` reads an unfinished last
    line as complete; ``latest`` is the last :class:`Sample` read (None before the first) and ``stage`` the name of
    the current stage (None before the first stage marker).
    """

    def feed(self, text: str) -> list: ...

    def flush(self) -> list: ...

    @property
    def latest(self) -> Sample | None: ...

    @property
    def stage(self) -> str | None: ...


@dataclass(frozen=True)
class Progress:
    """How far a run has come and when it will end.

    Attributes
    ----------
    simulated_time_s : float
        Simulated time reached (s).
    target_time_s : float
        Simulated time at the end of the run (s).
    fraction : float
        ``simulated / target`` clipped to [0, 1] (-).
    elapsed_wall_s : float
        Wall time since the run started (s).
    eta_s : float or None
        Wall time still to go, ``elapsed (1 - fraction) / fraction`` (s); None before any progress.
    clumps : float or None
        Clumps in the latest sample (-); None before the first.
    stage : str or None
        Stage name to show.
    run_id : str or None
        Run to name.
    """

    simulated_time_s: float
    target_time_s: float
    fraction: float
    elapsed_wall_s: float
    eta_s: float | None
    clumps: float | None = None
    stage: str | None = None
    run_id: str | None = None

    def __str__(self) -> str:
        """One line: ``run <id>: 0.42 / 1.20 s simulated (35 %), 5,168 clumps, stage settle, elapsed 3 min,
        ETA 5.6 min``; the run, clumps and stage parts only when known."""
        decimals = max(2, 2 - math.floor(math.log10(self.target_time_s)))
        parts = [
            f"{self.simulated_time_s:.{decimals}f} / {self.target_time_s:.{decimals}f} s simulated "
            f"({100.0 * self.fraction:.0f} %)"
        ]
        if self.clumps is not None:
            parts.append(f"{round(self.clumps):,} clumps")
        if self.stage is not None:
            parts.append(f"stage {self.stage}")
        parts.append(f"elapsed {format_duration(self.elapsed_wall_s)}")
        parts.append(f"ETA {format_duration(self.eta_s)}" if self.eta_s is not None else "ETA unknown")
        line = ", ".join(parts)
        return f"run {self.run_id}: {line}" if self.run_id is not None else line


def progress_report(
    latest: Sample | None,
    target_time: float,
    elapsed_wall_s: float,
    stage: str | None = None,
    run_id: str | None = None,
) -> Progress:
    """Fraction done and time to go, extrapolated linearly in simulated time.

    Parameters
    ----------
    latest : Sample or None
        Latest sample of the engine's output (:attr:`ScreenParser.latest`): its simulated time (s) and clump
        count (-); None before the first.
    target_time : float
        Simulated time at the end of the run (s, > 0), e.g. ``RunEstimate.simulated_time_s`` (a worst case:
        a fill that settles early ends the run sooner).
    elapsed_wall_s : float
        Wall time since the run started (s, >= 0).
    stage : str, optional
        Stage to show (:attr:`ScreenParser.stage`).
    run_id : str, optional
        Run to name.

    Returns
    -------
    Progress
        fraction = time / target clipped to [0, 1]; ETA = elapsed (1 - fraction) / fraction (s), None while the
        fraction is 0. Stages do not all cost the same per simulated second, so the ETA is a rough guide.

    Raises
    ------
    ValueError
        When ``target_time`` is not a finite number > 0 or ``elapsed_wall_s`` not a finite number >= 0.
    """
    if not (isinstance(target_time, (int, float)) and math.isfinite(target_time) and target_time > 0):
        raise ValueError(f"target_time must be a finite number > 0 s, got {target_time!r}")
    if not (isinstance(elapsed_wall_s, (int, float)) and math.isfinite(elapsed_wall_s) and elapsed_wall_s >= 0):
        raise ValueError(f"elapsed_wall_s must be a finite number >= 0 s, got {elapsed_wall_s!r}")
    simulated = latest.time if latest is not None else 0.0
    fraction = min(max(simulated / target_time, 0.0), 1.0)
    eta = elapsed_wall_s * (1.0 - fraction) / fraction if fraction > 0 else None
    return Progress(
        simulated_time_s=simulated,
        target_time_s=float(target_time),
        fraction=fraction,
        elapsed_wall_s=float(elapsed_wall_s),
        eta_s=eta,
        clumps=latest.clumps if latest is not None else None,
        stage=stage,
        run_id=run_id,
    )


class ProgressMonitor:
    """Follows a running engine's growing screen output and reports its progress.

    Every ``report_every`` seconds of wall time, and once more at :meth:`finish`, a progress line
    (:class:`Progress`) goes to ``logger`` (the rule's log) and, when ``terminal`` is given, to the terminal as
    one whole line naming the run (see the module docstring for why it is never rewritten in place). The ETA is
    extrapolated from the rate since the first sample this monitor saw, so a run resumed from a restart estimates
    from its own pace.

    Parameters
    ----------
    screen_path : path-like
        The engine's screen output file, read from where the last poll stopped; a file that does not exist yet
        reads as empty.
    parser : ScreenParser
        The engine's parser of that output (a fresh one: the monitor feeds it from the start of the file).
    target_time : float
        Simulated time at the end of the run (s, > 0).
    run_id : str, optional
        Run to name in the lines.
    report_every : float
        Wall time between reported lines (s, > 0).
    logger : logging.Logger, optional
        Where the lines are logged (level INFO, prefixed ``progress: ``).
    terminal : text stream, optional
        Where the lines are also written (the job's terminal); None writes none.
    clock : callable, optional
        Wall clock in seconds (s); :func:`time.monotonic` unless given (tests pass a fake one).

    Raises
    ------
    ValueError
        When ``target_time`` or ``report_every`` is not a finite number > 0.
    """

    def __init__(self, screen_path: str | os.PathLike, parser: ScreenParser, target_time: float,
                 run_id: str | None = None, report_every: float = 30.0, logger=None, terminal: TextIO | None = None,
                 clock: Callable[[], float] | None = None):
        for name, value in (("target_time", target_time), ("report_every", report_every)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0 s, got {value!r}")
        self._path = screen_path
        self._parser = parser
        self._target = float(target_time)
        self._run_id = run_id
        self._report_every = float(report_every)
        self._logger = logger
        self._terminal = terminal
        self._clock = clock or time.monotonic
        self._started = self._clock()
        self._last_report = self._started
        self._offset = 0
        self._first: tuple[float, float] | None = None  # (wall, simulated) of the first sample seen

    def _read(self) -> None:
        try:
            with open(self._path, "rb") as handle:
                handle.seek(self._offset)
                chunk = handle.read()
        except FileNotFoundError:
            return
        self._offset += len(chunk)
        # bytes are decoded per chunk: a character cut at a chunk boundary becomes U+FFFD, harmless in numbers
        self._parser.feed(chunk.decode("utf-8", errors="replace"))

    def progress(self) -> Progress:
        """Progress as of the last poll.

        Returns
        -------
        Progress
            With the ETA (s) from the simulated-time rate since the first sample this monitor saw, once the
            simulated time has moved on from it.
        """
        now = self._clock()
        latest = self._parser.latest
        report = progress_report(latest, self._target, now - self._started, self._parser.stage, self._run_id)
        if latest is not None and self._first is None:
            self._first = (now, latest.time)
        if latest is not None and self._first is not None and latest.time > self._first[1]:
            rate = (latest.time - self._first[1]) / max(now - self._first[0], 1e-9)
            eta = max(self._target - latest.time, 0.0) / rate
            report = dataclasses.replace(report, eta_s=eta)
        return report

    def _report(self, report: Progress) -> None:
        if self._logger is not None:
            self._logger.info("progress: %s", report)
        if self._terminal is not None:
            # one write of one whole line: lines of runs sharing the terminal never mix
            self._terminal.write(f"{report}\n")
            self._terminal.flush()

    def poll(self) -> Progress:
        """Read what the engine printed since the last poll; report the progress when a report is due.

        Returns
        -------
        Progress
            Progress as of this poll, reported or not.
        """
        self._read()
        report = self.progress()
        now = self._clock()
        if now - self._last_report >= self._report_every:
            self._report(report)
            self._last_report = now
        return report

    def finish(self) -> Progress:
        """Last poll (whatever remains, including a last line without a newline), always reported.

        Returns
        -------
        Progress
            Progress at the end of the run.
        """
        self._read()
        self._parser.flush()
        report = self.progress()
        self._report(report)
        self._last_report = self._clock()
        return report


#: How long a stopped engine gets to exit after SIGTERM before it is killed (s).
STOP_GRACE_S = 30.0


def stop_process(process: subprocess.Popen, grace: float = STOP_GRACE_S) -> int:
    """Stop a child process: SIGTERM (mpirun passes it on to its ranks), then SIGKILL after ``grace`` seconds;
    returns its exit code."""
    process.terminate()
    try:
        return process.wait(timeout=grace)
    except subprocess.TimeoutExpired:
        process.kill()
        return process.wait()


class Terminated(Exception):
    """The run step was told to stop (SIGTERM or SIGHUP: a killed job, a cancelled batch job) while its engine ran."""


@contextmanager
def _stop_signals_raise() -> Iterator[None]:
    """While the body runs, SIGTERM and SIGHUP raise :class:`Terminated` instead of ending the process at once, so
    that :func:`run_with_progress` stops its engine first rather than leaving it running without its job (as a
    process ended by the signal's default action would). Signal handlers belong to the main thread: elsewhere the
    body runs as is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        raise Terminated(f"stopped by {signal.Signals(signum).name}")

    previous = {signum: signal.signal(signum, stop) for signum in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def run_with_progress(command: list[str], run_dir: str | os.PathLike, output_path: str | os.PathLike,
                      environment: dict, parser: ScreenParser, target_time: float | None, report_every: float,
                      poll_every: float = 1.0) -> int:
    """Run ``command`` in ``run_dir`` with its output (stdout and stderr) written to ``output_path``, and return its
    exit code. With ``target_time`` [s of simulated time] a :class:`ProgressMonitor` reads the output with
    ``parser`` every ``poll_every`` s and reports every ``report_every`` s, in the log and, when the job's stderr is
    a terminal, as one line naming the run there. No shell is involved and stdin is closed. An exception while it
    runs (a part's deadline, :mod:`siloflow.engines.deadline`; an interrupt; SIGTERM or SIGHUP to the step, which
    raise :class:`Terminated`) stops the command first."""
    terminal = sys.__stderr__ if sys.__stderr__ is not None and sys.__stderr__.isatty() else None
    monitor = (ProgressMonitor(output_path, parser, target_time, os.path.basename(os.fspath(run_dir)), report_every,
                               logging.getLogger("siloflow"), terminal) if target_time else None)
    with open(output_path, "w", encoding="utf-8") as output:
        process = subprocess.Popen(command, cwd=run_dir, stdout=output, stderr=subprocess.STDOUT, env=environment,
                                   stdin=subprocess.DEVNULL)
        try:
            with _stop_signals_raise():
                while True:
                    try:
                        returncode = process.wait(timeout=poll_every)
                        break
                    except subprocess.TimeoutExpired:
                        if monitor is not None:
                            output.flush()
                            monitor.poll()
        except BaseException:
            # interrupted (a part's deadline, Ctrl-C, SIGTERM): the engine must not run on without its job
            stop_process(process)
            raise
    if monitor is not None:
        monitor.finish()
    return returncode
