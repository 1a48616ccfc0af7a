"""Readers (and the one writer) of PIV velocity fields, each file read with the meaning its program gives its flags
and masks. They return :class:`PivRows` (one row per vector, in the file's units and axes); :func:`piv_field`
(:mod:`analysis.piv.calibration`'s scale) turns them into the neutral :class:`~analysis.piv.field.PlanarField`.

Formats
-------
OpenPIV (``openpiv.tools.save``)
    One title line ``# x y u v flags mask``, then six columns (tab by default): x, y (px, or m when the user scaled),
    u, v (px/frame or m/s), ``flags`` (0 valid, 1 invalid and replaced, 2 interpolated) and ``mask`` (1 inside the
    image mask, where u and v are written as 0). Valid: flags 0 and mask 0. Rows from ``pyprocess`` are in image
    axes (y and v down); ``tools.transform_coordinates`` turns y and v up: the caller says which (``y_down``).
PIVlab (``.txt`` export)
    Up to two information lines and an optional header, then 5 columns ``x y u v type`` (12 with derivatives: the
    first 5 are these), comma, tab or space delimited, CR LF line ends; type 0 masked (u, v NaN), 1 measured, 2
    filtered or interpolated. Valid: type 1. Image axes (y and v down).
siloflow CSV
    A header ``x_m,z_m,u_m_s,w_m_s,valid`` and one row per node in silo coordinates (x across, z up; m, m/s; valid
    1 or 0): what a user converts any other program's output to, and what :func:`write_piv_csv` writes.

The OpenPIV and CSV files are read with ``numpy.loadtxt``; PIVlab's mixed information lines, header and delimiters
are sorted out line by line first, because ``numpy.loadtxt`` takes one delimiter and no free-text preamble.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.io.tables import write_text
from analysis.piv.field import PlanarField, field_from_rows

__all__ = ["PivFormatError", "PivRows", "read_openpiv", "read_piv_csv", "read_pivlab_txt", "write_piv_csv"]

CSV_HEADER = "x_m,z_m,u_m_s,w_m_s,valid"


class PivFormatError(ValueError):
    """A PIV file does not follow its documented layout; the message names the file and the problem."""


@dataclass(frozen=True)
class PivRows:
    """One row per vector as a PIV program wrote it: positions (x, y) and displacements or velocities (u, v) in the
    file's units, ``y_down`` when y and v point down the image, and which vectors are measurements."""

    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    v: np.ndarray
    valid: np.ndarray
    y_down: bool


def _table(path: Path, columns: tuple[int, ...], delimiter: str | None, skip: int = 0) -> np.ndarray:
    try:
        table = np.loadtxt(path, delimiter=delimiter, comments="#", skiprows=skip, ndmin=2)
    except ValueError as error:
        raise PivFormatError(f"{path}: not a numeric table ({error})") from None
    if table.size == 0:
        raise PivFormatError(f"{path}: no vectors")
    if table.shape[1] not in columns:
        raise PivFormatError(f"{path}: {table.shape[1]} columns, expected {' or '.join(map(str, columns))}")
    return table


def _finite_positions(path: Path, x: np.ndarray, y: np.ndarray) -> None:
    bad = ~(np.isfinite(x) & np.isfinite(y))
    if bad.any():
        raise PivFormatError(f"{path}: {int(bad.sum())} vector(s) without a finite position (first at row "
                             f"{int(np.argmax(bad)) + 1})")


def read_openpiv(path: str | Path, y_down: bool) -> PivRows:
    """An OpenPIV field file (module docstring); ``y_down`` says whether its y and v point down the image.

    Raises
    ------
    PivFormatError
        Naming the file: not six numeric columns, or a position that is not finite.
    """
    path = Path(path)
    table = _table(path, (6,), None)
    x, y, u, v, flags, mask = table.T
    _finite_positions(path, x, y)
    valid = (flags == 0) & (mask == 0) & np.isfinite(u) & np.isfinite(v)
    return PivRows(x, y, u, v, valid, y_down)


_SPLIT = re.compile(r"[,\t ]+")


def read_pivlab_txt(path: str | Path) -> PivRows:
    """A PIVlab ``.txt`` export (module docstring): image axes, valid where type is 1.

    Raises
    ------
    PivFormatError
        Naming the file: no numeric rows, rows of another column count than 5 or 12, or a position that is not
        finite.
    """
    path = Path(path)
    rows = []
    for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), start=1):
        fields = [f for f in _SPLIT.split(line.strip()) if f]
        try:
            values = [float(f) for f in fields]
        except ValueError:
            if rows:  # text after the data has begun is not PIVlab's layout
                raise PivFormatError(f"{path}: line {number} is not numeric: {line.strip()[:60]!r}") from None
            continue  # information lines and the header
        if len(values) not in (5, 12):
            raise PivFormatError(f"{path}: line {number} has {len(values)} columns, expected 5 (x y u v type) or 12")
        rows.append(values[:5])
    if not rows:
        raise PivFormatError(f"{path}: no vectors")
    x, y, u, v, kind = np.array(rows).T
    _finite_positions(path, x, y)
    return PivRows(x, y, u, v, (kind == 1) & np.isfinite(u) & np.isfinite(v), True)


def read_piv_csv(path: str | Path, time: float = 0.0) -> PlanarField:
    """A siloflow PIV CSV (module docstring) as a field at ``time`` [s].

    Raises
    ------
    PivFormatError
        Naming the file: another header, not five numeric columns, a position that is not finite, or nodes that do
        not fill a regular grid.
    """
    path = Path(path)
    with open(path, encoding="utf-8") as handle:
        header = handle.readline().strip()
    if header != CSV_HEADER:
        raise PivFormatError(f"{path}: the header is {header[:60]!r}, expected {CSV_HEADER!r}")
    table = _table(path, (5,), ",", skip=1)
    x, z, u, w, valid = table.T
    _finite_positions(path, x, z)
    try:
        return field_from_rows(x, z, u, w, (valid == 1) & np.isfinite(u) & np.isfinite(w), time)
    except ValueError as error:
        raise PivFormatError(f"{path}: {error}") from None


def write_piv_csv(path: str | Path, field: PlanarField) -> Path:
    """Write ``field`` as a siloflow PIV CSV (x fastest; invalid nodes with NaN velocities and valid 0)."""
    z, x = np.meshgrid(field.z, field.x, indexing="ij")
    # repr of a Python float is the shortest text that reads back to the same double
    lines = [CSV_HEADER] + [f"{float(a)!r},{float(b)!r},{float(c)!r},{float(d)!r},{int(e)}" for a, b, c, d, e in
                            zip(x.ravel(), z.ravel(), field.u.ravel(), field.w.ravel(), field.valid.ravel())]
    return write_text(path, "\n".join(lines) + "\n")
