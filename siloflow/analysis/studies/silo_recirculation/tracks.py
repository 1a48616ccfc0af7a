"""The events on the clump tracks of a recirculating silo: outlet crossings, re-entries, passes, and the holdup.

Pure functions on numpy arrays; no file I/O. SI units: positions in m, times in s.

Geometry
--------
A planar silo: x across the width, y depth, z up. The silo floor and outlet plane is
``z = outlet_z``; below it a vertical channel runs down to ``z = domain_bottom``. The domain is
periodic in z with height ``L = domain_top - domain_bottom``: a clump leaving the bottom re-enters
at ``domain_top`` and falls onto the pile again. The clump tracks
(:class:`siloflow.analysis.numerics.clump_tracks.ClumpTracks`, from the engine's frames by
:func:`siloflow.analysis.numerics.clump_tracks.tracks_from_frames` with the run's ``domain_z``) give the clump centres
wrapped into ``[domain_bottom, domain_top)`` at the saved instants, NaN where a clump is absent from a frame.

Events (:func:`recirculation_events`)
-------------------------------------
The outlet crossings, the re-entries at the top and the passes between them are those of
:func:`siloflow.analysis.numerics.exit_times.outlet_exits` (where the rules are): every re-entry begins a pass, whose exit
is its first outlet crossing. The study adds what it needs of them: the exit of each clump's previous pass (the
loop time, outlet to outlet), and a flag on the first pass of a clump that was at or below the outlet plane when
first seen (in the channel): its exit is normally NaN and it ends at its re-entry; such passes are kept (flagged)
and drop out of the pass-based quantities by their NaN entry or exit time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number
from siloflow.analysis.numerics.clump_tracks import ClumpTracks, checked_tracks
from siloflow.analysis.numerics.exit_times import PassTable, outlet_exits

__all__ = [
    "RecirculationEvents",
    "recirculation_events",
    "above_outlet",
    "clumps_above_outlet",
]


@dataclass(frozen=True, eq=False)
class RecirculationEvents(PassTable):
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
    exits = outlet_exits(tracks, outlet_z, (domain_bottom, domain_top))
    times, position = checked_tracks(tracks)
    present = np.all(np.isfinite(position), axis=2)
    n_c = exits.n_clumps
    pass_number, pass_clump_index = exits.pass_number, exits.pass_clump_index

    previous_exit_time = np.full(exits.n_passes, np.nan)
    later = pass_number > 0
    previous_exit_time[later] = exits.exit_time[np.flatnonzero(later) - 1]

    first_frame = np.argmax(present, axis=0)
    z_first = position[first_frame, np.arange(n_c), 2]
    started_below_outlet = (pass_number == 0) & (z_first[pass_clump_index] <= exits.outlet_z)

    return RecirculationEvents(
        clump_id=exits.clump_id,
        pass_clump_index=pass_clump_index,
        pass_clump_id=exits.clump_id[pass_clump_index],
        pass_number=pass_number,
        entry_time=exits.entry_time,
        exit_time=exits.exit_time,
        previous_exit_time=previous_exit_time,
        started_below_outlet=started_below_outlet,
        exit_times_all=exits.crossing_time,
        exit_clump_index=exits.crossing_clump_index,
        exit_pass_number=exits.crossing_pass_number,
        exit_is_pass_exit=exits.crossing_is_pass_exit,
        first_exit_time=exits.first_exit_time,
        n_frames_absent=(times.size - present.sum(axis=0)).astype(np.int64),
        first_frame_time=exits.first_frame_time,
        last_frame_time=exits.last_frame_time,
        outlet_z=exits.outlet_z,
        domain_bottom=exits.domain_z[0],
        domain_top=exits.domain_z[1],
    )


def clumps_above_outlet(tracks: ClumpTracks, outlet_z: float) -> np.ndarray:
    """Number of clumps above the outlet plane in each frame (the holdup of the silo).

    Counts the present clumps with ``z > outlet_z``, which includes clumps falling from the top
    of the domain onto the pile after re-entry (passes begin at the re-entry, so the fall is part of
    every pass) and the clumps of the stagnant zones: its ratio to the throughput is the holdup
    residence time (Little's law,
    :func:`siloflow.analysis.studies.silo_recirculation.vrr.holdup_residence_time`), which exceeds the mean of
    the passes that leave within a run by the stagnant part
    (:mod:`siloflow.analysis.studies.silo_recirculation.transit`).

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
    _, position = checked_tracks(tracks)
    outlet = finite_number("outlet_z", outlet_z)
    z = np.where(np.isfinite(position[:, :, 2]), position[:, :, 2], -np.inf)  # absent: not counted
    return z > outlet
