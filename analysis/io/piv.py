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
PIVlab (``.mat`` export)
    Per frame n (1, 2, ...) the arrays ``x_<n>``, ``y_<n>``, ``u_<n>``, ``v_<n>`` and ``typevector_<n>`` (types as in
    the text export), in image axes; MATLAB v7.3 files are HDF5 (read with ``h5py``), older ones MATLAB 5 (read with
    ``scipy.io.loadmat``).
DaVis (``.vc7``, ``.set``; LaVision's ``lvpyio``, the optional extra ``siloflow[davis]``)
    Each vector frame's first choice of vectors, valid where DaVis' mask and "enabled" flag both hold. Vector (i, j)
    sits at ``(i + 0.5) grid slope + offset`` of the frame's x and y scales; velocities are in the intensity scale's
    unit. A calibrated frame (lengths in mm or m, velocities in m/s) gives metres with y up; an uncalibrated one
    (unit ``pixel``) gives pixels and displacements per frame with y down.
siloflow CSV
    A header ``x_m,z_m,u_m_s,w_m_s,valid`` and one row per node in silo coordinates (x across, z up; m, m/s; valid
    1 or 0): what a user converts any other program's output to, and what :func:`write_piv_csv` writes.

The OpenPIV and CSV files are read with ``numpy.loadtxt``; PIVlab's mixed information lines, header and delimiters
are sorted out line by line first, because ``numpy.loadtxt`` takes one delimiter and no free-text preamble.
:func:`read_piv_file` reads any of them as a list of frames.
"""

from __future__ import annotations

import re
from pathlib import Path

import h5py
import numpy as np
import scipy.io

try:
    import lvpyio
except ImportError:  # LaVision's reader is the optional extra siloflow[davis] (its licence restricts its use)
    lvpyio = None

from analysis.io.tables import write_text
from analysis.piv.field import PivRows, PlanarField, field_from_rows

__all__ = ["PIV_FORMATS", "PivFormatError", "PivRows", "read_davis", "read_openpiv", "read_piv_csv", "read_piv_file",
           "read_pivlab_mat", "read_pivlab_txt", "write_piv_csv"]

#: The formats :func:`read_piv_file` reads (the ``silo_flat.piv.measured.format`` values).
PIV_FORMATS = ("openpiv", "pivlab_txt", "pivlab_mat", "davis", "csv")

CSV_HEADER = "x_m,z_m,u_m_s,w_m_s,valid"


class PivFormatError(ValueError):
    """A PIV file does not follow its documented layout; the message names the file and the problem."""


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


def _pivlab_frames(arrays: dict, path: Path) -> list[PivRows]:
    numbers = sorted(int(key[2:]) for key in arrays if re.fullmatch(r"u_\d+", key))
    if not numbers:
        raise PivFormatError(f"{path}: no u_<n> array; PIVlab's .mat export has x_<n>, y_<n>, u_<n>, v_<n> and "
                             "typevector_<n> per frame n")
    frames = []
    for n in numbers:
        missing = [f"{name}_{n}" for name in ("x", "y", "v", "typevector") if f"{name}_{n}" not in arrays]
        if missing:
            raise PivFormatError(f"{path}: frame {n} has no {', '.join(missing)}")
        x, y, u, v, kind = (np.asarray(arrays[f"{name}_{n}"], dtype=float).ravel()
                            for name in ("x", "y", "u", "v", "typevector"))
        if not x.size == y.size == u.size == v.size == kind.size:
            raise PivFormatError(f"{path}: the arrays of frame {n} differ in size")
        _finite_positions(path, x, y)
        frames.append(PivRows(x, y, u, v, (kind == 1) & np.isfinite(u) & np.isfinite(v), True))
    return frames


def read_pivlab_mat(path: str | Path) -> list[PivRows]:
    """The frames of a PIVlab ``.mat`` export (module docstring), in frame order: image axes, valid where the type
    is 1.

    Raises
    ------
    PivFormatError
        Naming the file: not a MATLAB file, no ``u_<n>`` array, a frame without one of its arrays, arrays of
        different sizes, or a position that is not finite.
    """
    path = Path(path)
    if h5py.is_hdf5(path):  # MATLAB v7.3
        with h5py.File(path, "r") as handle:
            arrays = {key: handle[key][()] for key in handle if isinstance(handle[key], h5py.Dataset)}
    else:
        try:
            arrays = scipy.io.loadmat(path)
        except (scipy.io.matlab.MatReadError, ValueError, TypeError, OSError) as error:
            raise PivFormatError(f"{path}: not a MATLAB file ({error})") from None
    return _pivlab_frames(arrays, path)


#: Metres per unit of a DaVis length scale, and m/s per unit of its velocity (intensity) scale.
_DAVIS_LENGTHS = {"m": 1.0, "mm": 1e-3}
_DAVIS_VELOCITIES = {"m/s": 1.0, "mm/s": 1e-3}


def _davis_rows(frame, path: Path) -> PivRows:
    if not hasattr(frame, "grid"):
        raise PivFormatError(f"{path}: an image frame, not vectors")
    scales, grid = frame.scales, frame.grid
    length, speed = scales.x.unit.strip().lower(), scales.i.unit.strip().lower()
    if length == "pixel":
        factor, velocity_factor, pixels = 1.0, 1.0, True
    elif length in _DAVIS_LENGTHS and speed in _DAVIS_VELOCITIES:
        factor, velocity_factor, pixels = _DAVIS_LENGTHS[length], _DAVIS_VELOCITIES[speed], False
    else:
        raise PivFormatError(f"{path}: units {scales.x.unit!r} and {scales.i.unit!r}; expected pixel, or mm or m with "
                             "m/s or mm/s")
    vectors = frame.as_masked_array()  # u and v along the scales' axes: v points down when the y slope is positive
    rows, columns = vectors.shape
    j, i = np.meshgrid(np.arange(rows), np.arange(columns), indexing="ij")
    x = factor * ((i + 0.5) * grid.x * scales.x.slope + scales.x.offset)
    y = factor * ((j + 0.5) * grid.y * scales.y.slope + scales.y.offset)
    u, v = (velocity_factor * np.asarray(vectors[name].filled(np.nan), dtype=float) for name in ("u", "v"))
    valid = ~np.ma.getmaskarray(vectors["u"]) & np.isfinite(u) & np.isfinite(v)
    return PivRows(x.ravel(), y.ravel(), u.ravel(), v.ravel(), valid.ravel(), bool(scales.y.slope > 0), pixels)


def read_davis(path: str | Path) -> list[PivRows]:
    """The vector frames of a DaVis buffer (``.vc7``) or set (a ``.set`` file or its folder) through ``lvpyio``
    (module docstring).

    Raises
    ------
    PivFormatError
        Naming the file: ``lvpyio`` not installed, an image instead of vectors, or units other than pixels, or mm or
        m with m/s or mm/s.
    """
    path = Path(path)
    if lvpyio is None:
        raise PivFormatError(f"{path}: reading DaVis files needs LaVision's lvpyio: pip install 'siloflow[davis]'")
    buffers = [lvpyio.read_buffer(str(path))] if path.suffix.lower() in (".vc7", ".im7") \
        else list(lvpyio.read_set(str(path)))
    frames = [_davis_rows(frame, path) for buffer in buffers for frame in buffer]
    if not frames:
        raise PivFormatError(f"{path}: no vector frame")
    return frames


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


def read_piv_file(path: str | Path, file_format: str, y_down: bool = True) -> list[PivRows]:
    """The frames of one PIV file in ``file_format`` (one of :data:`PIV_FORMATS`); ``y_down`` is for OpenPIV files,
    which do not say. A siloflow CSV gives one frame in metres with y up.

    Raises
    ------
    PivFormatError
        Naming the file: an unknown format, a missing file, or what the format's reader refuses.
    """
    path = Path(path)
    if file_format not in PIV_FORMATS:
        raise PivFormatError(f"{path}: unknown PIV format {file_format!r}; expected one of {', '.join(PIV_FORMATS)}")
    if not path.exists():
        raise PivFormatError(f"{path}: no such file")
    if file_format == "openpiv":
        return [read_openpiv(path, y_down)]
    if file_format == "pivlab_txt":
        return [read_pivlab_txt(path)]
    if file_format == "pivlab_mat":
        return read_pivlab_mat(path)
    if file_format == "davis":
        return read_davis(path)
    field = read_piv_csv(path)
    z, x = np.meshgrid(field.z, field.x, indexing="ij")
    return [PivRows(x.ravel(), z.ravel(), field.u.ravel(), field.w.ravel(), field.valid.ravel(), False, False)]
