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
