"""Particle dumps: parsing LIGGGHTS legacy VTK POLYDATA files into particle frames.

LIGGGHTS writes one file per dump step with::

    dump ID all custom/vtk N dumps/silo_*.vtk id type id_multisphere x y z vx vy vz \
        fx fy fz omegax omegay omegaz radius mass
    dump_modify ID binary yes

The result is a legacy VTK file (VTK 5.1 header; the binary variant holds raw big-endian
arrays, each followed by a newline) with the positions as POINTS (float32) and the other
columns as a FIELD block under POINT_DATA. LIGGGHTS groups the split columns back into
vectors named ``v``, ``f`` and ``omega``. A ``<prefix>_boundingBox_<step>.vtk`` file is
written beside each dump and is not a particle dump.

The module is layered:

- pure parsing and formatting on bytes: :func:`parse_legacy_vtk_polydata`,
  :func:`format_legacy_vtk_polydata`;
- pure computation on arrays and frames: :func:`frame_from_arrays`,
  :func:`clumps_from_frame`, :func:`dump_step`;
- file I/O at the edges: :func:`write_legacy_vtk_polydata`, :func:`list_dumps`,
  :func:`read_frame`, :func:`read_frames` (with an optional ``.npz`` cache so each dump is
  parsed once).

All quantities are SI: metres, seconds, kilograms, newtons, radians.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import tempfile
import warnings
import zipfile
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.data.frames import OPTIONAL_VECTORS, ClumpFrame, ParticleFrame, clumps_from_frame

__all__ = [
    "DumpFormatError",
    "ParticleFrame",
    "ClumpFrame",
    "parse_legacy_vtk_polydata",
    "format_legacy_vtk_polydata",
    "write_legacy_vtk_polydata",
    "frame_from_arrays",
    "clumps_from_frame",
    "dump_step",
    "list_dumps",
    "read_frame",
    "read_frames",
]


class DumpFormatError(ValueError):
    """A dump file (or the arrays parsed from it) is malformed; the message names the source."""


# --------------------------------------------------------------------------- VTK types

# Legacy VTK type names (the reader compares them in lower case) -> big-endian dtype of the
# BINARY variant. "long" is 8 bytes: VTK writes sizeof(long), which is 8 on LP64 Linux;
# "vtkIdType" is 4 bytes: VTK's legacy writer narrows ids to int.
_VTK_BINARY_DTYPES: dict[str, np.dtype] = {
    name: np.dtype(code)
    for name, code in {
        "char": ">i1",
        "signed_char": ">i1",
        "unsigned_char": ">u1",
        "short": ">i2",
        "unsigned_short": ">u2",
        "int": ">i4",
        "unsigned_int": ">u4",
        "long": ">i8",
        "unsigned_long": ">u8",
        "vtktypeint32": ">i4",
        "vtktypeuint32": ">u4",
        "vtktypeint64": ">i8",
        "vtktypeuint64": ">u8",
        "vtkidtype": ">i4",
        "float": ">f4",
        "double": ">f8",
    }.items()
}

# numpy dtype -> legacy VTK type name used by the writer.
_VTK_WRITE_TYPES: dict[np.dtype, str] = {
    np.dtype(np.uint8): "unsigned_char",
    np.dtype(np.int16): "short",
    np.dtype(np.uint16): "unsigned_short",
    np.dtype(np.int32): "int",
    np.dtype(np.uint32): "unsigned_int",
    np.dtype(np.int64): "vtktypeint64",
    np.dtype(np.uint64): "vtktypeuint64",
    np.dtype(np.float32): "float",
    np.dtype(np.float64): "double",
}

_CELL_SECTIONS = ("VERTICES", "LINES", "POLYGONS", "TRIANGLE_STRIPS")
_ASCII_VALUES_PER_LINE = 9  # what VTK's own writer uses
_WHITESPACE = b" \t\r\n\f\v"


def _native(dtype: np.dtype) -> np.dtype:
    return dtype.newbyteorder("=")


def _decode_name(name: str) -> str:
    # VTK percent-encodes spaces and other special characters in array names.
    return re.sub(r"%([0-9A-Fa-f]{2})", lambda m: chr(int(m.group(1), 16)), name)


def _encode_name(name: str) -> str:
    return "".join(
        f"%{ord(ch):02X}" if (ch.isspace() or ch == "%" or not ch.isprintable() or ord(ch) > 126) else ch
        for ch in name
    )


# --------------------------------------------------------------------------- parsing


class _Cursor:
    """Position in the content of one legacy VTK file; reads keyword lines and data arrays."""

    def __init__(self, content: bytes, source: str, binary: bool, pos: int) -> None:
        self.content = content
        self.source = source
        self.binary = binary
        self.pos = pos

    def error(self, message: str) -> DumpFormatError:
        return DumpFormatError(f"{self.source}: {message}")

    def _skip_blank(self) -> int:
        pos = self.pos
        content = self.content
        while pos < len(content) and content[pos] in _WHITESPACE:
            pos += 1
        return pos

    def at_end(self) -> bool:
        return self._skip_blank() >= len(self.content)

    def next_starts_with(self, keyword: bytes) -> bool:
        """Whether the next non-blank text starts with ``keyword`` (consumes nothing)."""
        start = self._skip_blank()
        return self.content[start : start + len(keyword)].upper() == keyword

    def next_line(self, expected: str) -> list[str]:
        """Tokens of the next non-blank line; ``expected`` describes it for error messages."""
        start = self._skip_blank()
        if start >= len(self.content):
            raise self.error(f"the file ends where {expected} was expected")
        end = self.content.find(b"\n", start)
        if end == -1:
            end = len(self.content)
        raw = self.content[start:end]
        self.pos = end + 1
        try:
            text = raw.decode("ascii")
        except UnicodeDecodeError:
            raise self.error(
                f"expected {expected} at byte {start} but found binary data "
                "(do the declared counts match the data?)"
            ) from None
        return text.split()

    def skip_metadata(self) -> None:
        """Skip a METADATA block: text lines up to the next empty line."""
        content = self.content
        while self.pos < len(content):
            end = content.find(b"\n", self.pos)
            if end == -1:
                end = len(content)
            line = content[self.pos : end]
            self.pos = end + 1
            if not line.strip():
                return

    def read_array(
        self, count: int, vtk_type: str, what: str, unit: int = 1, unit_name: str = "values"
    ) -> np.ndarray:
        """Read ``count`` values of ``vtk_type`` as a flat native-endian array.

        ``unit`` values make one ``unit_name`` (e.g. 3 values per point); it only shapes
        the message of a truncated file.
        """
        dtype = _VTK_BINARY_DTYPES.get(vtk_type.lower())
        if dtype is None:
            raise self.error(f"{what} has unknown data type {vtk_type!r}")
        if self.binary:
            return self._read_binary(count, dtype, what, unit, unit_name)
        return self._read_ascii(count, dtype, vtk_type, what, unit, unit_name)

    def _truncated(self, count: int, found: int, what: str, unit: int, unit_name: str) -> DumpFormatError:
        return self.error(
            f"{what} declares {count // unit} {unit_name} but the file ends after {found // unit}"
        )

    def _read_binary(self, count: int, dtype: np.dtype, what: str, unit: int, unit_name: str) -> np.ndarray:
        nbytes = count * dtype.itemsize
        available = len(self.content) - self.pos
        if available < nbytes:
            raise self._truncated(count, available // dtype.itemsize, what, unit, unit_name)
        # astype copies, so the array owns native-endian memory and not a view of the bytes
        values = np.frombuffer(self.content, dtype=dtype, count=count, offset=self.pos).astype(_native(dtype))
        self.pos += nbytes
        if self.content[self.pos : self.pos + 1] == b"\n":
            self.pos += 1
        return values

    def _read_ascii(
        self, count: int, dtype: np.dtype, vtk_type: str, what: str, unit: int, unit_name: str
    ) -> np.ndarray:
        content = self.content
        tokens: list[bytes] = []
        pos = self.pos
        while len(tokens) < count:
            if pos >= len(content):
                raise self._truncated(count, len(tokens), what, unit, unit_name)
            end = content.find(b"\n", pos)
            if end == -1:
                end = len(content)
            line = content[pos:end]
            if b"_" in line:  # Python's float() accepts "1_000"; a dump never contains it
                bad = next(t for t in line.split() if b"_" in t)
                raise self.error(f"{what}: {bad.decode('ascii', 'replace')!r} is not a valid {vtk_type} number")
            tokens.extend(line.split())
            pos = end + 1
        if len(tokens) > count:
            raise self.error(
                f"{what} declares {count // unit} {unit_name} but its last line holds "
                f"{len(tokens) - count} more values"
            )
        self.pos = pos
        return _ascii_numbers(tokens, dtype, vtk_type, what, self)


def _ascii_numbers(tokens: list[bytes], dtype: np.dtype, vtk_type: str, what: str, cursor: _Cursor) -> np.ndarray:
    native = _native(dtype)
    if not tokens:
        return np.empty(0, dtype=native)
    raw = np.array(tokens)
    # Integers are parsed strictly as integers ("1.0" is not an id); floats via float64.
    parse_dtype = np.float64 if native.kind == "f" else (np.uint64 if native.kind == "u" else np.int64)
    try:
        values = raw.astype(parse_dtype)
    except (ValueError, OverflowError):
        convert = float if native.kind == "f" else int
        for index, token in enumerate(tokens):
            try:
                convert(token)
            except ValueError:
                raise cursor.error(
                    f"{what}: {token.decode('ascii', 'replace')!r} (value {index}) is not a valid "
                    f"{vtk_type} number"
                ) from None
        raise cursor.error(f"{what}: a value is out of range for {vtk_type}") from None
    if native.kind in "iu":
        info = np.iinfo(native)
        if values.size and (values.min() < info.min or values.max() > info.max):
            raise cursor.error(f"{what}: a value is out of range for {vtk_type}")
    return values.astype(native)


def _parse_int(token: str, what: str, cursor: _Cursor) -> int:
    try:
        value = int(token)
    except ValueError:
        raise cursor.error(f"{what}: {token!r} is not an integer") from None
    if value < 0:
        raise cursor.error(f"{what}: negative count {value}")
    return value


def _require_tokens(tokens: list[str], n_min: int, n_max: int, form: str, cursor: _Cursor) -> None:
    if not n_min <= len(tokens) <= n_max:
        raise cursor.error(f"malformed line {' '.join(tokens)!r}, expected {form!r}")


def _check_finite(values: np.ndarray, what: str, cursor: _Cursor, per: int) -> None:
    if values.dtype.kind != "f":
        return
    finite = np.isfinite(values)
    if not finite.all():
        first = int(np.argmin(finite))
        raise cursor.error(
            f"{what} contains a non-finite value ({values[first]!r}) at point {first // per}"
        )


def _read_cells(tokens: list[str], n_points: int | None, cursor: _Cursor) -> None:
    """Read (and check) a VERTICES/LINES/POLYGONS/TRIANGLE_STRIPS section; the result is unused."""
    keyword = tokens[0].upper()
    _require_tokens(tokens, 3, 3, f"{keyword} n size", cursor)
    first = _parse_int(tokens[1], keyword, cursor)
    second = _parse_int(tokens[2], keyword, cursor)
    if cursor.next_starts_with(b"OFFSETS"):
        # VTK 5.x: "KEYWORD n_offsets n_connectivity", OFFSETS (n_cells + 1), CONNECTIVITY.
        offsets_line = cursor.next_line("OFFSETS")
        _require_tokens(offsets_line, 2, 2, "OFFSETS type", cursor)
        offsets = cursor.read_array(first, offsets_line[1], f"{keyword} OFFSETS")
        if not cursor.next_starts_with(b"CONNECTIVITY"):
            raise cursor.error(f"{keyword}: CONNECTIVITY expected after OFFSETS")
        conn_line = cursor.next_line("CONNECTIVITY")
        _require_tokens(conn_line, 2, 2, "CONNECTIVITY type", cursor)
        connectivity = cursor.read_array(second, conn_line[1], f"{keyword} CONNECTIVITY")
        if offsets.size and (
            offsets[0] != 0 or offsets[-1] != second or np.any(np.diff(offsets) < 0)
        ):
            raise cursor.error(
                f"{keyword}: OFFSETS do not run from 0 to the {second} CONNECTIVITY entries"
            )
        if offsets.size == 0 and second != 0:
            raise cursor.error(f"{keyword}: {second} CONNECTIVITY entries but no OFFSETS")
    else:
        # VTK 4.x: "KEYWORD n_cells size", then per cell: n_ids id_1 ... id_n (int32).
        stream = cursor.read_array(second, "int", keyword)
        if second == 2 * first and np.all(stream[0::2] == 1):
            connectivity = stream[1::2]
        else:
            ids, index = [], 0
            for _ in range(first):
                if index >= stream.size or stream[index] < 0:
                    break
                ids.append(stream[index + 1 : index + 1 + stream[index]])
                index += 1 + int(stream[index])
            if index != stream.size or len(ids) != first:
                raise cursor.error(f"{keyword}: {first} cells do not fill the declared size {second}")
            connectivity = np.concatenate(ids) if ids else stream[:0]
    if connectivity.size and n_points is not None:
        if connectivity.min() < 0 or connectivity.max() >= n_points:
            raise cursor.error(f"{keyword}: a cell refers to a point outside the {n_points} POINTS")


def _read_attribute_arrays(
    tokens: list[str], n_tuples: int, cursor: _Cursor
) -> list[tuple[str, np.ndarray]]:
    """Arrays of one attribute entry (FIELD block, SCALARS, VECTORS or NORMALS), as (name, array)."""
    keyword = tokens[0].upper()
    if keyword == "FIELD":
        _require_tokens(tokens, 3, 3, "FIELD name n_arrays", cursor)
        n_arrays = _parse_int(tokens[2], "FIELD", cursor)
        arrays = []
        for _ in range(n_arrays):
            line = cursor.next_line("a FIELD array line")
            if len(line) == 1 and line[0].upper() == "NULL_ARRAY":
                continue
            _require_tokens(line, 4, 4, "name n_components n_tuples type", cursor)
            name = _decode_name(line[0])
            what = f"field {name!r}"
            n_components = _parse_int(line[1], what, cursor)
            declared_tuples = _parse_int(line[2], what, cursor)
            if n_components < 1:
                raise cursor.error(f"{what} declares {n_components} components")
            if n_tuples >= 0 and declared_tuples != n_tuples:
                raise cursor.error(
                    f"{what} has {declared_tuples} tuples but the data section declares {n_tuples}"
                )
            values = cursor.read_array(
                declared_tuples * n_components, line[3], what, unit=n_components, unit_name="tuples"
            )
            arrays.append((name, values, n_components))
            if cursor.next_starts_with(b"METADATA"):
                cursor.skip_metadata()
    elif keyword == "SCALARS":
        _require_tokens(tokens, 3, 4, "SCALARS name type [n_components]", cursor)
        name = _decode_name(tokens[1])
        what = f"field {name!r}"
        n_components = _parse_int(tokens[3], what, cursor) if len(tokens) == 4 else 1
        if n_components < 1:
            raise cursor.error(f"{what} declares {n_components} components")
        if cursor.next_starts_with(b"LOOKUP_TABLE"):
            cursor.next_line("LOOKUP_TABLE")
        values = cursor.read_array(n_tuples * n_components, tokens[2], what, unit=n_components, unit_name="tuples")
        arrays = [(name, values, n_components)]
    else:  # VECTORS, NORMALS
        _require_tokens(tokens, 3, 3, f"{keyword} name type", cursor)
        name = _decode_name(tokens[1])
        what = f"field {name!r}"
        values = cursor.read_array(n_tuples * 3, tokens[2], what, unit=3, unit_name="tuples")
        arrays = [(name, values, 3)]
    return [(name, values if k == 1 else values.reshape(-1, k)) for name, values, k in arrays]


def _read_header(content: bytes, cursor: _Cursor) -> tuple[bool, int]:
    """Check the three header lines; return (binary, position after them)."""
    pos = 0
    lines = []
    for _ in range(3):
        end = content.find(b"\n", pos)
        if end == -1:
            raise cursor.error("the file ends inside the 3-line VTK header")
        lines.append(content[pos:end].strip())
        pos = end + 1
    if not lines[0].startswith(b"# vtk DataFile Version"):
        raise cursor.error(f"not a legacy VTK file (first line {lines[0][:40]!r})")
    file_format = lines[2].upper()
    if file_format not in (b"ASCII", b"BINARY"):
        raise cursor.error(f"unknown file format {lines[2][:20]!r}, expected ASCII or BINARY")
    return file_format == b"BINARY", pos


def parse_legacy_vtk_polydata(content: bytes, source: str = "<bytes>") -> dict[str, np.ndarray]:
    """Parse a legacy VTK POLYDATA file (as written by LIGGGHTS ``dump custom/vtk``).

    Both the BINARY (big-endian raw arrays) and the ASCII variants are read, with the
    VTK 5.x cell layout (OFFSETS/CONNECTIVITY) or the VTK 4.2 one (``VERTICES n 2n`` and
    pairs ``1 i``). Point data may come as FIELD arrays or as SCALARS/VECTORS/NORMALS.
    Cell sections are checked but not returned; CELL_DATA and dataset-level FIELD arrays
    are read and discarded.

    Parameters
    ----------
    content : bytes
        The whole file.
    source : str
        Name of the file, used in error messages.

    Returns
    -------
    dict of str to numpy.ndarray
        ``"points"``: point coordinates, shape (n, 3), in the declared precision (float32
        for ``float``, float64 for ``double``) [m for LIGGGHTS dumps]. Then one entry per
        point-data array, keyed by its name: shape (n,) for one component, (n, k) for k
        components, native-endian dtype of the declared type (``int`` -> int32, ``long``
        and ``vtktypeint64`` -> int64, ``float`` -> float32, ``double`` -> float64).
        Units are those of the writer (SI for LIGGGHTS with ``units si``).

    Raises
    ------
    DumpFormatError
        When the file is truncated, a count disagrees with the data, a type is unknown, a
        number is garbled, POINTS are missing, the dataset is not POLYDATA, or a floating
        value (points or any point-data field) is not finite. The message starts with ``source``.
    """
    cursor = _Cursor(content, source, binary=False, pos=0)
    cursor.binary, cursor.pos = _read_header(content, cursor)
    dataset = cursor.next_line("DATASET POLYDATA")
    if [token.upper() for token in dataset[:1]] != ["DATASET"] or len(dataset) != 2:
        raise cursor.error(f"expected 'DATASET POLYDATA', found {' '.join(dataset)!r}")
    if dataset[1].upper() != "POLYDATA":
        raise cursor.error(f"dataset is {dataset[1]}, not POLYDATA (a bounding-box file?)")

    points: np.ndarray | None = None
    point_arrays: dict[str, np.ndarray] = {}
    section: str | None = None  # None (dataset level), "POINT_DATA" or "CELL_DATA"
    n_section_tuples = -1
    while not cursor.at_end():
        tokens = cursor.next_line("a section keyword")
        keyword = tokens[0].upper()
        if keyword == "POINTS":
            _require_tokens(tokens, 3, 3, "POINTS n type", cursor)
            if points is not None:
                raise cursor.error("a second POINTS section")
            n_points = _parse_int(tokens[1], "POINTS", cursor)
            flat = cursor.read_array(3 * n_points, tokens[2], "POINTS", unit=3, unit_name="points")
            _check_finite(flat, "POINTS", cursor, 3)
            points = flat.reshape(n_points, 3)
        elif keyword in _CELL_SECTIONS:
            _read_cells(tokens, None if points is None else len(points), cursor)
        elif keyword in ("POINT_DATA", "CELL_DATA"):
            _require_tokens(tokens, 2, 2, f"{keyword} n", cursor)
            n_section_tuples = _parse_int(tokens[1], keyword, cursor)
            section = keyword
            if keyword == "POINT_DATA":
                if points is None:
                    raise cursor.error("POINT_DATA comes before POINTS")
                if n_section_tuples != len(points):
                    raise cursor.error(
                        f"POINT_DATA declares {n_section_tuples} points but POINTS has {len(points)}"
                    )
        elif keyword in ("FIELD", "SCALARS", "VECTORS", "NORMALS"):
            if keyword != "FIELD" and section is None:
                raise cursor.error(f"{keyword} outside POINT_DATA/CELL_DATA")
            arrays = _read_attribute_arrays(tokens, n_section_tuples if section else -1, cursor)
            if section == "POINT_DATA":
                for name, values in arrays:
                    if name == "points" or name in point_arrays:
                        raise cursor.error(f"point-data array name {name!r} occurs twice or is reserved")
                    n_components = 1 if values.ndim == 1 else values.shape[1]
                    _check_finite(values.reshape(-1), f"field {name!r}", cursor, n_components)
                    point_arrays[name] = values
        elif keyword == "METADATA":
            cursor.skip_metadata()
        else:
            raise cursor.error(f"unknown or unsupported section {tokens[0]!r}")
    if points is None:
        raise cursor.error("no POINTS section")
    return {"points": points, **point_arrays}


# --------------------------------------------------------------------------- formatting


def _format_values(values: np.ndarray, binary: bool) -> bytes:
    flat = values.ravel()
    if binary:
        return flat.astype(flat.dtype.newbyteorder(">")).tobytes() + b"\n"
    # repr of a Python float is the shortest string that reads back to the same double,
    # so ASCII round trips are exact (float32 goes through its exact double value).
    texts = [repr(v) for v in flat.tolist()] if flat.dtype.kind == "f" else [str(v) for v in flat.tolist()]
    lines = [
        " ".join(texts[i : i + _ASCII_VALUES_PER_LINE]) for i in range(0, len(texts), _ASCII_VALUES_PER_LINE)
    ]
    return ("\n".join(lines) + "\n").encode("ascii")


def format_legacy_vtk_polydata(
    points: np.ndarray, fields: Mapping[str, np.ndarray], binary: bool = True
) -> bytes:
    """Format points and point fields as a legacy VTK POLYDATA file (the LIGGGHTS layout).

    The layout is the one LIGGGHTS writes: VTK 5.1 header, POINTS, one vertex per point
    (VERTICES with vtktypeint64 OFFSETS and CONNECTIVITY) and a ``FIELD FieldData`` block
    under POINT_DATA. Like LIGGGHTS, a file with no points holds only an empty POINTS
    section (fields of length 0 are then not written).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Point coordinates [m]. float32 is written as ``float``, anything else as ``double``.
    fields : mapping of str to array_like
        Point-data arrays of shape (n,) or (n, k). Supported dtypes: int16/32/64,
        uint8/16/32/64, float32, float64 (int64 is written as ``vtktypeint64``).
    binary : bool
        Big-endian BINARY variant when True, ASCII otherwise (floats written with the
        shortest exact representation, so both variants read back exactly).

    Returns
    -------
    bytes
        The file content.

    Raises
    ------
    ValueError
        On a wrong shape, an unsupported dtype, or an empty or reserved field name.
    """
    points = np.asarray(points)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {points.shape}")
    # float32 stays "float" (as LIGGGHTS writes positions); everything else becomes "double"
    is_float32 = points.dtype.kind == "f" and points.dtype.itemsize == 4
    points = points.astype(np.float32 if is_float32 else np.float64)
    n = points.shape[0]
    chunks = [
        b"# vtk DataFile Version 5.1\n",
        b"Generated by siloflow\n",
        b"BINARY\n" if binary else b"ASCII\n",
        b"DATASET POLYDATA\n",
        f"POINTS {n} {_VTK_WRITE_TYPES[points.dtype]}\n".encode("ascii"),
        _format_values(points, binary),
    ]
    prepared = []
    for name, values in fields.items():
        values = np.asarray(values)
        if not name or name == "points":
            raise ValueError(f"field name {name!r} is empty or reserved")
        if values.ndim not in (1, 2) or values.shape[0] != n or (values.ndim == 2 and values.shape[1] < 1):
            raise ValueError(f"field {name!r} must have shape ({n},) or ({n}, k), got {values.shape}")
        vtk_type = _VTK_WRITE_TYPES.get(values.dtype.newbyteorder("="))
        if vtk_type is None:
            raise ValueError(f"field {name!r}: dtype {values.dtype} has no legacy VTK type here")
        prepared.append((name, values, vtk_type))
    if n == 0:
        return b"".join(chunks)
    vertex_ids = np.arange(n + 1, dtype=np.int64)
    chunks += [
        f"VERTICES {n + 1} {n}\n".encode("ascii"),
        b"OFFSETS vtktypeint64\n",
        _format_values(vertex_ids, binary),
        b"CONNECTIVITY vtktypeint64\n",
        _format_values(vertex_ids[:n], binary),
    ]
    if prepared:
        chunks += [f"POINT_DATA {n}\n".encode("ascii"), f"FIELD FieldData {len(prepared)}\n".encode("ascii")]
        for name, values, vtk_type in prepared:
            n_components = 1 if values.ndim == 1 else values.shape[1]
            chunks.append(f"{_encode_name(name)} {n_components} {n} {vtk_type}\n".encode("ascii"))
            chunks.append(_format_values(values, binary))
    return b"".join(chunks)


def write_legacy_vtk_polydata(
    path: str | os.PathLike, points: np.ndarray, fields: Mapping[str, np.ndarray], binary: bool = True
) -> Path:
    """Write :func:`format_legacy_vtk_polydata` output to ``path``; return the path.

    Parameters
    ----------
    path : str or path-like
        File to write (its folder must exist).
    points : array_like, shape (n, 3)
        Point coordinates [m].
    fields : mapping of str to array_like
        Point-data arrays of shape (n,) or (n, k).
    binary : bool
        BINARY (big-endian) when True, ASCII otherwise.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    path = Path(path)
    path.write_bytes(format_legacy_vtk_polydata(points, fields, binary))
    return path


# --------------------------------------------------------------------------- arrays to frames


def _vector_field(arrays: Mapping[str, np.ndarray], vector: str, components: tuple[str, str, str], n: int,
                  source: str) -> np.ndarray | None:
    if vector in arrays:
        values = np.asarray(arrays[vector])
        if values.shape != (n, 3):
            raise DumpFormatError(f"{source}: field {vector!r} has shape {values.shape}, expected ({n}, 3)")
        return values.astype(np.float64)
    if all(name in arrays for name in components):
        return np.stack([np.asarray(arrays[name], dtype=np.float64).reshape(n) for name in components], axis=1)
    return None


def _integer_field(values: np.ndarray, name: str, source: str) -> np.ndarray:
    values = np.asarray(values)
    if values.dtype.kind in "iu":
        return values.astype(np.int64)
    if values.dtype.kind == "f" and np.all(np.isfinite(values)) and np.all(values == np.round(values)):
        return values.astype(np.int64)  # e.g. ids written as double by another writer
    raise DumpFormatError(f"{source}: field {name!r} must hold integers, got dtype {values.dtype}")


def frame_from_arrays(
    arrays: Mapping[str, np.ndarray], step: int, time: float, *, source: str = "<arrays>"
) -> ParticleFrame:
    """Build a :class:`ParticleFrame` from the arrays of :func:`parse_legacy_vtk_polydata`.

    Parameters
    ----------
    arrays : mapping of str to numpy.ndarray
        ``points`` (n, 3) [m] (or ``x``, ``y``, ``z``), ``id``, ``type``, ``radius`` [m],
        ``mass`` [kg], velocity as ``v`` (n, 3) or ``vx``/``vy``/``vz`` [m/s], angular
        velocity as ``omega`` or ``omegax``/``omegay``/``omegaz`` [rad/s]; optional
        ``id_multisphere`` (absent, 0 or negative for a free sphere; LIGGGHTS writes -1)
        and force as ``f`` or ``fx``/``fy``/``fz`` [N]. A frame with no points may lack
        every field.
    step : int
        Time step number of the dump [-].
    time : float
        Simulated time [s].
    source : str
        Name of the dump for error messages.

    Returns
    -------
    ParticleFrame
        The frame; a free sphere gets its own sphere id as clump id, negated when the dump has
        ``id_multisphere`` so that it cannot collide with a clump id.

    Raises
    ------
    DumpFormatError
        When a required field is missing or malformed, or a position or velocity is not
        finite.
    """
    if "points" in arrays:
        position = np.asarray(arrays["points"], dtype=np.float64)
    elif all(name in arrays for name in ("x", "y", "z")):
        position = np.stack([np.asarray(arrays[name], dtype=np.float64) for name in ("x", "y", "z")], axis=1)
    else:
        raise DumpFormatError(f"{source}: no positions (points or x, y, z)")
    if position.ndim != 2 or position.shape[1] != 3:
        raise DumpFormatError(f"{source}: positions have shape {position.shape}, expected (n, 3)")
    n = position.shape[0]

    velocity = _vector_field(arrays, "v", ("vx", "vy", "vz"), n, source)
    angular_velocity = _vector_field(arrays, "omega", ("omegax", "omegay", "omegaz"), n, source)
    force = _vector_field(arrays, "f", ("fx", "fy", "fz"), n, source)
    present = {
        "id": "id" in arrays,
        "type": "type" in arrays,
        "radius": "radius" in arrays,
        "mass": "mass" in arrays,
        "v (or vx vy vz)": velocity is not None,
    }
    missing = [name for name, found in present.items() if not found]
    if missing and n > 0:
        raise DumpFormatError(
            f"{source}: missing fields {', '.join(missing)} (dump at least 'id type id_multisphere x y z vx vy vz "
            "radius mass')"
        )

    def column(name: str) -> np.ndarray:
        if name not in arrays:  # only reached for an empty frame
            return np.empty(0)
        values = np.asarray(arrays[name])
        if values.shape != (n,):
            raise DumpFormatError(f"{source}: field {name!r} has shape {values.shape}, expected ({n},)")
        return values

    empty_vectors = np.empty((0, 3))
    for name, values in (("points", position), ("v", velocity), ("omega", angular_velocity)):
        if values is not None and not np.all(np.isfinite(values)):
            raise DumpFormatError(f"{source}: field {name!r} contains non-finite values")

    ids = _integer_field(column("id"), "id", source)
    clump_id = ids.copy()
    if "id_multisphere" in arrays:
        body = _integer_field(column("id_multisphere"), "id_multisphere", source)
        in_clump = body > 0
        # A sphere outside any body (a free sphere, or the remnant of a clump that was cut in two as it
        # left the domain) gets the negative of its sphere id, which can never equal a clump id.
        clump_id[in_clump] = body[in_clump]
        clump_id[~in_clump] = -ids[~in_clump]
    try:
        return ParticleFrame(
            time=time,
            step=step,
            id=ids,
            type=_integer_field(column("type"), "type", source),
            clump_id=clump_id,
            position=position,
            velocity=empty_vectors if velocity is None else velocity,
            angular_velocity=empty_vectors if angular_velocity is None and n == 0 else angular_velocity,
            radius=column("radius"),
            mass=column("mass"),
            force=force,
        )
    except ValueError as error:
        raise DumpFormatError(f"{source}: {error}") from None



# --------------------------------------------------------------------------- files


def dump_step(path: str | os.PathLike) -> int:
    """Time step number in a dump file name: the integer after the last underscore.

    Parameters
    ----------
    path : str or path-like
        E.g. ``dumps/silo_12000.vtk``.

    Returns
    -------
    int
        E.g. 12000.

    Raises
    ------
    ValueError
        When the name does not end in ``_<digits>`` before its extension.
    """
    stem = Path(path).stem
    _, underscore, digits = stem.rpartition("_")
    if not underscore or not digits.isdigit() or not digits.isascii():
        raise ValueError(f"{path}: file name does not end in _<step>")
    return int(digits)


def list_dumps(dump_dir: str | os.PathLike, prefix: str) -> list[Path]:
    """Dump files ``<prefix>_<digits>.vtk`` in a folder, sorted by step.

    Files such as ``<prefix>_boundingBox_<step>.vtk`` are ignored.

    Parameters
    ----------
    dump_dir : str or path-like
        Folder holding the dumps.
    prefix : str
        File name prefix (``silo`` for ``silo_*.vtk``).

    Returns
    -------
    list of pathlib.Path
        Ascending by step number (numerically: 2000 before 10000).
    """
    pattern = re.compile(re.escape(prefix) + r"_([0-9]+)\.vtk")
    matches = [
        (int(match.group(1)), entry)
        for entry in Path(dump_dir).iterdir()
        if (match := pattern.fullmatch(entry.name)) and entry.is_file()
    ]
    return [entry for _, entry in sorted(matches)]


_CACHE_FORMAT = 2  # bump when the cached arrays change meaning (2: angular velocity optional)
_FRAME_ARRAYS = ("id", "type", "clump_id", "position", "velocity", "radius", "mass")
#: Per-sphere vectors a dump may leave out (None in the frame).


def _cache_path(dump: Path, cache_dir: Path) -> Path:
    return cache_dir / (dump.name.rsplit(".", 1)[0] + ".npz")


def _load_cache(cache_path: Path, dump: Path, dump_stat: os.stat_result) -> dict[str, np.ndarray] | None:
    """Cached arrays when the entry is complete and matches the dump; otherwise None."""
    try:
        if cache_path.stat().st_mtime_ns < dump_stat.st_mtime_ns:
            return None
        with np.load(cache_path, allow_pickle=False) as data:
            cached = {key: data[key] for key in data.files}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None  # no entry, or one that cannot be read: parse the dump again
    try:
        valid = (
            int(cached["cache_format"]) == _CACHE_FORMAT
            and int(cached["source_size"]) == dump_stat.st_size
            and int(cached["source_mtime_ns"]) == dump_stat.st_mtime_ns
            and str(cached["source_name"]) == dump.name
            and all(name in cached for name in _FRAME_ARRAYS)
        )
    except (KeyError, ValueError, TypeError):
        return None
    return cached if valid else None


def _write_cache(cache_path: Path, dump: Path, dump_stat: os.stat_result, frame: ParticleFrame) -> None:
    """Write the cache entry atomically: a killed writer leaves only a temporary file."""
    cache_path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {name: getattr(frame, name) for name in _FRAME_ARRAYS}
    arrays.update({name: getattr(frame, name) for name in OPTIONAL_VECTORS if getattr(frame, name) is not None})
    fd, temporary = tempfile.mkstemp(dir=cache_path.parent, prefix=f".{cache_path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, 0o644)  # mkstemp makes 0600; others on the cluster read the cache too
        with os.fdopen(fd, "wb") as handle:
            np.savez(
                handle,
                cache_format=np.int64(_CACHE_FORMAT),
                source_name=np.str_(dump.name),
                source_size=np.int64(dump_stat.st_size),
                source_mtime_ns=np.int64(dump_stat.st_mtime_ns),
                step=np.int64(frame.step),
                **arrays,
            )
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, cache_path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


def read_frame(
    path: str | os.PathLike, timestep: float, cache_dir: str | os.PathLike | None = None
) -> ParticleFrame:
    """Read one LIGGGHTS dump into a :class:`ParticleFrame`, parsing it at most once.

    Parameters
    ----------
    path : str or path-like
        Dump file ``<prefix>_<step>.vtk``.
    timestep : float
        Simulation time step [s]; the frame time is ``step * timestep``.
    cache_dir : str or path-like, optional
        Folder for the compact cache (``<prefix>_<step>.npz``, uncompressed). An entry is
        reused when it is at least as new as the dump and records the dump's name, size
        and mtime_ns; otherwise the dump is parsed and the entry rewritten atomically
        (temporary file + ``os.replace``). A dump that changes while it is read is parsed
        but not cached.

    Returns
    -------
    ParticleFrame
        The spheres of that step.

    Raises
    ------
    DumpFormatError
        When the dump is malformed (the message names the file).
    ValueError
        When ``timestep`` is not a finite positive number or the name has no step.
    """
    path = Path(path)
    timestep = float(timestep)
    if not np.isfinite(timestep) or timestep <= 0:
        raise ValueError(f"timestep must be a finite positive number of seconds, got {timestep!r}")
    step = dump_step(path)
    time = step * timestep
    if cache_dir is None:
        return frame_from_arrays(parse_legacy_vtk_polydata(path.read_bytes(), str(path)), step, time, source=str(path))

    cache_path = _cache_path(path, Path(cache_dir))
    stat_before = path.stat()
    cached = _load_cache(cache_path, path, stat_before)
    if cached is not None:
        return ParticleFrame(
            time=time,
            step=step,
            **{name: cached.get(name) for name in OPTIONAL_VECTORS},
            **{name: cached[name] for name in _FRAME_ARRAYS},
        )
    content = path.read_bytes()
    frame = frame_from_arrays(parse_legacy_vtk_polydata(content, str(path)), step, time, source=str(path))
    stat_after = path.stat()
    unchanged = (
        len(content) == stat_before.st_size == stat_after.st_size
        and stat_before.st_mtime_ns == stat_after.st_mtime_ns
    )
    if unchanged:
        _write_cache(cache_path, path, stat_before, frame)
    return frame


DAMAGED_DUMP_POLICIES = ("error", "skip")


def readable_frames(paths, timestep: float, cache_dir: str | os.PathLike | None = None,
                    on_damaged: str = "error") -> Iterator[ParticleFrame]:
    """Read dumps one after another; a damaged one (truncated, garbled number, non-finite value) raises
    :class:`DumpFormatError` naming the file, or with ``on_damaged="skip"`` is left out with a warning
    (``warnings`` and the ``siloflow`` logger) that names the file and the problem."""
    if on_damaged not in DAMAGED_DUMP_POLICIES:
        raise ValueError(f"on_damaged must be one of {DAMAGED_DUMP_POLICIES}, got {on_damaged!r}")
    for path in paths:
        try:
            yield read_frame(path, timestep, cache_dir)
        except DumpFormatError as error:
            if on_damaged == "error":
                raise
            message = f"skipping damaged dump ({error})"
            warnings.warn(message, stacklevel=2)
            logging.getLogger("siloflow").warning(message)


def read_frames(
    dump_dir: str | os.PathLike, prefix: str, timestep: float, cache_dir: str | os.PathLike | None = None,
    on_damaged: str = "error",
) -> list[ParticleFrame]:
    """Read every ``<prefix>_<step>.vtk`` dump of a folder, in step order.

    Parameters
    ----------
    dump_dir : str or path-like
        Folder holding the dumps.
    prefix : str
        Dump file name prefix.
    timestep : float
        Simulation time step [s].
    cache_dir : str or path-like, optional
        Cache folder, see :func:`read_frame`.
    on_damaged : {"error", "skip"}
        What a damaged dump does (:func:`readable_frames`).

    Returns
    -------
    list of ParticleFrame
        One frame per readable dump, ascending step.
    """
    return list(readable_frames(list_dumps(dump_dir, prefix), timestep, cache_dir, on_damaged))
