"""The cost of a LIGGGHTS run, measured from its log or screen output: the CPU time of each ``run`` command (its
``Loop time of ...`` line) against the sphere-steps it made, integrated over its thermo rows."""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable, Iterator, Mapping

from siloflow.model.cost import CostModel, MeasuredWork
from siloflow.engines.liggghts.thermo import ThermoProgress

__all__ = ["StageCost", "TimedRun", "calibrate_cost_model", "elapsed_seconds", "measured_work", "stage_costs", "timed_runs"]

_LOOP_TIME = re.compile(
    r"Loop time of\s+([-+0-9.eE]+)\s+on\s+(\d+)\s+procs\s+for\s+(\d+)\s+steps\s+with\s+(\d+)\s+atoms"
)


@dataclasses.dataclass(frozen=True)
class TimedRun:
    """One ``run`` command that finished: its CPU time and the work it did.

    Attributes
    ----------
    events : tuple of str
        Events of the ``SILOFLOW`` markers printed since the previous timed run (or the start), in order.
    cpu_seconds : float
        Loop time times the process count (CPU s).
    steps : int
        Time steps it made (-).
    sphere_steps : float
        Atoms summed over its steps (sphere-steps): the trapezoid rule over its thermo rows, and the atom count
        of its ``Loop time`` line for any steps the rows do not span.
    """

    events: tuple[str, ...]
    cpu_seconds: float
    steps: int
    sphere_steps: float


def timed_runs(log_text: str) -> Iterator[TimedRun]:
    """The ``run`` commands of one LIGGGHTS log or screen output that printed their ``Loop time`` line, in order.

    LIGGGHTS prints a thermo row at the first and the last step of every ``run`` and every ``thermo`` steps in
    between, then ``Loop time of <s> on <procs> procs for <steps> steps with <atoms> atoms``; the atom count of that
    line is the count at the end only, which a pour (from 0 up) or a draining silo does not hold. So each run's
    sphere-steps integrate its rows, ``sum (a_i + a_{i+1}) / 2 (s_{i+1} - s_i)``, exact while the count changes
    linearly between rows. Steps its rows do not span (a run without rows) count at the line's atoms. Rows not
    followed by a ``Loop time`` line (a run cut off by a failure) count for nothing, as their CPU time is unknown;
    a row whose step goes back (a resumed attempt in the same text) starts over.

    Parameters
    ----------
    log_text : str
        The text of one attempt's log or screen output.

    Yields
    ------
    TimedRun
        One per ``Loop time`` line whose time parses as a finite number >= 0.
    """
    progress = ThermoProgress()
    first = last = None  # (step, atoms) of the current run's first and last thermo rows
    integral = 0.0
    events: list[str] = []
    for line in log_text.splitlines():
        markers = progress.markers_read
        for row in progress.feed(line + "\n"):
            if last is None or row.step < last[0]:
                first, integral = (row.step, row.atoms), 0.0
            else:
                integral += 0.5 * (row.atoms + last[1]) * (row.step - last[0])
            last = (row.step, row.atoms)
        if progress.markers_read > markers:
            events.append(progress.stage)
        match = _LOOP_TIME.search(line)
        if not match:
            continue
        try:
            seconds = float(match.group(1))
        except ValueError:  # the pattern also takes a garbled number such as 1.2.3
            seconds = math.nan
        procs, steps, atoms = (int(match.group(i)) for i in (2, 3, 4))
        if math.isfinite(seconds) and seconds >= 0:
            spanned = last[0] - first[0] if last is not None else 0
            yield TimedRun(tuple(events), seconds * procs, steps, integral + max(0, steps - spanned) * atoms)
            events = []
        first = last = None
        integral = 0.0


def elapsed_seconds(log_text: str) -> float:
    """Wall time the ``run`` commands of one attempt's log took (s), also when the attempt was cut off.

    A ``run`` that finished counts its ``Loop time`` (the wall time LIGGGHTS measures for it); a ``run`` cut off
    before its ``Loop time`` line (a killed attempt) counts the ``cpu`` column of its last thermo row, the wall time
    since that ``run`` began, so the time after its last row is missing. The set-up between runs (reading the data,
    building the neighbour lists) is not timed by LIGGGHTS and is not counted.

    Parameters
    ----------
    log_text : str
        The text of one attempt's log or screen output (decks whose thermo rows carry ``cpu``).

    Returns
    -------
    float
        Seconds; 0 for a log with no timed run.
    """
    progress = ThermoProgress()
    total = unfinished = 0.0
    for line in log_text.splitlines():
        for row in progress.feed(line + "\n"):
            if row.cpu is not None and math.isfinite(row.cpu):
                unfinished = row.cpu
        match = _LOOP_TIME.search(line)
        if match:
            try:
                seconds = float(match.group(1))
            except ValueError:  # a garbled number: the run's last row is the best left
                seconds = unfinished
            total += seconds if math.isfinite(seconds) and seconds >= 0 else unfinished
            unfinished = 0.0
    return total + unfinished


def measured_work(log_texts: Iterable[str]) -> MeasuredWork | None:
    """CPU time and sphere-steps of a run over all its attempts (:func:`timed_runs` of each).

    Parameters
    ----------
    log_texts : iterable of str
        The log or screen output of each attempt (the first and its resumptions), one text each.

    Returns
    -------
    MeasuredWork or None
        The sums (CPU s, sphere-steps); None when no ``run`` finished with sphere-steps and CPU time (> 0).
    """
    cpu = work = 0.0
    for text in log_texts:
        for run in timed_runs(text):
            cpu += run.cpu_seconds
            work += run.sphere_steps
    if cpu <= 0 or work <= 0:
        return None
    return MeasuredWork(cpu, work)


def calibrate_cost_model(log_text: str, base: CostModel = CostModel()) -> CostModel:
    """A cost model whose CPU time per sphere-step is measured from a LIGGGHTS log.

    c = sum(loop seconds * procs) / sum(sphere-steps) over its ``run`` commands, the sphere-steps integrated over
    the thermo rows of each (:func:`timed_runs`): a filling or draining silo counts the atoms it holds at each row,
    not those it ends with.

    Parameters
    ----------
    log_text : str
        Text of one engine log or screen output.
    base : CostModel
        Model whose other values are kept.

    Returns
    -------
    CostModel
        ``base`` with ``seconds_per_sphere_step`` replaced (s).

    Raises
    ------
    ValueError
        When the text holds no ``Loop time`` line of a run with steps and atoms (> 0).
    """
    work = measured_work([log_text])
    if work is None:
        raise ValueError(
            "the log holds no 'Loop time of <s> on <procs> procs for <steps> steps with <atoms> atoms' line "
            "of a run with steps and atoms; pass the log.liggghts or engine.out of a run that got past its "
            "first stage"
        )
    return dataclasses.replace(base, seconds_per_sphere_step=work.seconds_per_sphere_step)


@dataclasses.dataclass(frozen=True)
class StageCost:
    """CPU time and work of one stage of a run, from its log.

    Attributes
    ----------
    seconds : float
        Sum of the stage's ``Loop time`` lines times their process counts (CPU s).
    steps : int
        Time steps the stage's ``run`` commands made (-).
    sphere_steps : float
        Atoms summed over the stage's steps, integrated over its thermo rows (:func:`timed_runs`) (-): a filling
        or draining silo counts the spheres it has at each row, not only at the end.
    """

    seconds: float
    steps: int
    sphere_steps: float

    @property
    def sphere_steps_per_second(self) -> float:
        """Throughput (sphere-steps per CPU second); nan for a stage without measured time."""
        return self.sphere_steps / self.seconds if self.seconds > 0 else math.nan


def stage_costs(log_text: str, stage_after: Mapping[str | None, str]) -> dict[str, StageCost]:
    """CPU time, steps and sphere-steps of each stage of a LIGGGHTS run, from its log or screen output.

    The stage changes at each ``SILOFLOW <event>`` marker: ``stage_after[event]`` names the stage that follows
    it (``stage_after[None]`` the one before the first marker); an event missing from the mapping keeps the
    stage. Each ``run`` (:func:`timed_runs`) counts for the stage it ran in.

    Parameters
    ----------
    log_text : str
        The engine's log or screen output.
    stage_after : mapping of str or None to str
        Stage that follows each marker event (and None: the first stage).

    Returns
    -------
    dict of str to StageCost
        One entry per stage that had a ``Loop time`` line, in the order the stages came.
    """
    stage = stage_after[None]
    costs: dict[str, StageCost] = {}
    for run in timed_runs(log_text):
        for event in run.events:
            stage = stage_after.get(event, stage)
        cost = costs.get(stage, StageCost(0.0, 0, 0.0))
        costs[stage] = StageCost(cost.seconds + run.cpu_seconds, cost.steps + run.steps,
                                 cost.sphere_steps + run.sphere_steps)
    return costs
