"""Particle-particle contacts from LIGGGHTS local dumps, read into neutral :class:`ContactFrame` objects.

The silo deck writes ``compute pair/gran/local pos id force`` through ``dump local`` as text::

    ITEM: TIMESTEP
    22000
    ITEM: NUMBER OF ENTRIES
    533
    ITEM: BOX BOUNDS ff ff ff
    ...three lines...
    ITEM: ENTRIES c_contacts[1] ... c_contacts[12]
    x_i y_i z_i x_j y_j z_j id_i id_j periodic f_x f_y f_z

``f`` is the force on particle i by particle j (N). Parsing is pure (text in, arrays out); reading a file
is a thin wrapper. A message names the file, the line and column and what was expected there, never what the file
holds (:mod:`siloflow.model.file_messages`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from siloflow.model.contacts import ContactFrame
from siloflow.model.file_messages import first_not_read

N_COLUMNS = 12


class ContactDumpError(ValueError):
    """A local dump is truncated or malformed; the message names the file."""


def parse_local_table(
    text: str, n_columns: int, source: str = "<text>", count_item: str = "NUMBER OF ENTRIES", table_item: str = "ENTRIES"
) -> tuple[int, np.ndarray]:
    """The time step and the (n, n_columns) value table of one ``dump local`` snapshot (or, with ``count_item``
    "NUMBER OF ATOMS" and ``table_item`` "ATOMS", of one text ``dump custom`` snapshot).

    Raises
    ------
    ContactDumpError
        Naming ``source`` (and the line) when a header item is missing, the entry count disagrees with the lines,
        a row has another number of columns, or a value is not a finite number; never what the file holds there.
    """
    lines = text.splitlines()

    def item(name: str) -> int:
        for index, line in enumerate(lines):
            if line.startswith(f"ITEM: {name}"):
                return index
        raise ContactDumpError(f"{source}: no 'ITEM: {name}' header (not a complete LIGGGHTS local dump?)")

    stepped, counted = item("TIMESTEP") + 1, item(count_item) + 1
    try:
        step = int(lines[stepped])
        count = int(lines[counted])
    except (IndexError, ValueError):
        raise ContactDumpError(f"{source}: malformed TIMESTEP or {count_item}") from None
    table = item(table_item) + 1
    numbered = [(number, line.split()) for number, line in enumerate(lines[table:], start=table + 1) if line.strip()]
    if len(numbered) != count:  # the count is the file's: the message gives the line that declares it
        found = f"{len(numbered)} line{'' if len(numbered) == 1 else 's'}"
        raise ContactDumpError(f"{source}: the {count_item} of line {counted + 1} differs from the {found} after "
                               f"'ITEM: {table_item}' (line {table})")
    for number, row in numbered:
        if len(row) != n_columns:
            raise ContactDumpError(f"{source}: line {number} holds {len(row)} values, expected {n_columns}")
    try:
        values = np.array([row for _, row in numbered], dtype=float).reshape(count, n_columns)
    except ValueError:
        # numpy's message quotes the value: the place is found again, row by row
        found = next((f"line {number}, column {place}" for number, row in numbered if (place := first_not_read(row))),
                     "a value")
        raise ContactDumpError(f"{source}: {found} is not a number") from None
    if not np.all(np.isfinite(values)):
        row, column = (int(index[0]) for index in np.nonzero(~np.isfinite(values)))
        raise ContactDumpError(f"{source}: line {numbered[row][0]}, column {column + 1} is not finite")
    return step, values


def parse_local_dump(text: str, source: str = "<text>") -> ContactFrame:
    """Parse one ``dump local`` snapshot of ``pos id force`` contacts (see the module docstring).

    Raises
    ------
    ContactDumpError
        As :func:`parse_local_table`.
    """
    step, values = parse_local_table(text, N_COLUMNS, source)
    return ContactFrame(
        step=step,
        position_i=values[:, 0:3],
        position_j=values[:, 3:6],
        id_i=values[:, 6].astype(np.int64),
        id_j=values[:, 7].astype(np.int64),
        force=values[:, 9:12],
    )


def read_contacts(path: str | Path) -> ContactFrame:
    """Read a local dump file written by the silo deck."""
    path = Path(path)
    return parse_local_dump(path.read_text(encoding="utf-8", errors="replace"), str(path))
