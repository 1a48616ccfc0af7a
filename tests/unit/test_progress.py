"""Progress of a running simulation, whatever the engine: the progress line and the monitor that reports it.

The monitor is driven here by LIGGGHTS' thermo parser on screen output written as LIGGGHTS writes it.
"""

from __future__ import annotations

import io
import itertools
import logging
import os
import re
import threading

import pytest

from siloflow.engines.liggghts.thermo import ThermoProgress, ThermoRow
from siloflow.engines.progress import Progress, ProgressMonitor, progress_report

HEADER = "Step Atoms Time n_clumps ke_per_c CPU\n"


class _Collect(logging.Handler):
    """Keeps the messages of the records it handles."""

    def __init__(self) -> None:
        super().__init__()
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


class _Writes(io.StringIO):
    """A text stream that also keeps the text of every ``write`` call."""

    def __init__(self) -> None:
        super().__init__()
        self.calls: list[str] = []

    def write(self, text: str) -> int:
        self.calls.append(text)
        return super().write(text)


def _logger(name: str) -> tuple[logging.Logger, _Collect]:
    logger = logging.getLogger(name)
    collect = _Collect()
    logger.addHandler(collect)
    logger.setLevel(logging.INFO)
    return logger, collect


def _row(time: float, clumps: float = 5168.0) -> ThermoRow:
    return ThermoRow(step=1000, atoms=2 * int(clumps), time=time, clumps=clumps, ke_per_clump=1e-9, cpu=1.0)


def test_progress_line_as_documented():
    progress = progress_report(_row(0.42), 1.2, 180.0, stage="settle", run_id="sphere2-abc")
    assert progress.fraction == pytest.approx(0.35, rel=1e-12)
    assert progress.eta_s == pytest.approx(180.0 * 0.65 / 0.35, rel=1e-12)
    assert str(progress) == (
        "run sphere2-abc: 0.42 / 1.20 s simulated (35 %), 5,168 clumps, stage settle, elapsed 3 min, ETA 5.6 min"
    )


def test_fraction_and_eta_exact():
    progress = progress_report(_row(0.5), 2.0, 60.0)
    assert progress == Progress(simulated_time_s=0.5, target_time_s=2.0, fraction=0.25, elapsed_wall_s=60.0,
                                eta_s=180.0, clumps=5168.0, stage=None, run_id=None)
    assert str(progress) == "0.50 / 2.00 s simulated (25 %), 5,168 clumps, elapsed 1 min, ETA 3 min"


def test_progress_is_clipped_at_the_target():
    progress = progress_report(_row(2.5), 2.0, 100.0)
    assert (progress.fraction, progress.eta_s) == (1.0, 0.0)
    assert str(progress).endswith("(100 %), 5,168 clumps, elapsed 1.7 min, ETA 0 s")


def test_no_eta_before_any_progress():
    before_first_row = progress_report(None, 1.2, 5.0, stage="fill", run_id="r")
    assert (before_first_row.fraction, before_first_row.eta_s, before_first_row.clumps) == (0.0, None, None)
    assert str(before_first_row) == "run r: 0.00 / 1.20 s simulated (0 %), stage fill, elapsed 5 s, ETA unknown"
    at_time_zero = progress_report(_row(0.0, 0.0), 1.2, 5.0)
    assert at_time_zero.eta_s is None
    assert str(at_time_zero) == "0.00 / 1.20 s simulated (0 %), 0 clumps, elapsed 5 s, ETA unknown"


def test_short_targets_get_more_decimals():
    assert str(progress_report(_row(0.0125, 331.0), 0.05, 30.0)).startswith(
        "0.0125 / 0.0500 s simulated (25 %), 331 clumps"
    )


@pytest.mark.parametrize("target, elapsed, message", [(0.0, 1.0, "target_time"), (float("nan"), 1.0, "target_time"),
                                                      (1.0, -1.0, "elapsed_wall_s")])
def test_progress_report_refuses_impossible_input(target, elapsed, message):
    with pytest.raises(ValueError, match=message):
        progress_report(None, target, elapsed)


def test_monitor_follows_a_growing_screen_output_logs_and_writes_whole_lines_when_due(tmp_path):
    screen = tmp_path / "engine.out"
    screen.write_text(HEADER)
    now = [0.0]
    logger, collect = _logger("test_progress_monitor")
    records = collect.messages
    terminal = io.StringIO()
    monitor = ProgressMonitor(screen, ThermoProgress(), target_time=2.0, run_id="r1", report_every=30.0, logger=logger,
                              terminal=terminal, clock=lambda: now[0])
    with open(screen, "a") as handle:
        handle.write("100 200 0.5 100 1e-6 1.0\n")
    now[0] = 10.0
    first = monitor.poll()
    assert first.simulated_time_s == 0.5 and first.fraction == 0.25 and records == []  # not due yet
    assert terminal.getvalue() == ""  # nor on the terminal
    with open(screen, "a") as handle:
        handle.write("200 200 1.0 100 1e-6 2.0\nSILOFLOW opened step=200 time=1.0 clumps=100 ke_per_clump=1e-6\n")
    now[0] = 40.0
    second = monitor.poll()
    # 0.5 s simulated in the 30 s since the first row: 1.0 s to go takes 60 s
    assert second.eta_s == pytest.approx(60.0) and second.stage == "opened"
    assert len(records) == 1 and records[0].startswith("progress: run r1: ")
    # replaces the old count of "\r" (the line rewritten in place at every poll): one whole line, when due
    assert terminal.getvalue() == f"{second}\n" and records[0] == f"progress: {second}"
    final = monitor.finish()
    assert final.fraction == 0.5 and terminal.getvalue().endswith("\n") and len(records) == 2
    assert terminal.getvalue() == f"{second}\n{final}\n"


def test_monitor_reports_at_most_once_per_interval_and_at_the_end(tmp_path):
    screen = tmp_path / "engine.out"
    screen.write_text(HEADER)
    now = [0.0]
    logger, collect = _logger("test_progress_monitor_rate")
    terminal = _Writes()
    monitor = ProgressMonitor(screen, ThermoProgress(), 1.0, "r1", report_every=30.0, logger=logger,
                              terminal=terminal, clock=lambda: now[0])
    due = []
    for second in range(1, 96):  # polled every second for 95 s, the engine printing a row each second
        with open(screen, "a") as handle:
            handle.write(f"{second} 10 {second / 100} 5 1e-9 {second}\n")
        now[0] = float(second)
        report = monitor.poll()
        if second % 30 == 0:
            due.append(report)
    now[0] = 95.5
    due.append(monitor.finish())
    assert [report.elapsed_wall_s for report in due] == [30.0, 60.0, 90.0, 95.5]
    assert terminal.calls == [f"{report}\n" for report in due]
    assert collect.messages == [f"progress: {report}" for report in due]


def test_each_report_is_one_write_of_one_line_without_control_characters(tmp_path):
    screen = tmp_path / "engine.out"
    screen.write_text(HEADER + "10 20 0.25 10 1e-9 0.5\n"
                      "SILOFLOW settle step=10 time=0.25 clumps=10 ke_per_clump=1e-9\n")
    now = [0.0]
    terminal = _Writes()
    monitor = ProgressMonitor(screen, ThermoProgress(), 1.0, "sphere2-ab12", report_every=5.0, terminal=terminal,
                              clock=lambda: now[0])
    for second in range(1, 21):
        now[0] = float(second)
        monitor.poll()
    monitor.finish()
    assert len(terminal.calls) == 5  # at 5, 10, 15 and 20 s, and at the end
    for text in terminal.calls:
        assert text.startswith("run sphere2-ab12: 0.25 / 1.00 s simulated (25 %), 10 clumps, stage settle, elapsed ")
        assert text.endswith("\n") and text.count("\n") == 1
        assert not re.search(r"[\x00-\x09\x0b-\x1f\x7f]", text), repr(text)


def test_two_runs_sharing_one_pipe_write_only_whole_lines_each_naming_its_run(tmp_path):
    """Two monitors at once on one pipe, each through its own write-through stream as a job's ``sys.__stderr__``
    is: the lines they write never mix."""
    read_end, write_end = os.pipe()
    polls = 40
    runs = ("silo_flat-0a1b2c3d4e", "sphere2-ab12")
    streams, monitors = [], []
    for number, run_id in enumerate(runs):
        screen = tmp_path / f"engine{number}.out"
        screen.write_text(HEADER + "".join(f"{step} 10 {step / polls} 5 1e-9 {step}\n" for step in range(1, polls)))
        stream = io.TextIOWrapper(io.FileIO(os.dup(write_end), "w"), encoding="utf-8", write_through=True)
        ticks = itertools.count()
        streams.append(stream)
        monitors.append(ProgressMonitor(screen, ThermoProgress(), 1.0, run_id, report_every=1.0, terminal=stream,
                                        clock=lambda ticks=ticks: float(next(ticks))))
    os.close(write_end)

    failures = []

    def follow(monitor: ProgressMonitor) -> None:
        try:
            for _ in range(polls):
                monitor.poll()
            monitor.finish()
        except Exception as error:  # a thread's exception does not fail the test by itself
            failures.append(error)

    threads = [threading.Thread(target=follow, args=(monitor,)) for monitor in monitors]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for stream in streams:
        stream.close()
    assert failures == []
    chunks = []
    while chunk := os.read(read_end, 65536):
        chunks.append(chunk)
    os.close(read_end)
    lines = b"".join(chunks).decode("utf-8").split("\n")
    assert lines.pop() == ""  # the output ends with a whole line
    whole = re.compile(r"^run (\S+): \d\.\d\d / 1\.00 s simulated \(\d+ %\), 5 clumps, elapsed [^,]+, ETA [^,]+$")
    assert all(whole.match(line) for line in lines), [line for line in lines if not whole.match(line)]
    # every poll is due (the fake clock ticks 1 s per reading, a report is due every 1 s) and the end is reported
    assert sorted(whole.match(line).group(1) for line in lines) == sorted(runs * (polls + 1))


@pytest.mark.parametrize("target, every, message", [(0.0, 30.0, "target_time"), (1.0, 0.0, "report_every"),
                                                    (1.0, float("inf"), "report_every")])
def test_monitor_refuses_impossible_settings(tmp_path, target, every, message):
    with pytest.raises(ValueError, match=message):
        ProgressMonitor(tmp_path / "engine.out", ThermoProgress(), target, report_every=every)


def test_monitor_of_output_not_yet_written_reports_no_progress(tmp_path):
    now = [0.0]
    monitor = ProgressMonitor(tmp_path / "engine.out", ThermoProgress(), 2.0, "r", clock=lambda: now[0])
    now[0] = 3.0
    report = monitor.poll()
    assert (report.simulated_time_s, report.fraction, report.eta_s, report.elapsed_wall_s) == (0.0, 0.0, None, 3.0)
