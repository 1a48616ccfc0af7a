"""The cost model measured from LIGGGHTS' own timing lines (``Loop time of ...``) in its log or screen output."""

from __future__ import annotations

import dataclasses
import math
import re

from engines.estimates import CostModel

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
