"""Writers and readers of coarse-grained fields: VTK image data (.vti) with a .pvd index, and .npz.

- :func:`write_fields_vti` writes one :class:`~analysis.numerics.coarse_graining.Fields` as a VTK XML
  ImageData file that ParaView (or pyvista) opens; :func:`write_pvd` writes the ParaView
  collection that makes a time series of them. The XML is written here directly (no VTK
  needed to write): binary appended data, zlib-compressed by default.
- :func:`save_fields_npz` / :func:`load_fields_npz` store the exact arrays (float64, lossless)
  as a compact compressed .npz, the cache the analysis reads back.
- :func:`read_fields_vti` reads a .vti written by :func:`write_fields_vti` back through pyvista
  (used to check the files in the tests; ParaView is the usual reader).

Every writer writes to a temporary file in the destination folder and moves it into place with
:func:`os.replace` (:func:`analysis.io.tables.atomic_output`), so no reader ever sees a half-written
file.

Layout of a .vti
----------------
* Point data on the grid nodes (the cell centres of :class:`~analysis.numerics.coarse_graining.Grid`):
  the image origin is the first node, ``grid.origin + spacing / 2``, and the extent is
  ``0 .. n - 1`` per axis, so ParaView interpolates between nodes (slices, plot over line,
  stream tracers). With ``cell_data=True`` the arrays are written as cell data of an image
  whose cells are the grid cells (origin ``grid.origin``, extent ``0 .. n``) instead.
* Arrays (Float64 unless noted): ``density`` [kg/m3]; ``velocity`` (3 components) [m/s];
  ``momentum_density`` (3) [kg/(m2 s)]; ``kinetic_stress`` (9 components, the full 3 x 3
  tensor in row-major order xx, xy, xz, yx, yy, yz, zx, zy, zz; compression positive) [Pa];
  ``mask`` (UInt8, 1 at nodes with particles). Extra arrays (e.g. a contact stress) may be
  added; tensors of shape (3, 3) are flattened the same way.
* Field data: ``grid_origin``, ``grid_spacing`` (exact grid, so reading back is lossless),
  ``density_threshold``, and ``TimeValue`` [s] when a time is given (ParaView shows it).
"""

from __future__ import annotations

import math
import os
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from analysis.numerics.grid import Fields, Grid
from analysis.io.tables import atomic_output

__all__ = [
    "NPZ_FORMAT",
    "write_fields_vti",
    "write_pvd",
    "read_fields_vti",
    "save_fields_npz",
    "load_fields_npz",
]

NPZ_FORMAT = "siloflow.fields/1"
"""Value of the ``format`` entry of a fields .npz file."""

_BLOCK_SIZE = 1 << 20  # uncompressed bytes per zlib block
_VTK_TYPES = {
    np.dtype(np.float64): "Float64",
    np.dtype(np.float32): "Float32",
    np.dtype(np.uint8): "UInt8",
    np.dtype(np.int32): "Int32",
    np.dtype(np.int64): "Int64",
}


# --------------------------------------------------------------------------- helpers


def _write_bytes_atomic(path: str | os.PathLike, chunks: Sequence[bytes]) -> Path:
    with atomic_output(path) as temporary:
        with open(temporary, "wb") as stream:
            for chunk in chunks:
                stream.write(chunk)
            stream.flush()
            os.fsync(stream.fileno())
    return Path(path)


def _number(value: float) -> str:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write the non-finite number {value!r}")
    return repr(value)


def _encode(values: np.ndarray, compress: bool) -> bytes:
    """One appended DataArray block: UInt64 header(s) + (compressed) little-endian data."""
    raw = np.ascontiguousarray(values).astype(values.dtype.newbyteorder("<"), copy=False).tobytes()
    if not compress:
        return np.array([len(raw)], dtype="<u8").tobytes() + raw
    # vtkZLibDataCompressor layout: [n_blocks, block_size, last_block_size, compressed sizes...].
    blocks = [raw[start : start + _BLOCK_SIZE] for start in range(0, len(raw), _BLOCK_SIZE)] or [b""]
    compressed = [zlib.compress(block, 6) for block in blocks]
    header = [len(blocks), _BLOCK_SIZE, len(blocks[-1])] + [len(block) for block in compressed]
    return np.array(header, dtype="<u8").tobytes() + b"".join(compressed)


def _vtk_order(array: np.ndarray, shape: tuple[int, int, int]) -> tuple[np.ndarray, int]:
    """(nx, ny, nz, ...) -> (n_points, n_components) with x varying fastest, as VTK stores images."""
    components = int(np.prod(array.shape[3:], dtype=np.int64)) if array.ndim > 3 else 1
    flat = array.reshape(shape + (components,))
    return flat.transpose(2, 1, 0, 3).reshape(-1, components), components


def _grid_shape_of(array: np.ndarray, shape: tuple[int, int, int], name: str) -> np.ndarray:
    array = np.asarray(array)
    if array.shape[:3] != shape:
        raise ValueError(f"{name} must have shape {shape} + (components...), got {array.shape}")
    if array.dtype == bool:
        array = array.astype(np.uint8)
    if array.dtype not in _VTK_TYPES:
        array = array.astype(np.float64)
    if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers")
    return array


# --------------------------------------------------------------------------- VTK writers


def write_fields_vti(
    path: str | os.PathLike,
    grid: Grid,
    fields: Fields,
    time: float | None = None,
    extra_arrays: Mapping[str, np.ndarray] | None = None,
    cell_data: bool = False,
    compress: bool = True,
) -> Path:
    """Write fields as a VTK XML ImageData file (.vti), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vti``.
    grid : Grid
        The grid of ``fields`` (must equal ``fields.grid``).
    fields : Fields
        Coarse-grained fields.
    time : float, optional
        Simulated time [s], written as the ``TimeValue`` field-data array.
    extra_arrays : mapping of str to array_like, optional
        More node arrays of shape ``grid.shape + (...)``, e.g. ``{"contact_stress": sigma_c}``;
        (3, 3) tensors become 9 components (row-major). Names must not repeat the standard ones.
    cell_data : bool, optional
        Write cell data on the grid cells instead of point data on the nodes (see the
        module notes).
    compress : bool, optional
        zlib-compress the binary data (default True; lossless).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    if not isinstance(grid, Grid):
        raise ValueError(f"grid must be a Grid, got {type(grid).__name__}")
    if not isinstance(fields, Fields):
        raise ValueError(f"fields must be a Fields, got {type(fields).__name__}")
    if fields.grid != grid:
        raise ValueError(f"grid {grid} differs from the grid of the fields {fields.grid}")
    shape = grid.shape
    arrays: dict[str, np.ndarray] = {
        "density": fields.density,
        "velocity": fields.velocity,
        "momentum_density": fields.momentum_density,
        "kinetic_stress": fields.kinetic_stress,
        "mask": fields.mask.astype(np.uint8),
    }
    for name, values in (extra_arrays or {}).items():
        if not isinstance(name, str) or not name or any(ch in name for ch in "<>&\"'") or name.strip() != name:
            raise ValueError(f"extra_arrays: invalid array name {name!r}")
        if name in arrays:
            raise ValueError(f"extra_arrays: the name {name!r} is already used by a standard array")
        arrays[name] = _grid_shape_of(values, shape, f"extra_arrays[{name!r}]")

    field_data: dict[str, np.ndarray] = {
        "grid_origin": np.array(grid.origin),
        "grid_spacing": np.array(grid.spacing),
        "density_threshold": np.array([fields.density_threshold]),
    }
    if time is not None:
        time = float(time)
        if not math.isfinite(time):
            raise ValueError(f"time must be finite, got {time!r}")
        field_data["TimeValue"] = np.array([time])

    spacing = np.array(grid.spacing)
    if cell_data:
        origin = np.array(grid.origin)
        extent = f"0 {shape[0]} 0 {shape[1]} 0 {shape[2]}"
        section = "CellData"
    else:
        origin = np.array(grid.origin) + 0.5 * spacing
        extent = f"0 {shape[0] - 1} 0 {shape[1] - 1} 0 {shape[2] - 1}"
        section = "PointData"

    blocks: list[bytes] = []
    offset = 0
    declarations: list[str] = []

    def declare(name: str, values: np.ndarray, components: int, tuples: int | None = None) -> None:
        nonlocal offset
        block = _encode(values, compress)
        vtk_type = _VTK_TYPES[values.dtype.newbyteorder("=")]
        tuples_attribute = f' NumberOfTuples="{tuples}"' if tuples is not None else ""
        declarations.append(
            f'        <DataArray type="{vtk_type}" Name={quoteattr(name)} NumberOfComponents="{components}"'
            f'{tuples_attribute} format="appended" offset="{offset}"/>'
        )
        blocks.append(block)
        offset += len(block)

    for name, values in arrays.items():
        ordered, components = _vtk_order(np.asarray(values), shape)
        declare(name, ordered, components)
    point_declarations = declarations
    declarations = []
    for name, values in field_data.items():
        declare(name, values.astype(np.float64), 1, tuples=values.size)
    field_declarations = declarations

    compressor = ' compressor="vtkZLibDataCompressor"' if compress else ""
    lines = [
        '<?xml version="1.0"?>',
        f'<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64"{compressor}>',
        f'  <ImageData WholeExtent="{extent}" Origin="{" ".join(_number(v) for v in origin)}" '
        f'Spacing="{" ".join(_number(v) for v in spacing)}" Direction="1 0 0 0 1 0 0 0 1">',
        "    <FieldData>",
        *[line[4:] for line in field_declarations],
        "    </FieldData>",
        f'    <Piece Extent="{extent}">',
        f'      <{section} Scalars="density" Vectors="velocity" Tensors="kinetic_stress">',
        *point_declarations,
        f"      </{section}>",
        "    </Piece>",
        "  </ImageData>",
        '  <AppendedData encoding="raw">',
        "   _",
    ]
    head = ("\n".join(lines)).encode("ascii")
    tail = b"\n  </AppendedData>\n</VTKFile>\n"
    return _write_bytes_atomic(path, [head, *blocks, tail])


def write_pvd(path: str | os.PathLike, entries: Sequence[tuple[float, str | os.PathLike]]) -> Path:
    """Write a ParaView collection (.pvd) indexing a time series of .vti files, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.pvd``.
    entries : sequence of (float, path)
        ``(time [s], file)`` pairs, one per data set. A relative file is taken relative to
        the folder of the .pvd (as ParaView reads it); an absolute one is rewritten relative
        to it. Times must be finite; entries are written in the order given.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    entries = list(entries)
    if not entries:
        raise ValueError("entries must contain at least one (time, path) pair")
    folder = Path(path).parent
    rows = []
    for index, entry in enumerate(entries):
        try:
            time, file = entry
        except (TypeError, ValueError):
            raise ValueError(f"entries[{index}] must be a (time, path) pair, got {entry!r}") from None
        time = float(time)
        if not math.isfinite(time):
            raise ValueError(f"entries[{index}]: time must be finite, got {time!r}")
        file = Path(file)
        if file.is_absolute():
            file = Path(os.path.relpath(file, folder.resolve()))
        if not str(file) or str(file) == ".":
            raise ValueError(f"entries[{index}]: empty file name")
        rows.append(
            f'    <DataSet timestep="{_number(time)}" group="" part="0" file={quoteattr(file.as_posix())}/>'
        )
    text = "\n".join(
        [
            '<?xml version="1.0"?>',
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
            "  <Collection>",
            *rows,
            "  </Collection>",
            "</VTKFile>",
            "",
        ]
    )
    return _write_bytes_atomic(path, [text.encode("utf-8")])


def read_fields_vti(path: str | os.PathLike) -> Fields:
    """Read a .vti written by :func:`write_fields_vti` (through pyvista) back into Fields.

    Parameters
    ----------
    path : str or os.PathLike
        A .vti file with the standard arrays.

    Returns
    -------
    Fields
        The fields; float64 arrays round-trip exactly, and the grid too (from the
        ``grid_origin`` / ``grid_spacing`` field data).
    """
    import pyvista

    image = pyvista.read(str(path))
    if "density" in image.point_data:
        data = image.point_data
        shape = tuple(int(n) for n in image.dimensions)
    elif "density" in image.cell_data:
        data = image.cell_data
        shape = tuple(int(n) - 1 for n in image.dimensions)
    else:
        raise ValueError(f"path: {path} holds no 'density' array; not written by write_fields_vti")
    missing = [name for name in ("velocity", "momentum_density", "kinetic_stress", "mask") if name not in data]
    if missing:
        raise ValueError(f"path: {path} lacks the arrays {missing}")
    if "grid_origin" in image.field_data and "grid_spacing" in image.field_data:
        origin = tuple(float(v) for v in image.field_data["grid_origin"])
        spacing = tuple(float(v) for v in image.field_data["grid_spacing"])
    else:
        spacing = tuple(float(v) for v in image.spacing)
        origin = tuple(float(o) - (0.0 if data is image.cell_data else 0.5 * d) for o, d in zip(image.origin, spacing))
    grid = Grid(origin=origin, spacing=spacing, shape=shape)
    threshold = (
        float(image.field_data["density_threshold"][0]) if "density_threshold" in image.field_data else None
    )

    def node_array(name: str, tail: tuple[int, ...]) -> np.ndarray:
        values = np.asarray(data[name])
        components = int(np.prod(tail, dtype=np.int64)) if tail else 1
        return values.reshape(shape[::-1] + (components,)).transpose(2, 1, 0, 3).reshape(shape + tail)

    kwargs = {} if threshold is None else {"density_threshold": threshold}
    return Fields(
        grid=grid,
        density=node_array("density", ()),
        momentum_density=node_array("momentum_density", (3,)),
        velocity=node_array("velocity", (3,)),
        kinetic_stress=node_array("kinetic_stress", (3, 3)),
        mask=node_array("mask", ()).astype(bool),
        **kwargs,
    )


# --------------------------------------------------------------------------- npz


def save_fields_npz(path: str | os.PathLike, fields: Fields, compress: bool = True) -> Path:
    """Save fields (and their grid) losslessly as a .npz, atomically.

    Entries: ``format`` (``"siloflow.fields/1"``), ``origin``, ``spacing``, ``shape``,
    ``density``, ``momentum_density``, ``velocity``, ``kinetic_stress``, ``mask``,
    ``density_threshold``; arrays in the layout of :class:`~analysis.numerics.coarse_graining.Fields`.

    Parameters
    ----------
    path : str or os.PathLike
        Destination (the name is used as given; numpy's automatic ``.npz`` suffix is not added).
    fields : Fields
        Fields to save.
    compress : bool, optional
        Use zlib compression (default True).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    if not isinstance(fields, Fields):
        raise ValueError(f"fields must be a Fields, got {type(fields).__name__}")
    grid = fields.grid
    save = np.savez_compressed if compress else np.savez
    with atomic_output(path) as temporary:
        with open(temporary, "wb") as stream:
            save(
                stream,
                format=np.array(NPZ_FORMAT),
                origin=np.array(grid.origin),
                spacing=np.array(grid.spacing),
                shape=np.array(grid.shape, dtype=np.int64),
                density=fields.density,
                momentum_density=fields.momentum_density,
                velocity=fields.velocity,
                kinetic_stress=fields.kinetic_stress,
                mask=fields.mask,
                density_threshold=np.array(fields.density_threshold),
            )
            stream.flush()
            os.fsync(stream.fileno())
    return Path(path)


def load_fields_npz(path: str | os.PathLike) -> Fields:
    """Load fields saved by :func:`save_fields_npz` (exactly as saved).

    Raises
    ------
    ValueError
        If the file is not a fields .npz of a known format version (naming ``path``).
    """
    with np.load(path, allow_pickle=False) as data:
        keys = set(data.files)
        if "format" not in keys or str(data["format"]) != NPZ_FORMAT:
            raise ValueError(f"path: {path} is not a fields file of format {NPZ_FORMAT!r}")
        required = {"origin", "spacing", "shape", "density", "momentum_density", "velocity", "kinetic_stress", "mask"}
        missing = sorted(required - keys)
        if missing:
            raise ValueError(f"path: {path} lacks the entries {missing}")
        grid = Grid(
            origin=tuple(data["origin"].tolist()),
            spacing=tuple(data["spacing"].tolist()),
            shape=tuple(int(n) for n in data["shape"]),
        )
        kwargs = {}
        if "density_threshold" in keys:
            kwargs["density_threshold"] = float(data["density_threshold"])
        return Fields(
            grid=grid,
            density=data["density"],
            momentum_density=data["momentum_density"],
            velocity=data["velocity"],
            kinetic_stress=data["kinetic_stress"],
            mask=data["mask"],
            **kwargs,
        )
