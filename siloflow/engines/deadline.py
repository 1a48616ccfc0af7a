"""A validation part's deadline: the engine runs of one `make validate GROUP=<part>` stop when the part's time is up,
and the next part resumes them from their restart files (a run longer than a part runs over several,
:class:`siloflow.engines.validation_groups.Part`).

`siloflow run --part-deadline` puts the deadline into the environment of the workflow it launches
(:data:`DEADLINE_VARIABLE`); each run step reads it at the edge (:func:`deadline_from`) and runs its engine
:func:`until` it: at the deadline the step's process gets SIGALRM, which stops the engine
(:func:`siloflow.engines.progress.run_with_progress` terminates its child on any exception) and fails the step with
:class:`PartDeadline`. The engine's restart files stay; the run's earlier attempts' time is counted in its record.
"""

from __future__ import annotations

import math
import signal
import time
from contextlib import contextmanager
from typing import Iterator, Mapping

from siloflow.engines.interface import EngineRunError

__all__ = ["DEADLINE_VARIABLE", "PartDeadline", "deadline_from", "until"]

#: The environment variable that carries a part's deadline to its run steps: seconds since the epoch.
DEADLINE_VARIABLE = "SILOFLOW_PART_DEADLINE"


class PartDeadline(EngineRunError):
    """An engine run stopped (or not started) because its validation part's time is up; the next part resumes it."""


def deadline_from(environment: Mapping[str, str]) -> float | None:
    """The part's deadline in ``environment`` (seconds since the epoch), None where none is set.

    Raises
    ------
    ValueError
        Naming :data:`DEADLINE_VARIABLE` when its value is not a finite number.
    """
    text = environment.get(DEADLINE_VARIABLE)
    if text is None or text == "":
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"environment variable {DEADLINE_VARIABLE}={text!r} is no time (seconds since the epoch)")
    return value


@contextmanager
def until(deadline: float | None, what: str, clock=time.time) -> Iterator[None]:
    """Run the body until ``deadline`` (seconds since the epoch; None: no limit), then raise :class:`PartDeadline`.

    The body is interrupted by SIGALRM, so it must run in the main thread (a Snakemake script's does). A deadline
    already past raises before the body starts.

    Parameters
    ----------
    deadline : float or None
        When the part's time is up (s since the epoch).
    what : str
        The run, for the message.
    clock : callable
        The current time (s since the epoch).
    """
    if deadline is None:
        yield
        return
    left = deadline - clock()
    message = (f"{what}: the validation part's time is up; the run carries on from its restart files with the next "
               "part (make validate GROUP=<the next part>)")
    if left <= 0:
        raise PartDeadline(message)

    def stop(signum, frame):
        raise PartDeadline(message)

    previous = signal.signal(signal.SIGALRM, stop)
    signal.setitimer(signal.ITIMER_REAL, left)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
