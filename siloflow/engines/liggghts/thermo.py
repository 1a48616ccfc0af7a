"""LIGGGHTS' thermo output: the latest thermo row and stage marker of its screen output, read as it grows.

Pure computation: :class:`ThermoProgress` is fed the text the engine prints (``engine.out``), in chunks as it
grows; the caller reads the file (:class:`siloflow.engines.progress.ProgressMonitor`, for which it is the
:class:`siloflow.engines.progress.ScreenParser` of LIGGGHTS: :class:`ThermoRow` has the ``time`` and ``clumps`` of a
:class:`siloflow.engines.progress.Sample`). The thermo block of every ``run`` starts with a header line (the decks'
``thermo_style custom step atoms time v_n_clumps v_ke_per_clump [extra columns] cpu``) and ends with the
``Loop time of ...`` line. LIGGGHTS 3.8 writes the header with the variable names cut to 8 characters and
without their ``v_`` prefix::

        Step    Atoms           Time       n_clumps       ke_per_c            CPU
        870      906    0.010040124            453  8.8671113e-08     0.12652729

Both spellings are recognised. Stage markers (``SILOFLOW <event> key=value ...``) are parsed by
:func:`siloflow.engines.liggghts.markers.parse_markers`, the parser the orchestrator checks finished runs with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from siloflow.engines.markers import Marker, parse_markers

#: Canonical thermo columns: the decks' thermo keywords without the ``v_`` prefix of variables.
STEP, ATOMS, TIME, CLUMPS, KE_PER_CLUMP, CPU = "step", "atoms", "time", "n_clumps", "ke_per_clump", "cpu"
_KNOWN_COLUMNS = (STEP, ATOMS, TIME, CLUMPS, KE_PER_CLUMP, CPU)
#: LIGGGHTS cuts thermo header names to this many characters.
_HEADER_NAME_WIDTH = 8
_LOOP_END = "Loop time of"


def column_name(header_word: str) -> str:
    """Canonical name of a thermo header word.

    Parameters
    ----------
    header_word : str
        A word of a thermo header line as LIGGGHTS printed it (``Step``, ``v_n_clumps``, ``ke_per_c``, ...).

    Returns
    -------
    str
        The word in lower case with its ``v_`` prefix dropped; a name LIGGGHTS cut to 8 characters (6 once a
        kept ``v_`` is dropped) is completed when it starts a known column (``ke_per_c`` and ``v_ke_per`` are
        ``ke_per_clump``); other words are kept as they are (``sample_t``).
    """
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
        Time step number (-).
    atoms : int
        Atoms in the simulation (-): clump spheres plus any lid atoms.
    time : float
        Simulated time since the start of the run (s).
    clumps : float
        Clumps (-): the deck's ``n_clumps``, atoms over spheres per clump; briefly fractional while LIGGGHTS
        removes the partner spheres of deleted clumps.
    ke_per_clump : float or None
        Mean kinetic energy per clump (J); None when the header has no such column.
    cpu : float or None
        CPU time since the start of the current ``run`` command (s); None when the header has no such column.
    extra : dict of str to float
        Further columns by header name (``sample_t``, ``lid_fx`` ... of the Jenike deck), in the deck's units.
    """

    step: int
    atoms: int
    time: float
    clumps: float
    ke_per_clump: float | None = None
    cpu: float | None = None
    extra: dict = field(default_factory=dict)


def _is_thermo_header(words: list[str]) -> bool:
    """Whether the words of a line are a thermo header of the decks (step, atoms, time, clumps first)."""
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

        Parameters
        ----------
        text : str
            The next chunk of the screen output, decoded; it may end anywhere, also inside a line.

        Returns
        -------
        list of ThermoRow
            Thermo rows completed by this chunk, in order.

        Raises
        ------
        ValueError
            When ``text`` is not a str (bytes must be decoded first).
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
        """Parse the unfinished last line as complete (when the output has ended without a newline).

        Returns
        -------
        list of ThermoRow
            The row that line completes, if it is one; empty otherwise.
        """
        partial, self._partial = self._partial, ""
        row = self._read_line(partial) if partial else None
        return [row] if row is not None else []

    def _read_line(self, line: str) -> ThermoRow | None:
        """Take in one complete line: a marker, the end or header of a thermo block, or a row (returned)."""
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
    """The row the words of a line under the header ``columns`` give, or None when they do not parse."""
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
