"""Progress of a running simulation, from the engine's screen output.

Pure computation: :class:`ThermoProgress` is fed the text the engine prints (``engine.out``), in chunks as it
grows; the caller reads the file. The thermo block of every ``run`` starts with a header line (the decks'
``thermo_style custom step atoms time v_n_clumps v_ke_per_clump [extra columns] cpu``) and ends with the
``Loop time of ...`` line. LIGGGHTS 3.8 writes the header with the variable names cut to 8 characters and
without their ``v_`` prefix::

        Step    Atoms           Time       n_clumps       ke_per_c            CPU
        870      906    0.010040124            453  8.8671113e-08     0.12652729

Both spellings are recognised. Stage markers (``SILOFLOW <event> key=value ...``) are parsed by
:func:`engines.liggghts.run.parse_markers`, the parser the orchestrator checks finished runs with.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from engines.estimates import format_duration
from engines.liggghts.run import Marker, parse_markers

#: Canonical thermo columns: the decks' thermo keywords without the ``v_`` prefix of variables.
STEP, ATOMS, TIME, CLUMPS, KE_PER_CLUMP, CPU = "step", "atoms", "time", "n_clumps", "ke_per_clump", "cpu"
_KNOWN_COLUMNS = (STEP, ATOMS, TIME, CLUMPS, KE_PER_CLUMP, CPU)
#: LIGGGHTS cuts thermo header names to this many characters.
_HEADER_NAME_WIDTH = 8
_LOOP_END = "Loop time of"


def column_name(header_word: str) -> str:
    """Canonical name of a thermo header word: lower case, ``v_`` prefix dropped, and a name LIGGGHTS cut
    to 8 characters (6 once a kept ``v_`` is dropped) completed when it starts a known column
    (``ke_per_c`` and ``v_ke_per`` are ``ke_per_clump``); other words are kept as they are."""
    word = header_word.lower()
    if word.startswith("v_"):
        word = word[2:]
    for known in _KNOWN_COLUMNS:
        if word == known or (len(word) >= _HEADER_NAME_WIDTH - 2 and known.startswith(word)):
            return known
    return word


@dataclass(frozen=True)
class ThermoRow:
    """One thermo output row.

    Attributes
    ----------
    step : int
        Time step number.
    atoms : int
        Atoms in the simulation (clump spheres plus any lid atoms).
    time : float
        Simulated time since the start of the run (s).
    clumps : float
        Clumps (the deck's ``n_clumps``, atoms over spheres per clump; briefly fractional while LIGGGHTS
        removes the partner spheres of deleted clumps).
    ke_per_clump : float or None
        Mean kinetic energy per clump (J); None when the header has no such column.
    cpu : float or None
        CPU time since the start of the current ``run`` command (s); None when the header has no such column.
    extra : dict of str to float
        Further columns by header name (``sample_t``, ``lid_fx`` ... of the Jenike deck).
    """

    step: int
    atoms: int
    time: float
    clumps: float
    ke_per_clump: float | None = None
    cpu: float | None = None
    extra: dict = field(default_factory=dict)


def _is_thermo_header(words: list[str]) -> bool:
    return (
        len(words) >= 4
        and [w.lower() for w in words[:3]] == [STEP, ATOMS, TIME]
        and column_name(words[3]) == CLUMPS
    )


class ThermoProgress:
    """Incremental parser of the engine's screen output: the latest thermo row and the last stage marker.

    Feed it text in chunks of any size (:meth:`feed`); a chunk may end anywhere, also inside a number or a
    header, and the rest of that line is kept for the next chunk. Lines that are neither thermo rows under a
    header nor markers (warnings, ``INFO`` lines, blank lines, run statistics) are ignored, and so is a row
    that does not parse: wrong number of columns, a word that is not a number, a non-integral step or atom
    count, a non-finite step, atom count, time or clump count.
    """

    def __init__(self) -> None:
        self._partial = ""
        self._columns: tuple[str, ...] | None = None
        self._latest: ThermoRow | None = None
        self._last_marker: Marker | None = None
        self.rows_read = 0
        self.markers_read = 0

    @property
    def latest(self) -> ThermoRow | None:
        """The last thermo row read, or None before the first."""
        return self._latest

    @property
    def last_marker(self) -> Marker | None:
        """The last ``SILOFLOW`` stage marker read, or None before the first."""
        return self._last_marker

    @property
    def stage(self) -> str | None:
        """Event name of the last stage marker (``settle``, ``opened``, ...), or None before the first."""
        return self._last_marker.event if self._last_marker is not None else None

    @property
    def columns(self) -> tuple[str, ...] | None:
        """Canonical column names of the thermo block being read, or None outside one."""
        return self._columns

    def feed(self, text: str) -> list[ThermoRow]:
        """Parse the complete lines of ``text`` (with what an earlier chunk left unfinished).

        Returns
        -------
        list of ThermoRow
            Thermo rows completed by this chunk, in order.
        """
        if not isinstance(text, str):
            raise ValueError(f"feed() takes the engine output as str, got {type(text).__name__}")
        lines = (self._partial + text).split("\n")
        self._partial = lines.pop()
        rows = []
        for line in lines:
            row = self._read_line(line)
            if row is not None:
                rows.append(row)
        return rows

    def flush(self) -> list[ThermoRow]:
        """Parse the unfinished last line as complete (when the output has ended without a newline)."""
        partial, self._partial = self._partial, ""
        row = self._read_line(partial) if partial else None
        return [row] if row is not None else []

    def _read_line(self, line: str) -> ThermoRow | None:
        stripped = line.strip()
        if not stripped:
            return None
        if stripped.startswith("SILOFLOW"):
            markers = parse_markers(stripped)
            if markers:
                self._last_marker = markers[-1]
                self.markers_read += 1
            return None
        if stripped.startswith(_LOOP_END):
            self._columns = None
            return None
        words = stripped.split()
        if _is_thermo_header(words):
            self._columns = tuple(column_name(word) for word in words)
            return None
        if self._columns is None or len(words) != len(self._columns):
            return None
        row = _parse_row(self._columns, words)
        if row is not None:
            self._latest = row
            self.rows_read += 1
        return row


def _parse_row(columns: tuple[str, ...], words: list[str]) -> ThermoRow | None:
    try:
        values = dict(zip(columns, (float(word) for word in words)))
    except ValueError:
        return None
    required = [values[STEP], values[ATOMS], values[TIME], values[CLUMPS]]
    if not all(math.isfinite(value) for value in required):
        return None
    if not (values[STEP].is_integer() and values[ATOMS].is_integer()):
        return None
    return ThermoRow(
        step=int(values[STEP]),
        atoms=int(values[ATOMS]),
        time=values[TIME],
        clumps=values[CLUMPS],
        ke_per_clump=values.get(KE_PER_CLUMP),
        cpu=values.get(CPU),
        extra={name: value for name, value in values.items() if name not in _KNOWN_COLUMNS},
    )


# ---------------------------------------------------------------------------------------------- report


@dataclass(frozen=True)
class Progress:
    """How far a run has come and when it will end.

    Attributes
    ----------
    simulated_time_s : float
        Simulated time reached (s).
    target_time_s : float
        Simulated time at the end of the run (s).
    fraction : float
        ``simulated / target`` clipped to [0, 1] (-).
    elapsed_wall_s : float
        Wall time since the run started (s).
    eta_s : float or None
        Wall time still to go, ``elapsed (1 - fraction) / fraction`` (s); None before any progress.
    clumps : float or None
        Clumps in the latest row; None before the first.
    stage : str or None
        Stage name to show.
    run_id : str or None
        Run to name.
    """

    simulated_time_s: float
    target_time_s: float
    fraction: float
    elapsed_wall_s: float
    eta_s: float | None
    clumps: float | None = None
    stage: str | None = None
    run_id: str | None = None

    def __str__(self) -> str:
        """One line: ``run <id>: 0.42 / 1.20 s simulated (35 %), 5,168 clumps, stage settle, elapsed 3 min,
        ETA 5.6 min``; the run, clumps and stage parts only when known."""
        decimals = max(2, 2 - math.floor(math.log10(self.target_time_s)))
        parts = [
            f"{self.simulated_time_s:.{decimals}f} / {self.target_time_s:.{decimals}f} s simulated "
            f"({100.0 * self.fraction:.0f} %)"
        ]
        if self.clumps is not None:
            parts.append(f"{round(self.clumps):,} clumps")
        if self.stage is not None:
            parts.append(f"stage {self.stage}")
        parts.append(f"elapsed {format_duration(self.elapsed_wall_s)}")
        parts.append(f"ETA {format_duration(self.eta_s)}" if self.eta_s is not None else "ETA unknown")
        line = ", ".join(parts)
        return f"run {self.run_id}: {line}" if self.run_id is not None else line


def progress_report(
    latest: ThermoRow | None,
    target_time: float,
    elapsed_wall_s: float,
    stage: str | None = None,
    run_id: str | None = None,
) -> Progress:
    """Fraction done and time to go, extrapolated linearly in simulated time.

    Parameters
    ----------
    latest : ThermoRow or None
        Latest thermo row (:attr:`ThermoProgress.latest`); None before the first.
    target_time : float
        Simulated time at the end of the run (s, > 0), e.g. ``RunEstimate.simulated_time_s`` (a worst case:
        a fill that settles early ends the run sooner).
    elapsed_wall_s : float
        Wall time since the run started (s, >= 0).
    stage : str, optional
        Stage to show (:attr:`ThermoProgress.stage`).
    run_id : str, optional
        Run to name.

    Returns
    -------
    Progress
        fraction = time / target clipped to [0, 1]; ETA = elapsed (1 - fraction) / fraction, None while the
        fraction is 0. Stages do not all cost the same per simulated second, so the ETA is a rough guide.
    """
    if not (isinstance(target_time, (int, float)) and math.isfinite(target_time) and target_time > 0):
        raise ValueError(f"target_time must be a finite number > 0 s, got {target_time!r}")
    if not (isinstance(elapsed_wall_s, (int, float)) and math.isfinite(elapsed_wall_s) and elapsed_wall_s >= 0):
        raise ValueError(f"elapsed_wall_s must be a finite number >= 0 s, got {elapsed_wall_s!r}")
    simulated = latest.time if latest is not None else 0.0
    fraction = min(max(simulated / target_time, 0.0), 1.0)
    eta = elapsed_wall_s * (1.0 - fraction) / fraction if fraction > 0 else None
    return Progress(
        simulated_time_s=simulated,
        target_time_s=float(target_time),
        fraction=fraction,
        elapsed_wall_s=float(elapsed_wall_s),
        eta_s=eta,
        clumps=latest.clumps if latest is not None else None,
        stage=stage,
        run_id=run_id,
    )


class ProgressMonitor:
    """Follows a running engine's growing screen output and reports its progress.

    Every ``log_every`` seconds of wall time a progress line (:class:`Progress`) goes to ``logger`` (the rule's
    log); when ``terminal`` is given (a stream that is a terminal) the line is also kept live on it, rewritten in
    place. The ETA is extrapolated from the rate since the first thermo row this monitor saw, so a run resumed
    from a restart estimates from its own pace.

    Parameters
    ----------
    screen_path : path-like
        The engine's screen output file (``engine.out``), read from where the last poll stopped.
    target_time : float
        Simulated time at the end of the run (s).
    run_id : str, optional
        Run to name in the lines.
    log_every : float
        Wall time between logged lines (s).
    logger : logging.Logger, optional
    terminal : text stream, optional
    clock : callable
        Wall clock in seconds (tests pass a fake one).
    """

    def __init__(self, screen_path, target_time: float, run_id: str | None = None, log_every: float = 30.0,
                 logger=None, terminal=None, clock=None):
        import time

        self._path = screen_path
        self._target = float(target_time)
        self._run_id = run_id
        self._log_every = float(log_every)
        self._logger = logger
        self._terminal = terminal
        self._clock = clock or time.monotonic
        self._started = self._clock()
        self._last_log = self._started
        self._offset = 0
        self._parser = ThermoProgress()
        self._first: tuple[float, float] | None = None  # (wall, simulated) of the first row seen

    def _read(self) -> None:
        try:
            with open(self._path, "rb") as handle:
                handle.seek(self._offset)
                chunk = handle.read()
        except FileNotFoundError:
            return
        self._offset += len(chunk)
        self._parser.feed(chunk.decode("utf-8", errors="replace"))

    def progress(self) -> Progress:
        """Progress as of the last poll."""
        now = self._clock()
        latest = self._parser.latest
        report = progress_report(latest, self._target, now - self._started, self._parser.stage, self._run_id)
        if latest is not None and self._first is None:
            self._first = (now, latest.time)
        if latest is not None and self._first is not None and latest.time > self._first[1]:
            rate = (latest.time - self._first[1]) / max(now - self._first[0], 1e-9)
            eta = max(self._target - latest.time, 0.0) / rate
            report = dataclasses.replace(report, eta_s=eta)
        return report

    def poll(self) -> Progress:
        """Read what the engine printed since the last poll; log and show the progress when due."""
        self._read()
        report = self.progress()
        now = self._clock()
        if self._logger is not None and now - self._last_log >= self._log_every:
            self._logger.info("progress: %s", report)
            self._last_log = now
        if self._terminal is not None:
            self._terminal.write(f"\r{report}\033[K")
            self._terminal.flush()
        return report

    def finish(self) -> Progress:
        """Last poll (whatever remains, including a last line without a newline); ends the live line."""
        self._read()
        self._parser.flush()
        report = self.progress()
        if self._logger is not None:
            self._logger.info("progress: %s", report)
        if self._terminal is not None:
            self._terminal.write(f"\r{report}\033[K\n")
            self._terminal.flush()
        return report
