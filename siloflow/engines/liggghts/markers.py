"""What the LIGGGHTS log tells the orchestrator beyond the stage markers (:mod:`siloflow.engines.markers`): fatal error lines."""

from __future__ import annotations

__all__ = ["error_lines", "log_excerpt"]


def error_lines(log_text: str) -> list[str]:
    """Lines that report a fatal engine problem (``ERROR``, lost atoms, a crash signal)."""
    patterns = ("ERROR", "Lost atoms", "Segmentation fault", "received signal", "MPI_ABORT")
    return [line.rstrip() for line in log_text.splitlines() if any(p in line for p in patterns)]


def log_excerpt(log_text: str, lines: int = 15) -> str:
    """Error lines if there are any, else the last lines of the log, indented for quoting."""
    selected = error_lines(log_text) or log_text.rstrip().splitlines()[-lines:]
    return "\n".join("    " + line for line in selected[-lines:])
