"""Writer of depth-averaged planar fields for ParaView: VTK XML ImageData (.vti) per field and a .pvd index.

The blender's fields and those of the recirculating silo are depth-averaged on x-z bins
(:class:`siloflow.analysis.studies.blender.window_fields.PlanarField`: mass-weighted velocity and solid fraction, NaN
velocity in bins no clump entered), not the 3-D coarse-grained :class:`siloflow.analysis.numerics.grid.Fields` of the
flat-bottom silo that :func:`siloflow.analysis.io.fields.write_fields_vti` writes: they carry no density or kinetic stress, so
they get their own image here, through the same writer (:func:`siloflow.analysis.io.vtk_xml.write_vtk_xml`) and index
(:func:`siloflow.analysis.io.fields.write_pvd`).

Layout of a .vti
----------------
* A one-node-thick image in the x-z plane at the given ``y`` (normally mid-depth, so that it cuts through the
  particles): dimensions ``(nx, 1, nz)``, point data on the bin centres (origin the first centre, spacing the bin
  edges), x varying fastest, as :mod:`siloflow.analysis.io.fields` lays out its images.
* Point data: ``velocity`` (3 components; v_y is 0, the fields being depth averages) [m/s], 0 in bins no clump
  entered; ``solid_fraction`` [-]; ``mask`` (UInt8, 1 in bins a clump entered). ``velocity`` and
  ``solid_fraction`` are the active vectors and scalars.
* Field data: ``window`` (start, end) [s] and ``n_frames`` [-] of the average, and ``TimeValue`` [s] when a time is
  given.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pyvista

from siloflow.analysis.io.fields import write_pvd
from siloflow.analysis.io.vtk_xml import write_vtk_xml
from siloflow.analysis.studies.blender.window_fields import PlanarField

__all__ = ["planar_field_image", "write_planar_field_vti", "write_planar_field_series"]


def _uniform_step(name: str, centres: np.ndarray) -> float | None:
    """The spacing of uniform bin centres [m]; None for a single bin; ValueError for uneven ones."""
    if centres.size < 2:
        return None
    steps = np.diff(centres)
    step = float(steps.mean())
    if not step > 0.0 or not np.allclose(steps, step, rtol=1e-9, atol=0.0):
        raise ValueError(f"field.{name}: the bin centres must be increasing and evenly spaced")
    return step


def planar_field_image(field: PlanarField, y: float = 0.0, time: float | None = None) -> pyvista.ImageData:
    """The :class:`pyvista.ImageData` that :func:`write_planar_field_vti` writes (same arguments, see there)."""
    if not isinstance(field, PlanarField):
        raise ValueError(f"field must be a PlanarField, got {type(field).__name__}")
    x, z = np.asarray(field.x, dtype=float), np.asarray(field.z, dtype=float)
    shape = (x.size, z.size)
    for name in ("v_x", "v_z", "solid_fraction"):
        if np.shape(getattr(field, name)) != shape:
            raise ValueError(f"field.{name} must have shape {shape} (x bins, z bins), got "
                             f"{np.shape(getattr(field, name))}")
    dx, dz = _uniform_step("x", x), _uniform_step("z", z)
    # a single bin along an axis has no spacing of its own; the other axis' stands in (ParaView needs one > 0)
    dx, dz = dx or dz or 1.0, dz or dx or 1.0
    y = float(y)
    if not math.isfinite(y):
        raise ValueError(f"y must be finite, got {y!r}")
    v_x, v_z = np.asarray(field.v_x, dtype=float), np.asarray(field.v_z, dtype=float)
    entered = np.isfinite(v_x) & np.isfinite(v_z)
    velocity = np.zeros(shape + (3,))
    velocity[..., 0] = np.where(entered, v_x, 0.0)
    velocity[..., 2] = np.where(entered, v_z, 0.0)

    image = pyvista.ImageData(dimensions=(x.size, 1, z.size), spacing=(dx, dx, dz), origin=(x[0], y, z[0]))
    # (nx, nz) arrays to VTK's point order, x fastest
    image.point_data["velocity"] = velocity.transpose(1, 0, 2).reshape(-1, 3)
    image.point_data["solid_fraction"] = np.asarray(field.solid_fraction, dtype=float).T.reshape(-1)
    image.point_data["mask"] = entered.T.reshape(-1).astype(np.uint8)
    image.point_data.active_scalars_name = "solid_fraction"
    image.point_data.active_vectors_name = "velocity"
    image.field_data["window"] = np.array([float(field.window[0]), float(field.window[1])])
    image.field_data["n_frames"] = np.array([int(field.n_frames)], dtype=np.int64)
    if time is not None:
        time = float(time)
        if not math.isfinite(time):
            raise ValueError(f"time must be finite, got {time!r}")
        image.field_data["TimeValue"] = np.array([time])
    return image


def write_planar_field_vti(path: str | os.PathLike, field: PlanarField, y: float = 0.0,
                           time: float | None = None) -> Path:
    """Write one planar field as a VTK XML ImageData file (.vti), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vti``.
    field : PlanarField
        Depth-averaged field on uniform x-z bins.
    y : float, optional
        Depth coordinate of the image plane [m] (mid-depth puts it among the particles); default 0.
    time : float, optional
        Simulated time [s], written as the ``TimeValue`` field-data array.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    return write_vtk_xml(path, planar_field_image(field, y, time))


def write_planar_field_series(pvd_path: str | os.PathLike, fields: Sequence[PlanarField], times: Sequence[float],
                              y: float = 0.0) -> Path:
    """Write planar fields as .vti files and the .pvd that indexes them by time, the .pvd last.

    Parameters
    ----------
    pvd_path : str or os.PathLike
        The index, e.g. ``paraview/fields.pvd``; the fields go into the folder of the same name without the suffix
        (``paraview/fields/fields_<k>.vti``, k counting from 0 in time order).
    fields : sequence of PlanarField
        The fields, at least one.
    times : sequence of float
        The simulated time of each field [s], strictly increasing (on the clock of the run's particle frames, so that
        ParaView plays both in step).
    y : float, optional
        Depth coordinate of the image planes [m].

    Returns
    -------
    pathlib.Path
        The .pvd.

    Raises
    ------
    ValueError
        With no field, a count of times other than of fields, or times that do not increase; nothing is written
        then.
    """
    fields = list(fields)
    times = np.asarray(times, dtype=float)
    if not fields:
        raise ValueError("fields must hold at least one PlanarField")
    if times.shape != (len(fields),):
        raise ValueError(f"times must give one time per field ({len(fields)}), got shape {times.shape}")
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0.0):
        raise ValueError("times must be finite and strictly increasing")
    pvd_path = Path(pvd_path)
    folder = pvd_path.with_suffix("")
    entries = []
    for index, (field, time) in enumerate(zip(fields, times.tolist())):
        name = f"fields_{index}.vti"
        write_planar_field_vti(folder / name, field, y, time)
        entries.append((time, f"{folder.name}/{name}"))
    return write_pvd(pvd_path, entries)
