"""The readers of PIVlab's text export and of its MATLAB files (GUI export, command-line workspace, session).

Text export (PIVlab's "ASCII chart" export: ``PIVlab_GUI.m`` up to 2.63, ``+export/file_save.m`` since 3.00)
-------------------------------------------------------------------------------------------------------------
Up to two information lines (``PIVlab by W.Th. & E.J.S., ASCII chart output - <date>``, later ``PIVlab, ASCII chart
output - <date>``; then ``FRAME: <n>, filenames: ..., conversion factor xy (px -> m): <calxy>, conversion factor uv
(px/frame -> m/s): <calu>``), an optional header naming each column with its unit, then one row per vector written by
``dlmwrite`` (10 significant digits, comma, tab or space delimited, CR LF line ends, ``NaN`` where the vector is
masked), a grid column after the other from the image's left (MATLAB's column-major ``reshape``). The columns:

- up to 2.36 (October 2020, and the File Exchange releases before it, such as those of 2017): 4 columns
  ``x y u v``, or 11 with the derivatives (vorticity, magnitude, divergence, dcev, simple shear, simple strain,
  vector direction); no vector type;
- 2.37 to 2.43 (December 2020 to March 2021): 4, or 12 with the correlation coefficient after the derivatives;
- 2.44 (March 2021, commit 4214486) to 3.13: 5 columns ``x y u v type``, or 12 with the seven derivatives (dcev became the Q
  criterion in 3.10, "simple shear" the shear rate);
- 3.14 (May and June 2026): 5, or 13 with the correlation coefficient, then 14 with the uncertainty.

The two layouts of 12 columns differ in their fifth column (vorticity, or the vector type): without the header that
names it, a file of 12 columns is refused. Units come from the header (``x [px]``, ``u [px/frame]``; ``x [m]``,
``u [m/s]``) or the information line (pixels when both factors are 1, as PIVlab's own test is); velocities in
``m/frame`` (PIVlab 3.07 and later, when the calibration's time step is 0) are refused, and so is a file whose factors
xy and uv are equal and not 1: that is the displacement-only calibration, whose 5-column export PIVlab labels
``m/s``, or a time step of exactly 1 s, and the file cannot say which. Without header and information lines the units
are the configuration's to say. PIVlab writes what its display shows: the smoothed field if there is one, else the
validated (filtered) one, else the original.

MATLAB files (``scipy.io.loadmat`` for MATLAB 5 to 7.2, ``h5py`` for 7.3, which is HDF5)
-----------------------------------------------------------------------------------------
GUI export (``mat_file_save``, every PIVlab release)
    ``x``, ``y``, ``u_original``, ``v_original``, ``typevector_original``, ``u_filtered``, ``v_filtered``,
    ``typevector_filtered``, ``u_smoothed``, ``v_smoothed``, the calibration (``calxy`` and ``caluv``, since 2.44
    ``calu`` and ``calv``) and ``units`` (``[px] respectively [px/frame]``, ``[m] respectively [m/s]``, since 3.07
    ``[m] respectively [m/frame]``, which is refused): cell arrays of one cell per frame when all frames are
    exported, plain arrays for the current frame only. A frame that PIVlab never validated has empty filtered
    cells.
Command-line workspace (``PIVlab_commandline.m``, in ``Example_scripts/`` from 3.04, ``PIVlab_process_commandline.m``
from 3.14; saved by the user, or by ``PIVlab_commandline.m``'s own ``save`` from November 2020 until its rework of April
2026, MATLAB's default format 7 (MATLAB 5, compressed), as ``<first image>_<last image>_<images>_frames_result_.mat``)
    ``x``, ``y``, ``u``, ``v``, ``typevector``, ``u_filt``, ``v_filt``, ``typevector_filt``: cell arrays of one
    cell per image pair (single precision in PIVlab's own sample of 3.10, September 2025), and since the script's
    rework of April 2026 (3.14) three-dimensional arrays (rows, columns, pairs). Pixels and displacements per
    frame: the script does not calibrate (its factors ``r{1,2}`` and ``r{2,2}`` only scale the velocity limits of
    the validation).
Session (``save_session_function``, always MATLAB 7.3)
    ``resultslist``, a cell array of one column per frame: rows 1 to 5 ``x``, ``y``, ``u``, ``v``, ``typevector``
    of the correlation, rows 7 to 9 the validated ``u``, ``v`` and ``typevector``; uncalibrated (pixels and
    displacements per frame) whatever calibration the session holds.

``field`` chooses the correlation's own field (``original``: its types say only measured or masked, so outliers count
as measured until siloflow's Hampel filter) or the validated one (``filtered``, PIVlab's data validation with its
interpolation of rejected vectors).

Types (all files with one): 0 ``masked``, 1 ``measured``, 2 ``interpolated`` (rejected by validation and filled in;
``invalid`` when PIVlab left it NaN), 3 ``second_peak`` (from 3.14: a rejected vector replaced by its second
correlation peak). A text file without a type column says only NaN (``masked``) or a number (``unflagged``).

Axes: PIVlab computes its grid in image axes and, when calibrated since 2.44, turns them as its "x axis direction"
and "y axis direction" settings say (``calibrate.xy``: ``x_cal = (width - x) calxy - offset_x`` for an x increasing to
the left, likewise y) with v turned alike; before 2.44 a calibrated file kept image axes. The order of the grid says
which way the file's y points (:mod:`siloflow.analysis.io.piv_base`); an x increasing to the left is refused (the silo's x
points right).
"""

from __future__ import annotations

import re
import zlib
from pathlib import Path

import h5py
import numpy as np
import scipy.io

from siloflow.analysis.io.piv_base import (
    PivFormatError,
    axis_steps,
    finite_positions,
    first_at,
    header_names,
    numeric_table,
    readable_file,
    text_lines,
)
from siloflow.analysis.piv.field import INTERPOLATED, INVALID, MASKED, MEASURED, SECOND_PEAK, UNFLAGGED, PivRows

__all__ = ["PIVLAB_FIELDS", "PIVLAB_TEXT_LAYOUTS", "read_pivlab_mat", "read_pivlab_txt"]

#: The fields of a PIVlab MATLAB file ``read_pivlab_mat`` can read.
PIVLAB_FIELDS = ("original", "filtered")

#: The text export's layouts: (columns, has a type column) -> the PIVlab releases that write it.
PIVLAB_TEXT_LAYOUTS = {
    (4, False): "up to 2.43, without derivatives",
    (11, False): "up to 2.36, with derivatives",
    (12, False): "2.37 to 2.43, with derivatives and the correlation coefficient",
    (5, True): "2.44 and later, without derivatives",
    (12, True): "2.44 to 3.13, with derivatives",
    (13, True): "3.14, with derivatives and the correlation coefficient",
    (14, True): "3.14, with derivatives, the correlation coefficient and the uncertainty",
}

_NUMBERS = re.compile(r"[,\t ]+")
_HEADER = re.compile(r"([^\[\]]*?)\s*\[([^\]]*)\]")
_FACTORS = re.compile(r"conversion factor xy \(px -> m\):\s*([^,]+?)\s*,\s*conversion factor uv "
                      r"\(px/frame -> m/s\):\s*(\S+)")
_TYPES = {0: "masked", 1: "measured", 2: "interpolated", 3: "second peak"}
#: The column names (lower case) and units of PIVlab's text headers: a message quotes a header's names or units only
#: when each is one of these (anything else is the file's text).
_HEADER_NAMES = {"x", "y", "u", "v", "vector type", "vorticity", "magnitude", "divergence", "dcev", "simple shear",
                 "simple strain", "vector direction", "correlation coefficient", "q criterion",
                 "shear rate (magnitude of the rate-of-strain tensor)", "uncertainty"}
_HEADER_UNITS = {"px", "m", "px/frame", "m/s", "m/frame"}
#: The units variable of PIVlab's GUI export, and whether it means pixels.
_MAT_UNITS = {"[px] respectively [px/frame]": True, "[m] respectively [m/s]": False}


def _kinds(path: Path, where: str, types: np.ndarray | None, u: np.ndarray, v: np.ndarray,
           lines: np.ndarray | None = None) -> np.ndarray:
    """The node kinds of PIVlab's vector types (module docstring), or of NaN alone without types; ``lines``, each
    vector's line in a text file, for messages."""
    finite = np.isfinite(u) & np.isfinite(v)
    if types is None:
        return np.where(finite, UNFLAGGED, MASKED).astype(np.int8)
    unknown = ~np.isin(types, list(_TYPES))
    if unknown.any():
        raise PivFormatError(f"{path}: {where}{first_at(unknown, lines)} has a vector type PIVlab does not write; "
                             "PIVlab's types are " + ", ".join(f"{k} ({v})" for k, v in _TYPES.items()))
    kind = np.full(types.shape, INVALID, dtype=np.int8)
    kind[(types == 1) & finite] = MEASURED
    kind[(types == 3) & finite] = SECOND_PEAK
    kind[(types == 2) & finite] = INTERPOLATED
    kind[types == 0] = MASKED
    return kind


def _oriented(path: Path, x, y, u, v, kind, pixels: bool | None, where: str = "",
              lines: np.ndarray | None = None) -> PivRows:
    """Rows in PIVlab's column-major order, with the file's y direction read off the grid; ``lines``, each vector's
    line in a text file, for messages."""
    finite_positions(path, x, y, lines)
    dx, dy = axis_steps(x, y, x_fastest=False)
    if dx is not None and dx < 0:
        raise PivFormatError(f"{path}: {where}x increases to the left (PIVlab's calibration setting \"x axis "
                             "direction: increase to left\"); the silo's x points right: export with x increasing to "
                             "the right")
    if dy is None and not pixels:
        raise PivFormatError(f"{path}: {where}a single grid row does not show which way PIVlab's y axis points")
    return PivRows(x, y, u, v, kind, True if dy is None else dy > 0, pixels)


def _text_units(path: Path, header: list[tuple[str, str]] | None, factors: tuple[str, str] | None,
                lines: tuple[int, int]) -> bool | None:
    """True for pixels, False for metres, None when the file does not say; ``lines``, the header's and the factors'
    line numbers, for messages."""
    said = []
    if header:
        position, velocity = header[0][1].strip(), header[2][1].strip()
        if velocity == "m/frame":
            raise PivFormatError(f"{path}: velocities in m/frame (PIVlab's displacement-only calibration, a time step "
                                 "of 0): give the calibration's time step, or export uncalibrated (px) and give the "
                                 "markers and the frame rate")
        if (position, velocity) not in (("px", "px/frame"), ("m", "m/s")):
            units = (f"units x [{position}], u [{velocity}]" if {position, velocity} <= _HEADER_UNITS else
                     "units of x and u that are not PIVlab's")
            raise PivFormatError(f"{path}: the header on line {lines[0]} gives {units}; PIVlab writes px with "
                                 "px/frame or m with m/s")
        said.append(position == "px")
    if factors:
        try:
            xy, uv = float(factors[0]), float(factors[1])
        except ValueError:
            raise PivFormatError(f"{path}: line {lines[1]}: the conversion factors xy and uv are not both numbers") \
                from None
        pixels = xy == 1 and abs(uv) == 1
        if not pixels and factors[0] == factors[1].lstrip("-"):
            raise PivFormatError(
                f"{path}: line {lines[1]}: the conversion factors xy and uv are equal: PIVlab's displacement-only "
                "calibration (time step 0, PIVlab 3.07 and later) writes displacements per frame under an m/s header, "
                "and a time step of exactly 1 s gives the same factors; the file cannot say which. Export "
                "uncalibrated (px) and give the markers and the frame rate")
        said.append(pixels)
    if len(said) == 2 and said[0] != said[1]:
        raise PivFormatError(f"{path}: the header says {'px' if said[0] else 'm'}, the conversion factors say "
                             f"{'px' if said[1] else 'm'}")
    return said[0] if said else None


def read_pivlab_txt(path: str | Path) -> PivRows:
    """A PIVlab text export in any of its layouts (module docstring).

    Returns
    -------
    PivRows
        Positions [px or m] and vectors [px/frame or m/s] as written, y down or up as the file's grid order says,
        ``pixels`` as its header or information line says (None when it has neither), the kind of each vector.

    Raises
    ------
    PivFormatError
        Naming the file and, where it can, the line (and column): a folder or a file that cannot be read; a line
        that is neither PIVlab's information lines, its header nor numbers; a value that is not a number; rows of
        unequal length; a column count or header of no PIVlab layout, or 12 columns without a header; units PIVlab
        does not write, velocities per frame in metres, or header and factors that disagree; a vector type PIVlab
        does not write; a position that is not finite; x increasing to the left; or, in metres, a single grid row.
        No message quotes the file's text (a header's names and units only when they are PIVlab's).
    """
    path = Path(path)
    lines = text_lines(path)
    header, factors, start = None, None, None
    header_line = factors_line = 0
    for number, line in enumerate(lines):
        text = line.strip()
        if not text:
            continue
        try:
            [float(f) for f in _NUMBERS.split(text) if f]
        except ValueError:
            if text.startswith("PIVlab"):
                continue
            if text.startswith("FRAME:"):
                match = _FACTORS.search(text)
                factors = (match.group(1), match.group(2)) if match else None
                factors_line = number + 1
                continue
            if text.startswith("x ["):
                header = [(name.strip(" ,\t"), unit) for name, unit in _HEADER.findall(text)]
                header_line = number + 1
                continue
            raise PivFormatError(f"{path}: line {number + 1} is neither PIVlab's information lines, its header nor "
                                 "numbers") from None
        start = number
        break
    if start is None:
        raise PivFormatError(f"{path}: no vectors")
    table, numbers = numeric_table(path, lines, start, delimiters=(",", "\t", None))
    columns = table.shape[1]
    if header is not None:
        names = [name.lower() for name, _ in header]
        if len(names) != columns or names[:4] != ["x", "y", "u", "v"]:
            raise PivFormatError(f"{path}: the header on line {header_line} "
                                 f"{header_names(names, _HEADER_NAMES, 'PIVlab')} over {columns} columns; PIVlab's "
                                 "begin x, y, u, v (then the vector type since 2.44)")
        typed = len(names) > 4 and names[4] == "vector type"
    elif columns == 12:
        raise PivFormatError(f"{path}: 12 columns without a header: PIVlab 2.37 to 2.43 wrote x y u v and eight "
                             "derivatives, 2.44 to 3.13 x y u v, the vector type and seven; export with the header "
                             "(PIVlab's 'add column headers')")
    else:
        typed = columns in (5, 13, 14)
    if (columns, typed) not in PIVLAB_TEXT_LAYOUTS:
        raise PivFormatError(f"{path}: {columns} columns{' with' if typed else ' without'} a vector type; PIVlab "
                             "writes " + "; ".join(f"{c} columns{' with' if t else ' without'} a type ({d})"
                                                   for (c, t), d in PIVLAB_TEXT_LAYOUTS.items()))
    pixels = _text_units(path, header, factors, (header_line, factors_line))
    x, y, u, v = table[:, :4].T
    kind = _kinds(path, "", table[:, 4] if typed else None, u, v, numbers)
    return _oriented(path, x, y, u, v, kind, pixels, lines=numbers)


# ---------------------------------------------------------------------------------------------- MATLAB files

#: The variables of each PIVlab MATLAB layout: positions, then (u, v, types) of the original and filtered fields.
_GUI = (("x", "y"), {"original": ("u_original", "v_original", "typevector_original"),
                     "filtered": ("u_filtered", "v_filtered", "typevector_filtered")})
_COMMAND_LINE = (("x", "y"), {"original": ("u", "v", "typevector"),
                              "filtered": ("u_filt", "v_filt", "typevector_filt")})
#: Rows (from 0) of a session's resultslist.
_SESSION_ROWS = {"original": (2, 3, 4), "filtered": (6, 7, 8)}
#: What scipy.io and h5py raise on a file that is not MATLAB 5 to 7.3 (zlib's on a damaged compressed variable).
_MATLAB_ERRORS = (scipy.io.matlab.MatReadError, ValueError, TypeError, KeyError, OSError, zlib.error)


def _h5_value(handle: h5py.File, node):
    """A MATLAB 7.3 variable in MATLAB's axis order: an array, a string, or an object array of cells."""
    if not isinstance(node, h5py.Dataset):
        return None  # a struct or an object: no PIVlab variable this reader uses is one
    attributes = node.attrs
    matlab_class = attributes.get("MATLAB_class", b"")
    matlab_class = matlab_class.decode(errors="replace") if isinstance(matlab_class, bytes) else str(matlab_class)
    if int(attributes.get("MATLAB_empty", 0)):
        return np.zeros((0, 0))
    # MATLAB writes its column-major arrays as HDF5's row-major ones with the axes reversed
    values = node[()].T
    if matlab_class == "cell":
        cells = np.empty(values.shape, dtype=object)
        for index, reference in np.ndenumerate(values):
            cells[index] = _h5_value(handle, handle[reference])
        return cells
    if matlab_class == "char":
        return "".join(map(chr, values.ravel(order="F")))
    return values


def _not_matlab(path: Path) -> PivFormatError:
    # scipy's and h5py's messages may quote the file's bytes (scipy's "version 61, 97" is two of them), so they are
    # not passed on
    return PivFormatError(f"{path}: not a MATLAB file (5 to 7.3) that scipy.io or h5py can read")


def _present(path: Path) -> set[str]:
    """The names of the variables of a MATLAB file."""
    try:
        if h5py.is_hdf5(path):  # MATLAB 7.3
            with h5py.File(path, "r") as handle:
                return set(handle.keys())
        return {name for name, _, _ in scipy.io.whosmat(path)}
    except _MATLAB_ERRORS:
        raise _not_matlab(path) from None


def _variables(path: Path, wanted: set[str]) -> dict:
    """The variables named in ``wanted`` that the file holds, in MATLAB's axis order."""
    names = wanted & _present(path)
    try:
        if h5py.is_hdf5(path):  # MATLAB 7.3
            with h5py.File(path, "r") as handle:
                return {name: _h5_value(handle, handle[name]) for name in names}
        arrays = scipy.io.loadmat(path, variable_names=sorted(names))
    except _MATLAB_ERRORS:
        raise _not_matlab(path) from None
    values = {}
    for name in names:
        value = arrays[name]
        values[name] = str(value[0]) if value.dtype.kind == "U" and value.size else value
    return values


def _numeric(value, path: Path, name: str) -> np.ndarray:
    """``value`` as an array of floats; refused when it holds anything but numbers (numpy's conversion of text would
    quote the text)."""
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":
        raise PivFormatError(f"{path}: {name} is not numeric")
    return array.astype(float)


def _frames(value, path: Path, name: str) -> list[np.ndarray]:
    """The per-frame arrays of a variable: a cell per frame, a 2-D array (one frame) or a 3-D one (frames last)."""
    if value is None:
        raise PivFormatError(f"{path}: {name} is not an array")
    if isinstance(value, np.ndarray) and value.dtype == object:
        if min(value.shape) > 1:
            raise PivFormatError(f"{path}: {name} is a {' x '.join(map(str, value.shape))} cell array; PIVlab writes "
                                 "one cell per frame")
        return [_numeric(cell, path, f"{name}{{{n}}}") for n, cell in enumerate(value.ravel(), start=1)]
    value = _numeric(value, path, name)
    if value.ndim == 3:
        return [value[:, :, n] for n in range(value.shape[2])]
    return [value]


def _mat_units(path: Path, variables: dict) -> bool:
    units = variables.get("units")
    if units is None:
        raise PivFormatError(f"{path}: no units variable; PIVlab's export writes units ('[px] respectively "
                             "[px/frame]' or '[m] respectively [m/s]')")
    units = " ".join(str(units).split())
    if units in _MAT_UNITS:
        return _MAT_UNITS[units]
    if units == "[m] respectively [m/frame]":
        raise PivFormatError(f"{path}: velocities in m/frame (PIVlab's displacement-only calibration, a time step of "
                             "0): give the calibration's time step, or export uncalibrated (px) and give the markers "
                             "and the frame rate")
    raise PivFormatError(f"{path}: the units variable is none of PIVlab's: '[px] respectively [px/frame]' or '[m] "
                         "respectively [m/s]'")


def _rows_of_frames(path: Path, field: str, x, y, u, v, types, pixels: bool, names: tuple[str, ...]) -> list[PivRows]:
    counts = {name: len(frames) for name, frames in zip(names, (x, y, u, v, types))}
    if len(set(counts.values())) > 1:
        raise PivFormatError(f"{path}: different frame counts: " + ", ".join(f"{k} {n}" for k, n in counts.items()))
    rows = []
    for number, arrays in enumerate(zip(x, y, u, v, types), start=1):
        where = f"frame {number}: "
        if any(a.size == 0 for a in arrays):
            empty = [name for name, a in zip(names, arrays) if a.size == 0]
            hint = (" (PIVlab fills the filtered field only for frames that went through its data validation: "
                    "validate every frame, or set silo_flat.piv.measured.pivlab.field: original)"
                    if field == "filtered" else "")
            raise PivFormatError(f"{path}: {where}{', '.join(empty)} empty{hint}")
        shapes = {a.shape for a in arrays}
        if len(shapes) > 1:
            raise PivFormatError(f"{path}: {where}arrays of different shapes: "
                                 + ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays)))
        # PIVlab's own order, a grid column after the other (MATLAB's column-major reshape)
        fx, fy, fu, fv, ft = (a.ravel(order="F") for a in arrays)
        rows.append(_oriented(path, fx, fy, fu, fv, _kinds(path, where, ft, fu, fv), pixels, where))
    if not rows:
        raise PivFormatError(f"{path}: no frame")
    return rows


def read_pivlab_mat(path: str | Path, field: str = "filtered") -> list[PivRows]:
    """The frames of a PIVlab MATLAB file (module docstring): a GUI export, a command-line workspace or a session.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.mat`` file (MATLAB 5 to 7.3).
    field : {"original", "filtered"}
        The correlation's own field, or the one after PIVlab's data validation.

    Returns
    -------
    list of PivRows
        One per frame, in frame order: positions [px or m] and vectors [px/frame or m/s] as stored, y down or up as
        the grid says, ``pixels`` as the file says, the kind of each vector.

    Raises
    ------
    PivFormatError
        Naming the file (and the frame, variable or vector): a folder or a file that cannot be read, not a MATLAB
        file, none of PIVlab's layouts, a variable that is not numbers, units PIVlab does not write or per frame in
        metres, an empty field, arrays or frame counts that differ, a vector type PIVlab does not write, a position
        that is not finite, x increasing to the left, or, in metres, a single grid row. No message quotes the
        file's contents.
    """
    path = Path(path)
    if field not in PIVLAB_FIELDS:
        raise ValueError(f"field must be one of {', '.join(PIVLAB_FIELDS)}, got {field!r}")
    readable_file(path)
    present = _present(path)
    for (positions, fields), pixels in ((_GUI, None), (_COMMAND_LINE, True)):
        names = positions + fields[field]
        if set(positions + fields["original"]) <= present:
            variables = _variables(path, set(names) | {"units"})
            missing = [n for n in names if n not in variables]
            if missing:
                raise PivFormatError(f"{path}: no {', '.join(missing)} (silo_flat.piv.measured.pivlab.field: "
                                     f"{field})")
            frames = [_frames(variables[n], path, n) for n in names]
            return _rows_of_frames(path, field, *frames, _mat_units(path, variables) if pixels is None else pixels,
                                   names)
    if "resultslist" in present:
        results = _variables(path, {"resultslist"})["resultslist"]
        if not (isinstance(results, np.ndarray) and results.dtype == object and results.shape[0] >= 5):
            raise PivFormatError(f"{path}: resultslist is not PIVlab's cell array of five or more rows per frame")
        rows = (0, 1) + _SESSION_ROWS[field]
        if results.shape[0] <= max(rows):
            raise PivFormatError(f"{path}: resultslist has no filtered field (rows 7 to 9) for any frame "
                                 "(silo_flat.piv.measured.pivlab.field: filtered)")
        frames = [[_numeric(cell, path, f"resultslist{{{r + 1},{n}}}") for n, cell in enumerate(results[r], start=1)]
                  for r in rows]
        names = tuple(f"resultslist{{{r + 1},:}}" for r in rows)
        return _rows_of_frames(path, field, *frames, True, names)
    raise PivFormatError(f"{path}: none of PIVlab's layouts: the GUI export has x, y, u_original, v_original, "
                         "typevector_original (and _filtered), the command-line workspace x, y, u, v, typevector (and "
                         "u_filt, v_filt, typevector_filt), a session resultslist")
