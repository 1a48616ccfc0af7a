"""Progress of a YADE script from its output: the ``SILOFLOW progress`` lines (simulated time, clumps, stage) and
the stage markers, for :class:`siloflow.engines.progress.ProgressMonitor`."""

from __future__ import annotations

from dataclasses import dataclass

from siloflow.engines.markers import parse_markers

__all__ = ["ProgressSample", "ScriptProgress"]


@dataclass(frozen=True)
class ProgressSample:
    """One progress line: simulated time [s] and clumps in the simulation."""

    time: float
    clumps: float | None


class ScriptProgress:
    """Incremental parser of a script's output (chunks may end inside a line)."""

    def __init__(self) -> None:
        self._partial = ""
        self._latest: ProgressSample | None = None
        self._stage: str | None = None

    @property
    def latest(self) -> ProgressSample | None:
        return self._latest

    @property
    def stage(self) -> str | None:
        """The stage of the last progress line, or the event of the last stage marker after it."""
        return self._stage

    def feed(self, text: str) -> list[ProgressSample]:
        if not isinstance(text, str):
            raise ValueError(f"feed() takes the script output as str, got {type(text).__name__}")
        lines = (self._partial + text).split("\n")
        self._partial = lines.pop()
        return self._read("\n".join(lines))

    def flush(self) -> list[ProgressSample]:
        partial, self._partial = self._partial, ""
        return self._read(partial)

    def _read(self, text: str) -> list[ProgressSample]:
        samples = []
        for marker in parse_markers(text):
            if marker.event != "progress":
                self._stage = marker.event
                continue
            values = marker.values
            if isinstance(values.get("time"), float):
                clumps = values.get("clumps")
                self._latest = ProgressSample(values["time"], clumps if isinstance(clumps, float) else None)
                samples.append(self._latest)
                if isinstance(values.get("stage"), str):
                    self._stage = values["stage"]
        return samples
