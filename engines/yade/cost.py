"""What a YADE run cost: its scripts print, with every stage marker, the CPU time of the process so far
(``cpu_s``, Python's ``time.process_time``) and the sphere-steps it integrated (``sphere_steps``)."""

from __future__ import annotations

from pathlib import Path

from engines.markers import parse_markers

__all__ = ["measured_seconds_per_sphere_step"]


def measured_seconds_per_sphere_step(logs: list[Path]) -> float | None:
    """CPU seconds per sphere and time step over every attempt of a run (each attempt's last marker counts), or
    None when no attempt reached a stage marker."""
    cpu = steps = 0.0
    for path in logs:
        timed = [m.values for m in parse_markers(Path(path).read_text(encoding="utf-8", errors="replace"))
                 if isinstance(m.values.get("cpu_s"), float) and isinstance(m.values.get("sphere_steps"), float)]
        if timed:
            cpu += timed[-1]["cpu_s"]
            steps += timed[-1]["sphere_steps"]
    return cpu / steps if steps > 0 else None
