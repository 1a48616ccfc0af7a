"""RTD from Eulerian fields: bin-averaged clump velocities and virtual tracers advected through them.

Pure computation on numpy arrays; no file I/O. SI units: m, m/s, s, kg.

The method of thesis ch. 6 ("RTD from Eulerian fields"):

1. Split the silo into bins (a regular grid, :class:`siloflow.analysis.numerics.grid.Grid`) and take, at every
   saved instant, the mass-weighted mean velocity of the clumps whose centres lie in each bin
   (:func:`bin_velocity_series`). A bin that is empty at an instant (a dilute falling stream, the
   free surface) takes its mass-weighted velocity over all instants; a bin that is never occupied gets
   zero velocity, so a tracer there stays put.
2. Place virtual tracers on a lattice in the inlet bins, the top row of bins above the outlet
   (:func:`inlet_bins`, :func:`siloflow.analysis.numerics.tracer_seeds.lattice_seeds`); in the recirculating silo the
   re-entering clumps fall through them.
3. Integrate ``x(t + dt) = x(t) + v(x, t) dt`` with the velocity interpolated trilinearly between bin
   centres and linearly in time (:func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`), and take the time to
   cross the outlet plane as the residence time (:func:`eulerian_residence_times`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, positive_number
from siloflow.analysis.numerics.grid import Grid
from siloflow.analysis.numerics.pathlines import PathlineResult, integrate_pathlines
from siloflow.analysis.numerics.tracer_seeds import lattice_seeds

__all__ = ["silo_bins", "bin_sums", "bin_velocity_series", "inlet_bins", "EulerianRTD", "eulerian_residence_times"]


def silo_bins(width: float, depth: float, top: float, bin_size: float) -> Grid:
    """Bins of edge about ``bin_size`` in x and z covering the silo above the outlet, one bin across the depth.

    The silo interior ``[-W/2, W/2] x [0, T] x [0, top]`` is split into ``max(1, round(W / b))`` columns and
    ``max(1, round(top / b))`` rows, so the bins tile it exactly (their edges are stretched to whole bins).

    Parameters
    ----------
    width, depth, top : float
        Silo width W, depth T and height of the binned region above the outlet plane [m].
    bin_size : float
        Wanted bin edge b in x and z [m].
    """
    width, depth, top = (positive_number(n, v) for n, v in (("width", width), ("depth", depth), ("top", top)))
    bin_size = positive_number("bin_size", bin_size)
    nx, nz = max(1, round(width / bin_size)), max(1, round(top / bin_size))
    return Grid(origin=(-0.5 * width, 0.0, 0.0), spacing=(width / nx, depth, top / nz), shape=(nx, 1, nz))


def bin_velocity_series(positions, velocities, masses, grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    """Mass-weighted mean clump velocity per bin at every instant.

    Parameters
    ----------
    positions, velocities : array_like, shape (n_times, n_clumps, 3)
        Clump centres [m] and velocities [m/s]; NaN rows mark clumps absent at an instant.
    masses : array_like, shape (n_clumps,)
        Clump masses [kg], > 0.
    grid : Grid
        The bins; clumps outside its box are ignored.

    Returns
    -------
    velocity : numpy.ndarray, shape (n_times, nx, ny, nz, 3)
        Bin velocity [m/s]: the instant's mass-weighted mean where the bin holds clumps, else the bin's
        mass-weighted mean over all instants, else 0.
    occupied : numpy.ndarray of bool, shape (n_times, nx, ny, nz)
        Whether the bin held a clump at that instant.
    """
    mass_sum, momentum_sum = bin_sums(positions, velocities, masses, grid)
    shape = grid.shape
    n_times, n_bins = mass_sum.shape
    occupied = mass_sum > 0.0
    total_mass = mass_sum.sum(axis=0)
    mean_over_time = np.divide(
        momentum_sum.sum(axis=0), total_mass[:, None], out=np.zeros((n_bins, 3)), where=total_mass[:, None] > 0.0
    )
    velocity = np.where(
        occupied[..., None],
        momentum_sum / np.where(occupied, mass_sum, 1.0)[..., None],
        mean_over_time[None, :, :],
    )
    return velocity.reshape(n_times, *shape, 3), occupied.reshape(n_times, *shape)


def bin_sums(positions, velocities, masses, grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    """Clump mass and momentum summed per bin at every instant (clumps outside the grid or absent ignored).

    Parameters
    ----------
    positions, velocities : array_like, shape (n_times, n_clumps, 3)
        Clump centres [m] and velocities [m/s]; NaN rows mark clumps absent at an instant.
    masses : array_like, shape (n_clumps,)
        Clump masses [kg], > 0.
    grid : Grid
        The bins.

    Returns
    -------
    mass : numpy.ndarray, shape (n_times, n_bins)
        Mass per bin [kg], bins in C order of ``grid.shape``.
    momentum : numpy.ndarray, shape (n_times, n_bins, 3)
        Momentum per bin [kg m/s].
    """
    positions = np.asarray(positions, dtype=float)
    velocities = np.asarray(velocities, dtype=float)
    if positions.ndim != 3 or positions.shape[-1] != 3:
        raise ValueError(f"positions must have shape (n_times, n_clumps, 3), got {positions.shape}")
    if velocities.shape != positions.shape:
        raise ValueError(f"velocities must have the shape of positions {positions.shape}, got {velocities.shape}")
    n_times, n_clumps, _ = positions.shape
    masses = finite_array("masses", masses, ndim=1)
    if masses.shape != (n_clumps,) or np.any(masses <= 0.0):
        raise ValueError(f"masses must be {n_clumps} numbers > 0 (one per clump)")
    shape = grid.shape
    n_bins = shape[0] * shape[1] * shape[2]
    origin, spacing = np.asarray(grid.origin), np.asarray(grid.spacing)
    mass_sum = np.zeros((n_times, n_bins))
    momentum_sum = np.zeros((n_times, n_bins, 3))
    for k in range(n_times):
        present = np.all(np.isfinite(positions[k]), axis=1) & np.all(np.isfinite(velocities[k]), axis=1)
        index = np.floor((positions[k, present] - origin) / spacing).astype(np.int64)
        inside = np.all((index >= 0) & (index < np.asarray(shape)), axis=1)
        index = index[inside]
        flat = np.ravel_multi_index(index.T, shape) if index.size else np.empty(0, dtype=np.int64)
        weight = masses[present][inside]
        mass_sum[k] = np.bincount(flat, weights=weight, minlength=n_bins)
        for axis in range(3):
            momentum_sum[k, :, axis] = np.bincount(
                flat, weights=weight * velocities[k, present][inside][:, axis], minlength=n_bins
            )
    return mass_sum, momentum_sum


def inlet_bins(grid: Grid, inlet_width: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of the inlet region: the top row of bins whose centres lie within the inlet.

    In the recirculating silo the clumps re-enter at the top in a stream as wide as the outlet channel,
    centred on x = 0; the inlet region is the top row of bins over ``|x| <= inlet_width / 2`` (at least the
    central bin), spanning the depth.

    Returns
    -------
    lower, upper : numpy.ndarray, shape (3,)
        Corners of the inlet region [m].
    """
    inlet_width = positive_number("inlet_width", inlet_width)
    origin, spacing, shape = np.asarray(grid.origin), np.asarray(grid.spacing), grid.shape
    centres = origin[0] + (np.arange(shape[0]) + 0.5) * spacing[0]
    inside = np.flatnonzero(np.abs(centres) <= 0.5 * inlet_width + 1e-12 * spacing[0])
    if inside.size == 0:
        inside = np.array([int(np.argmin(np.abs(centres)))])
    lower = np.array([origin[0] + inside[0] * spacing[0], origin[1], origin[2] + (shape[2] - 1) * spacing[2]])
    upper = np.array([origin[0] + (inside[-1] + 1) * spacing[0], origin[1] + shape[1] * spacing[1],
                      origin[2] + shape[2] * spacing[2]])
    return lower, upper


@dataclass(frozen=True, eq=False)
class EulerianRTD:
    """Residence times of virtual tracers released in the inlet bins.

    Attributes
    ----------
    grid : Grid
        The bins.
    seeds : numpy.ndarray, shape (n, 3)
        Release positions [m].
    pathlines : PathlineResult
        Residence times (NaN for tracers that did not leave within ``max_time``) and optional paths.
    """

    grid: Grid
    seeds: np.ndarray
    pathlines: PathlineResult

    @property
    def residence_time(self) -> np.ndarray:
        """Residence time per virtual tracer [s] (NaN: not out within the time followed)."""
        return self.pathlines.residence_time


def eulerian_residence_times(
    times, positions, velocities, masses, grid: Grid, inlet_width: float, n_tracers: int, release_time: float,
    dt: float, max_time: float, outlet_z: float = 0.0, record_every: int = 0,
) -> EulerianRTD:
    """RTD from Eulerian fields: bin velocities from the clumps, tracers from the inlet bins, pathlines to the outlet.

    Parameters
    ----------
    times : array_like, shape (n_times,)
        Instants of the saved clump states [s], strictly increasing.
    positions, velocities : array_like, shape (n_times, n_clumps, 3)
        Clump centres [m] and velocities [m/s] (NaN where absent).
    masses : array_like, shape (n_clumps,)
        Clump masses [kg].
    grid : Grid
        The bins (:func:`silo_bins`).
    inlet_width : float
        Width of the re-entering stream [m] (the outlet width).
    n_tracers : int
        Virtual tracers, about as many as the tracer has particles (from bulk density and tracer volume);
        put on an approximately cubic lattice in the inlet region.
    release_time : float
        When the tracers are released [s] (on the clock of ``times``).
    dt : float
        Integration step [s].
    max_time : float
        Longest residence time followed [s].
    outlet_z : float, optional
        Height of the outlet plane [m]; default 0.
    record_every : int, optional
        Record the paths every this many steps (0: not recorded).
    """
    if int(n_tracers) != n_tracers or n_tracers < 1:
        raise ValueError(f"n_tracers must be an integer >= 1, got {n_tracers!r}")
    times = finite_array("times", times, ndim=1)
    velocity, _ = bin_velocity_series(positions, velocities, masses, grid)
    lower, upper = inlet_bins(grid, inlet_width)
    seeds = lattice_seeds(lower, upper, count=int(n_tracers))
    result = integrate_pathlines(
        seeds, float(release_time), velocity, times, grid.origin, grid.spacing, dt, outlet_z, max_time,
        record_every=record_every,
    )
    return EulerianRTD(grid=grid, seeds=seeds, pathlines=result)

