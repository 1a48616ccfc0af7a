"""Reader and writer of the blender's window-averaged planar fields as ``.npz``.

The only place the blender analysis touches files besides :mod:`analysis.studies.silo_recirculation.tracks_io`
(clump tracks).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from analysis.io.tables import atomic_output
from analysis.studies.blender.window_fields import PlanarField


def write_planar_fields(path: str | os.PathLike, steady: PlanarField, windows: list[PlanarField]) -> Path:
    """Save the steady field and the fields of the profile windows (same bins) as a compressed ``.npz``."""
    for field in windows:
        if field.x.shape != steady.x.shape or field.z.shape != steady.z.shape:
            raise ValueError("the window fields must have the bins of the steady field")
    stacked = [steady, *windows]
    with atomic_output(path) as temporary:
        with open(temporary, "wb") as handle:
            np.savez_compressed(
                handle, x=steady.x, z=steady.z,
                v_x=np.stack([f.v_x for f in stacked]), v_z=np.stack([f.v_z for f in stacked]),
                solid_fraction=np.stack([f.solid_fraction for f in stacked]),
                window=np.array([f.window for f in stacked]), n_frames=np.array([f.n_frames for f in stacked]),
            )
    return Path(path)


def read_planar_fields(path: str | os.PathLike) -> tuple[PlanarField, list[PlanarField]]:
    """Load what :func:`write_planar_fields` wrote: the steady field and the window fields."""
    with np.load(path) as data:
        fields = [
            PlanarField(x=data["x"], z=data["z"], v_x=data["v_x"][k], v_z=data["v_z"][k],
                        solid_fraction=data["solid_fraction"][k], window=tuple(map(float, data["window"][k])),
                        n_frames=int(data["n_frames"][k]))
            for k in range(data["v_z"].shape[0])
        ]
    return fields[0], fields[1:]
