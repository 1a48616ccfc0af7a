"""Blending in a recirculating silo from clump tracks: passes, batch layers, outlet concentration.

Pure functions on numpy arrays; no file I/O. SI units: positions in m, times in s, volumes in
m^3, densities in kg/m^3, masses in kg, E in 1/s; concentrations are blue fractions [-].

Geometry
--------
A planar silo: x across the width, y depth, z up. The silo floor and outlet plane is
``z = outlet_z``; below it a vertical channel runs down to ``z = domain_bottom``. The domain is
periodic in z with height ``L = domain_top - domain_bottom``: a clump leaving the bottom re-enters
at ``domain_top`` and falls onto the pile again. Dumps give clump centres wrapped into
``[domain_bottom, domain_top)`` at the saved instants ``times``, assembled by :func:`clump_tracks`
into one array with NaN where a clump is absent from a frame.

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

Batch layers and outlet concentration
-------------------------------------
The batch is coloured after the fact from one assembly (:func:`layer_colours`): clumps ranked by
height, ``r = (rank + 0.5) / N`` (``1 - r`` when counting from the top), blue iff
``frac(r * sublayers) < blue_fraction``. The outlet concentration in a time window is the number
of blue outlet crossings over the number of all outlet crossings in it
(:func:`outlet_concentration`).

Recirculation number and VRR
----------------------------
``Nr = (t - t_open) / t_res`` with the mean residence time ``t_res`` = holdup / throughput
(Little's law, :func:`holdup_residence_time`). The windows of recirculation k are those with
``k - 1 <= Nr < k``; ``VRR_k = p (1 - p) / var(c)`` over them (:func:`vrr_by_recirculation`), the
input variance being that of the 0/1 batch with blue fraction ``p``.

Renewal model
-------------
Material that leaves re-enters at once and the flow is steady, so the blue outflow is the first
outlet crossing of what the loop held at the start plus whatever re-entered and leaves again:
``c = c_first + c * E`` with ``E`` the loop RTD (outlet crossing to the next outlet crossing)
and ``*`` the convolution. Its series solution ``c = c_first + c_first * E + c_first * E * E + ...``
is :func:`predicted_concentration_from_first_pass` (:func:`analysis.numerics.lti.recirculate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.checks import finite_array, finite_number, positive_number

__all__ = [
    "ClumpTracks",
    "RecirculationEvents",
    "OutletConcentration",
    "RecirculationVRR",
    "TracerPasses",
    "clump_tracks",
    "recirculation_events",
    "clumps_above_outlet",
    "layer_colours",
    "outlet_concentration",
    "first_pass_concentration",
    "recirculation_number",
    "holdup_residence_time",
    "vrr_by_recirculation",
    "sampling_noise_vrr_limit",
    "tracer_passes",
    "tracer_count",
    "predicted_concentration_from_first_pass",
    "batch_inlet_signal",
]


# --------------------------------------------------------------------------- results


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
class OutletConcentration:
    """Blue fraction of the outlet crossings in consecutive time windows.

    Attributes
    ----------
    edges : numpy.ndarray, shape (n_w + 1,)
        Window edges ``t_start + i window`` [s]; window i is ``[edges[i], edges[i + 1])``.
    centres : numpy.ndarray, shape (n_w,)
        Window centres [s].
    n_total : numpy.ndarray of int64, shape (n_w,)
        Outlet crossings in each window [-].
    n_blue : numpy.ndarray of int64, shape (n_w,)
        Blue crossings counted in each window [-].
    concentration : numpy.ndarray, shape (n_w,)
        ``n_blue / n_total`` [-]; NaN where ``n_total`` is 0.
    window : float
        Window length [s].
    """

    edges: np.ndarray
    centres: np.ndarray
    n_total: np.ndarray
    n_blue: np.ndarray
    concentration: np.ndarray
    window: float

    @property
    def mean_crossings(self) -> float:
        """Mean number of crossings per window (the ``n`` of :func:`sampling_noise_vrr_limit`) [-]."""
        return float(np.mean(self.n_total))

    def rows(self) -> list[dict]:
        """One dict per window (for :func:`analysis.io.tables.write_flow_table`)."""
        return [
            {
                "t_start_s": float(a),
                "t_end_s": float(b),
                "t_centre_s": float(c),
                "n_total": int(n),
                "n_blue": int(nb),
                "concentration": float(x),
            }
            for a, b, c, n, nb, x in zip(
                self.edges[:-1], self.edges[1:], self.centres, self.n_total, self.n_blue, self.concentration
            )
        ]


@dataclass(frozen=True, eq=False)
class RecirculationVRR:
    """Variance reduction ratio of the outlet concentration, recirculation by recirculation.

    Attributes
    ----------
    recirculation_number : numpy.ndarray, shape (K,)
        Midpoints ``k - 0.5`` of the recirculation intervals ``[k - 1, k)`` [-].
    vrr : numpy.ndarray, shape (K,)
        ``sigma_in^2 / sigma_out^2`` [-]; inf where ``sigma_out`` is 0, NaN with fewer than 2
        windows.
    sigma_out : numpy.ndarray, shape (K,)
        Population standard deviation of the window concentrations [-]; NaN with fewer than 2
        windows.
    n_windows : numpy.ndarray of int64, shape (K,)
        Windows (with a concentration) in each interval [-].
    sigma_in : float
        Standard deviation of the 0/1 batch, ``sqrt(p (1 - p))`` [-].
    blue_fraction : float
        Blue fraction ``p`` of the batch [-].
    """

    recirculation_number: np.ndarray
    vrr: np.ndarray
    sigma_out: np.ndarray
    n_windows: np.ndarray
    sigma_in: float
    blue_fraction: float

    def rows(self) -> list[dict]:
        """One dict per recirculation (for :func:`analysis.io.tables.write_flow_table`)."""
        return [
            {
                "recirculation_number": float(nr),
                "vrr": float(v),
                "sigma_out": float(s),
                "n_windows": int(n),
                "sigma_in": self.sigma_in,
                "blue_fraction": self.blue_fraction,
            }
            for nr, v, s, n in zip(self.recirculation_number, self.vrr, self.sigma_out, self.n_windows)
        ]


@dataclass(frozen=True, eq=False)
class TracerPasses:
    """A tracer made of the passes that enter first after a start time.

    Attributes
    ----------
    entry_time : numpy.ndarray, shape (n,)
        Entry time of each tracer pass, ascending [s].
    exit_time : numpy.ndarray, shape (n,)
        Its exit time; NaN when not out by the last frame [s].
    pass_index : numpy.ndarray of int64, shape (n,)
        Row of the pass in :class:`RecirculationEvents` [-].
    clump_index : numpy.ndarray of int64, shape (n,)
        Clump column [-].
    clump_id : numpy.ndarray of int64, shape (n,)
        Clump id [-].
    entry_at : str
        ``"wrap"`` (entry = re-entry at the top) or ``"outlet"`` (entry = the previous outlet
        crossing of the clump).
    """

    entry_time: np.ndarray
    exit_time: np.ndarray
    pass_index: np.ndarray
    clump_index: np.ndarray
    clump_id: np.ndarray
    entry_at: str

    @property
    def n_tracer(self) -> int:
        """Number of tracer passes ``N0``."""
        return int(self.entry_time.shape[0])

    @property
    def n_exited(self) -> int:
        """Tracer passes that left by the last frame."""
        return int(np.count_nonzero(np.isfinite(self.exit_time)))

    @property
    def residence_time(self) -> np.ndarray:
        """``exit_time - entry_time`` [s] (NaN where not out)."""
        return self.exit_time - self.entry_time


# --------------------------------------------------------------------------- validation




def _integer(name: str, value, minimum: int) -> int:
    if (
        isinstance(value, (bool, np.bool_))
        or not isinstance(value, (int, np.integer, float, np.floating))
        or not math.isfinite(float(value))
        or int(value) != value
        or int(value) < minimum
    ):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _fraction(name: str, value) -> float:
    """A number strictly between 0 and 1."""
    value = float(value)
    if not math.isfinite(value) or not 0.0 < value < 1.0:
        raise ValueError(f"{name} must be a number in (0, 1), got {value!r}")
    return value


def _blue_at(value) -> str:
    if value not in ("bottom", "top"):
        raise ValueError(f"blue_at must be 'bottom' or 'top', got {value!r}")
    return value


def _ids(name: str, values) -> np.ndarray:
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


def _mask(name: str, values, shape: tuple) -> np.ndarray:
    """A boolean mask (bool, or numbers that are all 0 or 1) of the given shape."""
    array = np.asarray(values)
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if array.dtype == bool:
        return array
    if array.dtype.kind in "iuf" and np.all((array == 0) | (array == 1)):
        return array.astype(bool)
    raise ValueError(f"{name} must be a boolean mask (True/False or 0/1)")


def _event_times(name: str, values) -> np.ndarray:
    """A 1-D float array of times; NaN allowed (no crossing), infinities not."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {array.shape}")
    if np.any(np.isinf(array)):
        raise ValueError(f"{name} must not contain infinite values (use NaN for no crossing)")
    return array


def _increasing_times(name: str, values) -> np.ndarray:
    times = finite_array(name, values, ndim=1)
    if times.size == 0:
        raise ValueError(f"{name} must not be empty")
    if np.any(np.diff(times) <= 0.0):
        raise ValueError(f"{name} must be strictly increasing")
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


def _window_edges(window, t_start, t_end) -> tuple[np.ndarray, float]:
    window = positive_number("window", window)
    t_start = finite_number("t_start", t_start)
    t_end = finite_number("t_end", t_end)
    if t_end <= t_start:
        raise ValueError(f"t_end must be > t_start = {t_start!r} s, got {t_end!r}")
    n_windows = int(math.floor((t_end - t_start) / window + 1.0e-9))
    if n_windows < 1:
        raise ValueError(f"window ({window!r} s) must fit at least once into [t_start, t_end] = [{t_start!r}, {t_end!r}] s")
    return t_start + np.arange(n_windows + 1) * window, window


def _window_counts(edges: np.ndarray, times: np.ndarray, counted: np.ndarray | None = None) -> np.ndarray:
    """Number of ``times`` (NaN ignored; only where ``counted``) in each window ``[edges[i], edges[i + 1])``."""
    n_windows = edges.size - 1
    keep = np.isfinite(times) if counted is None else np.isfinite(times) & counted
    index = np.searchsorted(edges, times[keep], side="right") - 1
    index = index[(index >= 0) & (index < n_windows)]
    return np.bincount(index, minlength=n_windows).astype(np.int64)


def _concentration(edges: np.ndarray, n_total: np.ndarray, n_blue: np.ndarray, window: float) -> OutletConcentration:
    with np.errstate(invalid="ignore", divide="ignore"):
        concentration = np.where(n_total > 0, n_blue / np.maximum(n_total, 1), np.nan)
    return OutletConcentration(
        edges=edges,
        centres=0.5 * (edges[1:] + edges[:-1]),
        n_total=n_total,
        n_blue=n_blue,
        concentration=concentration,
        window=float(window),
    )


# --------------------------------------------------------------------------- tracks and events


def clump_tracks(times, ids_per_frame, positions_per_frame) -> ClumpTracks:
    """Assemble per-frame clump ids and centres into one array, one column per clump.

    Parameters
    ----------
    times : array_like, shape (n_t,)
        Frame times, strictly increasing [s].
    ids_per_frame : sequence of array_like
        One 1-D array of integer clump ids per frame, in any order (e.g.
        :attr:`engines.liggghts.dumps.ClumpFrame.clump_id`). Ids may be negative; duplicates within a
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
        ids = _ids(f"ids_per_frame[{k}]", ids)
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
    of the domain onto the pile after re-entry: with passes beginning at the re-entry, this is the
    holdup whose ratio to the throughput is the mean pass residence time (Little's law,
    :func:`holdup_residence_time`).

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
    _, position = _checked_tracks(tracks)
    outlet = finite_number("outlet_z", outlet_z)
    z = np.where(np.isfinite(position[:, :, 2]), position[:, :, 2], -np.inf)  # absent: not counted
    return np.count_nonzero(z > outlet, axis=1).astype(np.int64)


# --------------------------------------------------------------------------- batch layers


def layer_colours(initial_height, blue_fraction: float, sublayers: int = 1, blue_at: str = "bottom") -> np.ndarray:
    """Colour the clumps of one assembly in horizontal batch layers (True = blue).

    The clumps are ranked by height (stable sort: equal heights by index), ``r_i = (rank_i + 0.5) / N``
    from the bottom (``1 - r_i``, i.e. ranked from the top, when ``blue_at = "top"``), and clump i is
    blue iff ``frac(r_i * sublayers) < blue_fraction``. The rule is evaluated in integers,
    ``((2 rank + 1) sublayers mod 2N) / 2N < p``, so the counts are exact. With ``sublayers = 1``
    the lowest (highest) fraction ``p`` is blue; ``sublayers = 3`` with ``p = 0.5`` gives six equal
    layers B W B W B W from the bottom (from the top with ``blue_at = "top"``).

    Parameters
    ----------
    initial_height : array_like, shape (N,)
        Heights of the clumps at the assembly, finite [m] (e.g. ``tracks.z[0]``; pass a subset to
        colour only, say, the clumps above the outlet).
    blue_fraction : float
        Blue fraction ``p`` of each layer pair, in (0, 1) [-].
    sublayers : int, optional
        Number of blue/white layer pairs, >= 1; default 1.
    blue_at : {"bottom", "top"}, optional
        Whether each pair starts with blue at its bottom (default) or the ranks count from the top.

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        True for blue clumps.
    """
    heights = finite_array("initial_height", initial_height, ndim=1)
    p = _fraction("blue_fraction", blue_fraction)
    sublayers = _integer("sublayers", sublayers, 1)
    blue_at = _blue_at(blue_at)
    n = heights.size
    if n == 0:
        return np.zeros(0, dtype=bool)
    rank = np.empty(n, dtype=np.int64)
    rank[np.argsort(heights, kind="stable")] = np.arange(n, dtype=np.int64)
    if blue_at == "top":
        rank = n - 1 - rank
    numerator = ((2 * rank + 1) * sublayers) % (2 * n)
    return numerator / (2.0 * n) < p


def batch_inlet_signal(
    blue_fraction: float, sublayers: int, blue_at: str, residence_time: float, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """The layered batch as an inlet concentration fed over one mean residence time.

    The batch is fed bottom layer first over ``t_res``: the material entering at time t is the
    layer at relative height ``r = t / t_res`` of the batch, blue (1) iff
    ``frac(r * sublayers) < blue_fraction`` (``r -> 1 - r`` for ``blue_at = "top"``), the rule of
    :func:`layer_colours`. The signal has ``N = round(t_res / dt)`` samples at the midpoints
    ``t_i = (i + 0.5) dt``, i = 0 ... N - 1, each standing for ``[i dt, (i + 1) dt)``; its mean is
    ``p`` up to discretisation, exactly when ``N dt = t_res`` and ``N / sublayers`` and
    ``N p / sublayers`` are whole numbers (every layer boundary then falls between samples).
    Feed it to :func:`analysis.numerics.lti.recirculate` with an RTD sampled with the same ``dt``.

    Parameters
    ----------
    blue_fraction : float
        Blue fraction ``p``, in (0, 1) [-].
    sublayers : int
        Number of blue/white layer pairs, >= 1.
    blue_at : {"bottom", "top"}
        Where the blue layer of each pair lies (bottom enters first).
    residence_time : float
        Mean residence time ``t_res`` over which the batch is fed [s], > 0.
    dt : float
        Sample step [s], > 0 and at most ``2 t_res`` (at least one sample).

    Returns
    -------
    time : numpy.ndarray, shape (N,)
        Sample times ``(i + 0.5) dt`` [s].
    c_in : numpy.ndarray, shape (N,)
        Inlet concentration, 1.0 blue or 0.0 white [-].
    """
    p = _fraction("blue_fraction", blue_fraction)
    sublayers = _integer("sublayers", sublayers, 1)
    blue_at = _blue_at(blue_at)
    t_res = positive_number("residence_time", residence_time)
    dt = positive_number("dt", dt)
    n = int(round(t_res / dt))
    if n < 1:
        raise ValueError(f"dt ({dt!r} s) must be at most twice residence_time ({t_res!r} s): no sample")
    time = (np.arange(n) + 0.5) * dt
    r = time / t_res
    if blue_at == "top":
        r = 1.0 - r
    scaled = r * sublayers
    c_in = np.where(scaled - np.floor(scaled) < p, 1.0, 0.0)
    return time, c_in


# --------------------------------------------------------------------------- outlet concentration


def outlet_concentration(exit_times, is_blue, window: float, t_start: float, t_end: float) -> OutletConcentration:
    """Blue fraction of the outlet crossings in consecutive windows of ``[t_start, t_end]``.

    The span is cut into ``floor((t_end - t_start) / window)`` windows ``[t_start + i window,
    t_start + (i + 1) window)`` (the incomplete last one is dropped); each counts the crossings in it
    and the blue ones. For every outlet crossing of a run use
    ``outlet_concentration(events.exit_times_all, colours[events.exit_clump_index], ...)``.

    Parameters
    ----------
    exit_times : array_like, shape (n,)
        Crossing times [s]; NaN entries (no crossing) are ignored.
    is_blue : array_like of bool, shape (n,)
        Colour of each crossing clump.
    window : float
        Window length [s], > 0.
    t_start, t_end : float
        Span to cut into windows [s], ``t_end > t_start``.

    Returns
    -------
    OutletConcentration
        ``concentration = n_blue / n_total`` per window (NaN where no crossing).
    """
    exits = _event_times("exit_times", exit_times)
    blue = _mask("is_blue", is_blue, exits.shape)
    edges, window = _window_edges(window, t_start, t_end)
    n_total = _window_counts(edges, exits)
    n_blue = _window_counts(edges, exits, blue)
    return _concentration(edges, n_total, n_blue, window)


def first_pass_concentration(
    events: RecirculationEvents, is_blue, window: float, t_start: float, t_end: float
) -> OutletConcentration:
    """Blue first exits of the initial contents over all outlet crossings, per window.

    The initial contents are everything the loop holds at the first frame; the first exit of a
    clump is its first outlet crossing after that (``events.first_exit_time``): the exit of its
    pass 0, or, for a clump that started in the channel below the outlet, the exit after its first
    re-entry (in a run whose channel is empty at the first frame, exactly the exits with
    ``pass_number`` 0). ``n_blue`` counts the blue first exits in each window and ``n_total`` every
    outlet crossing (``events.exit_times_all``), so ``c_first + c_recycled = c`` with
    ``c = outlet_concentration(events.exit_times_all, is_blue[events.exit_clump_index], ...)``.
    ``c_first`` is the source term of the renewal equation
    (:func:`predicted_concentration_from_first_pass`).

    Parameters
    ----------
    events : RecirculationEvents
        Crossings and passes of the run.
    is_blue : array_like of bool, shape (n_c,)
        Colour of each clump, in the column order of the events (e.g. :func:`layer_colours`).
    window : float
        Window length [s], > 0.
    t_start, t_end : float
        Span to cut into windows [s] (as in :func:`outlet_concentration`).

    Returns
    -------
    OutletConcentration
        ``concentration`` is ``c_first`` (NaN where no crossing at all).
    """
    blue = _mask("is_blue", is_blue, (events.n_clumps,))
    edges, window = _window_edges(window, t_start, t_end)
    n_total = _window_counts(edges, np.asarray(events.exit_times_all, dtype=float))
    n_blue = _window_counts(edges, np.asarray(events.first_exit_time, dtype=float), blue)
    return _concentration(edges, n_total, n_blue, window)


def predicted_concentration_from_first_pass(c_first, E, dt: float, passes: int) -> np.ndarray:
    """Outlet concentration predicted from the first exits of the initial contents (renewal equation).

    Model: material leaving the outlet re-enters at once (the periodic silo) and the flow is
    steady, so the outlet concentration is the first-exit contribution of the initial contents
    plus the re-entered outflow that leaves again:

        c(t) = c_first(t) + integral_0^t c(t - tau) E(tau) dtau,

    a renewal equation whose series solution ``c = c_first + c_first * E + c_first * E * E + ...``
    is summed by :func:`analysis.numerics.lti.recirculate` (its pass-1 output is ``c_first * E``), plus
    ``c_first`` itself, on the axis of ``c_first`` (longer parts are cut). ``E`` must be the RTD of
    the whole loop, from an outlet crossing to the next one of the same clump (channel and free
    fall included: :func:`tracer_passes` with ``entry_at = "outlet"``); "at once" then holds by
    construction. Discretisation is that of :mod:`analysis.numerics.lti` (rectangle rule, first order in
    ``dt``); ``E`` is normalised to unit area (a closed loop loses nothing).

    The sum is complete on the axis once pass ``passes + 1`` contributes nothing there: if ``E``
    vanishes below the lag of ``m0`` samples, ``passes >= len(c_first) / m0`` suffices; with
    ``E[0] > 0`` the terms decay geometrically instead.

    Parameters
    ----------
    c_first : array_like, shape (N,)
        First-exit concentration per window (:func:`first_pass_concentration`), finite, N >= 2 [-].
    E : array_like, shape (m,)
        Loop RTD at residence times ``0, dt, 2 dt, ...`` [1/s] (for a histogram from
        :func:`analysis.numerics.rtd.rtd_from_exit_times` with bins of width ``dt`` from 0, its ``E``).
    dt : float
        Window length, the step of ``c_first`` and ``E`` [s], > 0.
    passes : int
        Number of recirculations summed, >= 1.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Predicted outlet concentration on the windows of ``c_first`` [-].
    """
    from analysis.numerics.lti import recirculate

    c1 = finite_array("c_first", c_first, ndim=1)
    if c1.size < 2:
        raise ValueError(f"c_first must have at least 2 samples, got {c1.size}")
    dt = positive_number("dt", dt)
    passes = _integer("passes", passes, 1)
    loop = recirculate(c1, E, np.arange(c1.size) * dt, passes, normalise=True)
    return c1 + loop.concentration[: c1.size]


# --------------------------------------------------------------------------- recirculation number and VRR


def recirculation_number(t, t_open: float, residence_time: float):
    """Recirculation number ``Nr = (t - t_open) / t_res`` [-].

    Parameters
    ----------
    t : float or array_like
        Times [s].
    t_open : float
        Time the outlet opened (start of the discharge) [s].
    residence_time : float
        Mean residence time ``t_res`` [s], > 0 (:func:`holdup_residence_time`).

    Returns
    -------
    float or numpy.ndarray
        ``Nr``, the shape of ``t`` (a float for a scalar ``t``).
    """
    times = finite_array("t", t, ndim=None)
    t_open = finite_number("t_open", t_open)
    t_res = positive_number("residence_time", residence_time)
    nr = (times - t_open) / t_res
    return float(nr) if nr.ndim == 0 else nr


def holdup_residence_time(n_in_silo, exit_times, t_start: float, t_end: float) -> float:
    """Mean residence time ``t_res`` = mean holdup / throughput (Little's law) [s].

    ``t_res = mean(n_in_silo) / (n_exits / (t_end - t_start))``, with ``n_exits`` the crossings with
    ``t_start <= t <= t_end``. In a steady flow it equals the mean pass residence time (re-entry to
    outlet) when the holdup counts the clumps above the outlet (:func:`clumps_above_outlet`).

    Parameters
    ----------
    n_in_silo : array_like, shape (n,)
        Clumps in the silo at the frames inside ``[t_start, t_end]`` (the caller restricts it to
        the window), >= 0 [-].
    exit_times : array_like, shape (m,)
        Outlet crossing times [s] (e.g. ``events.exit_times_all``); NaN ignored.
    t_start, t_end : float
        The window [s], ``t_end > t_start``.

    Returns
    -------
    float
        ``t_res`` [s].

    Raises
    ------
    ValueError
        On an empty or negative holdup, a bad window, or no crossing in the window.
    """
    holdup = finite_array("n_in_silo", n_in_silo, ndim=1)
    if holdup.size == 0:
        raise ValueError("n_in_silo must not be empty")
    if np.any(holdup < 0.0):
        raise ValueError("n_in_silo must contain counts >= 0")
    exits = _event_times("exit_times", exit_times)
    t_start = finite_number("t_start", t_start)
    t_end = finite_number("t_end", t_end)
    if t_end <= t_start:
        raise ValueError(f"t_end must be > t_start = {t_start!r} s, got {t_end!r}")
    n_exits = int(np.count_nonzero((exits >= t_start) & (exits <= t_end)))
    if n_exits == 0:
        raise ValueError(f"exit_times: no outlet crossing in [t_start, t_end] = [{t_start!r}, {t_end!r}] s")
    return float(np.mean(holdup)) * (t_end - t_start) / n_exits


def vrr_by_recirculation(
    window_centres,
    concentration,
    t_open: float,
    residence_time: float,
    blue_fraction: float,
    n_recirculations: int,
) -> RecirculationVRR:
    """Variance reduction ratio of the outlet concentration in each recirculation.

    For k = 1 ... K the windows whose recirculation number ``Nr`` (:func:`recirculation_number` of
    their centres) lies in ``[k - 1, k)`` and whose concentration is not NaN give
    ``sigma_out^2``, the population variance (``ddof = 0``) of their concentrations; the input
    variance is that of the 0/1 batch, ``sigma_in^2 = p (1 - p)``, and ``VRR_k = sigma_in^2 /
    sigma_out^2`` (inf if ``sigma_out`` is 0, NaN with fewer than 2 windows).

    Sampling noise: a window of ``n`` crossings from a perfectly mixed outflow has a binomial blue
    count, so its concentration still varies with variance ``p (1 - p) / n``; the measurable VRR is
    capped at about ``n`` (:func:`sampling_noise_vrr_limit`). Windows of unequal ``n`` are weighted
    equally.

    Parameters
    ----------
    window_centres : array_like, shape (n_w,)
        Window centre times [s] (:attr:`OutletConcentration.centres`).
    concentration : array_like, shape (n_w,)
        Blue fraction per window [-]; NaN windows are ignored.
    t_open : float
        Time the outlet opened [s].
    residence_time : float
        Mean residence time [s], > 0.
    blue_fraction : float
        Blue fraction ``p`` of the batch, in (0, 1) [-].
    n_recirculations : int
        Number K of recirculations, >= 1.

    Returns
    -------
    RecirculationVRR
    """
    centres = finite_array("window_centres", window_centres, ndim=1)
    c = np.asarray(concentration, dtype=float)
    if c.shape != centres.shape:
        raise ValueError(f"concentration must have the shape of window_centres {centres.shape}, got {c.shape}")
    if np.any(np.isinf(c)):
        raise ValueError("concentration must not contain infinite values (NaN marks an empty window)")
    p = _fraction("blue_fraction", blue_fraction)
    k_max = _integer("n_recirculations", n_recirculations, 1)
    nr = np.asarray(recirculation_number(centres, t_open, residence_time), dtype=float)
    sigma_in2 = p * (1.0 - p)
    vrr = np.full(k_max, np.nan)
    sigma_out = np.full(k_max, np.nan)
    n_windows = np.zeros(k_max, dtype=np.int64)
    for k in range(1, k_max + 1):
        values = c[(nr >= k - 1) & (nr < k) & np.isfinite(c)]
        n_windows[k - 1] = values.size
        if values.size < 2:
            continue
        variance = float(np.var(values))
        sigma_out[k - 1] = math.sqrt(variance)
        vrr[k - 1] = math.inf if variance == 0.0 else sigma_in2 / variance
    return RecirculationVRR(
        recirculation_number=np.arange(1, k_max + 1) - 0.5,
        vrr=vrr,
        sigma_out=sigma_out,
        n_windows=n_windows,
        sigma_in=math.sqrt(sigma_in2),
        blue_fraction=p,
    )


def sampling_noise_vrr_limit(blue_fraction: float, particles_per_window: float) -> float:
    """Largest VRR measurable with ``n`` particles per window: ``p (1 - p) / (p (1 - p) / n) = n`` [-].

    A perfectly mixed outflow still gives window concentrations with the binomial variance
    ``p (1 - p) / n``, so ``sigma_in^2`` over it, i.e. ``n``, is the VRR of perfect mixing as measured
    (a reference line for plots of :func:`vrr_by_recirculation`).

    Parameters
    ----------
    blue_fraction : float
        Blue fraction ``p``, in (0, 1) [-].
    particles_per_window : float
        Mean outlet crossings per window ``n`` (:attr:`OutletConcentration.mean_crossings`), > 0 [-].

    Returns
    -------
    float
        The VRR limit [-].
    """
    p = _fraction("blue_fraction", blue_fraction)
    n = positive_number("particles_per_window", particles_per_window)
    return n


# --------------------------------------------------------------------------- tracer


def tracer_passes(events: RecirculationEvents, start_time: float, n_tracer: int, entry_at: str = "wrap") -> TracerPasses:
    """The tracer of the particle RTD: the first ``n_tracer`` passes entering at or after ``start_time``.

    Passes are ordered by entry time (ties by pass row) and the first ``n_tracer`` with
    ``entry >= start_time`` are taken. ``entry_at = "wrap"`` (default): the entry is the re-entry at
    the top, so ``exit - entry`` is the residence time of a pass through the silo (free fall from
    the top included). ``entry_at = "outlet"``: the entry is the previous outlet crossing of the
    clump, so ``exit - entry`` is the loop time (channel, re-entry and silo), the ``E`` of the
    renewal equation (:func:`predicted_concentration_from_first_pass`). Feed the result to
    ``analysis.numerics.rtd.rtd_from_exit_times(tracer.exit_time, t_entry=tracer.entry_time,
    n_total=tracer.n_tracer)``.

    Parameters
    ----------
    events : RecirculationEvents
        Passes of the run.
    start_time : float
        Earliest entry time [s].
    n_tracer : int
        Number of tracer passes, >= 1 (e.g. :func:`tracer_count`).
    entry_at : {"wrap", "outlet"}, optional
        Which event is the entry; default ``"wrap"``.

    Returns
    -------
    TracerPasses
        Exit times are NaN for passes not out by the last frame.

    Raises
    ------
    ValueError
        If fewer than ``n_tracer`` passes enter at or after ``start_time``.
    """
    start = finite_number("start_time", start_time)
    n_tracer = _integer("n_tracer", n_tracer, 1)
    if entry_at == "wrap":
        entry = np.asarray(events.entry_time, dtype=float)
    elif entry_at == "outlet":
        entry = np.asarray(events.previous_exit_time, dtype=float)
    else:
        raise ValueError(f"entry_at must be 'wrap' or 'outlet', got {entry_at!r}")
    candidates = np.flatnonzero(np.isfinite(entry) & (entry >= start))
    if candidates.size < n_tracer:
        raise ValueError(
            f"n_tracer: only {candidates.size} passes enter at or after start_time = {start!r} s "
            f"(entry_at = {entry_at!r}), {n_tracer} wanted"
        )
    chosen = candidates[np.argsort(entry[candidates], kind="stable")[:n_tracer]]
    clump_index = np.asarray(events.pass_clump_index, dtype=np.int64)[chosen]
    return TracerPasses(
        entry_time=entry[chosen],
        exit_time=np.asarray(events.exit_time, dtype=float)[chosen],
        pass_index=chosen.astype(np.int64),
        clump_index=clump_index,
        clump_id=np.asarray(events.clump_id, dtype=np.int64)[clump_index],
        entry_at=entry_at,
    )


def tracer_count(silo_volume: float, tracer_fraction: float, bulk_density: float, clump_mass: float) -> int:
    """Number of tracer clumps filling a fraction of the silo: ``round(f V rho_b / m)``, at least 1.

    Rounded half up. The same number serves as the count of virtual tracers seeded for the
    Eulerian RTD (:func:`analysis.numerics.pathlines.lattice_seeds`), so that both RTDs carry the same
    sampling noise.

    Parameters
    ----------
    silo_volume : float
        Volume ``V`` of the silo contents [m^3], > 0.
    tracer_fraction : float
        Fraction ``f`` of that volume the tracer fills, in (0, 1] [-].
    bulk_density : float
        Bulk density ``rho_b`` [kg/m^3], > 0.
    clump_mass : float
        Mass ``m`` of one clump [kg], > 0.

    Returns
    -------
    int
        Number of tracer clumps, >= 1.
    """
    volume = positive_number("silo_volume", silo_volume)
    fraction = float(tracer_fraction)
    if not math.isfinite(fraction) or not 0.0 < fraction <= 1.0:
        raise ValueError(f"tracer_fraction must be a number in (0, 1], got {tracer_fraction!r}")
    density = positive_number("bulk_density", bulk_density)
    mass = positive_number("clump_mass", clump_mass)
    return max(1, int(math.floor(fraction * volume * density / mass + 0.5)))
