"""Writer of a run's particle frames for ParaView: one VTK XML PolyData file (.vtp) per frame and a .pvd index.

The frames are the engine-neutral :class:`siloflow.model.frames.ParticleFrame` objects every engine reader returns (LIGGGHTS'
legacy VTK dumps, YADE's numpy archives alike), so both engines' runs open the same way. The .pvd gives each frame
its **simulated time** (s), so ParaView's animation runs on the physical clock rather than on file numbers, and the
other time series of a run (fields, written on the same clock) play in step with the particles.

Layout
------
``<name>.pvd`` indexes ``<name>/particles_<step>.vtp`` (a folder named after the index, beside it). Each .vtp holds
one point per sphere with a vertex cell each (so that every ParaView representation draws it), and:

* point data: ``id``, ``clump_id`` (Int64), ``type`` (Int32), ``velocity`` (3 components) [m/s], ``speed`` (the
  velocity's magnitude) [m/s], ``radius`` [m], ``mass`` [kg] (LIGGGHTS writes the clump's mass on each of its
  spheres), and where the frame carries them ``angular_velocity`` (3) [rad/s] and ``force`` (3) [N]. ``speed`` and
  ``velocity`` are the active scalars and vectors;
* field data: ``TimeValue`` [s] and ``step`` [-].

Coordinates and real-valued arrays are written as float32 by default: ParaView draws them, and the engine's dumps
stay the record (a float32 position is within 1e-7 of its value, 0.01 micrometre in a 0.1 m silo). Pass
``float_dtype=numpy.float64`` for exact copies.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pyvista

from siloflow.analysis.io.fields import write_pvd
from siloflow.analysis.io.vtk_xml import write_vtk_xml
from siloflow.model.frames import OPTIONAL_VECTORS, ParticleFrame

__all__ = ["particle_file_name", "particle_polydata", "write_particle_frame_vtp", "write_particle_series"]

_FLOAT_DTYPES = (np.dtype(np.float32), np.dtype(np.float64))


def particle_file_name(step: int) -> str:
    """The name of the .vtp of the frame of time step ``step``: ``particles_<step>.vtp``."""
    return f"particles_{int(step)}.vtp"


def _float_dtype(float_dtype) -> np.dtype:
    dtype = np.dtype(float_dtype)
    if dtype not in _FLOAT_DTYPES:
        raise ValueError(f"float_dtype must be float32 or float64, got {dtype}")
    return dtype


def particle_polydata(frame: ParticleFrame, float_dtype=np.float32) -> pyvista.PolyData:
    """The :class:`pyvista.PolyData` of one frame that :func:`write_particle_frame_vtp` writes (see the module notes).

    Parameters
    ----------
    frame : ParticleFrame
        The spheres of one saved step.
    float_dtype : numpy dtype, optional
        float32 (default) or float64, of the coordinates and real-valued arrays.
    """
    if not isinstance(frame, ParticleFrame):
        raise ValueError(f"frame must be a ParticleFrame, got {type(frame).__name__}")
    dtype = _float_dtype(float_dtype)
    points = frame.position.astype(dtype)
    data = pyvista.PolyData(points) if len(frame) else pyvista.PolyData()
    arrays = {
        "id": frame.id,
        "clump_id": frame.clump_id,
        "type": frame.type,
        "velocity": frame.velocity.astype(dtype),
        "speed": np.linalg.norm(frame.velocity, axis=1).astype(dtype),
        "radius": frame.radius.astype(dtype),
        "mass": frame.mass.astype(dtype),
    }
    for name in OPTIONAL_VECTORS:
        values = getattr(frame, name)
        if values is not None:
            arrays[name] = values.astype(dtype)
    if len(frame):
        for name, values in arrays.items():
            data.point_data[name] = values
        data.point_data.active_scalars_name = "speed"
        data.point_data.active_vectors_name = "velocity"
    data.field_data["TimeValue"] = np.array([frame.time])
    data.field_data["step"] = np.array([frame.step], dtype=np.int64)
    return data


def write_particle_frame_vtp(path: str | os.PathLike, frame: ParticleFrame, float_dtype=np.float32) -> Path:
    """Write one frame as a VTK XML PolyData file (.vtp), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vtp``.
    frame : ParticleFrame
        The spheres of one saved step.
    float_dtype : numpy dtype, optional
        float32 (default) or float64, of the coordinates and real-valued arrays.

    Returns
    -------
    pathlib.Path
        The written path.
    """
    return write_vtk_xml(path, particle_polydata(frame, float_dtype))


def write_particle_series(pvd_path: str | os.PathLike, frames: Sequence[ParticleFrame],
                          float_dtype=np.float32) -> Path:
    """Write the frames of a run as .vtp files and the .pvd that indexes them by simulated time, the .pvd last.

    Parameters
    ----------
    pvd_path : str or os.PathLike
        The index, e.g. ``paraview/particles.pvd``; the frames go into the folder of the same name without the
        suffix (``paraview/particles/``).
    frames : sequence of ParticleFrame
        The frames, oldest first (as :meth:`siloflow.engines.interface.Engine.read_frames` returns them): at least one,
        times strictly increasing.
    float_dtype : numpy dtype, optional
        float32 (default) or float64, of the coordinates and real-valued arrays.

    Returns
    -------
    pathlib.Path
        The .pvd.

    Raises
    ------
    ValueError
        With no frame, or when the times do not increase (ParaView orders a time series by its times); nothing
        is written then.
    """
    frames = list(frames)
    if not frames:
        raise ValueError("frames must hold at least one ParticleFrame")
    times = np.array([frame.time for frame in frames])
    if np.any(np.diff(times) <= 0.0):
        index = int(np.flatnonzero(np.diff(times) <= 0.0)[0]) + 1
        raise ValueError(f"frame times must increase: frame {index} (step {frames[index].step}) is at "
                         f"{times[index]!r} s, after {times[index - 1]!r} s")
    dtype = _float_dtype(float_dtype)
    pvd_path = Path(pvd_path)
    folder = pvd_path.with_suffix("")
    entries = []
    for frame in frames:
        name = particle_file_name(frame.step)
        write_particle_frame_vtp(folder / name, frame, dtype)
        entries.append((frame.time, f"{folder.name}/{name}"))
    return write_pvd(pvd_path, entries)
