"""Reader and writer of the recirculation study's clump tracks as ``.npz``.

The only place the recirculation analysis touches files; the tracks themselves are built from the engine's
frames by :func:`siloflow.analysis.numerics.clump_tracks.tracks_from_frames`, and the other modules
of :mod:`siloflow.analysis.studies.silo_recirculation` compute on the arrays.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from siloflow.analysis.io.tables import atomic_output
from siloflow.analysis.numerics.clump_tracks import ClumpTracks, TrackedClumps

__all__ = ["write_tracks", "load_tracks"]


def write_tracks(tracks: TrackedClumps, path: str | os.PathLike) -> Path:
    """Save tracks as a compressed ``.npz`` (atomically); positions and velocities as float32."""
    with atomic_output(path) as temporary:
        with open(temporary, "wb") as handle:
            np.savez_compressed(
                handle, times=tracks.tracks.times, clump_id=tracks.tracks.clump_id,
                position=tracks.tracks.position.astype(np.float32), velocity=tracks.velocity.astype(np.float32),
                mass=tracks.mass,
            )
    return Path(path)


def load_tracks(path: str | os.PathLike) -> TrackedClumps:
    """Load tracks written by :func:`write_tracks` (positions and velocities back in float64)."""
    with np.load(path) as data:
        tracks = ClumpTracks(times=data["times"], clump_id=data["clump_id"],
                             position=data["position"].astype(np.float64))
        return TrackedClumps(tracks=tracks, velocity=data["velocity"].astype(np.float64), mass=data["mass"])
