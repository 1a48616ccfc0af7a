"""The clump tracks of a recirculating silo cut into passes: one path per pass, to draw.

Pure computation on :class:`siloflow.analysis.numerics.clump_tracks.TrackedClumps`; no file I/O (the
ParaView writer is :func:`siloflow.analysis.io.vtk_lines.write_pass_paths_vtp`). SI units: m, m/s, s.

A clump's track jumps by the height of the periodic domain each time it re-enters at the top, so a line through all
its frames would cross the silo at every re-entry. Cut at the re-entries (those of
:func:`siloflow.analysis.numerics.exit_times.outlet_exits`, which also end and begin the passes), each pass is a path from the
top of the fill (or, for the pass a clump is on when first seen, from where it was) down through the outlet and the
channel, and carries that pass's entry, exit and residence time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.analysis.numerics.clump_tracks import TrackedClumps
from siloflow.analysis.numerics.exit_times import outlet_exits

__all__ = ["PassPaths", "pass_paths"]


@dataclass(frozen=True, eq=False)
class PassPaths:
    """Per pass of every clump, the frames it spans, as one array of points and the offsets of each pass in it.

    Pass ``i`` is ``position[offsets[i]:offsets[i + 1]]`` (at least one point). Passes are ordered by clump, then by
    pass number; a pass in no frame of which its clump is present is left out.

    Attributes
    ----------
    position : numpy.ndarray, shape (n, 3)
        Clump centres [m], within the periodic domain.
    time : numpy.ndarray, shape (n,)
        Frame time of each point [s].
    velocity : numpy.ndarray, shape (n, 3)
        Clump velocity at each point [m/s].
    offsets : numpy.ndarray of int64, shape (m + 1,)
        Start of each pass in the point arrays, then ``n``.
    clump_id : numpy.ndarray of int64, shape (m,)
        Id of the clump making each pass [-].
    pass_number : numpy.ndarray of int64, shape (m,)
        0 for the pass a clump is on when first seen, 1 after its first re-entry, ... [-].
    entry_time, exit_time : numpy.ndarray, shape (m,)
        Re-entry time that begins the pass (NaN for pass 0) and its first outlet crossing (NaN if none) [s].
    residence_time : numpy.ndarray, shape (m,)
        ``exit_time - entry_time`` [s]: re-entry to outlet; NaN where either is.
    """

    position: np.ndarray
    time: np.ndarray
    velocity: np.ndarray
    offsets: np.ndarray
    clump_id: np.ndarray
    pass_number: np.ndarray
    entry_time: np.ndarray
    exit_time: np.ndarray
    residence_time: np.ndarray

    @property
    def n_passes(self) -> int:
        """Number of passes (paths)."""
        return int(self.offsets.size - 1)


def pass_paths(recorded: TrackedClumps, outlet_z: float, domain_bottom: float, domain_top: float) -> PassPaths:
    """Cut every clump's track into its passes.

    A frame at time t belongs to the pass whose entry time is before t and whose next pass (of the same clump)
    begins at or after t; a re-entry falls between two frames, so each frame belongs to exactly one pass.

    Parameters
    ----------
    recorded : TrackedClumps
        Clump centres [m] and velocities [m/s] over the frames (NaN where a clump is absent).
    outlet_z : float
        Height of the outlet plane [m].
    domain_bottom, domain_top : float
        Bottom and top of the domain, periodic in z [m].

    Returns
    -------
    PassPaths
    """
    tracks = recorded.tracks
    events = outlet_exits(tracks, outlet_z, (domain_bottom, domain_top))
    times = np.asarray(tracks.times, dtype=float)
    present = tracks.present
    clump_index = events.pass_clump_index
    # a pass ends where the next row of the same clump begins; the last pass of a clump runs to the last frame
    next_entry = np.full(events.n_passes, np.inf)
    same_clump = clump_index[1:] == clump_index[:-1]
    next_entry[:-1][same_clump] = events.entry_time[1:][same_clump]
    start = np.where(np.isnan(events.entry_time), -np.inf, events.entry_time)
    first = np.searchsorted(times, start, side="right")
    stop = np.searchsorted(times, next_entry, side="right")

    frames, kept = [], []
    for row in range(events.n_passes):
        k = np.arange(first[row], stop[row])
        k = k[present[k, clump_index[row]]]
        if k.size:
            frames.append((k, clump_index[row]))
            kept.append(row)
    kept = np.array(kept, dtype=np.int64)
    counts = np.array([k.size for k, _ in frames], dtype=np.int64)
    offsets = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    frame_index = np.concatenate([k for k, _ in frames]) if frames else np.empty(0, dtype=np.int64)
    column = np.repeat([c for _, c in frames], counts) if frames else np.empty(0, dtype=np.int64)
    return PassPaths(
        position=tracks.position[frame_index, column].reshape(-1, 3),
        time=times[frame_index],
        velocity=np.asarray(recorded.velocity)[frame_index, column].reshape(-1, 3),
        offsets=offsets,
        clump_id=events.clump_id[clump_index[kept]],
        pass_number=events.pass_number[kept],
        entry_time=events.entry_time[kept],
        exit_time=events.exit_time[kept],
        residence_time=events.residence_time[kept],
    )
