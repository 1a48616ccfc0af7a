"""Clump tracks of a recirculating silo and the events on them: outlet crossings, re-entries, passes.

Pure functions on numpy arrays and :mod:`model.frames`; no file I/O. SI units: positions in m,
velocities in m/s, masses in kg, times in s.

Geometry
--------
A planar silo: x across the width, y depth, z up. The silo floor and outlet plane is
``z = outlet_z``; below it a vertical channel runs down to ``z = domain_bottom``. The domain is
periodic in z with height ``L = domain_top - domain_bottom``: a clump leaving the bottom re-enters
at ``domain_top`` and falls onto the pile again. The engine's frames give clump centres wrapped into
``[domain_bottom, domain_top)`` at the saved instants ``times``, assembled by :func:`clump_tracks`
(or, from the frames themselves, :func:`recirculation_tracks`) into one array with NaN where a clump
is absent from a frame.

Events (:func:`recirculation_events`)
-------------------------------------
Events are looked for between consecutive frames ``k, k + 1`` in which the clump is present in
both (an interval with the clump absent from either frame is not bridged; frames must be close
enough that a clump moves less than ``L / 2`` between them).

- **Wrap** (re-entry at the top): ``z_{k+1} - z_k > L / 2``. The unwrapped position is
  ``z_{k+1} - L``; the wrap time is where the straight path from ``z_k`` to ``z_{k+1} - L`` crosses
  ``domain_bottom``: ``t_k + (t_{k+1} - t_k)(z_k - domain_bottom) / (z_k - z_{k+1} + L)``.
- **Exit** (outlet crossing): ``z_k > outlet_z >= z_{k+1}`` (unwrapped), at
  ``t_k + (t_{k+1} - t_k)(z_k - outlet_z) / (z_k - z_{k+1})`` (the rule of
  :mod:`analysis.numerics.pathlines`). In one interval an exit comes before a wrap.

**Passes.** A clump's first pass begins at the first frame in which it is present (the *initial
content*, ``pass_number`` 0, entry time NaN); every wrap ends a pass and begins the next one
(``pass_number`` 1, 2, ..., entry time the wrap time). The exit of a pass is its first outlet
crossing (NaN if none by the last frame). A clump that is at or below the outlet plane when first
seen (in the channel) has a first pass with ``started_below_outlet`` True whose exit is normally
NaN and which ends at its wrap; such passes are kept (flagged) and drop out of the pass-based
quantities by their NaN entry or exit time.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from model.checks import finite_number, increasing_times
from model.frames import ClumpFrame, ParticleFrame, clumps_from_frame

__all__ = [
    "ClumpTracks",
    "RecirculationEvents",
    "RecirculationTracks",
    "clump_tracks",
    "recirculation_tracks",
    "recirculation_events",
    "above_outlet",
    "clumps_above_outlet",
]


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
        Clump centres wrapped into ``[domain_bottom, domain_top)`` in z [m]; NaN where a clump is
        absent from a frame.
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


@dataclass(frozen=True, eq=False)
class RecirculationEvents:
    """Outlet crossings, re-entries and passes of the clumps of a recirculating silo.

    Pass rows are ordered by clump index, then by ``pass_number``. Crossing rows (``exit_*``) are
    ordered by time.

    Attributes
    ----------
    clump_id : numpy.ndarray of int64, shape (n_c,)
        Clump ids, as in the tracks [-].
    pass_clump_index : numpy.ndarray of int64, shape (n_p,)
        Column of the clump making the pass (index into ``clump_id``) [-].
    pass_clump_id : numpy.ndarray of int64, shape (n_p,)
        Id of the clump making the pass [-].
    pass_number : numpy.ndarray of int64, shape (n_p,)
        0 for the pass a clump is on when first seen (initial content), 1 after its first
        re-entry, ... [-].
    entry_time : numpy.ndarray, shape (n_p,)
        Re-entry (wrap) time that begins the pass; NaN for pass 0 [s].
    exit_time : numpy.ndarray, shape (n_p,)
        First outlet crossing of the pass; NaN if none by the last frame [s].
    previous_exit_time : numpy.ndarray, shape (n_p,)
        Exit time of the clump's previous pass (NaN for pass 0 or when that pass has no exit) [s].
        ``exit_time - previous_exit_time`` is the loop time: channel, re-entry and silo.
    started_below_outlet : numpy.ndarray of bool, shape (n_p,)
        True for the first pass of a clump that was at or below the outlet plane (in the channel)
        when first seen; its exit is normally NaN.
    exit_times_all : numpy.ndarray, shape (n_x,)
        Every outlet crossing of every clump, ascending [s]. A clump bouncing back up through the
        outlet plane and falling again crosses twice in one pass.
    exit_clump_index : numpy.ndarray of int64, shape (n_x,)
        Clump column of each crossing [-].
    exit_pass_number : numpy.ndarray of int64, shape (n_x,)
        ``pass_number`` of the pass each crossing belongs to [-].
    exit_is_pass_exit : numpy.ndarray of bool, shape (n_x,)
        True for the crossings that are the exit of their pass (the first one of the pass).
    first_exit_time : numpy.ndarray, shape (n_c,)
        First outlet crossing of each clump; NaN if it never crossed [s].
    n_frames_absent : numpy.ndarray of int64, shape (n_c,)
        Frames in which each clump is missing (0 in a good run); crossings in intervals next to a
        missing frame are not detected [-].
    first_frame_time, last_frame_time : float
        Times of the first and last frame [s].
    outlet_z, domain_bottom, domain_top : float
        Heights of the outlet plane and of the periodic domain boundaries [m].
    """

    clump_id: np.ndarray
    pass_clump_index: np.ndarray
    pass_clump_id: np.ndarray
    pass_number: np.ndarray
    entry_time: np.ndarray
    exit_time: np.ndarray
    previous_exit_time: np.ndarray
    started_below_outlet: np.ndarray
    exit_times_all: np.ndarray
    exit_clump_index: np.ndarray
    exit_pass_number: np.ndarray
    exit_is_pass_exit: np.ndarray
    first_exit_time: np.ndarray
    n_frames_absent: np.ndarray
    first_frame_time: float
    last_frame_time: float
    outlet_z: float
    domain_bottom: float
    domain_top: float

    @property
    def n_clumps(self) -> int:
        """Number of clumps."""
        return int(self.clump_id.shape[0])

    @property
    def n_passes(self) -> int:
        """Number of passes (rows of the pass table)."""
        return int(self.pass_number.shape[0])

    @property
    def residence_time(self) -> np.ndarray:
        """``exit_time - entry_time`` of each pass: re-entry to outlet [s] (NaN where either is NaN)."""
        return self.exit_time - self.entry_time


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


def _checked_tracks(tracks: ClumpTracks) -> tuple[np.ndarray, np.ndarray]:
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
        :attr:`model.frames.ClumpFrame.clump_id`). Ids may be negative; duplicates within a
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


def recirculation_tracks(
    frames: Iterable[ParticleFrame | ClumpFrame], domain_z: tuple[float, float]
) -> RecirculationTracks:
    """Clump tracks, velocities and masses of a recirculation run from its frames (z periodic in ``domain_z``).

    Parameters
    ----------
    frames : iterable of ParticleFrame or ClumpFrame
        The saved frames of the run in time order, as the engine reads them. A
        :class:`~model.frames.ParticleFrame` is grouped into clumps by
        :func:`~model.frames.clumps_from_frame` with z periodic in ``domain_z`` (a clump that
        straddles the periodic boundary is put back together and its centre wrapped into the domain);
        a :class:`~model.frames.ClumpFrame` is taken as it is (its centres already in the domain).
    domain_z : (float, float)
        Bottom and top of the periodic domain [m].

    Returns
    -------
    RecirculationTracks
        Tracks assembled by :func:`clump_tracks`; velocities laid out in the same columns; the mass of
        each clump (the last one seen).

    Raises
    ------
    ValueError
        With fewer than 2 frames, or as :func:`clump_tracks`.
    """
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
        raise ValueError(f"a recirculation run needs at least 2 frames, got {len(times)}")
    tracks = clump_tracks(np.array(times), ids, positions)
    # the same assembly lays the velocities out in the tracks' columns
    velocity = clump_tracks(tracks.times, ids, velocities).position
    mass = np.array([masses[i] for i in tracks.clump_id.tolist()])
    return RecirculationTracks(tracks=tracks, velocity=velocity, mass=mass)


def recirculation_events(tracks: ClumpTracks, outlet_z: float, domain_bottom: float, domain_top: float) -> RecirculationEvents:
    """Outlet crossings, re-entries (wraps) and passes of every clump (see the module docstring).

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres, z wrapped into ``[domain_bottom, domain_top]`` [m].
    outlet_z : float
        Height of the outlet plane [m], strictly between the domain boundaries.
    domain_bottom, domain_top : float
        Bottom and top of the domain, periodic in z [m].

    Returns
    -------
    RecirculationEvents

    Raises
    ------
    ValueError
        If the heights are not ordered ``domain_bottom < outlet_z < domain_top``, the tracks are
        malformed, or a height lies outside the domain.
    """
    times, position = _checked_tracks(tracks)
    outlet = finite_number("outlet_z", outlet_z)
    bottom = finite_number("domain_bottom", domain_bottom)
    top = finite_number("domain_top", domain_top)
    if not bottom < outlet < top:
        raise ValueError(
            f"outlet_z must lie strictly between domain_bottom and domain_top, got "
            f"domain_bottom={bottom!r}, outlet_z={outlet!r}, domain_top={top!r}"
        )
    height = top - bottom
    clump_id = np.asarray(tracks.clump_id).astype(np.int64)
    n_c = clump_id.size
    present = np.all(np.isfinite(position), axis=2)
    z = position[:, :, 2]
    seen = z[present]
    if np.any(seen < bottom) or np.any(seen > top):
        raise ValueError(
            f"tracks.position: z must lie in [domain_bottom, domain_top] = [{bottom!r}, {top!r}] m, "
            f"got values from {seen.min()!r} to {seen.max()!r}"
        )

    # --- events between consecutive frames with the clump present in both
    z0 = np.where(present[:-1], z[:-1], 0.0)
    z1 = np.where(present[1:], z[1:], 0.0)
    both = present[:-1] & present[1:]
    wrap = both & (z1 - z0 > 0.5 * height)
    z1_unwrapped = np.where(wrap, z1 - height, z1)
    crossing = both & (z0 > outlet) & (z1_unwrapped <= outlet)
    drop = z0 - z1_unwrapped  # > 0 at every crossing and (but for a clump sitting on the boundary) every wrap
    step = np.diff(times)

    k_exit, c_exit = np.nonzero(crossing)
    t_exit = times[k_exit] + step[k_exit] * (z0[k_exit, c_exit] - outlet) / drop[k_exit, c_exit]
    k_wrap, c_wrap = np.nonzero(wrap)
    wrap_drop = drop[k_wrap, c_wrap]
    safe = np.where(wrap_drop > 0.0, wrap_drop, 1.0)
    t_wrap = times[k_wrap] + step[k_wrap] * np.where(wrap_drop > 0.0, (z0[k_wrap, c_wrap] - bottom) / safe, 0.0)

    # --- all events of a clump in time order: by interval, an exit before a wrap in the same interval
    clump = np.concatenate([c_exit, c_wrap]).astype(np.int64)
    interval = np.concatenate([k_exit, k_wrap]).astype(np.int64)
    is_wrap = np.concatenate([np.zeros(c_exit.size, dtype=bool), np.ones(c_wrap.size, dtype=bool)])
    event_time = np.concatenate([t_exit, t_wrap])
    order = np.lexsort((is_wrap, interval, clump))
    clump, is_wrap, event_time = clump[order], is_wrap[order], event_time[order]

    wraps_per_clump = np.bincount(clump[is_wrap], minlength=n_c).astype(np.int64)
    wraps_before_clump = np.concatenate([[0], np.cumsum(wraps_per_clump)[:-1]]).astype(np.int64)
    wraps_before_event = np.cumsum(is_wrap) - is_wrap  # over all clumps, exclusive
    event_pass = wraps_before_event - wraps_before_clump[clump]  # pass the event happens on

    # --- the pass table
    ever_present = present.any(axis=0)
    passes_per_clump = np.where(ever_present, wraps_per_clump + 1, 0).astype(np.int64)
    pass_offset = np.concatenate([[0], np.cumsum(passes_per_clump)[:-1]]).astype(np.int64)
    n_passes = int(passes_per_clump.sum())
    pass_clump_index = np.repeat(np.arange(n_c, dtype=np.int64), passes_per_clump)
    pass_number = np.arange(n_passes, dtype=np.int64) - pass_offset[pass_clump_index]

    entry_time = np.full(n_passes, np.nan)
    entry_time[pass_offset[clump[is_wrap]] + event_pass[is_wrap] + 1] = event_time[is_wrap]

    exits = ~is_wrap
    exit_row = pass_offset[clump[exits]] + event_pass[exits]
    exit_row_unique, first_of_row = np.unique(exit_row, return_index=True)
    exit_time = np.full(n_passes, np.nan)
    exit_time[exit_row_unique] = event_time[exits][first_of_row]

    previous_exit_time = np.full(n_passes, np.nan)
    later = pass_number > 0
    previous_exit_time[later] = exit_time[np.flatnonzero(later) - 1]

    first_frame = np.argmax(present, axis=0)
    z_first = z[first_frame, np.arange(n_c)]
    started_below_outlet = (pass_number == 0) & (z_first[pass_clump_index] <= outlet)

    # --- every crossing, in time order
    crossing_time = event_time[exits]
    crossing_clump = clump[exits]
    crossing_pass = event_pass[exits]
    is_pass_exit = np.zeros(crossing_time.size, dtype=bool)
    is_pass_exit[first_of_row] = True
    first_exit_time = np.full(n_c, np.nan)
    exit_clumps, first_of_clump = np.unique(crossing_clump, return_index=True)
    first_exit_time[exit_clumps] = crossing_time[first_of_clump]
    by_time = np.argsort(crossing_time, kind="stable")

    return RecirculationEvents(
        clump_id=clump_id,
        pass_clump_index=pass_clump_index,
        pass_clump_id=clump_id[pass_clump_index],
        pass_number=pass_number,
        entry_time=entry_time,
        exit_time=exit_time,
        previous_exit_time=previous_exit_time,
        started_below_outlet=started_below_outlet,
        exit_times_all=crossing_time[by_time],
        exit_clump_index=crossing_clump[by_time],
        exit_pass_number=crossing_pass[by_time],
        exit_is_pass_exit=is_pass_exit[by_time],
        first_exit_time=first_exit_time,
        n_frames_absent=(times.size - present.sum(axis=0)).astype(np.int64),
        first_frame_time=float(times[0]),
        last_frame_time=float(times[-1]),
        outlet_z=outlet,
        domain_bottom=bottom,
        domain_top=top,
    )


def clumps_above_outlet(tracks: ClumpTracks, outlet_z: float) -> np.ndarray:
    """Number of clumps above the outlet plane in each frame (the holdup of the silo).

    Counts the present clumps with ``z > outlet_z``, which includes clumps falling from the top
    of the domain onto the pile after re-entry (passes begin at the re-entry, so the fall is part of
    every pass) and the clumps of the stagnant zones: its ratio to the throughput is the holdup
    residence time (Little's law,
    :func:`analysis.studies.silo_recirculation.vrr.holdup_residence_time`), which exceeds the mean of
    the passes that leave within a run by the stagnant part
    (:mod:`analysis.studies.silo_recirculation.transit`).

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres [m].
    outlet_z : float
        Height of the outlet plane [m].

    Returns
    -------
    numpy.ndarray of int64, shape (n_t,)
        Clumps above the outlet plane per frame [-].
    """
    return np.count_nonzero(above_outlet(tracks, outlet_z), axis=1).astype(np.int64)


def above_outlet(tracks: ClumpTracks, outlet_z: float) -> np.ndarray:
    """Which clumps are above the outlet plane in each frame, ``z > outlet_z``; an absent clump (NaN) is not.

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres [m].
    outlet_z : float
        Height of the outlet plane [m].

    Returns
    -------
    numpy.ndarray of bool, shape (n_t, n_c)
    """
    _, position = _checked_tracks(tracks)
    outlet = finite_number("outlet_z", outlet_z)
    z = np.where(np.isfinite(position[:, :, 2]), position[:, :, 2], -np.inf)  # absent: not counted
    return z > outlet
