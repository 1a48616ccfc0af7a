"""Writers and readers of coarse-grained fields: VTK image data (.vti) with a .pvd index, and .npz.

- :func:`write_fields_vti` writes one :class:`~siloflow.analysis.numerics.grid.Fields` as a VTK XML ImageData file
  through :class:`pyvista.ImageData` and pyvista's ``XMLImageDataWriter``; :func:`write_pvd` writes the
  ParaView collection that makes a time series of them.
- :func:`read_fields_vti` reads such a file back through :func:`pyvista.read` (used to check the files in
  the tests; ParaView is the usual reader). :func:`read_pvd` reads a .pvd's entries back (time, file), through
  :class:`pyvista.PVDReader`.
- :func:`save_fields_npz` / :func:`load_fields_npz` store the exact arrays (float64, lossless) as a compact
  compressed .npz, the cache the analysis reads back (``averaged.npz`` of the silo workflow).

Every writer writes to a temporary file in the destination folder and moves it into place with
:func:`os.replace` (:func:`siloflow.analysis.io.tables.atomic_output`), so no reader ever sees a half-written file.

Why the two small hand-made parts
---------------------------------
* The .vti is written in VTK's *appended raw* mode (UInt64 headers) rather than with
  :meth:`pyvista.DataObject.save`, whose inline base64 makes the file a third larger (measured: 302 kB
  against 228 kB for the 25 x 10 x 10 test field, zlib in both) for no gain; it is three setter calls on the
  VTK writer that pyvista wraps (:func:`siloflow.analysis.io.vtk_xml.write_vtk_xml`, which every VTK file goes through).
* The .pvd index is written here with :mod:`xml.etree.ElementTree`: pyvista only reads PVD
  (:class:`pyvista.PVDReader`), meshio writes time series as XDMF only, and VTK's PVD writer
  (``vtkXMLPVDWriter``) ships with ParaView, not VTK.
* VTK writes array names into the XML unescaped (measured: a name with ``<`` gives a file pyvista cannot
  read), so names are checked here.

Layout of a .vti
----------------
* Point data on the grid nodes (the cell centres of :class:`~siloflow.analysis.numerics.grid.Grid`): the image
  origin is the first node, ``grid.origin + spacing / 2``, and the dimensions are ``grid.shape``, so
  ParaView interpolates between nodes (slices, plot over line, stream tracers). With ``cell_data=True``
  the arrays are written as cell data of an image whose cells are the grid cells (origin ``grid.origin``,
  dimensions ``grid.shape + 1``) instead.
* Arrays (Float64 unless noted): ``density`` [kg/m3]; ``velocity`` (3 components) [m/s];
  ``momentum_density`` (3) [kg/(m2 s)]; ``kinetic_stress`` (9 components, the full 3 x 3 tensor in
  row-major order xx, xy, xz, yx, yy, yz, zx, zy, zz; compression positive) [Pa]; ``mask`` (UInt8, 1 at
  nodes with particles). Extra arrays (e.g. a contact stress) may be added; tensors of shape (3, 3) are
  flattened the same way. ``density``, ``velocity`` and ``kinetic_stress`` are the active scalars,
  vectors and tensors.
* Field data: ``grid_origin``, ``grid_spacing`` (exact grid, so reading back is lossless),
  ``density_threshold``, and ``TimeValue`` [s] when a time is given (ParaView shows it).
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ElementTree
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pyvista

from siloflow.analysis.io.tables import atomic_output
from siloflow.analysis.io.vtk_xml import checked_array_name, write_vtk_xml
from siloflow.analysis.numerics.grid import Fields, Grid

__all__ = [
    "NPZ_FORMAT",
    "fields_image",
    "write_fields_vti",
    "write_pvd",
    "read_pvd",
    "read_fields_vti",
    "save_fields_npz",
    "load_fields_npz",
]

NPZ_FORMAT = "siloflow.api.fields/1"
"""Value of the ``format`` entry of a fields .npz file."""

_VTK_DTYPES = (np.dtype(np.float64), np.dtype(np.float32), np.dtype(np.uint8), np.dtype(np.int32), np.dtype(np.int64))


# --------------------------------------------------------------------------- helpers


def _vtk_order(array: np.ndarray, shape: tuple[int, int, int]) -> np.ndarray:
    """(nx, ny, nz, ...) -> (n_points,) or (n_points, n_components) with x varying fastest, as VTK
    stores images; trailing axes flattened row-major (a 3 x 3 tensor becomes xx, xy, ..., zz)."""
    components = int(np.prod(array.shape[3:], dtype=np.int64)) if array.ndim > 3 else 1
    ordered = array.reshape(shape + (components,)).transpose(2, 1, 0, 3).reshape(-1, components)
    return ordered[:, 0] if components == 1 else ordered


def _grid_shape_of(array, shape: tuple[int, int, int], name: str) -> np.ndarray:
    array = np.asarray(array)
    if array.shape[:3] != shape:
        raise ValueError(f"{name} must have shape {shape} + (components...), got {array.shape}")
    if array.dtype == bool:
        array = array.astype(np.uint8)
    if array.dtype not in _VTK_DTYPES:
        array = array.astype(np.float64)
    if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers")
    return array


# --------------------------------------------------------------------------- VTK writers


def fields_image(
    grid: Grid,
    fields: Fields,
    time: float | None = None,
    extra_arrays: Mapping[str, np.ndarray] | None = None,
    cell_data: bool = False,
) -> pyvista.ImageData:
    """The :class:`pyvista.ImageData` that :func:`write_fields_vti` writes (same arguments, see there)."""
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
        if checked_array_name(name, "extra_arrays") in arrays:
            raise ValueError(f"extra_arrays: the name {name!r} is already used by a standard array")
        arrays[name] = _grid_shape_of(values, shape, f"extra_arrays[{name!r}]")
    if time is not None:
        time = float(time)
        if not math.isfinite(time):
            raise ValueError(f"time must be finite, got {time!r}")

    spacing = np.array(grid.spacing)
    if cell_data:
        image = pyvista.ImageData(dimensions=np.array(shape) + 1, spacing=spacing, origin=np.array(grid.origin))
        data = image.cell_data
    else:
        image = pyvista.ImageData(dimensions=shape, spacing=spacing, origin=np.array(grid.origin) + 0.5 * spacing)
        data = image.point_data
    for name, values in arrays.items():
        data[name] = _vtk_order(np.asarray(values), shape)
    data.active_scalars_name = "density"
    data.active_vectors_name = "velocity"
    data.VTKObject.SetActiveTensors("kinetic_stress")  # pyvista has no property for the active tensors
    image.field_data["grid_origin"] = np.array(grid.origin)
    image.field_data["grid_spacing"] = spacing
    image.field_data["density_threshold"] = np.array([fields.density_threshold])
    if time is not None:
        image.field_data["TimeValue"] = np.array([time])
    return image


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
    return write_vtk_xml(path, fields_image(grid, fields, time, extra_arrays, cell_data), compress)


def write_pvd(path: str | os.PathLike, entries: Sequence[tuple[float, str | os.PathLike]]) -> Path:
    """Write a ParaView collection (.pvd) indexing a time series of .vti files, atomically.

    Hand-written (a few lines of :mod:`xml.etree.ElementTree`) because no declared library writes PVD;
    see the module notes.

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
    root = ElementTree.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    collection = ElementTree.SubElement(root, "Collection")
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
        ElementTree.SubElement(collection, "DataSet", timestep=repr(time), group="", part="0", file=file.as_posix())
    ElementTree.indent(root)
    with atomic_output(path) as temporary:
        ElementTree.ElementTree(root).write(temporary, encoding="utf-8", xml_declaration=True)
    return Path(path)


def read_pvd(path: str | os.PathLike) -> list[tuple[float, Path]]:
    """The entries of a ParaView collection (.pvd), read through :class:`pyvista.PVDReader`.

    Parameters
    ----------
    path : str or os.PathLike
        A .pvd file, e.g. one :func:`write_pvd` wrote.

    Returns
    -------
    list of (float, pathlib.Path)
        ``(time [s], file)`` per data set in the file's order; each file as the .pvd names it, joined to the
        .pvd's folder.
    """
    folder = Path(path).parent
    return [(float(entry.time), folder / entry.path) for entry in pyvista.PVDReader(str(path)).datasets]


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

    Entries: ``format`` (``"siloflow.api.fields/1"``), ``origin``, ``spacing``, ``shape``,
    ``density``, ``momentum_density``, ``velocity``, ``kinetic_stress``, ``mask``,
    ``density_threshold``; arrays in the layout of :class:`~siloflow.analysis.numerics.grid.Fields`.

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
