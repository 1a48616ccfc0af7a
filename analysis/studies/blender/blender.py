"""Analysis of the multi-flow blender (SEED_DIGEST section 5) from steady Eulerian fields.

Pure computation on numpy arrays; no file I/O. SI units: lengths in m, velocities in m/s, times in s,
mass flow rates in kg/s, E in 1/s; concentrations are tracer fractions [-].

Input
-----
The caller builds from the LIGGGHTS dumps a time-averaged, depth-averaged steady field on a regular
(x, z) grid, a :class:`BlenderField`: bin centres ``x`` (nx,) and ``z`` (nz,), velocities ``v_x``,
``v_z`` (nx, nz) and the solid fraction (nx, nz) (only its ratios are used, as tracer weights).
A bin is *occupied* where the solid fraction is finite and > 0; elsewhere (inside walls, above the fill)
the velocity is not used. x runs across the width with x = 0 on the axis of the mirror-symmetric
silo (a field may cover both halves or only x >= 0), z is up with the outlet plane at z = 0, and the
flow is downward (``v_z < 0``). The clear passages at a height come as plain numbers: a mapping
name -> ``(x_lo, x_hi)`` of intervals on the right half (``0 <= x_lo < x_hi``), e.g.
``{"tube": (0, 0.009), "interior": (0.011, 0.05), "exterior": (0.052, 0.1125)}``; a bin belongs to
an interval when its centre's ``|x|`` lies in it (both halves count).

Interpolation in height
-----------------------
A profile at a height ``z`` between two bin rows is linear in z between the rows (exact at a row;
:func:`analysis.numerics.profiles.velocity_profile`); where only one of the two bins is occupied its value is
taken, where neither is the profile is NaN.

What is computed
----------------
1. Velocity profiles and the normalised profile ``v_z / cross-section mean`` at a height
   (:func:`height_profile`), and at key heights for several time windows (:func:`profiles_over_time`).
2. Mean ``v_z`` of each passage (:func:`passage_velocities`).
3. The flow channel boundary at 10 % of the centreline velocity after subtracting the near-wall
   velocity, at every row (:func:`flow_channel_boundary_over_height`, wrapping
   :func:`analysis.numerics.profiles.flow_channel_boundary`).
4. Pathlines of virtual tracers released across the width and their residence times
   (:func:`tracer_pathlines`, through :func:`analysis.numerics.pathlines.integrate_pathlines`).
5. The RTD of virtual tracers filling a layer at the top of the fill (:func:`tracer_layer`,
   :func:`layer_rtd`, :func:`virtual_tracer_rtd`).
6. Discontinuous mode: a two-layer fill recirculated (:func:`discontinuous_mode`).
7. Continuous mode: sine inputs through the RTD, VRR and CoV against the period
   (:func:`continuous_mode`).
8. Gravity scaling (:func:`gravity_normalised_time`, :func:`gravity_normalised_velocity`,
   :func:`gravity_scaling`).
9. Comparison of configurations (:class:`BlenderMetrics`, :func:`comparison_table`,
   :func:`best_blender`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from analysis.studies.silo_recirculation.blending import predicted_concentration_from_first_pass
from analysis.checks import finite_array, finite_number, positive_number, uniform_step
from analysis.numerics.coarse_graining import Fields
from analysis.numerics.lti import VRRTable, recirculations_to_homogenise, vrr_versus_period
from analysis.numerics.pathlines import PathlineResult, integrate_pathlines, lattice_seeds
from analysis.numerics.profiles import flow_channel_boundary, velocity_profile
from analysis.numerics.rtd import RTD, rtd_from_exit_times

__all__ = [
    "BlenderField",
    "HeightProfile",
    "ProfilesOverTime",
    "PassageVelocities",
    "ChannelBoundary",
    "TracerPathlines",
    "VirtualTracerRTD",
    "DiscontinuousMode",
    "ContinuousMode",
    "GravityScaling",
    "BlenderMetrics",
    "height_profile",
    "profiles_over_time",
    "passage_velocities",
    "flow_channel_boundary_over_height",
    "tracer_pathlines",
    "tracer_layer",
    "layer_rtd",
    "virtual_tracer_rtd",
    "tabulated_rtd",
    "discontinuous_mode",
    "continuous_mode",
    "gravity_normalised_time",
    "gravity_normalised_velocity",
    "gravity_scaling",
    "comparison_table",
    "best_blender",
]

DEFAULT_RELEASE_SPACING = 0.015
"""Spacing of the pathline tracers across the width [m] (15 mm in the study)."""

_DEPTH_CELL = 1.0
"""Size of the single cell along y given to the pathline integrator (y plays no part) [m]."""


# --------------------------------------------------------------------------- field


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


def _increasing(name: str, values) -> np.ndarray:
    array = finite_array(name, values, ndim=1)
    if array.size == 0 or np.any(np.diff(array) <= 0.0):
        raise ValueError(f"{name} must be a non-empty, strictly increasing array")
    return array


@dataclass(frozen=True, eq=False)
class BlenderField:
    """A steady (time-averaged), depth-averaged field on a regular (x, z) grid of bins.

    Arrays are copied and read-only. Velocities are NaN and the solid fraction 0 in unoccupied bins.

    Attributes
    ----------
    x : numpy.ndarray, shape (nx,)
        Bin centres across the width, strictly increasing [m] (x = 0 on the silo axis).
    z : numpy.ndarray, shape (nz,)
        Bin centres in height, strictly increasing [m] (z = 0 at the outlet plane).
    v_x, v_z : numpy.ndarray, shape (nx, nz)
        Velocity components [m/s] (``v_z < 0`` downward); they must be finite in occupied bins.
    solid_fraction : numpy.ndarray, shape (nx, nz)
        Solid volume fraction [-]; 0 or NaN where there are no particles, never negative or infinite.
        Only its ratios are used (as tracer weights), so any quantity proportional to it will do.
    """

    x: np.ndarray
    z: np.ndarray
    v_x: np.ndarray
    v_z: np.ndarray
    solid_fraction: np.ndarray

    def __post_init__(self) -> None:
        x = _increasing("x", self.x)
        z = _increasing("z", self.z)
        shape = (x.size, z.size)
        fraction = np.array(self.solid_fraction, dtype=float)
        if fraction.shape != shape:
            raise ValueError(f"solid_fraction must have shape {shape} = (len(x), len(z)), got {fraction.shape}")
        if np.any(np.isinf(fraction)) or np.any(fraction < 0.0):
            raise ValueError("solid_fraction must be >= 0 or NaN (no particles), never negative or infinite")
        occupied = np.isfinite(fraction) & (fraction > 0.0)
        set_field = object.__setattr__
        for name in ("v_x", "v_z"):
            velocity = np.array(getattr(self, name), dtype=float)
            if velocity.shape != shape:
                raise ValueError(f"{name} must have shape {shape} = (len(x), len(z)), got {velocity.shape}")
            if not np.all(np.isfinite(velocity[occupied])):
                raise ValueError(f"{name} must be finite in every occupied bin (solid_fraction > 0)")
            set_field(self, name, _read_only(np.where(occupied, velocity, np.nan)))
        set_field(self, "x", _read_only(x.copy()))
        set_field(self, "z", _read_only(z.copy()))
        set_field(self, "solid_fraction", _read_only(np.where(occupied, fraction, 0.0)))

    @classmethod
    def from_fields(cls, fields: Fields, particle_density: float) -> "BlenderField":
        """The field of a depth-averaged :class:`~analysis.numerics.coarse_graining.Fields` (one node layer in y).

        The solid fraction is the bulk density over ``particle_density`` [kg/m^3] where the fields' mask
        is set, 0 elsewhere.
        """
        if not isinstance(fields, Fields):
            raise ValueError(f"fields must be a Fields, got {type(fields).__name__}")
        if fields.grid.shape[1] != 1:
            raise ValueError(
                f"fields must have one node layer in y (use depth_average), got {fields.grid.shape[1]} layers"
            )
        particle_density = positive_number("particle_density", particle_density)
        return cls(
            x=fields.grid.x,
            z=fields.grid.z,
            v_x=fields.velocity[:, 0, :, 0],
            v_z=fields.velocity[:, 0, :, 2],
            solid_fraction=np.where(fields.mask[:, 0, :], fields.density[:, 0, :] / particle_density, 0.0),
        )

    @classmethod
    def from_planar(cls, planar) -> "BlenderField":
        """The field of an object with attributes ``x, z, v_x, v_z, solid_fraction`` (e.g.
        :class:`analysis.studies.blender.fields.PlanarField`, whose velocities are NaN in bins no clump entered)."""
        try:
            arrays = {name: getattr(planar, name) for name in ("x", "z", "v_x", "v_z", "solid_fraction")}
        except AttributeError as error:
            raise ValueError(f"planar must have x, z, v_x, v_z and solid_fraction ({error})") from None
        return cls(**arrays)

    @property
    def occupied(self) -> np.ndarray:
        """Bins with particles (solid fraction > 0), shape (nx, nz)."""
        return self.solid_fraction > 0.0

    def bin_size(self) -> tuple[float, float]:
        """Uniform bin edges ``(dx, dz)`` [m]; a ValueError unless both axes are uniform with >= 2 bins."""
        return uniform_step("field.x", self.x), uniform_step("field.z", self.z)


def _field(field) -> BlenderField:
    if not isinstance(field, BlenderField):
        raise ValueError(f"field must be a BlenderField, got {type(field).__name__}")
    return field


def _at_height(field: BlenderField, values: np.ndarray, z_value: float) -> np.ndarray:
    """``values`` (nx, nz) at height ``z_value``: linear in z between the occupied bins of the two rows.

    :func:`analysis.numerics.profiles.velocity_profile` interpolates the occupancy-weighted values and the
    occupancy together; their ratio renormalises the weights to the occupied bins (NaN where none).
    """
    occupancy = field.occupied.astype(float)
    weighted = velocity_profile((field.x, field.z, np.where(field.occupied, values, 0.0), occupancy), z_value)
    weight = weighted.v_z
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(weight > 0.0, weighted.v_x / np.where(weight > 0.0, weight, 1.0), np.nan)


# --------------------------------------------------------------------------- passages


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


# --------------------------------------------------------------------------- 1. profiles


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
    field = _field(field)
    z_value = finite_number("z_value", z_value)
    v_z = _at_height(field, field.v_z, z_value)
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
    fields = [_field(item) for item in fields]
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


# --------------------------------------------------------------------------- 2. passage velocities


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
    means, counts = {}, {}
    for name, interval in intervals.items():
        chosen = profile.is_open & _in_interval(profile.x, interval)
        counts[name] = int(np.count_nonzero(chosen))
        means[name] = float(np.mean(profile.v_z[chosen])) if counts[name] else math.nan
    return PassageVelocities(profile=profile, passages=intervals, mean_v_z=means, n_bins=counts)


# --------------------------------------------------------------------------- 3. flow channel boundary


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
    ``x >= 0`` is mirrored about the axis. :func:`analysis.numerics.profiles.flow_channel_boundary` with
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
    field = _field(field)
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


# --------------------------------------------------------------------------- pathlines through the steady field


def _velocity_grid(field: BlenderField):
    """The steady field as the (1, nx, 1, nz, 3) series of :func:`integrate_pathlines`, its origin and spacing.

    Unoccupied bins get zero velocity: a tracer that reaches one stops (it does not exit).
    """
    dx, dz = field.bin_size()
    velocity = np.zeros((1, field.x.size, 1, field.z.size, 3))
    velocity[0, :, 0, :, 0] = np.where(field.occupied, field.v_x, 0.0)
    velocity[0, :, 0, :, 2] = np.where(field.occupied, field.v_z, 0.0)
    origin = (field.x[0] - 0.5 * dx, 0.0, field.z[0] - 0.5 * dz)
    return velocity, origin, (dx, _DEPTH_CELL, dz)


def _default_step(field: BlenderField) -> float:
    """A tenth of the smallest bin edge over the fastest bin speed [s]."""
    dx, dz = field.bin_size()
    speed = np.hypot(field.v_x, field.v_z)[field.occupied]
    fastest = float(speed.max()) if speed.size else 0.0
    if not fastest > 0.0:
        raise ValueError("field: no occupied bin moves; give dt explicitly")
    return 0.1 * min(dx, dz) / fastest


def _integrate(field: BlenderField, x, z, dt, max_time, method, backend, record_every=0) -> PathlineResult:
    velocity, origin, spacing = _velocity_grid(field)
    step = _default_step(field) if dt is None else positive_number("dt", dt)
    seeds = np.column_stack([x, np.full(np.size(x), 0.5 * _DEPTH_CELL), z])
    return integrate_pathlines(seeds, 0.0, velocity, [0.0], origin, spacing, step, 0.0, max_time,
                               method=method, record_every=record_every, backend=backend)


class _TracerSample:
    """Mixin of the results holding ``residence_time`` per virtual tracer (NaN: not out)."""

    @property
    def n_not_exited(self) -> int:
        """Tracers that did not reach the outlet within ``max_time`` (counted, never dropped silently)."""
        return int(np.count_nonzero(~np.isfinite(self.residence_time)))


@dataclass(frozen=True, eq=False)
class TracerPathlines(_TracerSample):
    """Virtual tracers released across the width at one height and followed to the outlet plane.

    Attributes
    ----------
    release_x : numpy.ndarray, shape (n,)
        Release positions across the width [m].
    release_z : float
        Release height [m].
    residence_time : numpy.ndarray, shape (n,)
        Time to reach z = 0 [s]; NaN for tracers that did not exit within ``max_time``.
    paths : tuple of numpy.ndarray
        Per tracer, the recorded (x, z) points [m], shape (m_i, 2), ending at the exit point when it
        exited.
    pathlines : PathlineResult
        The integration result (status, steps, history).
    """

    release_x: np.ndarray
    release_z: float
    residence_time: np.ndarray
    paths: tuple
    pathlines: PathlineResult


def tracer_pathlines(
    field: BlenderField,
    release_z: float,
    max_time: float,
    spacing: float = DEFAULT_RELEASE_SPACING,
    dt: float | None = None,
    record_every: int | None = None,
    method: str = "rk2",
    backend: str = "auto",
) -> TracerPathlines:
    """Pathlines and residence times of virtual tracers released ``spacing`` apart across the width.

    Tracers start at ``x = k spacing`` (k integer, so one on the axis) between the outermost bins
    with particles at ``release_z`` (both halves when the field covers them; from the axis for a
    field of the right half only), at the time of the
    steady field, and move with the velocity interpolated between bin centres
    (:func:`analysis.numerics.pathlines.integrate_pathlines`, a single time level) until they cross z = 0.

    Parameters
    ----------
    field : BlenderField
        The steady field (uniform bins).
    release_z : float
        Release height [m] (1.2 m in the study), within the bin rows.
    max_time : float
        Longest residence time followed [s], > 0.
    spacing : float, optional
        Distance between tracers [m], > 0; default 0.015.
    dt : float, optional
        Time step [s]; default a tenth of the smallest bin edge over the largest bin speed.
    record_every : int, optional
        Record the paths every this many steps (>= 1); default about 500 points over ``max_time``.
    method : {"rk2", "euler"}, optional
        Integration scheme.
    backend : {"auto", "numba", "numpy"}, optional
        See :func:`analysis.numerics.pathlines.integrate_pathlines`.

    Returns
    -------
    TracerPathlines
    """
    field = _field(field)
    release_z = finite_number("release_z", release_z)
    max_time = positive_number("max_time", max_time)
    spacing = positive_number("spacing", spacing)
    moving = np.isfinite(_at_height(field, field.v_z, release_z))
    if not np.any(moving):
        raise ValueError(f"release_z = {release_z!r} m: no bin with particles at that height")
    lo, hi = field.x[moving].min(), field.x[moving].max()
    if field.x[0] >= 0.0:  # a half field: the axis is its mirror plane
        lo = 0.0
    k = np.arange(math.ceil(lo / spacing - 1.0e-9), math.floor(hi / spacing + 1.0e-9) + 1)
    release_x = k * spacing
    step = _default_step(field) if dt is None else positive_number("dt", dt)
    if record_every is None:
        record_every = max(1, int(math.ceil(max_time / step / 500.0)))
    elif isinstance(record_every, (bool, np.bool_)) or int(record_every) != record_every or record_every < 1:
        raise ValueError(f"record_every must be an integer >= 1, got {record_every!r}")
    result = _integrate(field, release_x, np.full(release_x.size, release_z), step, max_time, method, backend,
                        record_every=int(record_every))
    paths = []
    for i in range(release_x.size):
        points = result.history[:, i][:, [0, 2]]
        points = points[np.all(np.isfinite(points), axis=1)]
        if np.isfinite(result.residence_time[i]):
            points = np.vstack([points, result.exit_position[i, [0, 2]]])
        paths.append(points)
    return TracerPathlines(release_x=release_x, release_z=release_z, residence_time=result.residence_time,
                           paths=tuple(paths), pathlines=result)


# --------------------------------------------------------------------------- 5. RTD of a tracer layer


def _filled_area(field: BlenderField) -> tuple[np.ndarray, np.ndarray]:
    """Row edges clipped at z = 0 and the open area below each (occupied bins per unit depth) [m, m^2].

    A row covers ``[z_k - dz/2, z_k + dz/2]`` with ``dx`` times its number of occupied bins of open
    width; what lies below z = 0 (the channel) does not count, so the area grows linearly from 0 at
    z = 0 (edges below it are clipped to 0).
    """
    dx, dz = field.bin_size()
    edges = np.maximum(np.concatenate([field.z - 0.5 * dz, [field.z[-1] + 0.5 * dz]]), 0.0)
    width = dx * np.count_nonzero(field.occupied, axis=0)
    return edges, np.concatenate([[0.0], np.cumsum(width * np.diff(edges))])


def tracer_layer(field: BlenderField, fill_height: float, volume_fraction: float) -> tuple[float, float]:
    """The horizontal layer at the top of the fill that holds ``volume_fraction`` of the filled volume.

    The filled volume (per unit depth) is the open area of the occupied bins between z = 0 and
    ``fill_height``; the layer ``[z_bottom, fill_height]`` holds the fraction of it (linear within a row).

    Parameters
    ----------
    field : BlenderField
        The steady field (uniform bins).
    fill_height : float
        Fill height above the outlet [m], > 0, within the grid.
    volume_fraction : float
        Fraction of the filled volume in the layer, in (0, 1] [-].

    Returns
    -------
    z_bottom, z_top : float
        Bottom and top (``fill_height``) of the layer [m].
    """
    field = _field(field)
    fill_height = positive_number("fill_height", fill_height)
    volume_fraction = positive_number("volume_fraction", volume_fraction)
    if volume_fraction > 1.0:
        raise ValueError(f"volume_fraction must be in (0, 1], got {volume_fraction!r}")
    edges, area = _filled_area(field)
    if fill_height > edges[-1] * (1.0 + 1.0e-12):
        raise ValueError(f"fill_height = {fill_height!r} m lies above the grid (top {edges[-1]!r} m)")
    filled = float(np.interp(fill_height, edges, area))
    if not filled > 0.0:
        raise ValueError(f"fill_height = {fill_height!r} m: no occupied bin below it")
    bottom = float(np.interp((1.0 - volume_fraction) * filled, area, edges))
    return max(bottom, 0.0), fill_height


def _bin_index(centres: np.ndarray, step: float, positions) -> np.ndarray:
    """Index of the uniform bin containing each position (clamped to the bins)."""
    index = np.floor((np.asarray(positions, dtype=float) - centres[0]) / step + 0.5).astype(np.int64)
    return np.clip(index, 0, centres.size - 1)


def _tracer_spacing(field: BlenderField, tracer_spacing) -> float:
    """The lattice spacing of virtual tracers [m]: as given, or half the smaller bin edge."""
    if tracer_spacing is None:
        return 0.5 * min(field.bin_size())
    return positive_number("tracer_spacing", tracer_spacing)


def _weighted_rtd(residence_time: np.ndarray, weights: np.ndarray, bins) -> RTD:
    """:func:`analysis.numerics.rtd.rtd_from_exit_times` with tracer weights (mass) in E, mean and variance.

    ``E = (exited weight per bin) / (total weight * width)``, so ``sum(E * widths)`` is the exited
    fraction by weight; ``n_exited`` and ``n_total`` stay counts. Equal weights give the unweighted RTD.
    """
    base = rtd_from_exit_times(residence_time, t_entry=0.0, bins=bins)
    if np.all(weights == weights[0]):
        return base
    exited = np.isfinite(residence_time)
    tau, mass = residence_time[exited], weights[exited]
    per_bin, _ = np.histogram(tau, bins=base.edges, weights=mass)
    mean = float(np.average(tau, weights=mass))
    return dataclasses.replace(
        base, E=per_bin / (float(weights.sum()) * base.widths), t_mean=mean,
        variance=float(np.average((tau - mean) ** 2, weights=mass)),
    )


@dataclass(frozen=True, eq=False)
class VirtualTracerRTD(_TracerSample):
    """RTD of virtual tracers on a lattice filling a layer, weighted by the local solid fraction.

    Attributes
    ----------
    rtd : RTD
        E(t) [1/s], mean, variance, first and last residence time; tracers that did not exit count
        in ``n_total`` (and in the total weight) but not in E or the moments.
    release_x, release_z : numpy.ndarray, shape (n,)
        Tracer positions at release [m].
    weights : numpy.ndarray, shape (n,)
        Solid fraction of the bin each tracer starts in [-].
    residence_time : numpy.ndarray, shape (n,)
        Time to reach z = 0 [s]; NaN where not out within ``max_time``.
    layer_bottom, layer_top : float
        The layer [m].
    """

    rtd: RTD
    release_x: np.ndarray
    release_z: np.ndarray
    weights: np.ndarray
    residence_time: np.ndarray
    layer_bottom: float
    layer_top: float

    @property
    def spread(self) -> float:
        """``sigma / t_m`` [-]."""
        return math.sqrt(self.rtd.variance) / self.rtd.t_mean

    @property
    def ts_over_td(self) -> float:
        """First appearance over the time to discharge all the tracer, ``t_s / t_d`` [-]."""
        return self.rtd.ts_over_td


def _layer_tracers(field: BlenderField, z_bottom: float, z_top: float, tracer_spacing) -> tuple:
    """Lattice tracers filling ``[z_bottom, z_top]`` across the grid, kept where the bin has particles."""
    dx, dz = field.bin_size()
    spacing = _tracer_spacing(field, tracer_spacing)
    top = field.z[-1] + 0.5 * dz
    if z_top > top * (1.0 + 1.0e-12):
        raise ValueError(f"z_top = {z_top!r} m lies above the grid (top {top!r} m)")
    seeds = lattice_seeds((field.x[0] - 0.5 * dx, 0.0, z_bottom), (field.x[-1] + 0.5 * dx, 0.0, z_top),
                          spacing=(spacing, 1.0, spacing))
    weights = field.solid_fraction[_bin_index(field.x, dx, seeds[:, 0]), _bin_index(field.z, dz, seeds[:, 2])]
    keep = weights > 0.0
    if not np.any(keep):
        raise ValueError(f"no occupied bin in the layer [{z_bottom!r}, {z_top!r}] m")
    return seeds[keep, 0], seeds[keep, 2], weights[keep]


def layer_rtd(
    field: BlenderField,
    z_bottom: float,
    z_top: float,
    max_time: float,
    tracer_spacing: float | None = None,
    dt: float | None = None,
    bins=None,
    method: str = "rk2",
    backend: str = "auto",
) -> VirtualTracerRTD:
    """RTD of virtual tracers on a lattice filling the layer ``[z_bottom, z_top]``.

    Tracers sit on a square lattice of about ``tracer_spacing`` (:func:`analysis.numerics.pathlines.lattice_seeds`)
    over the width of the grid; those in bins without particles are left out (they are no material),
    the others carry the solid fraction of their bin as weight. Each is followed through the steady field to
    z = 0; the RTD is :func:`analysis.numerics.rtd.rtd_from_exit_times` with those weights.

    Parameters
    ----------
    field : BlenderField
        The steady field (uniform bins).
    z_bottom, z_top : float
        The layer [m], ``0 < z_bottom < z_top`` within the grid (``z_bottom = 0`` allowed).
    max_time : float
        Longest residence time followed [s], > 0.
    tracer_spacing : float, optional
        Lattice spacing [m]; default half the smaller bin edge.
    dt : float, optional
        Time step [s] (default as in :func:`tracer_pathlines`).
    bins : None, int or array_like, optional
        Residence-time bins of E (see :func:`analysis.numerics.rtd.rtd_from_exit_times`).
    method, backend : str, optional
        See :func:`analysis.numerics.pathlines.integrate_pathlines`.

    Returns
    -------
    VirtualTracerRTD

    Raises
    ------
    ValueError
        On a bad layer, no tracer in an occupied bin, or no tracer that exits.
    """
    field = _field(field)
    z_bottom = finite_number("z_bottom", z_bottom)
    z_top = finite_number("z_top", z_top)
    if not 0.0 <= z_bottom < z_top:
        raise ValueError(f"the layer must satisfy 0 <= z_bottom < z_top, got [{z_bottom!r}, {z_top!r}] m")
    max_time = positive_number("max_time", max_time)
    x, z, weights = _layer_tracers(field, z_bottom, z_top, tracer_spacing)
    residence = _integrate(field, x, z, dt, max_time, method, backend).residence_time
    if not np.any(np.isfinite(residence)):
        raise ValueError(f"no virtual tracer of the layer reached the outlet within max_time = {max_time!r} s")
    return VirtualTracerRTD(rtd=_weighted_rtd(residence, weights, bins), release_x=x, release_z=z, weights=weights,
                            residence_time=residence, layer_bottom=z_bottom, layer_top=z_top)


def virtual_tracer_rtd(
    field: BlenderField,
    fill_height: float,
    max_time: float,
    tracer_fraction: float = 0.10,
    tracer_spacing: float | None = None,
    dt: float | None = None,
    bins=None,
    method: str = "rk2",
    backend: str = "auto",
) -> VirtualTracerRTD:
    """RTD of a tracer filling ``tracer_fraction`` of the filled volume at the top of the fill.

    :func:`tracer_layer` then :func:`layer_rtd`; see those for the parameters.
    """
    tracer_fraction = positive_number("tracer_fraction", tracer_fraction)
    if tracer_fraction > 1.0:
        raise ValueError(f"tracer_fraction must be in (0, 1], got {tracer_fraction!r}")
    bottom, top = tracer_layer(field, fill_height, tracer_fraction)
    return layer_rtd(field, bottom, top, max_time, tracer_spacing=tracer_spacing, dt=dt, bins=bins,
                     method=method, backend=backend)


def tabulated_rtd(residence_time, step: float, weights=None) -> tuple[np.ndarray, np.ndarray]:
    """E of a residence-time sample at ``0, step, 2 step, ...``, the table of :mod:`analysis.numerics.lti`.

    ``E[k]`` is the weight of the residence times in ``[(k - 1/2) step, (k + 1/2) step)`` over the total
    weight (tracers that did not exit included) and ``step``, so a residence time of ``k step`` (to
    round-off) falls in sample k and a delay of k samples in the convolution.

    Parameters
    ----------
    residence_time : array_like, shape (n,)
        Residence times [s] (NaN: not out).
    step : float
        Sample step [s], > 0.
    weights : array_like, shape (n,), optional
        Tracer weights, > 0 (default equal).

    Returns
    -------
    time : numpy.ndarray, shape (m,)
        ``k step`` [s].
    E : numpy.ndarray, shape (m,)
        RTD [1/s].
    """
    residence = np.asarray(residence_time, dtype=float)
    step = positive_number("step", step)
    weight = _weights(weights, residence.shape)
    longest = float(np.nanmax(residence)) if np.any(np.isfinite(residence)) else 0.0
    count = int(math.floor(longest / step + 0.5)) + 2
    edges = (np.arange(count + 1) - 0.5) * step
    E = _weighted_rtd(residence, weight, edges).E
    return np.arange(count) * step, E


def _weights(weights, shape) -> np.ndarray:
    if weights is None:
        return np.ones(shape)
    weight = finite_array("weights", weights, ndim=None)
    if weight.shape != shape or np.any(weight <= 0.0):
        raise ValueError(f"weights must be numbers > 0 of shape {shape}, got shape {weight.shape}")
    return weight


# --------------------------------------------------------------------------- 6. discontinuous mode


@dataclass(frozen=True, eq=False)
class DiscontinuousMode:
    """A two-layer fill (tracer on top of base) recirculated at constant head.

    Attributes
    ----------
    window : float
        Window length [s].
    window_start : numpy.ndarray, shape (N,)
        Start of each window ``j window`` [s].
    time_in_passes : numpy.ndarray, shape (N,)
        ``window_start / t_m`` [-].
    first_pass : numpy.ndarray, shape (N,)
        Tracer of the initial fill leaving in each window over the outflow in it [-].
    concentration : numpy.ndarray, shape (N,)
        Outlet tracer concentration, recirculated [-].
    pass_mean : numpy.ndarray, shape (n_passes,)
        Mean concentration over each pass ``[p t_m, (p + 1) t_m)`` (windows by their centres) [-].
    tracer_fraction : float
        Tracer share of the fill by weight, the level ``c`` settles at [-].
    tracer_bottom : float
        Bottom of the tracer layer [m].
    mean_residence_time : float
        ``t_m`` of material entering at the fill surface [s].
    entry_time, entry_E : numpy.ndarray
        That entry RTD tabulated at ``k window`` [s, 1/s].
    homogenised_after : float
        Passes after which ``c`` stays within ``+-tolerance`` of ``tracer_fraction``; NaN if not within
        the windows.
    tolerance : float
        Relative band [-].
    n_not_exited : int
        Tracers of the fill that did not exit within ``max_time`` (their tracer never reaches the outlet).
    n_entry_not_exited : int
        Surface tracers of the entry RTD that did not exit.
    """

    window: float
    window_start: np.ndarray
    time_in_passes: np.ndarray
    first_pass: np.ndarray
    concentration: np.ndarray
    pass_mean: np.ndarray
    tracer_fraction: float
    tracer_bottom: float
    mean_residence_time: float
    entry_time: np.ndarray
    entry_E: np.ndarray
    homogenised_after: float
    tolerance: float
    n_not_exited: int
    n_entry_not_exited: int


def discontinuous_mode(
    field: BlenderField,
    fill_height: float,
    max_time: float,
    passes: int = 10,
    tracer_fraction: float = 0.20,
    window: float | None = None,
    tolerance: float = 0.10,
    tracer_spacing: float | None = None,
    dt: float | None = None,
    method: str = "rk2",
    backend: str = "auto",
) -> DiscontinuousMode:
    """Two-layer fill (tracer on top of base) discharged through the steady field and recirculated.

    Model (the renewal equation of :func:`analysis.studies.silo_recirculation.blending.predicted_concentration_from_first_pass`):
    the outflow is re-inserted at once at the fill surface and the flow is steady, so the outlet
    concentration is ``c = c_first + c * E``:

    - virtual tracers on a lattice over the whole fill ``[0, fill_height]`` (weights: bin solid fraction, as
      in :func:`layer_rtd`) give the first exits of the initial contents; those above the bottom of
      the top ``tracer_fraction`` by volume (:func:`tracer_layer`) are tracer;
    - ``E`` is the RTD of material entering at the surface: tracers released at ``fill_height`` with
      the lattice spacing across the width, weighted by the local flux ``solid_fraction |v_z|`` there,
      tabulated by :func:`tabulated_rtd`; ``t_m`` is its weighted mean;
    - the outflow rate is the holdup over ``t_m`` (Little's law, which makes the model conserve the
      tracer: ``c`` settles at the tracer's share of the fill), so
      ``c_first[j] = (tracer weight leaving in window j) t_m / (fill weight * window)``.

    The number of recirculations to homogenise is :func:`analysis.numerics.lti.recirculations_to_homogenise`
    of ``c`` around the tracer share, with ``t_m / window`` samples per pass.

    Parameters
    ----------
    field : BlenderField
        The steady field (uniform bins).
    fill_height : float
        Fill height [m] (within the grid).
    max_time : float
        Longest residence time followed [s], > 0.
    passes : int, optional
        Passes covered by the windows, >= 1; default 10.
    tracer_fraction : float, optional
        Tracer share of the filled volume, in (0, 1); default 0.20.
    window : float, optional
        Window length [s]; default ``t_m / 100``.
    tolerance : float, optional
        Relative band of homogenisation, > 0; default 0.10.
    tracer_spacing, dt, method, backend : optional
        As in :func:`layer_rtd`.

    Returns
    -------
    DiscontinuousMode
    """
    field = _field(field)
    max_time = positive_number("max_time", max_time)
    if isinstance(passes, (bool, np.bool_)) or int(passes) != passes or passes < 1:
        raise ValueError(f"passes must be an integer >= 1, got {passes!r}")
    tracer_fraction = positive_number("tracer_fraction", tracer_fraction)
    if tracer_fraction >= 1.0:
        raise ValueError(f"tracer_fraction must be in (0, 1), got {tracer_fraction!r}")
    tolerance = positive_number("tolerance", tolerance)
    tracer_bottom, _ = tracer_layer(field, fill_height, tracer_fraction)
    x, z, weights = _layer_tracers(field, 0.0, fill_height, tracer_spacing)
    fill_residence = _integrate(field, x, z, dt, max_time, method, backend).residence_time

    dx, dz = field.bin_size()
    # release just inside the grid box when the fill surface is its top face (round-off must not put it outside)
    release = min(float(fill_height), float(field.z[-1]) + 0.5 * dz * (1.0 - 1e-9))
    entry_x = lattice_seeds((field.x[0] - 0.5 * dx, 0.0, fill_height), (field.x[-1] + 0.5 * dx, 0.0, fill_height),
                            spacing=(_tracer_spacing(field, tracer_spacing), 1.0, 1.0))[:, 0]
    surface = float(np.clip(fill_height, field.z[0], field.z[-1]))
    surface_flux = _at_height(field, field.solid_fraction * np.abs(np.where(field.occupied, field.v_z, 0.0)), surface)
    flux = np.nan_to_num(surface_flux[_bin_index(field.x, dx, entry_x)], nan=0.0)
    entry_x, flux = entry_x[flux > 0.0], flux[flux > 0.0]
    if entry_x.size == 0:
        raise ValueError(f"fill_height = {fill_height!r} m: no flux through the fill surface")
    entry_residence = _integrate(field, entry_x, np.full(entry_x.size, release), dt, max_time, method,
                                 backend).residence_time
    entry_out = np.isfinite(entry_residence)
    if not np.any(entry_out):
        raise ValueError(f"no tracer released at the fill surface reached the outlet within max_time = {max_time!r} s")
    t_m = float(np.average(entry_residence[entry_out], weights=flux[entry_out]))
    step = t_m / 100.0 if window is None else positive_number("window", window)
    entry_time, entry_E = tabulated_rtd(entry_residence, step, flux)

    fill_out = np.isfinite(fill_residence)
    longest = float(fill_residence[fill_out].max()) if np.any(fill_out) else 0.0
    n_windows = max(int(math.ceil(passes * t_m / step - 1.0e-9)), int(math.floor(longest / step)) + 1, 2)
    is_tracer = z >= tracer_bottom
    index = np.floor(fill_residence[fill_out & is_tracer] / step).astype(np.int64)
    leaving = np.bincount(index, weights=weights[fill_out & is_tracer], minlength=n_windows)[:n_windows]
    c_first = leaving * t_m / (float(weights.sum()) * step)
    first_term = int(np.flatnonzero(entry_E > 0.0)[0])
    if first_term == 0:
        raise ValueError(f"window = {step!r} s: material entering at the fill surface leaves within half a window; "
                         "use a shorter window")
    terms = int(math.ceil(n_windows / first_term))
    c = predicted_concentration_from_first_pass(c_first, entry_E, step, terms)

    share = float(weights[is_tracer].sum() / weights.sum())
    starts = np.arange(n_windows) * step
    pass_index = np.floor((starts + 0.5 * step) / t_m).astype(np.int64)
    pass_mean = np.array([float(np.mean(c[pass_index == p])) for p in range(int(pass_index.max()) + 1)
                          if np.any(pass_index == p)])
    homogenised = recirculations_to_homogenise(c, mean=share, tolerance=tolerance, per_pass_length=t_m / step)
    return DiscontinuousMode(
        window=step, window_start=starts, time_in_passes=starts / t_m, first_pass=c_first, concentration=c,
        pass_mean=pass_mean, tracer_fraction=share, tracer_bottom=tracer_bottom, mean_residence_time=t_m,
        entry_time=entry_time, entry_E=entry_E, homogenised_after=homogenised, tolerance=tolerance,
        n_not_exited=int(np.count_nonzero(~fill_out)), n_entry_not_exited=int(np.count_nonzero(~entry_out)),
    )


# --------------------------------------------------------------------------- 7. continuous mode


@dataclass(frozen=True, eq=False)
class ContinuousMode:
    """Sine inputs through the RTD: damping against the input period.

    Attributes
    ----------
    vrr_table : VRRTable
        VRR against ``period / t_m`` (:func:`analysis.numerics.lti.vrr_versus_period`).
    cov_in : float
        CoV of the sine input, ``amplitude / (sqrt(2) mean)`` [-].
    cov_out : numpy.ndarray, shape (n,)
        CoV of the outlet, ``cov_in / sqrt(VRR)`` [-].
    weakest_damping_period_over_tm : float
        Period (over ``t_m``) with the smallest VRR [-].
    resonant_periods_over_tm : numpy.ndarray
        Periods (over ``t_m``) where the VRR has a local minimum inside the range (strictly below both
        neighbours): inputs in step with peaks of the RTD [-].
    """

    vrr_table: VRRTable
    cov_in: float
    cov_out: np.ndarray
    weakest_damping_period_over_tm: float
    resonant_periods_over_tm: np.ndarray

    @property
    def period_over_tm(self) -> np.ndarray:
        """Input periods over ``t_m`` [-]."""
        return self.vrr_table.period_over_tm

    @property
    def vrr(self) -> np.ndarray:
        """VRR per period [-]."""
        return self.vrr_table.vrr

    def vrr_at(self, period_over_tm: float) -> float:
        """The VRR at one of the computed periods (matched to 1e-9 relative)."""
        matches = np.flatnonzero(np.isclose(self.period_over_tm, float(period_over_tm), rtol=1.0e-9, atol=0.0))
        if matches.size == 0:
            raise ValueError(f"period_over_tm = {period_over_tm!r} was not computed ({self.period_over_tm.tolist()})")
        return float(self.vrr[matches[0]])


def continuous_mode(
    residence_time,
    step: float,
    periods_over_tm,
    weights=None,
    mean: float = 0.5,
    amplitude: float = 0.5,
    n_periods: int = 10,
) -> ContinuousMode:
    """VRR and CoV of sine inputs against the input period, through the RTD of a tracer sample.

    The RTD is the sample tabulated at ``k step`` (:func:`tabulated_rtd`); the periods are fractions of
    its weighted mean residence time ``t_m`` and :func:`analysis.numerics.lti.vrr_versus_period` convolves each
    sine with it. The outlet keeps the input mean, so its CoV is ``sqrt(var_in / VRR) / mean`` with
    ``var_in = amplitude^2 / 2`` (whole periods).

    Parameters
    ----------
    residence_time : array_like, shape (n,)
        Residence times [s] (NaN: not out; counted in the total, then E is normalised).
    step : float
        Sample step of the RTD and the signals [s]; each period must span >= 4 steps.
    periods_over_tm : array_like, shape (k,)
        Input periods over ``t_m``, strictly increasing, > 0.
    weights : array_like, shape (n,), optional
        Tracer weights (e.g. :attr:`VirtualTracerRTD.weights`).
    mean, amplitude : float, optional
        Input mean (> 0) and amplitude (> 0); default 0.5 and 0.5.
    n_periods : int, optional
        Whole periods in the steady window; default 10.

    Returns
    -------
    ContinuousMode
    """
    residence = np.asarray(residence_time, dtype=float)
    weight = _weights(weights, residence.shape)
    exited = np.isfinite(residence)
    if not np.any(exited):
        raise ValueError("residence_time: no tracer exited")
    fractions = finite_array("periods_over_tm", periods_over_tm, ndim=1)
    if fractions.size == 0 or np.any(fractions <= 0.0) or np.any(np.diff(fractions) <= 0.0):
        raise ValueError("periods_over_tm must be non-empty, > 0 and strictly increasing")
    mean = positive_number("mean", mean)
    amplitude = positive_number("amplitude", amplitude)
    time, E = tabulated_rtd(residence, step, weight)
    t_m = float(np.average(residence[exited], weights=weight[exited]))
    table = vrr_versus_period(E, time, fractions, mean=mean, amplitude=amplitude, waveform="sine",
                              n_periods=n_periods, t_mean=t_m)
    cov_in = amplitude / (math.sqrt(2.0) * mean)
    vrr = table.vrr
    inner = np.arange(1, vrr.size - 1)
    local_minimum = inner[(vrr[inner] < vrr[inner - 1]) & (vrr[inner] < vrr[inner + 1])]
    return ContinuousMode(
        vrr_table=table, cov_in=cov_in, cov_out=cov_in / np.sqrt(vrr),
        weakest_damping_period_over_tm=float(fractions[int(np.argmin(vrr))]),
        resonant_periods_over_tm=fractions[local_minimum],
    )


# --------------------------------------------------------------------------- 8. gravity scaling


def _gravity_factor(value) -> float:
    return positive_number("gravity_factor", value)


def gravity_normalised_time(time, gravity_factor: float):
    """Time of a run at ``gravity_factor`` g on the clock of a 1 g run, ``t sqrt(factor)`` [s].

    Times scale with ``sqrt(L / g)``: a run at ``f g`` does in ``t`` what a 1 g run does in ``t sqrt(f)``.
    """
    return finite_array("time", time, ndim=None) * math.sqrt(_gravity_factor(gravity_factor))


def gravity_normalised_velocity(velocity, gravity_factor: float):
    """Velocity of a run at ``gravity_factor`` g scaled to 1 g, ``v / sqrt(factor)`` [m/s].

    Velocities scale with ``sqrt(g L)``. NaN (no particles) is kept.
    """
    values = np.asarray(velocity, dtype=float)
    if np.any(np.isinf(values)):
        raise ValueError("velocity must not contain infinite values")
    return values / math.sqrt(_gravity_factor(gravity_factor))


@dataclass(frozen=True, eq=False)
class GravityScaling:
    """Which quantities scale with ``sqrt(g)`` across runs at several gravity factors.

    Attributes
    ----------
    rows : list of dict
        One row per quantity and factor, keys ``quantity, gravity_factor, value, ratio_to_1g,
        expected_ratio, relative_deviation, scales`` (for :func:`analysis.io.tables.write_flow_table`).
    scales : dict
        Quantity -> True when every factor's ratio to 1 g lies within the tolerance of ``sqrt(factor)``.
    tolerance : float
        Relative tolerance [-].
    """

    rows: list
    scales: dict
    tolerance: float


def gravity_scaling(gravity_factors, quantities: Mapping, tolerance: float = 0.05) -> GravityScaling:
    """Ratios of steady quantities (mass flow rate, mean velocity, ...) to their 1 g value against ``sqrt(factor)``.

    For each quantity ``q`` and factor ``f``: ``ratio = q(f) / q(1)`` and ``expected = sqrt(f)``; the
    quantity scales when ``|ratio / expected - 1| <= tolerance`` at every factor.

    Parameters
    ----------
    gravity_factors : array_like, shape (n,)
        Factors ``g_run / g``, > 0, distinct, one of them 1.
    quantities : mapping name -> array_like, shape (n,)
        Values per factor (e.g. ``"mass_flow_rate_kg_s"``), finite, non-zero at factor 1.
    tolerance : float, optional
        Relative tolerance, > 0; default 0.05.

    Returns
    -------
    GravityScaling
    """
    factors = finite_array("gravity_factors", gravity_factors, ndim=1)
    if factors.size == 0 or np.any(factors <= 0.0) or np.unique(factors).size != factors.size:
        raise ValueError("gravity_factors must be distinct numbers > 0")
    reference = np.flatnonzero(factors == 1.0)
    if reference.size != 1:
        raise ValueError("gravity_factors must include the factor 1 (the reference run)")
    tolerance = positive_number("tolerance", tolerance)
    if not isinstance(quantities, Mapping) or not quantities:
        raise ValueError("quantities must be a non-empty mapping name -> values per factor")
    rows, scales = [], {}
    for name, values in quantities.items():
        values = finite_array(f"quantities[{name!r}]", values, ndim=1)
        if values.shape != factors.shape:
            raise ValueError(
                f"quantities[{name!r}] must hold {factors.size} values (one per factor), got {values.size}"
            )
        base = float(values[reference[0]])
        if base == 0.0:
            raise ValueError(f"quantities[{name!r}] is 0 at factor 1; ratios are undefined")
        within = True
        for factor, value in zip(factors, values):
            ratio, expected = float(value) / base, math.sqrt(float(factor))
            deviation = ratio / expected - 1.0
            ok = abs(deviation) <= tolerance
            within &= ok
            rows.append({"quantity": str(name), "gravity_factor": float(factor), "value": float(value),
                         "ratio_to_1g": ratio, "expected_ratio": expected, "relative_deviation": deviation,
                         "scales": ok})
        scales[str(name)] = within
    return GravityScaling(rows=rows, scales=scales, tolerance=tolerance)


# --------------------------------------------------------------------------- 9. configuration comparison


@dataclass(frozen=True)
class BlenderMetrics:
    """The numbers that characterise one blender configuration.

    Attributes
    ----------
    name : str
        Configuration (e.g. ``"diverging"``).
    mass_flow_rate : float
        Steady mass flow rate [kg/s].
    exterior_v_z, interior_v_z, tube_v_z : float
        Mean vertical velocity of the exterior annulus, interior annulus and tube [m/s].
    rtd_mean : float
        Mean residence time ``t_m`` [s].
    rtd_spread : float
        ``sigma / t_m`` [-].
    ts_over_td : float
        ``t_s / t_d`` [-].
    recirculations_to_homogenise : float
        Passes until the outlet stays within the band; NaN if never [-].
    vrr_by_period : mapping
        ``period / t_m`` -> VRR of a sine input [-].
    """

    name: str
    mass_flow_rate: float
    exterior_v_z: float
    interior_v_z: float
    tube_v_z: float
    rtd_mean: float
    rtd_spread: float
    ts_over_td: float
    recirculations_to_homogenise: float
    vrr_by_period: Mapping


def _metrics(metrics) -> list[BlenderMetrics]:
    items = list(metrics)
    if not items or not all(isinstance(item, BlenderMetrics) for item in items):
        raise ValueError("metrics must be a non-empty sequence of BlenderMetrics")
    names = [item.name for item in items]
    if len(set(names)) != len(names):
        raise ValueError(f"metrics must have distinct names, got {names}")
    periods = sorted(float(p) for p in items[0].vrr_by_period)
    for item in items:
        if sorted(float(p) for p in item.vrr_by_period) != periods:
            raise ValueError(f"metrics {item.name!r}: VRR periods {sorted(item.vrr_by_period)} differ from {periods}")
    return items


def comparison_table(metrics: Sequence[BlenderMetrics]) -> list[dict]:
    """One row per configuration with a stable column order (for :func:`analysis.io.tables.write_flow_table`).

    Columns: ``configuration, mass_flow_rate_kg_s, exterior_v_z_m_s, interior_v_z_m_s, tube_v_z_m_s,
    rtd_mean_s, rtd_spread, ts_over_td, recirculations_to_homogenise``, then ``vrr_at_<f>_tm`` for each
    period fraction f in increasing order (all configurations must share them).
    """
    items = _metrics(metrics)
    rows = []
    for item in items:
        row = {
            "configuration": item.name,
            "mass_flow_rate_kg_s": float(item.mass_flow_rate),
            "exterior_v_z_m_s": float(item.exterior_v_z),
            "interior_v_z_m_s": float(item.interior_v_z),
            "tube_v_z_m_s": float(item.tube_v_z),
            "rtd_mean_s": float(item.rtd_mean),
            "rtd_spread": float(item.rtd_spread),
            "ts_over_td": float(item.ts_over_td),
            "recirculations_to_homogenise": float(item.recirculations_to_homogenise),
        }
        for period in sorted(item.vrr_by_period):
            row[f"vrr_at_{float(period):g}_tm"] = float(item.vrr_by_period[period])
        rows.append(row)
    return rows


def best_blender(metrics: Sequence[BlenderMetrics]) -> str:
    """The best blender: fewest recirculations to homogenise, ties broken by the highest VRR at the shortest period.

    A configuration that never homogenises (NaN) ranks after all that do; remaining ties keep the
    given order. Without VRR periods only the recirculations count.
    """
    items = _metrics(metrics)

    def key(item: BlenderMetrics):
        recirculations = float(item.recirculations_to_homogenise)
        periods = sorted(item.vrr_by_period)
        vrr = float(item.vrr_by_period[periods[0]]) if periods else 0.0
        return (recirculations if math.isfinite(recirculations) else math.inf, -vrr)

    return min(items, key=key).name
