"""Writers of lines for ParaView as VTK XML PolyData (.vtp): pathlines, clump tracks cut into passes, force chains.

One cell per line: a polyline per virtual tracer (:func:`write_pathlines_vtp`) or per pass of a clump
(:func:`write_pass_paths_vtp`), a two-point line per contact (:func:`write_force_chains_vtp`); all go through
:func:`write_polylines_vtp` (the points of every line in one array, each line's start in ``offsets``, as VTK stores
lines) and :func:`siloflow.analysis.io.vtk_xml.write_vtk_xml`. Every array says its unit in its writer's docstring; times are
in s, so ParaView can colour a line by its residence time or show how far along it a point is.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pyvista

from siloflow.analysis.io.vtk_xml import checked_array_name, write_vtk_xml
from siloflow.analysis.numerics.force_chains import ForceChainSegments
from siloflow.analysis.numerics.pathlines import PathlineResult
from siloflow.analysis.studies.silo_recirculation.pass_paths import PassPaths

__all__ = ["polyline_data", "write_polylines_vtp", "write_pathlines_vtp", "write_pass_paths_vtp",
           "write_force_chains_vtp"]


def _checked_offsets(offsets, n_points: int) -> np.ndarray:
    offsets = np.asarray(offsets)
    if (offsets.ndim != 1 or offsets.size < 1 or offsets.dtype.kind not in "iu" or offsets[0] != 0
            or offsets[-1] != n_points or np.any(np.diff(offsets) < 1)):
        raise ValueError(f"offsets must be integers rising from 0 to the {n_points} points, each line at least one "
                         f"point long")
    return offsets.astype(np.int64)


def _attach(data, arrays: Mapping[str, np.ndarray] | None, size: int, where: str) -> None:
    for name, values in (arrays or {}).items():
        values = np.asarray(values)
        if values.shape[:1] != (size,):
            raise ValueError(f"{where}[{name!r}] must have {size} rows, got shape {values.shape}")
        if values.dtype == bool:
            values = values.astype(np.uint8)
        data[checked_array_name(name, where)] = values


def polyline_data(points, offsets, point_arrays: Mapping[str, np.ndarray] | None = None,
                  cell_arrays: Mapping[str, np.ndarray] | None = None,
                  field_arrays: Mapping[str, np.ndarray] | None = None, float_dtype=np.float64) -> pyvista.PolyData:
    """The :class:`pyvista.PolyData` of lines that :func:`write_polylines_vtp` writes (same arguments, see there)."""
    if np.dtype(float_dtype) not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise ValueError(f"float_dtype must be float32 or float64, got {np.dtype(float_dtype)}")
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise ValueError(f"points must be finite, of shape (n, 3), got shape {points.shape}")
    points = points.astype(float_dtype)
    offsets = _checked_offsets(offsets, points.shape[0])
    counts = np.diff(offsets)
    n_lines = counts.size
    if n_lines:
        # VTK's cell array: per line its point count, then its point indices
        connectivity = np.empty(n_lines + points.shape[0], dtype=np.int64)
        heads = offsets[:-1] + np.arange(n_lines)
        connectivity[heads] = counts
        body = np.ones(connectivity.size, dtype=bool)
        body[heads] = False
        connectivity[body] = np.arange(points.shape[0])
        data = pyvista.PolyData(points, lines=connectivity)
    else:
        data = pyvista.PolyData()
    _attach(data.point_data, point_arrays, points.shape[0], "point_arrays")
    _attach(data.cell_data, cell_arrays, n_lines, "cell_arrays")
    for name, values in (field_arrays or {}).items():
        data.field_data[checked_array_name(name, "field_arrays")] = np.atleast_1d(values)
    return data


def write_polylines_vtp(path: str | os.PathLike, points, offsets, point_arrays: Mapping[str, np.ndarray] | None = None,
                        cell_arrays: Mapping[str, np.ndarray] | None = None,
                        field_arrays: Mapping[str, np.ndarray] | None = None, float_dtype=np.float64) -> Path:
    """Write lines as a VTK XML PolyData file (.vtp), atomically: one polyline cell per line.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vtp``.
    points : array_like, shape (n, 3)
        The points of every line, line after line [m].
    offsets : array_like of int, shape (m + 1,)
        Line i is ``points[offsets[i]:offsets[i + 1]]``: rising from 0 to n, each line at least one point.
    point_arrays, cell_arrays : mapping of str to array_like, optional
        Arrays with one row per point (n) and per line (m); booleans are written as UInt8.
    field_arrays : mapping of str to array_like, optional
        Arrays of the whole file (e.g. settings of the computation).
    float_dtype : numpy dtype, optional
        float64 (default) or float32, of the coordinates (the arrays are written as given).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    return write_vtk_xml(path, polyline_data(points, offsets, point_arrays, cell_arrays, field_arrays, float_dtype))


def write_pathlines_vtp(path: str | os.PathLike, result: PathlineResult, plane_y: float | None = None) -> Path:
    """Write the recorded paths of virtual tracers as polylines, one cell per tracer, atomically.

    Each path is the tracer's recorded positions (``result.history``) and, for a tracer that left, its crossing of
    the outlet plane; a seed outside the grid (no position recorded) has no cell.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vtp``.
    result : PathlineResult
        Integrated with ``record_every`` > 0, so that it holds the paths.
    plane_y : float, optional
        Put every point at this depth [m]: for paths integrated in a plane whose depth coordinate is a stand-in (the
        blender's depth-averaged field), mid-depth draws them among the particles. None keeps the recorded y.

    Returns
    -------
    pathlib.Path
        The written path. Point data ``time`` [s] (the simulated time of the field's clock, ``t0`` at release);
        cell data ``tracer`` (its index in ``result``), ``residence_time`` [s] (NaN: did not leave within
        ``max_time``) and ``status`` (:data:`siloflow.analysis.numerics.pathlines.EXITED`, ``NOT_EXITED``); field data ``t0``,
        ``dt``, ``max_time`` [s] and ``outlet_z`` [m].
    """
    if not isinstance(result, PathlineResult):
        raise ValueError(f"result must be a PathlineResult, got {type(result).__name__}")
    if result.history is None or result.history_time is None:
        raise ValueError("result holds no paths: integrate with record_every > 0")
    if plane_y is not None and not math.isfinite(float(plane_y)):
        raise ValueError(f"plane_y must be finite, got {plane_y!r}")
    lines, times, tracers = [], [], []
    for i in range(result.residence_time.size):
        recorded = result.history[:, i]
        finite = np.all(np.isfinite(recorded), axis=1)
        points, at = recorded[finite], np.asarray(result.history_time, dtype=float)[finite]
        if np.isfinite(result.residence_time[i]):
            points = np.vstack([points, result.exit_position[i]])
            at = np.append(at, result.exit_time[i])
        if points.shape[0]:
            lines.append(points)
            times.append(at)
            tracers.append(i)
    tracers = np.array(tracers, dtype=np.int64)
    points = np.vstack(lines) if lines else np.empty((0, 3))
    if plane_y is not None:
        points[:, 1] = float(plane_y)
    offsets = np.concatenate(([0], np.cumsum([line.shape[0] for line in lines], dtype=np.int64)))
    return write_polylines_vtp(
        path, points, offsets.astype(np.int64),
        point_arrays={"time": np.concatenate(times) if times else np.empty(0)},
        cell_arrays={"tracer": tracers, "residence_time": result.residence_time[tracers],
                     "status": result.status[tracers].astype(np.int32)},
        field_arrays={"t0": result.t0, "dt": result.dt, "max_time": result.max_time, "outlet_z": result.outlet_z},
    )


def write_pass_paths_vtp(path: str | os.PathLike, paths: PassPaths) -> Path:
    """Write the passes of a recirculating silo's clumps as polylines, one cell per pass, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vtp``.
    paths : PassPaths
        The tracks cut into passes (:func:`siloflow.analysis.studies.silo_recirculation.pass_paths.pass_paths`).

    Returns
    -------
    pathlib.Path
        The written path. Points and velocities are float32, as the tracks are stored (``tracks.npz``,
        :func:`siloflow.analysis.studies.silo_recirculation.tracks_io.write_tracks`), which halves the file for nothing lost.
        Point data ``time`` [s] (simulated time of the frame), ``velocity`` (3) and ``speed`` [m/s]; cell data
        ``clump_id``, ``pass_number`` [-], ``entry_time``, ``exit_time`` and ``residence_time`` [s] (NaN where not
        known: the pass a clump is on when first seen has no entry, a pass still in the silo at the last frame no
        exit).
    """
    if not isinstance(paths, PassPaths):
        raise ValueError(f"paths must be a PassPaths, got {type(paths).__name__}")
    return write_polylines_vtp(
        path, paths.position, paths.offsets,
        point_arrays={"time": paths.time, "velocity": paths.velocity.astype(np.float32),
                      "speed": np.linalg.norm(paths.velocity, axis=1).astype(np.float32)},
        cell_arrays={"clump_id": paths.clump_id, "pass_number": paths.pass_number, "entry_time": paths.entry_time,
                     "exit_time": paths.exit_time, "residence_time": paths.residence_time},
        float_dtype=np.float32,
    )


def write_force_chains_vtp(path: str | os.PathLike, segments: ForceChainSegments) -> Path:
    """Write force chains as lines, one two-point cell per contact (centre to centre), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vtp``.
    segments : ForceChainSegments
        Branch vectors and their normal forces
        (:func:`siloflow.analysis.numerics.force_chains.force_chain_segments`).

    Returns
    -------
    pathlib.Path
        The written path. Cell data ``normal_force`` [N] (compressive, as capped by the segments); field data
        ``cap`` [N] when the cap is finite.
    """
    if not isinstance(segments, ForceChainSegments):
        raise ValueError(f"segments must be a ForceChainSegments, got {type(segments).__name__}")
    start, end = np.asarray(segments.start, dtype=float), np.asarray(segments.end, dtype=float)
    if start.shape != end.shape or start.ndim != 2 or start.shape[1] != 3:
        raise ValueError(f"segments: start and end must both have shape (n, 3), got {start.shape} and {end.shape}")
    points = np.empty((2 * start.shape[0], 3))
    points[0::2], points[1::2] = start, end
    return write_polylines_vtp(
        path, points, np.arange(0, points.shape[0] + 1, 2, dtype=np.int64),
        cell_arrays={"normal_force": np.asarray(segments.normal_force, dtype=float)},
        field_arrays={"cap": segments.cap} if math.isfinite(segments.cap) else None,
    )
