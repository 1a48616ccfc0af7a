"""Clump tracks: the centres, velocities and masses of a run's clumps over its saved frames, one column per clump.

Pure functions on numpy arrays and :mod:`siloflow.model.frames`; no file I/O. SI units: positions in m, velocities in m/s,
masses in kg, times in s.

:func:`clump_tracks` lays per-frame clump ids and centres out in one array, NaN where a clump is absent from a frame;
:func:`tracks_from_frames` does the same from the frames an engine reads, grouping their spheres into clumps
(:func:`siloflow.model.frames.clumps_from_frame`). A run whose domain is periodic in z (the recirculating silo, the blender in
recirculation) gives its ``domain_z``: a clump that straddles the periodic boundary is put back together and its
centre wrapped into the domain. :meth:`ClumpTracks.until` and :meth:`TrackedClumps.until` keep the frames up to a
time (:func:`frames_until`), the part of a run before it changes what it does. When each clump leaves through an
outlet plane is :mod:`siloflow.analysis.numerics.exit_times`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number, increasing_times
from siloflow.model.frames import ClumpFrame, ParticleFrame, clumps_from_frame

__all__ = ["ClumpTracks", "TrackedClumps", "checked_tracks", "clump_tracks", "frames_until", "tracks_from_frames"]


@dataclass(frozen=True, eq=False)
class ClumpTracks:
    """Clump centres over the saved frames, one column per clump.

    Attributes
    ----------
    times : numpy.ndarray, shape (n_t,)
        Frame times, strictly increasing [s].
    clump_id : numpy.ndarray of int64, shape (n_c,)
        Clump ids, ascending (the union over all frames) [-].
    position : numpy.ndarray, shape (n_t, n_c, 3)
        Clump centres [m] (in a periodic domain, z wrapped into it); NaN where a clump is absent from a frame.
    """

    times: np.ndarray
    clump_id: np.ndarray
    position: np.ndarray

    @property
    def n_times(self) -> int:
        """Number of frames."""
        return int(self.times.shape[0])

    @property
    def n_clumps(self) -> int:
        """Number of clumps (seen in any frame)."""
        return int(self.clump_id.shape[0])

    @property
    def present(self) -> np.ndarray:
        """Mask of the clumps present in each frame, shape (n_t, n_c)."""
        return np.all(np.isfinite(self.position), axis=2)

    @property
    def z(self) -> np.ndarray:
        """Heights of the clump centres, shape (n_t, n_c) [m] (NaN where absent)."""
        return self.position[:, :, 2]

    def until(self, t_last: float) -> ClumpTracks:
        """The frames at or before ``t_last`` [s] (:func:`frames_until`) and the clumps seen in them: a clump that
        first appears later (LIGGGHTS gives what is left of a clump a fixed boundary took a sphere from a new id)
        is no part of the run before ``t_last``.

        Examples
        --------
        >>> tracks = clump_tracks([0.0, 0.1, 0.2], [[7], [7], [7]], [[[0, 0, 0.3]], [[0, 0, 0.2]], [[0, 0, 0.1]]])
        >>> tracks.until(0.1).times.tolist(), tracks.until(0.1).z.tolist()
        ([0.0, 0.1], [[0.3], [0.2]])
        """
        keep, seen = self._kept(t_last)
        return ClumpTracks(times=np.asarray(self.times)[:keep], clump_id=np.asarray(self.clump_id)[seen],
                           position=np.asarray(self.position)[:keep][:, seen])

    def of_clumps(self, clump_id) -> ClumpTracks:
        """The columns of the clumps ``clump_id`` [-], in that order: the whole run's tracks of the clumps a part of it
        (:meth:`until`) holds.

        Raises
        ------
        ValueError
            If an id is not a clump of the tracks.

        Examples
        --------
        >>> tracks = clump_tracks([0.0, 0.1], [[7, 3], [7, 3, 5]], [[[0, 0, 0.3], [1, 0, 0.2]],
        ...                                                        [[0, 0, 0.2], [1, 0, 0.1], [2, 0, -0.1]]])
        >>> tracks.of_clumps([7, 3]).clump_id.tolist(), tracks.of_clumps([7, 3]).z.tolist()
        ([7, 3], [[0.3, 0.2], [0.2, 0.1]])
        """
        ids = np.asarray(self.clump_id)
        wanted = np.asarray(clump_id, dtype=ids.dtype)
        order = np.argsort(ids, kind="stable")
        at = np.searchsorted(ids, wanted, sorter=order)
        found = at < ids.size
        found[found] = ids[order[at[found]]] == wanted[found]
        if not found.all():
            raise ValueError(f"clump ids {wanted[~found][:5].tolist()} are not clumps of the tracks")
        columns = order[at]
        return ClumpTracks(times=self.times, clump_id=ids[columns], position=np.asarray(self.position)[:, columns])

    def _kept(self, t_last: float) -> tuple[int, np.ndarray]:
        """The frames :meth:`until` keeps and the mask of the clump columns present in at least one of them."""
        keep = frames_until(self.times, t_last)
        return keep, np.isfinite(np.asarray(self.position)[:keep, :, 2]).any(axis=0)


@dataclass(frozen=True, eq=False)
class TrackedClumps:
    """Clump tracks of a run with velocities and masses.

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

    def until(self, t_last: float) -> TrackedClumps:
        """The frames at or before ``t_last`` [s] and the clumps seen in them (:meth:`ClumpTracks.until`), tracks,
        velocities and masses alike."""
        keep, seen = self.tracks._kept(t_last)
        return TrackedClumps(tracks=self.tracks.until(t_last), velocity=np.asarray(self.velocity)[:keep][:, seen],
                             mass=np.asarray(self.mass)[seen])


def frames_until(times, t_last: float) -> int:
    """How many of the leading frames lie at or before ``t_last``: ``times[:n] <= t_last`` [-].

    The cut of a run that changes what it does at ``t_last`` (a recirculating silo whose re-entry stops): the frame
    at exactly ``t_last`` is kept, as the last one of the part before. No tolerance is added, so a frame saved a
    round-off after ``t_last`` is left out; with frames far apart compared with the round-off that loses at most
    that one frame.

    Parameters
    ----------
    times : array_like, shape (n_t,)
        Frame times, strictly increasing [s].
    t_last : float
        Time of the last frame wanted [s].

    Returns
    -------
    int
        The number of frames kept, >= 2 [-].

    Raises
    ------
    ValueError
        If ``t_last`` is not a finite number or leaves fewer than 2 frames (the tracks of a run need 2).
    """
    t = _increasing_times("times", times)
    t_last = finite_number("t_last", t_last)
    keep = int(np.searchsorted(t, t_last, side="right"))
    if keep < 2:
        raise ValueError(f"the frames at or before t = {t_last!r} s are {keep}; at least 2 are needed "
                         f"(the run starts at {t[0]!r} s)")
    return keep


def _clump_ids(name: str, values) -> np.ndarray:
    """Integer ids as int64 (integral floats accepted, e.g. ids written as double)."""
    array = np.asarray(values)
    if array.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {array.shape}")
    if array.dtype.kind in "iu":
        return array.astype(np.int64)
    if array.size == 0:
        return np.zeros(0, dtype=np.int64)
    if array.dtype.kind == "f" and np.all(np.isfinite(array)) and np.all(array == np.round(array)):
        return array.astype(np.int64)
    raise ValueError(f"{name} must hold integer clump ids, got dtype {array.dtype}")


def _increasing_times(name: str, values) -> np.ndarray:
    times = increasing_times(name, values)
    if times.size == 0:
        raise ValueError(f"{name} must not be empty")
    return times


def checked_tracks(tracks: ClumpTracks) -> tuple[np.ndarray, np.ndarray]:
    """The times [s] and positions [m] of ``tracks`` as float arrays, checked.

    Raises
    ------
    ValueError
        When the times are empty or not strictly increasing, the positions do not have shape (n_t, n_c, 3), or a
        position is infinite (NaN marks an absent clump).
    """
    times = _increasing_times("tracks.times", tracks.times)
    position = np.asarray(tracks.position, dtype=float)
    n_c = np.asarray(tracks.clump_id).shape[0]
    if position.shape != (times.size, n_c, 3):
        raise ValueError(f"tracks.position must have shape ({times.size}, {n_c}, 3), got {position.shape}")
    if np.any(np.isinf(position)):
        raise ValueError("tracks.position must not contain infinite values (NaN marks an absent clump)")
    return times, position


def clump_tracks(times, ids_per_frame, positions_per_frame) -> ClumpTracks:
    """Assemble per-frame clump ids and centres into one array, one column per clump.

    Parameters
    ----------
    times : array_like, shape (n_t,)
        Frame times, strictly increasing [s].
    ids_per_frame : sequence of array_like
        One 1-D array of integer clump ids per frame, in any order (e.g.
        :attr:`siloflow.model.frames.ClumpFrame.clump_id`). Ids may be negative; duplicates within a
        frame are an error.
    positions_per_frame : sequence of array_like
        One array of shape ``(len(ids), 3)`` of clump centres per frame, finite [m].

    Returns
    -------
    ClumpTracks
        Columns for the union of the ids over all frames, ascending; NaN where a clump is absent.

    Raises
    ------
    ValueError
        On bad times, a number of frames that does not match ``times``, non-integer or duplicate
        ids in a frame, or positions of the wrong shape or not finite.

    Examples
    --------
    Clump 7 is missing from the second frame:

    >>> tracks = clump_tracks([0.0, 0.1], [[7, 3], [3]], [[[0, 0, 0.2], [0, 0, 0.1]], [[0, 0, 0.05]]])
    >>> tracks.clump_id.tolist(), tracks.z.tolist()
    ([3, 7], [[0.1, 0.2], [0.05, nan]])
    """
    t = _increasing_times("times", times)
    ids_list = list(ids_per_frame)
    positions_list = list(positions_per_frame)
    if len(ids_list) != t.size:
        raise ValueError(f"ids_per_frame must hold one array per time ({t.size}), got {len(ids_list)}")
    if len(positions_list) != t.size:
        raise ValueError(f"positions_per_frame must hold one array per time ({t.size}), got {len(positions_list)}")
    frame_ids = []
    frame_positions = []
    for k, (ids, positions) in enumerate(zip(ids_list, positions_list)):
        ids = _clump_ids(f"ids_per_frame[{k}]", ids)
        ordered = np.sort(ids)
        repeated = ordered[1:][ordered[1:] == ordered[:-1]]
        if repeated.size:
            raise ValueError(f"ids_per_frame[{k}] has duplicate clump ids, e.g. {int(repeated[0])}")
        positions = np.asarray(positions, dtype=float)
        if positions.shape != (ids.size, 3):
            raise ValueError(f"positions_per_frame[{k}] must have shape ({ids.size}, 3), got {positions.shape}")
        if not np.all(np.isfinite(positions)):
            raise ValueError(f"positions_per_frame[{k}] must contain only finite numbers")
        frame_ids.append(ids)
        frame_positions.append(positions)
    all_ids = np.unique(np.concatenate(frame_ids)) if frame_ids else np.zeros(0, dtype=np.int64)
    position = np.full((t.size, all_ids.size, 3), np.nan)
    for k, (ids, positions) in enumerate(zip(frame_ids, frame_positions)):
        position[k, np.searchsorted(all_ids, ids)] = positions
    return ClumpTracks(times=t, clump_id=all_ids.astype(np.int64), position=position)


def tracks_from_frames(frames: Iterable[ParticleFrame | ClumpFrame],
                       domain_z: tuple[float, float] | None = None) -> TrackedClumps:
    """Clump tracks, velocities and masses of a run from its frames.

    Parameters
    ----------
    frames : iterable of ParticleFrame or ClumpFrame
        The saved frames of the run in time order, as the engine reads them. A
        :class:`~siloflow.model.frames.ParticleFrame` is grouped into clumps by
        :func:`~siloflow.model.frames.clumps_from_frame` (with z periodic in ``domain_z`` when given: a clump that
        straddles the periodic boundary is put back together and its centre wrapped into the domain);
        a :class:`~siloflow.model.frames.ClumpFrame` is taken as it is.
    domain_z : (float, float) or None, optional
        Bottom and top of a domain periodic in z [m] (the run record's ``domain_z``); None (default) for a run
        without a periodic boundary.

    Returns
    -------
    TrackedClumps
        Tracks assembled by :func:`clump_tracks`; velocities laid out in the same columns; the mass of
        each clump (the last one seen).

    Raises
    ------
    ValueError
        With fewer than 2 frames, a ``domain_z`` whose top is not above its bottom, or as :func:`clump_tracks`.

    Examples
    --------
    One two-sphere clump (id 4, mass 2 g on each sphere) falling at 1 m/s:

    >>> import numpy as np
    >>> from siloflow.model.frames import ParticleFrame
    >>> def frame(t):
    ...     z = 0.5 - t
    ...     return ParticleFrame(time=t, step=int(t * 1000), id=[1, 2], type=[1, 1], clump_id=[4, 4],
    ...                          position=[[-0.001, 0, z], [0.001, 0, z]], velocity=[[0, 0, -1.0]] * 2,
    ...                          angular_velocity=None, radius=[0.001] * 2, mass=[0.002] * 2)
    >>> tracked = tracks_from_frames([frame(0.0), frame(0.1)])
    >>> tracked.tracks.z[:, 0].round(12).tolist(), tracked.velocity[:, 0, 2].tolist(), tracked.mass.tolist()
    ([0.5, 0.4], [-1.0, -1.0], [0.002])
    """
    periodic = None
    if domain_z is not None:
        bottom, top = (finite_number("domain_z", bound) for bound in domain_z)
        if not top > bottom:
            raise ValueError(f"domain_z must be (bottom, top) with top > bottom, got {tuple(domain_z)!r}")
        periodic = [None, None, (bottom, top)]
    times, ids, positions, velocities, masses = [], [], [], [], {}
    for frame in frames:
        clumps = frame if isinstance(frame, ClumpFrame) else clumps_from_frame(frame, periodic_bounds=periodic)
        times.append(clumps.time)
        ids.append(clumps.clump_id)
        positions.append(clumps.position)
        velocities.append(clumps.velocity)
        masses.update(zip(clumps.clump_id.tolist(), clumps.mass.tolist()))
    if len(times) < 2:
        raise ValueError(f"tracks need at least 2 frames, got {len(times)}")
    tracks = clump_tracks(np.array(times), ids, positions)
    # the same assembly lays the velocities out in the tracks' columns
    velocity = clump_tracks(tracks.times, ids, velocities).position
    mass = np.array([masses[i] for i in tracks.clump_id.tolist()])
    return TrackedClumps(tracks=tracks, velocity=velocity, mass=mass)
