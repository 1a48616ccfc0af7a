"""When the clumps of a run leave through a horizontal outlet plane: every crossing, and the passes they end.

Pure functions on numpy arrays and :mod:`siloflow.model.frames`; no file I/O. SI units: heights in m, times in s.

The clump tracks (:mod:`siloflow.analysis.numerics.clump_tracks`) give each clump's centre at the saved instants. Events are
looked for between consecutive frames ``k, k + 1`` in which the clump is present in both (an interval with the clump
absent from either frame is not bridged, so a deck that deletes clumps must save them once below the plane).

- **Exit** (a downward crossing of the outlet plane ``z = outlet_z``): ``z_k > outlet_z >= z_{k+1}``, at the
  linearly interpolated time ``t_k + (t_{k+1} - t_k)(z_k - outlet_z) / (z_k - z_{k+1})`` (the rule of
  :mod:`siloflow.analysis.numerics.pathlines`). A clump that bounces back up through the plane and falls again crosses
  twice.
- **Re-entry** (only in a domain periodic in z, ``domain_z = (bottom, top)`` of height ``L``): a clump leaving the
  bottom re-enters at the top, ``z_{k+1} - z_k > L / 2``; its unwrapped position is ``z_{k+1} - L``, and the
  re-entry time is where the straight path from ``z_k`` to ``z_{k+1} - L`` crosses ``bottom``. Frames must be close
  enough that a clump moves less than ``L / 2`` between them. In one interval an exit comes before a re-entry.

**Passes.** A clump's first pass (``pass_number`` 0) begins at the first frame in which it is present (entry time
NaN: it was already inside); every re-entry ends a pass and begins the next one (``pass_number`` 1, 2, ..., entry
time the re-entry time). The exit of a pass is its first crossing (NaN if none by the last frame), so
``exit_time - entry_time`` is the residence time of the passes that begin with a re-entry: the sample of a
residence time distribution (:func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times`). Without a periodic boundary every
clump makes one pass.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number
from siloflow.model.frames import ClumpFrame, ParticleFrame
from siloflow.analysis.numerics.clump_tracks import ClumpTracks, checked_tracks, tracks_from_frames

__all__ = ["ExitTimes", "PassTable", "exit_times", "outlet_exits"]


class PassTable:
    """What a table of passes (``clump_id``, ``pass_number``, ``entry_time``, ``exit_time``) tells about itself: the
    counts and each pass's residence time."""

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
class ExitTimes(PassTable):
    """Outlet crossings, re-entries and passes of the clumps of a run.

    Pass rows are ordered by clump index, then by ``pass_number``; crossing rows by time.

    Attributes
    ----------
    clump_id : numpy.ndarray of int64, shape (n_c,)
        Clump ids, as in the tracks [-].
    pass_clump_index : numpy.ndarray of int64, shape (n_p,)
        Column of the clump making the pass (index into ``clump_id``) [-].
    pass_number : numpy.ndarray of int64, shape (n_p,)
        0 for the pass a clump is on when first seen, 1 after its first re-entry, ... [-].
    entry_time : numpy.ndarray, shape (n_p,)
        Re-entry time that begins the pass; NaN for pass 0 [s].
    exit_time : numpy.ndarray, shape (n_p,)
        First outlet crossing of the pass; NaN if none by the last frame [s].
    crossing_time : numpy.ndarray, shape (n_x,)
        Every outlet crossing of every clump, ascending [s].
    crossing_clump_index : numpy.ndarray of int64, shape (n_x,)
        Clump column of each crossing [-].
    crossing_pass_number : numpy.ndarray of int64, shape (n_x,)
        ``pass_number`` of the pass each crossing belongs to [-].
    crossing_is_pass_exit : numpy.ndarray of bool, shape (n_x,)
        True for the crossings that are the exit of their pass (the first one of the pass).
    first_exit_time : numpy.ndarray, shape (n_c,)
        First outlet crossing of each clump; NaN if it never crossed [s].
    first_frame_time, last_frame_time : float
        Times of the first and last frame [s].
    outlet_z : float
        Height of the outlet plane [m].
    domain_z : tuple of float or None
        Bottom and top of the domain periodic in z [m]; None without a periodic boundary.
    """

    clump_id: np.ndarray
    pass_clump_index: np.ndarray
    pass_number: np.ndarray
    entry_time: np.ndarray
    exit_time: np.ndarray
    crossing_time: np.ndarray
    crossing_clump_index: np.ndarray
    crossing_pass_number: np.ndarray
    crossing_is_pass_exit: np.ndarray
    first_exit_time: np.ndarray
    first_frame_time: float
    last_frame_time: float
    outlet_z: float
    domain_z: tuple[float, float] | None


def _checked_domain(outlet: float, domain_z) -> tuple[float, float] | None:
    if domain_z is None:
        return None
    bottom, top = (finite_number("domain_z", bound) for bound in domain_z)
    if not bottom < outlet < top:
        raise ValueError(
            f"outlet_z must lie strictly between domain_bottom and domain_top, got "
            f"domain_bottom={bottom!r}, outlet_z={outlet!r}, domain_top={top!r}"
        )
    return bottom, top


def outlet_exits(tracks: ClumpTracks, outlet_z: float, domain_z: tuple[float, float] | None = None) -> ExitTimes:
    """Outlet crossings, re-entries and passes of every tracked clump (see the module docstring).

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres [m]; in a periodic domain, z wrapped into ``[domain_z[0], domain_z[1]]``.
    outlet_z : float
        Height of the outlet plane [m]; in a periodic domain strictly between its bottom and top.
    domain_z : (float, float) or None, optional
        Bottom and top of the domain periodic in z [m] (``domain_bottom``, ``domain_top``); None (default) for a run
        without a periodic boundary, whose clumps never re-enter.

    Returns
    -------
    ExitTimes

    Raises
    ------
    ValueError
        If the heights are not ordered ``domain_bottom < outlet_z < domain_top``, the tracks are malformed, or a
        height lies outside the periodic domain.

    Examples
    --------
    A clump falling from 0.3 m to 0.1 m between frames at 0 s and 1 s crosses an outlet at 0.2 m half-way:

    >>> from siloflow.analysis.numerics.clump_tracks import clump_tracks
    >>> tracks = clump_tracks([0.0, 1.0], [[5], [5]], [[[0, 0, 0.3]], [[0, 0, 0.1]]])
    >>> outlet_exits(tracks, 0.2).first_exit_time.round(12).tolist()
    [0.5]
    """
    times, position = checked_tracks(tracks)
    outlet = finite_number("outlet_z", outlet_z)
    domain = _checked_domain(outlet, domain_z)
    clump_id = np.asarray(tracks.clump_id).astype(np.int64)
    n_c = clump_id.size
    present = np.all(np.isfinite(position), axis=2)
    z = position[:, :, 2]
    if domain is not None:
        bottom, top = domain
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
    if domain is None:
        wrap = np.zeros_like(both)
        z1_unwrapped = z1
    else:
        height = domain[1] - domain[0]
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
    bottom = domain[0] if domain is not None else 0.0
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

    return ExitTimes(
        clump_id=clump_id,
        pass_clump_index=pass_clump_index,
        pass_number=pass_number,
        entry_time=entry_time,
        exit_time=exit_time,
        crossing_time=crossing_time[by_time],
        crossing_clump_index=crossing_clump[by_time],
        crossing_pass_number=crossing_pass[by_time],
        crossing_is_pass_exit=is_pass_exit[by_time],
        first_exit_time=first_exit_time,
        first_frame_time=float(times[0]),
        last_frame_time=float(times[-1]),
        outlet_z=outlet,
        domain_z=domain,
    )


def exit_times(frames: Iterable[ParticleFrame | ClumpFrame], outlet_z: float,
               domain_z: tuple[float, float] | None = None) -> ExitTimes:
    """When each clump of a run leaves through the outlet plane, from the run's frames.

    The frames become clump tracks (:func:`siloflow.analysis.numerics.clump_tracks.tracks_from_frames`) whose crossings of
    the plane are found by :func:`outlet_exits`.

    Parameters
    ----------
    frames : iterable of ParticleFrame or ClumpFrame
        The saved frames of the run in time order (at least 2), as the engine reads them.
    outlet_z : float
        Height of the outlet plane [m] (the run record's ``outlet_z``).
    domain_z : (float, float) or None, optional
        Bottom and top of the domain periodic in z [m] (the run record's ``domain_z``); None (default) without a
        periodic boundary.

    Returns
    -------
    ExitTimes

    Examples
    --------
    Two single-sphere clumps falling at 1 m/s through a domain periodic over [-0.1, 0.2) m, outlet at 0, frames
    every 0.05 s: clump 1 starts at 0.12 m and clump 2 at 0.03 m.

    >>> import numpy as np
    >>> from siloflow.model.frames import ParticleFrame
    >>> def frame(t):
    ...     z = -0.1 + np.mod(np.array([0.12, 0.03]) - t + 0.1, 0.3)
    ...     return ParticleFrame(time=t, step=round(t * 1e4), id=[1, 2], type=[1, 1], clump_id=[1, 2],
    ...                          position=np.column_stack([[0.0, 0.01], [0.0, 0.0], z]), velocity=[[0, 0, -1.0]] * 2,
    ...                          angular_velocity=None, radius=[0.001] * 2, mass=[1e-5] * 2)
    >>> exits = exit_times([frame(0.05 * k) for k in range(9)], 0.0, (-0.1, 0.2))
    >>> exits.first_exit_time.round(6).tolist()
    [0.12, 0.03]
    >>> exits.pass_clump_index.tolist(), exits.pass_number.tolist()
    ([0, 0, 1, 1], [0, 1, 0, 1])
    >>> exits.entry_time.round(6).tolist(), exits.exit_time.round(6).tolist()
    ([nan, 0.22, nan, 0.13], [0.12, nan, 0.03, 0.33])
    >>> exits.residence_time[np.isfinite(exits.residence_time)].round(6).tolist()
    [0.2]
    """
    tracked = tracks_from_frames(frames, domain_z)
    return outlet_exits(tracked.tracks, outlet_z, domain_z)
