"""Readers and writers of the blending study: clump tracks from the dumps of a recirculation run.

The only place the blending analysis touches files; :mod:`analysis.studies.silo_recirculation.blending` and :mod:`analysis.studies.silo_recirculation.study`
compute on the arrays.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.studies.silo_recirculation.blending import ClumpTracks, clump_tracks
from analysis.data.frames import clumps_from_frame
from engines.liggghts.dumps import list_dumps, readable_frames
from analysis.io.tables import atomic_output


@dataclass(frozen=True, eq=False)
class RecirculationTracks:
    """Clump tracks of a recirculation run with velocities and masses.

    Attributes
    ----------
    tracks : ClumpTracks
        Times [s], clump ids and centres [m] (NaN where absent).
    velocity : numpy.ndarray, shape (n_t, n_c, 3)
        Clump velocities [m/s] (NaN where absent).
    mass : numpy.ndarray, shape (n_c,)
        Clump masses [kg].
    """

    tracks: ClumpTracks
    velocity: np.ndarray
    mass: np.ndarray


def read_recirculation_tracks(
    dump_dir: str | os.PathLike, prefix: str, timestep: float, domain_z: tuple[float, float],
    cache_dir: str | os.PathLike | None = None, on_damaged: str = "error",
) -> RecirculationTracks:
    """Read every dump of a recirculation run into clump tracks (z periodic in ``domain_z``); a damaged dump
    raises or is skipped with a warning (:func:`engines.liggghts.dumps.readable_frames`)."""
    periodic = [None, None, tuple(domain_z)]
    times, ids, positions, velocities, masses = [], [], [], [], {}
    for frame in readable_frames(list_dumps(dump_dir, prefix), timestep, cache_dir, on_damaged):
        clumps = clumps_from_frame(frame, periodic_bounds=periodic)
        times.append(clumps.time)
        ids.append(clumps.clump_id)
        positions.append(clumps.position)
        velocities.append(clumps.velocity)
        masses.update(zip(clumps.clump_id.tolist(), clumps.mass.tolist()))
    if len(times) < 2:
        raise ValueError(f"{dump_dir}: a recirculation run needs at least 2 dumps, found {len(times)}")
    tracks = clump_tracks(np.array(times), ids, positions)
    # the same assembly lays the velocities out in the tracks' columns
    velocity = clump_tracks(tracks.times, ids, velocities).position
    mass = np.array([masses[i] for i in tracks.clump_id.tolist()])
    return RecirculationTracks(tracks=tracks, velocity=velocity, mass=mass)


def write_tracks(tracks: RecirculationTracks, path: str | os.PathLike) -> Path:
    """Save tracks as a compressed ``.npz`` (atomically)."""
    with atomic_output(path) as temporary:
        with open(temporary, "wb") as handle:
            np.savez_compressed(
                handle, times=tracks.tracks.times, clump_id=tracks.tracks.clump_id,
                position=tracks.tracks.position.astype(np.float32), velocity=tracks.velocity.astype(np.float32),
                mass=tracks.mass,
            )
    return Path(path)


def load_tracks(path: str | os.PathLike) -> RecirculationTracks:
    """Load tracks written by :func:`write_tracks` (positions and velocities back in float64)."""
    with np.load(path) as data:
        tracks = ClumpTracks(times=data["times"], clump_id=data["clump_id"],
                             position=data["position"].astype(np.float64))
        return RecirculationTracks(tracks=tracks, velocity=data["velocity"].astype(np.float64), mass=data["mass"])
