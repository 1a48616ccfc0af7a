"""Stage markers: the ``SILOFLOW <event> key=value ...`` lines every engine's inputs print at a stage boundary, which
the orchestrator reads back to check what a run did (siloflow's own format, the same for every engine)."""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["Marker", "parse_markers"]


@dataclass(frozen=True)
class Marker:
    """A ``SILOFLOW <event> key=value ...`` line the deck prints at a stage boundary."""

    event: str
    values: dict


_MARKER = re.compile(r"^SILOFLOW (\w+)((?: \w+=\S+)*)\s*$")


def parse_markers(log_text: str) -> list[Marker]:
    """Stage markers in the order the engine printed them (echoed ``print`` commands are skipped)."""
    markers = []
    for line in log_text.splitlines():
        match = _MARKER.match(line.strip())
        if not match:
            continue
        values = {}
        for item in match.group(2).split():
            key, _, raw = item.partition("=")
            try:
                values[key] = float(raw)
            except ValueError:
                values[key] = raw
        markers.append(Marker(match.group(1), values))
    return markers


def without_redone(markers: list[Marker]) -> list[Marker]:
    """The markers of a run's attempts joined, in order, without those a later attempt made again.

    An attempt resumed from a restart file at step R prints a ``resumed`` marker at R: the markers that the attempts
    before it printed after step R belong to steps it runs again, and its own replace them. Markers without a step
    are kept.
    """
    def step(marker: Marker) -> float | None:
        value = marker.values.get("step")
        return value if isinstance(value, float) else None

    kept: list[Marker] = []
    for marker in markers:
        if marker.event == "resumed" and step(marker) is not None:
            kept = [m for m in kept if step(m) is None or step(m) <= step(marker)]
        kept.append(marker)
    return kept
