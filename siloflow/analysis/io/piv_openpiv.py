"""The reader of OpenPIV's text output (``openpiv.tools.save``, and ``windef``'s own ``save`` of 0.21 to 0.23.3).

Layouts, as OpenPIV's own code wrote them (openpiv-python, ``openpiv/tools.py`` and ``openpiv/windef.py`` at each
tag; tab-delimited unless the caller chose another delimiter)
------------------------------------------------------------------------------------------------------------------
0.19 (2015) to 0.22.x (2020), ``tools.save(x, y, u, v, mask, filename, fmt="%8.4f")``
    No header; five columns ``x y u v mask``. ``mask`` is whatever the caller passed: the tutorials pass the mask
    of ``validation.sig2noise_val`` (1 where a vector failed validation; ``filters.replace_outliers`` then usually
    filled it in), and some scripts pass the signal-to-noise ratio instead (the pivpy package's sample
    ``exp1_001_b.txt`` has it there). The file cannot say which: ``fifth_column`` does.
0.21.x to 0.23.3 (2019 to December 2020), ``windef.save`` and ``tools.save`` of 0.23.0 to 0.23.3
    Header ``# x y u v s2n mask``; six columns: the signal-to-noise ratio, then the validation mask (the sum of the
    masks of each validation step, so possibly 2).
0.23.4 (January 2021) to 0.24.2 (July 2022), ``tools.save(x, y, u, v, mask, filename, fmt="%8.4f")``
    Header ``# x y u v mask``; five columns, ``mask`` "where elements corresponding to invalid vectors are True"
    (its docstring). Vectors inside the image mask are written as 0 and not marked (``u.filled(0.)``): this layout
    cannot tell them from a measured zero.
0.24.4 (November 2022) onwards, ``tools.save(filename, x, y, u, v, flags=None, mask=None, fmt="%.4e")``
    Header ``# x y u v flags mask``; six columns: ``flags`` 0 valid, 1 invalid, 2 interpolated; ``mask`` 1 inside
    the image mask (u and v written as 0).

Node kinds (:data:`siloflow.analysis.piv.field.NODE_KINDS`): mask 1 of the current layout is ``masked``; flags 1, and a
validation mask that is not 0, are ``invalid``; flags 2 is ``interpolated``; flags 0 or a validation mask of 0 is
``measured``; a file that carries only the signal-to-noise ratio flags nothing: its vectors are ``unflagged``, or,
with ``sig2noise_threshold``, ``invalid`` below the threshold and ``measured`` from it on. A vector without a finite
velocity is ``invalid`` (``masked`` inside the image mask).

Axes and units: OpenPIV writes its arrays row by row from the image's top row (:mod:`siloflow.analysis.io.piv_base`), so the
file's row order says whether its y points down the image (``pyprocess`` output) or up (after
``tools.transform_coordinates``, which ``windef`` applies before saving since 0.23.4). Which way v points it does
not say, and OpenPIV's conventions changed between releases (0.21 and 0.22's ``process.extended_search_area_piv``
returned v pointing up next to ``process.get_coordinates``' y pointing down): ``y_down`` says it, or, when None, v
points the way y does. Units are not in the file: pixels (and displacements per frame: ``windef`` divides by its
``dt``) or metres (after ``scaling.uniform``) are the configuration's to say.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from siloflow.analysis.io.piv_base import (
    PivFormatError,
    axis_steps,
    finite_positions,
    first_at,
    header_names,
    numeric_table,
    text_lines,
)
from siloflow.analysis.piv.field import INTERPOLATED, INVALID, MASKED, MEASURED, UNFLAGGED, PivRows

__all__ = ["OPENPIV_FIFTH_COLUMNS", "OPENPIV_HEADERS", "read_openpiv"]

#: The header of each OpenPIV layout that has one (module docstring), by its column names.
OPENPIV_HEADERS = {
    ("x", "y", "u", "v", "s2n", "mask"): "windef.save of 0.21 to 0.23.3, tools.save of 0.23.0 to 0.23.3",
    ("x", "y", "u", "v", "mask"): "tools.save of 0.23.4 to 0.24.2",
    ("x", "y", "u", "v", "flags", "mask"): "tools.save of 0.24.4 onwards",
}
#: What the fifth column of a file without a header (OpenPIV 0.19 to 0.22) may hold.
OPENPIV_FIFTH_COLUMNS = ("mask", "sig2noise")

_NAMES = re.compile(r"[\s,;]+")
#: The column names of OpenPIV's headers: a message quotes a header only when it holds these alone.
_KNOWN_NAMES = {name for names in OPENPIV_HEADERS for name in names}
#: What a message says OpenPIV writes in each column of flags or masks.
_FLAGS = "OpenPIV writes 0 (valid), 1 (invalid) or 2 (interpolated) there"
_IMAGE_MASK = "OpenPIV writes 0 or 1 (inside the image mask) there"
_VALIDATION_MASK = "OpenPIV writes 0 (valid) or the count of validations a vector failed there"
_MASK_OR_SIG2NOISE = ("if the column holds the signal-to-noise ratio, set silo_flat.piv.measured.openpiv.fifth_column: "
                      "sig2noise")


def _header(path: Path, lines: list[str]) -> tuple[str, ...] | None:
    """The column names of the header, None without one: OpenPIV's header is a first line that begins with ``#``."""
    first = next((number for number, line in enumerate(lines) if line.strip()), None)
    if first is None or not lines[first].lstrip().startswith("#"):
        return None
    names = tuple(n.lower() for n in _NAMES.split(lines[first].lstrip()[1:].strip()) if n)
    if names not in OPENPIV_HEADERS:
        raise PivFormatError(
            f"{path}: the header on line {first + 1} {header_names(names, _KNOWN_NAMES, 'OpenPIV')}, none of OpenPIV's: "
            + "; ".join(f"'# {' '.join(k)}' ({v})" for k, v in OPENPIV_HEADERS.items()))
    return names


def _table(path: Path, lines: list[str], names: tuple[str, ...] | None) -> tuple[np.ndarray, np.ndarray]:
    # OpenPIV writes with the caller's delimiter (a tab by default); the header, a '#' line, is left out with comments
    table, numbers = numeric_table(path, lines, delimiters=(",", None))
    expected = len(names) if names else 5
    if table.shape[1] != expected:
        said = (f"its header names {' '.join(names)}" if names else
                "OpenPIV wrote five columns (x y u v mask) without a header, and six only with one")
        raise PivFormatError(f"{path}: {table.shape[1]} columns, expected {expected} ({said})")
    return table, numbers


def _whole(path: Path, table: np.ndarray, numbers: np.ndarray, column: int, name: str, hint: str) -> np.ndarray:
    """The flags or mask column (``column``, from 0) as integers; refused, with ``hint``, when it holds anything
    else."""
    values = table[:, column]
    odd = ~np.isfinite(values) | (values != np.round(values)) | (values < 0)
    if odd.any():
        raise PivFormatError(f"{path}: {first_at(odd, numbers)}, column {column + 1} ({name}) is not a whole number "
                             f">= 0; {hint}")
    return values.astype(int)


def read_openpiv(path: str | Path, y_down: bool | None = None, fifth_column: str = "mask",
                 sig2noise_threshold: float | None = None) -> PivRows:
    """An OpenPIV text file in any of its layouts (module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    y_down : bool or None
        Whether v points down the image (True) or up (False); None: the way the file's y points.
    fifth_column : {"mask", "sig2noise"}
        What the fifth column of a file without a header holds.
    sig2noise_threshold : float or None
        In layouts with a signal-to-noise ratio, vectors below it are invalid [-].

    Returns
    -------
    PivRows
        Positions and vectors as written (``pixels`` None: the file does not say), v turned to point the way y
        does, the kind of each vector.

    Raises
    ------
    PivFormatError
        Naming the file and, for its values, the line and column: a folder or a file that cannot be read, a header
        that is none of OpenPIV's, a column count its layout does not have, a value that is not a number, flags
        other than 0, 1 or 2, a mask that is not whole numbers, a position that is not finite, x decreasing along a
        grid row, or a single grid row with ``y_down`` None. No message quotes the file's text.
    """
    path = Path(path)
    if fifth_column not in OPENPIV_FIFTH_COLUMNS:
        raise ValueError(f"fifth_column must be one of {', '.join(OPENPIV_FIFTH_COLUMNS)}, got {fifth_column!r}")
    lines = text_lines(path)
    names = _header(path, lines)
    table, numbers = _table(path, lines, names)
    x, y, u, v = table[:, :4].T
    finite_positions(path, x, y, numbers)
    columns = {name: index for index, name in enumerate(names)} if names else {}
    kind = np.full(x.size, MEASURED, dtype=np.int8)
    sig2noise = None
    if names is None and fifth_column == "sig2noise":
        sig2noise = table[:, 4]
        kind[:] = UNFLAGGED
    elif names is None:
        kind[_whole(path, table, numbers, 4, "mask", _MASK_OR_SIG2NOISE) != 0] = INVALID
    elif "flags" in columns:
        flags = _whole(path, table, numbers, columns["flags"], "flags", _FLAGS)
        if np.any(flags > 2):
            raise PivFormatError(f"{path}: {first_at(flags > 2, numbers)}, column {columns['flags'] + 1} (flags) "
                                 f"holds a flag OpenPIV does not write; {_FLAGS}")
        kind[flags == 1] = INVALID
        kind[flags == 2] = INTERPOLATED
    else:
        kind[_whole(path, table, numbers, columns["mask"], "mask", _VALIDATION_MASK) != 0] = INVALID
        sig2noise = table[:, columns["s2n"]] if "s2n" in columns else None
    if sig2noise is not None and sig2noise_threshold is not None:
        kind[(kind == UNFLAGGED) | (kind == MEASURED)] = MEASURED
        kind[~(sig2noise >= sig2noise_threshold)] = INVALID
    kind[~(np.isfinite(u) & np.isfinite(v))] = INVALID
    if "flags" in columns:
        mask = _whole(path, table, numbers, columns["mask"], "mask", _IMAGE_MASK)
        if np.any(mask > 1):
            raise PivFormatError(f"{path}: {first_at(mask > 1, numbers)}, column {columns['mask'] + 1} (mask) is "
                                 f"neither 0 nor 1; {_IMAGE_MASK}")
        kind[mask == 1] = MASKED
    dx, dy = axis_steps(x, y, x_fastest=True)
    if dx is not None and dx < 0:
        raise PivFormatError(f"{path}: x decreases along a grid row; OpenPIV writes x increasing to the right")
    positions_down = None if dy is None else dy > 0
    if positions_down is None and y_down is None:
        raise PivFormatError(f"{path}: a single grid row does not show which way y points; say which way v points "
                             "(silo_flat.piv.measured.y_down)")
    if positions_down is None:
        positions_down = y_down
    if y_down is not None and y_down != positions_down:
        v = -v  # v as configured, y as the file's order says: v is turned to point the way y does
    return PivRows(x, y, u, v, kind, positions_down)
