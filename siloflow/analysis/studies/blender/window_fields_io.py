"""Reader and writer of the blender's window-averaged planar fields as ``.npz``: the depth-averaged steady and window
fields, the fields of the steady window's frames, and the wall layer's steady and frame fields.

The only place the blender analysis touches files besides :mod:`siloflow.analysis.studies.silo_recirculation.tracks_io`
(clump tracks).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from siloflow.analysis.io.tables import atomic_output
from siloflow.analysis.studies.blender.window_fields import PlanarField


def _write_fields(path: str | os.PathLike, fields: Sequence[PlanarField], mismatch: str) -> Path:
    """Save fields on the bins of the first one as a compressed ``.npz``, stacked in their order; ``mismatch`` is
    the message of the ValueError when one has other bins."""
    first = fields[0]
    for field in fields[1:]:
        if field.x.shape != first.x.shape or field.z.shape != first.z.shape:
            raise ValueError(mismatch)
    with atomic_output(path) as temporary:
        with open(temporary, "wb") as handle:
            np.savez_compressed(
                handle, x=first.x, z=first.z,
                v_x=np.stack([f.v_x for f in fields]), v_z=np.stack([f.v_z for f in fields]),
                solid_fraction=np.stack([f.solid_fraction for f in fields]),
                window=np.array([f.window for f in fields]), n_frames=np.array([f.n_frames for f in fields]),
            )
    return Path(path)


def _read_fields(path: str | os.PathLike) -> list[PlanarField]:
    """The fields :func:`_write_fields` wrote, in their order."""
    with np.load(path) as data:
        return [
            PlanarField(x=data["x"], z=data["z"], v_x=data["v_x"][k], v_z=data["v_z"][k],
                        solid_fraction=data["solid_fraction"][k], window=tuple(map(float, data["window"][k])),
                        n_frames=int(data["n_frames"][k]))
            for k in range(data["v_z"].shape[0])
        ]


def write_planar_fields(path: str | os.PathLike, steady: PlanarField, windows: list[PlanarField]) -> Path:
    """Save the steady field and the fields of the profile windows (same bins) as a compressed ``.npz``."""
    return _write_fields(path, [steady, *windows], "the window fields must have the bins of the steady field")


def read_planar_fields(path: str | os.PathLike) -> tuple[PlanarField, list[PlanarField]]:
    """Load what :func:`write_planar_fields` wrote: the steady field and the window fields."""
    fields = _read_fields(path)
    return fields[0], fields[1:]


def write_frame_fields(path: str | os.PathLike, frames: Sequence[PlanarField]) -> Path:
    """Save the fields of single frames (:func:`siloflow.analysis.studies.blender.window_fields.frame_fields`, same bins,
    at least one) as a compressed ``.npz``."""
    frames = list(frames)
    if not frames:
        raise ValueError("frames must hold at least one PlanarField")
    return _write_fields(path, frames, "the frame fields must all have the same bins")


def read_frame_fields(path: str | os.PathLike) -> list[PlanarField]:
    """Load what :func:`write_frame_fields` wrote, in time order."""
    return _read_fields(path)


def write_wall_layer_fields(path: str | os.PathLike, steady: PlanarField, frames: Sequence[PlanarField]) -> Path:
    """Save the wall layer's steady field and the fields of its single frames of the steady window (same bins, at
    least one frame) as a compressed ``.npz``
    (:func:`siloflow.analysis.studies.blender.window_fields.wall_layer_positions`)."""
    frames = list(frames)
    if not frames:
        raise ValueError("frames must hold at least one PlanarField")
    return _write_fields(path, [steady, *frames],
                         "the wall layer's frame fields must have the bins of its steady field")


def read_wall_layer_fields(path: str | os.PathLike) -> tuple[PlanarField, list[PlanarField]]:
    """Load what :func:`write_wall_layer_fields` wrote: the steady field and the frame fields, in time order."""
    fields = _read_fields(path)
    return fields[0], fields[1:]
