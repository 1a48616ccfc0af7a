"""Velocity profiles of the blender's steady field: profiles at heights and over time, passage velocities,
the flow channel boundary.

Pure computation on :class:`siloflow.analysis.studies.blender.steady_field.BlenderField`; no file I/O. SI units:
lengths in m, velocities in m/s. The clear passages at a height come as a mapping name -> ``(x_lo, x_hi)``
of intervals on the right half (``0 <= x_lo < x_hi``); a bin belongs to an interval when its centre's
``|x|`` lies in it (both halves count).

1. Velocity profiles and the normalised profile ``v_z / cross-section mean`` at a height
   (:func:`height_profile`), and at key heights for several time windows (:func:`profiles_over_time`).
2. Mean ``v_z`` of each passage (:func:`passage_velocities`; :func:`passage_mean_v_z` for the field of a single
   frame, where a passage may be empty).
3. The flow channel boundary at 10 % of the centreline velocity after subtracting the near-wall
   velocity, at every row (:func:`flow_channel_boundary_over_height`, wrapping
   :func:`siloflow.analysis.numerics.profiles.flow_channel_boundary`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, finite_number
from siloflow.analysis.numerics.profiles import flow_channel_boundary
from siloflow.analysis.studies.blender.steady_field import BlenderField, at_height, checked_field

__all__ = [
    "HeightProfile",
    "ProfilesOverTime",
    "PassageVelocities",
    "ChannelBoundary",
    "height_profile",
    "profiles_over_time",
    "passage_velocities",
    "passage_mean_v_z",
    "flow_channel_boundary_over_height",
]


def _passages(passages) -> dict[str, tuple[float, float]]:
    """Checked passages: a non-empty mapping name -> (x_lo, x_hi) with 0 <= x_lo < x_hi."""
    if not isinstance(passages, Mapping) or not passages:
        raise ValueError("passages must be a non-empty mapping name -> (x_lo, x_hi)")
    checked = {}
    for name, interval in passages.items():
        try:
            lo, hi = (float(bound) for bound in interval)
        except (TypeError, ValueError):
            raise ValueError(f"passages[{name!r}] must be two numbers (x_lo, x_hi), got {interval!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)) or not 0.0 <= lo < hi:
            raise ValueError(f"passages[{name!r}] must satisfy 0 <= x_lo < x_hi, got {interval!r}")
        checked[str(name)] = (lo, hi)
    return checked


def _in_interval(x: np.ndarray, interval: tuple[float, float]) -> np.ndarray:
    """Bins whose centre's |x| lies in the closed interval (to round-off of the bounds)."""
    lo, hi = interval
    slack = 1.0e-12 * max(1.0, abs(hi))
    distance = np.abs(x)
    return (distance >= lo - slack) & (distance <= hi + slack)


@dataclass(frozen=True, eq=False)
class HeightProfile:
    """Vertical velocity across the width at one height, and its normalised form.

    Attributes
    ----------
    z : float
        Height above the outlet plane [m].
    x : numpy.ndarray, shape (nx,)
        Bin centres [m].
    v_z : numpy.ndarray, shape (nx,)
        Vertical velocity [m/s]; NaN where neither bracketing bin is occupied.
    is_open : numpy.ndarray of bool, shape (nx,)
        Bins of the cross-section: a finite ``v_z`` and, with passages, the centre in a clear interval.
    cross_section_mean : float
        Mean ``v_z`` over the open bins [m/s] (negative for downward flow).
    normalised : numpy.ndarray, shape (nx,)
        ``v_z / cross_section_mean`` on the open bins, NaN elsewhere [-].
    """

    z: float
    x: np.ndarray
    v_z: np.ndarray
    is_open: np.ndarray
    cross_section_mean: float
    normalised: np.ndarray


def height_profile(field: BlenderField, z_value: float, passages: Mapping | None = None) -> HeightProfile:
    """Vertical velocity profile at a height and its normalised form ``v_z / cross-section mean``.

    Parameters
    ----------
    field : BlenderField
        The steady field.
    z_value : float
        Height [m], within the bin rows (linear interpolation between rows).
    passages : mapping name -> (x_lo, x_hi), optional
        Clear intervals at that height [m]; the cross-section is the bins whose centre lies in one of
        them (wall bins excluded). Default: every bin with a velocity.

    Returns
    -------
    HeightProfile

    Raises
    ------
    ValueError
        On a height outside the rows, bad passages, no open bin, or a zero cross-section mean.
    """
    field = checked_field(field)
    z_value = finite_number("z_value", z_value)
    v_z = at_height(field, field.v_z, z_value)
    is_open = np.isfinite(v_z)
    if passages is not None:
        intervals = _passages(passages)
        inside = np.zeros(field.x.size, dtype=bool)
        for interval in intervals.values():
            inside |= _in_interval(field.x, interval)
        is_open &= inside
    if not np.any(is_open):
        raise ValueError(f"z_value = {z_value!r} m: no open bin with particles in the cross-section")
    mean = float(np.mean(v_z[is_open]))
    if mean == 0.0:
        raise ValueError(f"z_value = {z_value!r} m: the cross-section mean velocity is 0; cannot normalise")
    normalised = np.where(is_open, v_z / mean, np.nan)
    return HeightProfile(z=z_value, x=field.x.copy(), v_z=v_z, is_open=is_open, cross_section_mean=mean,
                         normalised=normalised)


@dataclass(frozen=True, eq=False)
class ProfilesOverTime:
    """Normalised profiles at key heights for a series of time windows.

    Attributes
    ----------
    window_time : numpy.ndarray, shape (n_w,)
        Time of each window (e.g. its centre since the opening) [s].
    heights : numpy.ndarray, shape (n_h,)
        Key heights [m].
    x : numpy.ndarray, shape (nx,)
        Bin centres [m].
    v_z : numpy.ndarray, shape (n_w, n_h, nx)
        Vertical velocity [m/s] (NaN where no particles).
    normalised : numpy.ndarray, shape (n_w, n_h, nx)
        ``v_z / cross-section mean`` [-] (NaN outside the cross-section).
    cross_section_mean : numpy.ndarray, shape (n_w, n_h)
        Mean ``v_z`` over the open bins [m/s].
    """

    window_time: np.ndarray
    heights: np.ndarray
    x: np.ndarray
    v_z: np.ndarray
    normalised: np.ndarray
    cross_section_mean: np.ndarray


def profiles_over_time(fields: Sequence[BlenderField], window_time, heights, passages=None) -> ProfilesOverTime:
    """Normalised vertical velocity profiles at key heights, one set per time window.

    Parameters
    ----------
    fields : sequence of BlenderField
        One steady field per time window, all on the same x bins.
    window_time : array_like, shape (n_w,)
        Time of each window [s], finite.
    heights : array_like, shape (n_h,)
        Key heights [m].
    passages : None, mapping, or sequence of mappings, optional
        Clear intervals (see :func:`height_profile`): one mapping for all heights, or one per height
        (None entries allowed), or None for every occupied bin.

    Returns
    -------
    ProfilesOverTime
    """
    fields = [checked_field(item) for item in fields]
    if not fields:
        raise ValueError("fields must hold at least one BlenderField")
    times = finite_array("window_time", window_time, ndim=1)
    if times.size != len(fields):
        raise ValueError(f"window_time must hold one time per field ({len(fields)}), got {times.size}")
    levels = finite_array("heights", heights, ndim=1)
    if levels.size == 0:
        raise ValueError("heights must not be empty")
    x = fields[0].x
    if any(item.x.shape != x.shape or np.any(item.x != x) for item in fields):
        raise ValueError("fields must all have the same x bins")
    if passages is None or isinstance(passages, Mapping):
        per_height = [passages] * levels.size
    else:
        per_height = list(passages)
        if len(per_height) != levels.size:
            raise ValueError(f"passages must be one mapping or one per height ({levels.size}), got {len(per_height)}")
    shape = (times.size, levels.size)
    v_z = np.empty(shape + (x.size,))
    normalised = np.empty(shape + (x.size,))
    means = np.empty(shape)
    for w, item in enumerate(fields):
        for h, (level, intervals) in enumerate(zip(levels, per_height)):
            profile = height_profile(item, level, intervals)
            v_z[w, h], normalised[w, h], means[w, h] = profile.v_z, profile.normalised, profile.cross_section_mean
    return ProfilesOverTime(window_time=times, heights=levels, x=x.copy(), v_z=v_z, normalised=normalised,
                            cross_section_mean=means)


@dataclass(frozen=True, eq=False)
class PassageVelocities:
    """Mean vertical velocity of each passage at one height, with the profile across the width.

    Attributes
    ----------
    profile : HeightProfile
        The velocity distribution across the width at that height (cross-section = all passages).
    passages : dict
        Name -> (x_lo, x_hi) [m].
    mean_v_z : dict
        Name -> mean ``v_z`` over the bins of the passage, both halves [m/s]; NaN without a bin.
    n_bins : dict
        Name -> number of bins averaged [-].
    """

    profile: HeightProfile
    passages: dict
    mean_v_z: dict
    n_bins: dict


def _passage_means(x: np.ndarray, v_z: np.ndarray, intervals: Mapping) -> tuple[dict, dict]:
    """Name -> plain mean of the finite ``v_z`` whose bin centre's ``|x|`` lies in the interval (NaN without one),
    and name -> number of those bins."""
    means, counts = {}, {}
    for name, interval in intervals.items():
        chosen = np.isfinite(v_z) & _in_interval(x, interval)
        counts[name] = int(np.count_nonzero(chosen))
        means[name] = float(np.mean(v_z[chosen])) if counts[name] else math.nan
    return means, counts


def passage_velocities(field: BlenderField, z_value: float, passages: Mapping) -> PassageVelocities:
    """Mean ``v_z`` of each passage (e.g. exterior annulus, interior annulus, tube) at a height.

    The mean of a passage is the plain mean of ``v_z`` over the bins with particles whose centre's
    ``|x|`` lies in its interval (mirrored halves included; equal bins, so it is the width average).
    At the insert inlet and outlet, :attr:`PassageVelocities.profile` is the velocity distribution
    across the width.

    Parameters
    ----------
    field : BlenderField
        The steady field.
    z_value : float
        Height [m], within the bin rows.
    passages : mapping name -> (x_lo, x_hi)
        Clear intervals at that height [m].

    Returns
    -------
    PassageVelocities
    """
    intervals = _passages(passages)
    profile = height_profile(field, z_value, intervals)
    means, counts = _passage_means(profile.x, profile.v_z, intervals)
    return PassageVelocities(profile=profile, passages=intervals, mean_v_z=means, n_bins=counts)


def passage_mean_v_z(field: BlenderField, z_value: float, passages: Mapping) -> dict[str, float]:
    """Mean ``v_z`` of each passage at a height, as :func:`passage_velocities` but without the profile [m/s].

    The field of a single frame may leave a passage, or the whole height, without particles: that passage's
    mean is then NaN instead of an error, so that a series of frames can be averaged.

    Parameters
    ----------
    field : BlenderField
        A field (e.g. of one frame).
    z_value : float
        Height [m], within the bin rows.
    passages : mapping name -> (x_lo, x_hi)
        Clear intervals at that height [m].

    Returns
    -------
    dict
        Name -> mean ``v_z`` over the bins with particles whose centre's ``|x|`` lies in the interval [m/s]; NaN
        without such a bin.
    """
    field = checked_field(field)
    intervals = _passages(passages)
    return _passage_means(field.x, at_height(field, field.v_z, finite_number("z_value", z_value)), intervals)[0]


@dataclass(frozen=True, eq=False)
class ChannelBoundary:
    """Flow channel boundary at every bin row.

    Attributes
    ----------
    z : numpy.ndarray, shape (nz,)
        Row heights [m].
    x_boundary : numpy.ndarray, shape (nz,)
        Distance of the boundary from the axis [m] (mean of the two sides); NaN for rows with fewer
        than 2 occupied bins inside the wall.
    left, right : numpy.ndarray, shape (nz,)
        Boundary on each side (left <= 0 <= right) [m]; the wall where the velocity never falls to
        the threshold.
    wall_x : numpy.ndarray, shape (nz,)
        Inner wall position per row [m].
    wall_velocity : numpy.ndarray, shape (nz,)
        Velocity subtracted: that of the open bins next to the wall [m/s].
    centreline_speed : numpy.ndarray, shape (nz,)
        ``|v_z - v_wall|`` on the axis [m/s].
    reaches_wall : numpy.ndarray of bool, shape (nz,)
        True where a side has no crossing (the flow channel fills the width there).
    fraction : float
        Fraction of the centreline speed that defines the boundary [-].
    """

    z: np.ndarray
    x_boundary: np.ndarray
    left: np.ndarray
    right: np.ndarray
    wall_x: np.ndarray
    wall_velocity: np.ndarray
    centreline_speed: np.ndarray
    reaches_wall: np.ndarray
    fraction: float


def flow_channel_boundary_over_height(field: BlenderField, wall_x, fraction: float = 0.10) -> ChannelBoundary:
    """Flow channel boundary at ``fraction`` of the centreline velocity after subtracting the near-wall velocity.

    At each row the open bins are the occupied bins with ``|x| <= wall_x``; a field covering only
    ``x >= 0`` is mirrored about the axis. :func:`siloflow.analysis.numerics.profiles.flow_channel_boundary` with
    ``subtract_wall_velocity`` then takes ``v' = v_z - v_wall`` (``v_wall``: mean of the outermost open
    bins, the ones next to the wall), the centreline value ``v'(0)`` (linear between bins) and walks
    outward to the first ``|x|`` where ``|v'|`` falls to ``fraction |v'(0)|`` (linear interpolation
    between bins). A side without such a place, or a row with ``v'(0) = 0`` (plug flow), has its
    boundary at the wall.

    Parameters
    ----------
    field : BlenderField
        The steady field.
    wall_x : float or array_like, shape (nz,)
        Inner wall position ``|x|`` per row [m], > 0 (one number for all rows allowed).
    fraction : float, optional
        Fraction of the centreline speed, in (0, 1); default 0.10.

    Returns
    -------
    ChannelBoundary
    """
    field = checked_field(field)
    walls = np.asarray(wall_x, dtype=float)
    if walls.ndim == 0:
        walls = np.full(field.z.size, float(walls))
    walls = finite_array("wall_x", walls, ndim=1)
    if walls.shape != field.z.shape or np.any(walls <= 0.0):
        raise ValueError(f"wall_x must be a number > 0 or {field.z.size} numbers > 0 (one per row)")
    fraction = float(fraction)
    if not math.isfinite(fraction) or not 0.0 < fraction < 1.0:
        raise ValueError(f"fraction must be a number in (0, 1), got {fraction!r}")
    nz = field.z.size
    left, right = np.full(nz, np.nan), np.full(nz, np.nan)
    wall_velocity, centre_speed = np.full(nz, np.nan), np.full(nz, np.nan)
    reaches_wall = np.zeros(nz, dtype=bool)
    for row in range(nz):
        wall = walls[row]
        chosen = field.occupied[:, row] & (np.abs(field.x) <= wall * (1.0 + 1.0e-12))
        x, v = field.x[chosen], field.v_z[chosen, row]
        if x.size < 2:
            continue
        if x[0] >= 0.0 or x[-1] <= 0.0:  # one half only: mirror it about the axis
            order = np.argsort(np.abs(x))
            half_x, half_v = np.abs(x)[order], v[order]
            keep = half_x > 0.0
            x = np.concatenate([-half_x[keep][::-1], half_x])
            v = np.concatenate([half_v[keep][::-1], half_v])
        wall_velocity[row] = 0.5 * (v[0] + v[-1])
        centre_speed[row] = abs(float(np.interp(0.0, x, v)) - wall_velocity[row])
        if centre_speed[row] == 0.0:
            left[row], right[row], reaches_wall[row] = -wall, wall, True
            continue
        boundary = flow_channel_boundary(x, v, fractions=(fraction,), subtract_wall_velocity=True)
        row_left, row_right = float(boundary.left[0]), float(boundary.right[0])
        reaches_wall[row] = math.isnan(row_left) or math.isnan(row_right)
        left[row] = -wall if math.isnan(row_left) else row_left
        right[row] = wall if math.isnan(row_right) else row_right
    return ChannelBoundary(
        z=field.z.copy(), x_boundary=0.5 * (right - left), left=left, right=right, wall_x=walls,
        wall_velocity=wall_velocity, centreline_speed=centre_speed, reaches_wall=reaches_wall, fraction=fraction,
    )
