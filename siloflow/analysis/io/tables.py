"""Writers for flow metrics: CSV tables and JSON, written atomically.

Every writer writes to a temporary file in the destination folder and then
moves it into place with :func:`os.replace`, so a reader (or a Snakemake rule
checking its outputs) never sees a half-written file, and a failed write leaves
any previous file untouched and no temporary file behind.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import io
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any, Iterator

import numpy as np

__all__ = [
    "atomic_output",
    "write_flow_table",
    "write_text",
    "markdown_table",
    "write_json",
    "write_discharge_history_csv",
]


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; move it onto ``path`` on success.

    The parent folder is created if needed. On an exception the temporary file
    is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination.

    Yields
    ------
    pathlib.Path
        Temporary file (in the same folder, so the final rename is atomic).
    """
    destination = Path(path)
    destination.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary_name = tempfile.mkstemp(
        prefix=f".{destination.name}.", suffix=".tmp", dir=destination.parent
    )
    os.close(handle)
    temporary = Path(temporary_name)
    try:
        yield temporary
        # mkstemp creates mode 0600; give the result the usual permissions of a new file.
        os.chmod(temporary, 0o666 & ~_current_umask())
        os.replace(temporary, destination)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            temporary.unlink()
        raise


def _current_umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def _write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    with atomic_output(path) as temporary:
        with open(temporary, "w", encoding="utf-8", newline="") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
    return Path(path)


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write a text file (UTF-8) atomically."""
    return _write_text_atomic(path, text)


def markdown_table(rows: list[dict], digits: int = 4) -> str:
    """A Markdown table of rows (columns: the first row's keys); numbers with ``digits`` significant digits."""
    if not rows:
        raise ValueError("a table needs at least one row")
    columns = list(rows[0])

    def cell(value: Any) -> str:
        return f"{value:.{digits}g}" if isinstance(value, float) else str(value)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(row.get(column, "")) for column in columns) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _plain(value: Any) -> Any:
    """Convert numpy scalars/arrays and dataclasses to plain Python values."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {field.name: _plain(getattr(value, field.name)) for field in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(key): _plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    if isinstance(value, np.ndarray):
        return [_plain(item) for item in value.tolist()]
    if isinstance(value, np.generic):
        return _plain(value.item())
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, float) and not math.isfinite(value):
        # JSON has no NaN/inf; null says "not available" to every reader.
        return None
    return value


def write_flow_table(path: str | os.PathLike, rows: list[dict]) -> Path:
    """Write metric rows to a CSV file, atomically.

    The header is the keys of the first row, in their order; keys that appear
    only in later rows are appended in order of first appearance, and missing
    values are written as empty fields. Floats are written with full precision
    (``repr``), so reading the file back gives the same numbers.

    Parameters
    ----------
    path : str or os.PathLike
        Destination CSV file.
    rows : list of dict
        One dict per row (e.g. one per run or case).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    rows = list(rows)
    if not rows:
        raise ValueError("rows must contain at least one row (the header comes from its keys)")
    if not all(isinstance(row, dict) for row in rows):
        raise ValueError("rows must be a list of dicts")
    columns: list[str] = []
    for row in rows:
        for key in row:
            if key not in columns:
                columns.append(key)

    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, restval="", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({key: _csv_value(value) for key, value in row.items()})
    return _write_text_atomic(path, buffer.getvalue())


def _csv_value(value: Any) -> Any:
    value = _plain(value)
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return value


def write_json(path: str | os.PathLike, obj: Any) -> Path:
    """Write an object as JSON, atomically, with sorted keys.

    numpy scalars and arrays become plain numbers and lists, dataclasses become
    objects, and non-finite floats (NaN, inf) become ``null`` because JSON has
    no representation for them.

    Parameters
    ----------
    path : str or os.PathLike
        Destination JSON file.
    obj : object
        JSON-serialisable data (dicts, lists, numbers, strings, dataclasses,
        numpy values).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    text = json.dumps(_plain(obj), sort_keys=True, indent=2, allow_nan=False) + "\n"
    return _write_text_atomic(path, text)


def write_discharge_history_csv(path: str | os.PathLike, history) -> Path:
    """Write a discharge history as CSV with columns ``time_s, discharged_mass_kg``.

    Parameters
    ----------
    path : str or os.PathLike
        Destination CSV file.
    history : siloflow.analysis.numerics.flow.DischargeHistory
        Time since opening [s] and discharged mass [kg].

    Returns
    -------
    pathlib.Path
        The written path.
    """
    time = np.asarray(history.time, dtype=float)
    mass = np.asarray(history.discharged_mass, dtype=float)
    if time.shape != mass.shape or time.ndim != 1:
        raise ValueError(
            f"history: time and discharged_mass must be 1-D of equal length, got {time.shape} and {mass.shape}"
        )
    lines = ["time_s,discharged_mass_kg"]
    lines += [f"{t!r},{m!r}" for t, m in zip(time.tolist(), mass.tolist())]
    return _write_text_atomic(path, "\n".join(lines) + "\n")


def _cell_value(text: str):
    try:
        return float(text)
    except (TypeError, ValueError):
        return text if text != "" else None


def read_table(path: str | os.PathLike) -> list[dict]:
    """Rows of a CSV table written by :func:`write_flow_table`: numbers as float, empty cells as None, text as is."""
    with open(path, newline="", encoding="utf-8") as handle:
        return [{key: _cell_value(value) for key, value in row.items()} for row in csv.DictReader(handle)]
