"""The cost model measured from LIGGGHTS' own timing lines (``Loop time of ...``) in its log or screen output."""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping

from engines.estimates import CostModel
from engines.liggghts.thermo import ThermoProgress

_LOOP_TIME = re.compile(
    r"Loop time of\s+([-+0-9.eE]+)\s+on\s+(\d+)\s+procs\s+for\s+(\d+)\s+steps\s+with\s+(\d+)\s+atoms"
)


def calibrate_cost_model(log_text: str, base: CostModel = CostModel()) -> CostModel:
    """A cost model whose CPU time per sphere-step is measured from a LIGGGHTS log.

    Every line ``Loop time of <seconds> on <procs> procs for <steps> steps with <atoms> atoms`` with
    steps > 0 and atoms > 0 counts: c = sum(seconds * procs) / sum(steps * atoms). LIGGGHTS reports the
    atoms at the end of each ``run``, so a run whose sphere count changes (a filling or draining silo) is
    measured against its final count.

    Parameters
    ----------
    log_text : str
        Text of one or more engine logs or screen outputs (concatenate several runs to average them).
    base : CostModel
        Model whose other values are kept.

    Returns
    -------
    CostModel
        ``base`` with ``seconds_per_sphere_step`` replaced (s).

    Raises
    ------
    ValueError
        When the text holds no such line with steps > 0 and atoms > 0.
    """
    cpu_seconds = 0.0
    sphere_steps = 0
    for match in _LOOP_TIME.finditer(log_text):
        try:
            seconds = float(match.group(1))
        except ValueError:
            continue
        procs, steps, atoms = (int(match.group(i)) for i in (2, 3, 4))
        if steps > 0 and atoms > 0 and math.isfinite(seconds) and seconds >= 0:
            cpu_seconds += seconds * procs
            sphere_steps += steps * atoms
    if sphere_steps == 0 or cpu_seconds <= 0:
        raise ValueError(
            "the log holds no 'Loop time of <s> on <procs> procs for <steps> steps with <atoms> atoms' line "
            "with steps > 0 and atoms > 0; pass the log.liggghts or engine.out of a run that got past its "
            "first stage"
        )
    return dataclasses.replace(base, seconds_per_sphere_step=cpu_seconds / sphere_steps)


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
        Spheres times steps, integrated over the stage's thermo rows by the trapezoid rule (-): a filling or
        draining silo counts the spheres it has at each row, not only at the end.
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
    stage. Thermo rows (under a header ``Step Atoms Time <clumps> ...``) and ``Loop time`` lines count for the
    stage they fall in; sphere-steps integrate the atom count of consecutive rows of one stage.

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
    progress = ThermoProgress()
    stage = stage_after[None]
    seconds: dict[str, float] = {}
    steps: dict[str, int] = {}
    sphere_steps: dict[str, float] = {}
    previous = None  # (stage, step, atoms) of the last thermo row
    for line in log_text.splitlines():
        markers_before = progress.markers_read
        rows = progress.feed(line + "\n")
        if progress.markers_read > markers_before:
            stage = stage_after.get(progress.stage, stage)
            previous = None
        for row in rows:
            if previous is not None and previous[0] == stage and row.step > previous[1]:
                sphere_steps[stage] = sphere_steps.get(stage, 0.0) + 0.5 * (row.atoms + previous[2]) * (row.step - previous[1])
            previous = (stage, row.step, row.atoms)
        match = _LOOP_TIME.search(line)
        if match:
            seconds[stage] = seconds.get(stage, 0.0) + float(match.group(1)) * int(match.group(2))
            steps[stage] = steps.get(stage, 0) + int(match.group(3))
    return {name: StageCost(seconds[name], steps[name], sphere_steps.get(name, 0.0)) for name in seconds}
