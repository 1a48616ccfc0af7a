"""What the LIGGGHTS log tells the orchestrator: stage markers the decks print, and fatal error lines."""

from __future__ import annotations

import re
from dataclasses import dataclass


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


def error_lines(log_text: str) -> list[str]:
    """Lines that report a fatal engine problem (``ERROR``, lost atoms, a crash signal)."""
    patterns = ("ERROR", "Lost atoms", "Segmentation fault", "received signal", "MPI_ABORT")
    return [line.rstrip() for line in log_text.splitlines() if any(p in line for p in patterns)]


def log_excerpt(log_text: str, lines: int = 15) -> str:
    """Error lines if there are any, else the last lines of the log, indented for quoting."""
    selected = error_lines(log_text) or log_text.rstrip().splitlines()[-lines:]
    return "\n".join("    " + line for line in selected[-lines:])
