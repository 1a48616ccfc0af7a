"""Virtual tracers through the blender's steady field: pathlines, the RTD of a tracer layer, tabulated RTDs.

Pure computation on :class:`siloflow.analysis.studies.blender.steady_field.BlenderField`; no file I/O. SI units:
lengths in m, times in s, E in 1/s. Tracers move with the velocity interpolated between bin centres
(:func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`, a single time level) until they cross the outlet
plane z = 0; a tracer that reaches an unoccupied bin stops there (it does not exit).

1. Pathlines of virtual tracers released across the width and their residence times
   (:func:`tracer_pathlines`).
2. The RTD of virtual tracers filling a layer at the top of the fill (:func:`tracer_layer`,
   :func:`layer_rtd`, :func:`virtual_tracer_rtd`), and a residence-time sample tabulated on the
   uniform axis of :mod:`siloflow.analysis.numerics.lti` (:func:`tabulated_rtd`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, finite_number, positive_number
from siloflow.analysis.numerics.pathlines import PathlineResult, integrate_pathlines
from siloflow.analysis.numerics.rtd import RTD, rtd_from_exit_times
from siloflow.analysis.numerics.tracer_seeds import lattice_seeds
from siloflow.analysis.studies.blender.steady_field import BlenderField, at_height, checked_field

__all__ = [
    "DEFAULT_RELEASE_SPACING",
    "TracerPathlines",
    "VirtualTracerRTD",
    "tracer_pathlines",
    "tracer_layer",
    "layer_rtd",
    "virtual_tracer_rtd",
    "tabulated_rtd",
    "integrate_tracers",
    "layer_tracers",
    "lattice_spacing",
    "bin_index",
    "tracer_weights",
]

DEFAULT_RELEASE_SPACING = 0.015
"""Spacing of the pathline tracers across the width [m] (15 mm in the study)."""

_DEPTH_CELL = 1.0
"""Size of the single cell along y given to the pathline integrator (y plays no part) [m]."""


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


def integrate_tracers(field: BlenderField, x, z, dt, max_time, method, backend, record_every=0) -> PathlineResult:
    """Tracers released at ``(x, z)`` [m] at once, integrated through the steady field up to ``max_time`` [s].

    ``dt`` None takes :func:`_default_step`; ``method``, ``backend`` and ``record_every`` as in
    :func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`.
    """
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
    (:func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`, a single time level) until they cross z = 0.

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
        See :func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`.

    Returns
    -------
    TracerPathlines
    """
    field = checked_field(field)
    release_z = finite_number("release_z", release_z)
    max_time = positive_number("max_time", max_time)
    spacing = positive_number("spacing", spacing)
    moving = np.isfinite(at_height(field, field.v_z, release_z))
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
    result = integrate_tracers(field, release_x, np.full(release_x.size, release_z), step, max_time, method, backend,
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
    field = checked_field(field)
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


def bin_index(centres: np.ndarray, step: float, positions) -> np.ndarray:
    """Index of the uniform bin containing each position (clamped to the bins)."""
    index = np.floor((np.asarray(positions, dtype=float) - centres[0]) / step + 0.5).astype(np.int64)
    return np.clip(index, 0, centres.size - 1)


def lattice_spacing(field: BlenderField, tracer_spacing) -> float:
    """The lattice spacing of virtual tracers [m]: as given, or half the smaller bin edge."""
    if tracer_spacing is None:
        return 0.5 * min(field.bin_size())
    return positive_number("tracer_spacing", tracer_spacing)


def _weighted_rtd(residence_time: np.ndarray, weights: np.ndarray, bins) -> RTD:
    """:func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times` with tracer weights (mass) in E, mean and variance.

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


def layer_tracers(field: BlenderField, z_bottom: float, z_top: float, tracer_spacing) -> tuple:
    """Lattice tracers filling ``[z_bottom, z_top]`` across the grid, kept where the bin has particles."""
    dx, dz = field.bin_size()
    spacing = lattice_spacing(field, tracer_spacing)
    top = field.z[-1] + 0.5 * dz
    if z_top > top * (1.0 + 1.0e-12):
        raise ValueError(f"z_top = {z_top!r} m lies above the grid (top {top!r} m)")
    seeds = lattice_seeds((field.x[0] - 0.5 * dx, 0.0, z_bottom), (field.x[-1] + 0.5 * dx, 0.0, z_top),
                          spacing=(spacing, 1.0, spacing))
    weights = field.solid_fraction[bin_index(field.x, dx, seeds[:, 0]), bin_index(field.z, dz, seeds[:, 2])]
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

    Tracers sit on a square lattice of about ``tracer_spacing`` (:func:`siloflow.analysis.numerics.tracer_seeds.lattice_seeds`)
    over the width of the grid; those in bins without particles are left out (they are no material),
    the others carry the solid fraction of their bin as weight. Each is followed through the steady field to
    z = 0; the RTD is :func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times` with those weights.

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
        Residence-time bins of E (see :func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times`).
    method, backend : str, optional
        See :func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`.

    Returns
    -------
    VirtualTracerRTD

    Raises
    ------
    ValueError
        On a bad layer, no tracer in an occupied bin, or no tracer that exits.
    """
    field = checked_field(field)
    z_bottom = finite_number("z_bottom", z_bottom)
    z_top = finite_number("z_top", z_top)
    if not 0.0 <= z_bottom < z_top:
        raise ValueError(f"the layer must satisfy 0 <= z_bottom < z_top, got [{z_bottom!r}, {z_top!r}] m")
    max_time = positive_number("max_time", max_time)
    x, z, weights = layer_tracers(field, z_bottom, z_top, tracer_spacing)
    residence = integrate_tracers(field, x, z, dt, max_time, method, backend).residence_time
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
    """E of a residence-time sample at ``0, step, 2 step, ...``, the table of :mod:`siloflow.analysis.numerics.lti`.

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
    weight = tracer_weights(weights, residence.shape)
    longest = float(np.nanmax(residence)) if np.any(np.isfinite(residence)) else 0.0
    count = int(math.floor(longest / step + 0.5)) + 2
    edges = (np.arange(count + 1) - 0.5) * step
    E = _weighted_rtd(residence, weight, edges).E
    return np.arange(count) * step, E


def tracer_weights(weights, shape) -> np.ndarray:
    """Tracer weights of the given shape, each > 0; equal weights (ones) for None."""
    if weights is None:
        return np.ones(shape)
    weight = finite_array("weights", weights, ndim=None)
    if weight.shape != shape or np.any(weight <= 0.0):
        raise ValueError(f"weights must be numbers > 0 of shape {shape}, got shape {weight.shape}")
    return weight
