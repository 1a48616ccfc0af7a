"""What a YADE run cost: its scripts print, with every stage marker, the CPU time of the process so far
(``cpu_s``, Python's ``time.process_time``) and the sphere-steps it integrated (``sphere_steps``: the clump spheres
it held, summed over the steps, counted afresh at every scheduled stop)."""

from __future__ import annotations

import math
from pathlib import Path

from siloflow.model.cost import MeasuredWork
from siloflow.engines.markers import parse_markers

__all__ = ["elapsed_cpu_seconds", "measured_seconds_per_sphere_step", "measured_work"]


def elapsed_cpu_seconds(logs: list[Path]) -> float:
    """CPU time of a run's attempts up to each one's last timed marker (s), also when an attempt was cut off.

    Each attempt is its own single-threaded process, so its CPU time is its wall time less the waits; the time
    after its last marker is missing. 0 when no attempt reached a timed marker.

    Parameters
    ----------
    logs : list of Path
        The log of each attempt (the first and its resumptions).
    """
    return math.fsum(timed[-1]["cpu_s"] for timed in map(_timed_markers, logs) if timed)


def measured_work(logs: list[Path]) -> MeasuredWork | None:
    """CPU time and sphere-steps of a run over all its attempts.

    Each attempt is its own process, whose counts start from 0: its last marker that carries both ``cpu_s`` and
    ``sphere_steps`` counts, and the attempts add up.

    Parameters
    ----------
    logs : list of Path
        The log of each attempt (the first and its resumptions).

    Returns
    -------
    MeasuredWork or None
        CPU s and sphere-steps; None when no attempt reached a timed marker with sphere-steps (> 0).
    """
    cpu = steps = 0.0
    for path in logs:
        timed = _timed_markers(path, ("cpu_s", "sphere_steps"))
        if timed:
            cpu += timed[-1]["cpu_s"]
            steps += timed[-1]["sphere_steps"]
    return MeasuredWork(cpu, steps) if steps > 0 else None


def _timed_markers(path: Path, keys: tuple[str, ...] = ("cpu_s",)) -> list[dict]:
    """The values of the markers of one attempt's log that carry every one of ``keys`` as a finite number >= 0."""
    return [m.values for m in parse_markers(Path(path).read_text(encoding="utf-8", errors="replace"))
            if all(isinstance(m.values.get(key), float) and math.isfinite(m.values[key]) and m.values[key] >= 0
                   for key in keys)]


def measured_seconds_per_sphere_step(logs: list[Path]) -> float | None:
    """CPU seconds per sphere-step over every attempt of a run (:func:`measured_work`), or None when no attempt
    reached a timed marker."""
    work = measured_work(logs)
    return work.seconds_per_sphere_step if work is not None else None
