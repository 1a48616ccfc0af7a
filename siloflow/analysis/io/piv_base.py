"""What the PIV readers share: the error that names a file and its problem, the reading of a file's text and of its
numeric table, and what a program's row order says about its axes.

A configuration names the files a reader reads, and a configuration handed to a user may name any file (``/proc/self/
environ``, a key file): a reader's message names the file, the place in it (line, column, vector) and what was
expected there, and never quotes the text it found (numpy's and scipy's own messages do, so they are not passed on). A
header's names are quoted only when the reader knows each of them: they are then the reader's words, not the file's.

PIV programs write their vector grid in a fixed order: OpenPIV row by row from the image's top row, x fastest
(``numpy.ravel`` of its 2-D arrays), PIVlab column by column from the image's left column, y fastest (MATLAB's
``reshape`` of its 2-D arrays). Each program computes its grid in image order (columns to the right, rows down), so
the step of y from the first grid line to the second says whether the file's y points down the image or up, and the
step of x whether x points right or left, whatever units and offsets the program applied.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Sequence
from pathlib import Path

import numpy as np

from siloflow.model.file_messages import unreadable

__all__ = ["PivFormatError", "axis_steps", "finite_positions", "first_at", "header_names", "not_a_number",
           "numeric_table", "readable_file", "text_lines"]

#: Where numpy.loadtxt's ValueError places a value it cannot convert (row from 0, column from 1), and a row (from 1)
#: whose count of values differs from the rows before it. Anchored at the message's end and start: the text numpy
#: quotes before the place is the file's, and may itself read "at row 7, column 1".
_CONVERSION = re.compile(r"at row (\d+), column (\d+)\.\Z")
_COLUMNS_CHANGED = re.compile(r"the number of columns changed from (\d+) to (\d+) at row (\d+);")


class PivFormatError(ValueError):
    """A PIV file does not follow its documented layout, or says something siloflow cannot use; the message names the
    file and the problem."""


def readable_file(path: Path) -> None:
    """Refuse a path that is not a file this process may read (for the readers of binary formats, whose libraries
    say so less clearly).

    Raises
    ------
    PivFormatError
        Naming ``path``: a folder, no such file, or a file that cannot be read (the system's reason).
    """
    try:
        with open(path, "rb"):
            pass
    except OSError as error:
        raise PivFormatError(f"{path}: {unreadable(error)}") from None


def text_lines(path: Path) -> list[str]:
    """The lines of a text file, the first at index 0 (line 1): split at line ends only, so that an index is the line
    number an editor shows, less one; bytes that are not UTF-8 are replaced (a message says where, not what).

    Raises
    ------
    PivFormatError
        Naming ``path``: a folder, no such file, or a file that cannot be read (the system's reason).
    """
    try:
        return path.read_text(encoding="utf-8", errors="replace").split("\n")
    except OSError as error:
        raise PivFormatError(f"{path}: {unreadable(error)}") from None


def not_a_number(error: ValueError, lines: Sequence[int]) -> str:
    """Where ``numpy.loadtxt`` failed, without what it found there: its message quotes the text it could not convert,
    and the file may be any file at all.

    Parameters
    ----------
    error : ValueError
        ``numpy.loadtxt``'s error on a list of data lines (none blank or a comment, so that its row i is the list's
        item i).
    lines : sequence of int
        The line number in the file (from 1) of each data line.

    Returns
    -------
    str
        "line L, column C is not a number": L the line in the file, C the value's place on the line (from 1, values
        split at the delimiter); "line L holds N values where the lines before it hold M"; or, for a message of
        another form, "a value is not a number".

    Examples
    --------
    >>> not_a_number(ValueError("could not convert string 'A=b' to float64 at row 1, column 2."), [2, 4])
    'line 4, column 2 is not a number'
    """
    text = str(error)
    changed = _COLUMNS_CHANGED.match(text)
    if changed and 0 < int(changed.group(3)) <= len(lines):  # numpy counts this row from 1
        before, now, row = (int(g) for g in changed.groups())
        values = f"{now} value{'s' if now != 1 else ''}"
        return f"line {lines[row - 1]} holds {values} where the lines before it hold {before}"
    converted = _CONVERSION.search(text)
    if converted and int(converted.group(1)) < len(lines):  # numpy counts this row from 0 and the column from 1
        row, column = (int(g) for g in converted.groups())
        return f"line {lines[row]}, column {column} is not a number"
    return "a value is not a number"


def numeric_table(path: Path, lines: list[str], start: int = 0,
                  delimiters: tuple[str | None, ...] = (",",)) -> tuple[np.ndarray, np.ndarray]:
    """The table of numbers of ``lines`` from index ``start`` on, blank lines and ``#`` comment lines left out.

    Parameters
    ----------
    path : pathlib.Path
        The file, for messages.
    lines : list of str
        Its lines (:func:`text_lines`).
    start : int
        The index of the first line that may hold data.
    delimiters : tuple of str or None
        The delimiters the format allows, by preference: the first one the first data line holds is used; None
        stands for any whitespace; when the line holds none of them, the last.

    Returns
    -------
    table : numpy.ndarray, shape (rows, columns)
    numbers : numpy.ndarray of int, shape (rows,)
        The line number in the file (from 1) of each row.

    Raises
    ------
    PivFormatError
        Naming ``path``: no data line, or a line and column that is not a number, or a line whose count of values
        differs from the lines before it (:func:`not_a_number`).
    """
    numbered = [(number + 1, line) for number, line in enumerate(lines[start:], start)
                if line.strip() and not line.lstrip().startswith("#")]
    if not numbered:
        raise PivFormatError(f"{path}: no vectors")
    numbers, data = zip(*numbered)
    delimiter = next((d for d in delimiters if d is None or d in data[0]), delimiters[-1])
    try:
        table = np.loadtxt(list(data), delimiter=delimiter, comments="#", ndmin=2)
    except ValueError as error:
        raise PivFormatError(f"{path}: {not_a_number(error, numbers)}") from None
    return table, np.array(numbers)


def header_names(names: Sequence[str], known: Collection[str], program: str) -> str:
    """A header's names as a message gives them: themselves when ``known`` holds each, else only how many there are.

    Examples
    --------
    >>> header_names(["x", "y", "u"], {"x", "y", "u", "v"}, "PIVlab")
    'names x, y, u'
    >>> header_names(["x", "y", "A=b"], {"x", "y", "u", "v"}, "PIVlab")
    "has 3 names (not all PIVlab's)"
    """
    if not names:
        return "names nothing"
    if all(name in known for name in names):
        return "names " + ", ".join(names)
    return f"has {len(names)} name{'s' if len(names) > 1 else ''} (not all {program}'s)"


def first_at(bad: np.ndarray, lines: np.ndarray | None = None) -> str:
    """Where the first True of ``bad`` (one per vector, in the file's order) is: "line L" of the file when ``lines``
    gives each vector's line number, else "vector N" (from 1)."""
    index = int(np.argmax(bad))
    return f"line {int(lines[index])}" if lines is not None else f"vector {index + 1}"


def finite_positions(path: Path, x: np.ndarray, y: np.ndarray, lines: np.ndarray | None = None) -> None:
    """Refuse vectors without a finite position.

    Raises
    ------
    PivFormatError
        Naming ``path``, the number of such vectors and where the first one is (:func:`first_at`).
    """
    bad = ~(np.isfinite(x) & np.isfinite(y))
    if bad.any():
        raise PivFormatError(f"{path}: {int(bad.sum())} vector(s) without a finite position (first: "
                             f"{first_at(bad, lines)})")


def axis_steps(x: np.ndarray, y: np.ndarray, x_fastest: bool) -> tuple[float | None, float | None]:
    """The steps (dx, dy) [file units] from the first grid line to the next, along the image's columns (x) and rows
    (y), of vectors written in grid order; None along an axis with a single grid line.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (n,)
        Positions in the order of the file.
    x_fastest : bool
        True when x changes fastest (OpenPIV: a grid row after the other), False when y does (PIVlab: a grid column
        after the other).

    Examples
    --------
    >>> axis_steps(np.array([16.0, 48.0, 16.0, 48.0]), np.array([16.0, 16.0, 48.0, 48.0]), x_fastest=True)
    (32.0, 32.0)
    """
    fast, slow = (x, y) if x_fastest else (y, x)
    run = int(np.argmax(slow != slow[0])) if np.any(slow != slow[0]) else slow.size
    fast_step = float(fast[1] - fast[0]) if run > 1 else None
    slow_step = float(slow[run] - slow[0]) if run < slow.size else None
    return (fast_step, slow_step) if x_fastest else (slow_step, fast_step)
