"""What siloflow's file readers say about a file they refuse: the file, the place in it and what was expected there,
never what it holds.

A configuration names the files some readers read: the folder and the dump files of a run siloflow did not make
(``silo_flat.existing_runs``), the measured PIV files and profiles. A configuration handed to a user may name any file
there (a link to ``/proc/self/environ`` or to a key file). So a reader's message names the file, the place (line,
column, byte, field) and what was expected, and never quotes the text, the words or the numbers it found: not a line,
not a token, not a value, nor a count or a step the file declares; nor the message of numpy or of a codec, which quote
what they could not convert. A name found in the file (a column, a field, a section) is given only when the reader
knows it: it is then the reader's word, not the file's. Counts the reader makes itself (how many lines or values it
found) are given. In the neutral model, so that the engines' readers and the PIV readers (:mod:`siloflow.analysis.io.piv_base`)
share it.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable, Sequence

__all__ = ["first_not_read", "not_regular", "refuse_irregular", "unreadable"]

#: What a file that is not a regular file is, by the kind :func:`os.stat` reports.
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISSOCK, "a socket"))


def unreadable(error: OSError) -> str:
    """Why the system would not let a file be read, in words for a message: its reason, never the file's text.

    Examples
    --------
    >>> unreadable(PermissionError(13, "Permission denied"))
    'cannot be read (permission denied)'
    """
    if isinstance(error, IsADirectoryError):
        return "a folder, not a file"
    if isinstance(error, FileNotFoundError):
        return "no such file"
    reason = (error.strerror or "an error of the system").lower()
    return f"cannot be read ({reason})"


def not_regular(path: str | os.PathLike) -> str | None:
    """Why ``path`` is no regular file to read (a link is followed), or None when it is one.

    A folder cannot be read as a file, and a device or a pipe may never end (``/dev/zero``) or never begin (a FIFO
    no program writes): each is refused before it is opened, from what :func:`os.stat` says of it.

    Examples
    --------
    >>> not_regular("/dev/zero")
    'a character device, not a regular file'
    """
    try:
        mode = os.stat(path).st_mode
    except OSError as error:
        return unreadable(error)
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "a file of another kind")
    return f"{kind}, not a regular file"


def refuse_irregular(path: str | os.PathLike, error: type[Exception]) -> None:
    """Raise ``error`` (``"<path>: <why>"``) when ``path`` is no regular file (:func:`not_regular`), before any
    reader opens it."""
    refused = not_regular(path)
    if refused is not None:
        raise error(f"{path}: {refused}")


def first_not_read(words: Sequence[str | bytes], convert: Callable = float) -> int | None:
    """The place (from 1) of the first of ``words`` that ``convert`` cannot read, or None when it reads each.

    Examples
    --------
    >>> first_not_read(["1", "2.5", "SECRET=x"])
    3
    """
    for place, word in enumerate(words, start=1):
        try:
            convert(word)
        except (ValueError, OverflowError):
            return place
    return None
