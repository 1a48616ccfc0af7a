"""Window-averaged planar fields and the discharge history of a blender run, from clump tracks.

Pure functions on numpy arrays; no file I/O (:func:`siloflow.analysis.numerics.clump_tracks.tracks_from_frames`
builds the tracks from the engine's frames, :mod:`siloflow.analysis.studies.blender.window_fields_io` stores the
fields). SI units: positions in m, velocities in m/s, masses in kg, times in s.

Fields are mass-weighted bin averages over all frames of a time window: for bin b,
``v_b = sum_k sum_{i in b at k} m_i v_i / sum_k sum_{i in b at k} m_i`` (clumps of many frames pooled, so a bin
that is often empty still gets the mean of the clumps that passed through it), and the solid fraction is the
mean clump mass in the bin over the window divided by ``rho_s`` times the bin volume. The fields of the single
frames of a window (:func:`frame_fields`) give the series whose batch means carry the errors of the steady figures.

The wall layer (:func:`wall_layer_positions`, :data:`WALL_LAYER_DIAMETERS`): what the study's PIV sees through the front
wall (thesis §7.2, §7.8.2.1), the clumps whose centre lies within one particle diameter of the front or the back
wall, both walls folded onto one; binned on a grid one layer deep
(:func:`siloflow.analysis.numerics.eulerian_rtd.silo_bins` with the layer's depth), the same functions give its
fields.

Discharged mass: in batch mode the mass above the outlet plane at the first frame minus that at each frame
(clumps leave the domain below the outlet); in continuous mode the mass that crossed the outlet plane so far
(clumps re-enter at the top, the mass above the outlet stays about constant).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number, positive_number
from siloflow.analysis.numerics.eulerian_rtd import bin_sums
from siloflow.analysis.numerics.grid import Grid
from siloflow.analysis.numerics.clump_tracks import ClumpTracks
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events

__all__ = ["PlanarField", "window_average_field", "frame_fields", "discharged_mass_history", "frames_in_window",
           "mean_velocity_history", "WALL_LAYER_DIAMETERS", "wall_layer_depth", "wall_layer_positions"]

WALL_LAYER_DIAMETERS = 1.0
"""Depth of the wall layer, in volume-equivalent particle diameters (-). A clump touching a flat wall has its centre
between its sphere radius and half its length from it (1.5 to 1.875 mm for the study's two-sphere clump, whose
volume-equivalent diameter is about 3.3 mm), while the centres of the next layer lie about a radius plus a layer
spacing out (about 4 mm): a cut at one diameter keeps the clumps a camera sees through the wall and leaves the next
layer out. The study does not say how deep its DEM front-wall layer was (§5.4.3.4, §7.7)."""


@dataclass(frozen=True, eq=False)
class PlanarField:
    """A depth-averaged field on an x-z lattice of bins.

    Attributes
    ----------
    x, z : numpy.ndarray, shapes (nx,), (nz,)
        Bin centres [m].
    v_x, v_z : numpy.ndarray, shape (nx, nz)
        Mass-weighted mean velocity components [m/s]; NaN in bins no clump entered.
    solid_fraction : numpy.ndarray, shape (nx, nz)
        Mean solid volume fraction [-].
    window : tuple of float
        Time window averaged [s].
    n_frames : int
        Frames in the window.
    """

    x: np.ndarray
    z: np.ndarray
    v_x: np.ndarray
    v_z: np.ndarray
    solid_fraction: np.ndarray
    window: tuple[float, float]
    n_frames: int


def frames_in_window(times, window: tuple[float, float]) -> np.ndarray:
    """Indices of the frames with ``window[0] <= t <= window[1]``; ValueError when there are none."""
    times = np.asarray(times, dtype=float)
    start, end = (finite_number("window start", window[0]), finite_number("window end", window[1]))
    if not start < end:
        raise ValueError(f"time window must be increasing, got {window!r}")
    selected = np.flatnonzero((times >= start - 1e-12) & (times <= end + 1e-12))
    if selected.size == 0:
        raise ValueError(f"no frame in the time window [{start:.4g}, {end:.4g}] s (frames span "
                         f"{times[0]:.4g} to {times[-1]:.4g} s)")
    return selected


def _checked_inputs(positions, velocities, masses, grid: Grid, particle_density: float):
    if grid.shape[1] != 1:
        raise ValueError(f"a planar field needs one bin across the depth, got {grid.shape[1]}")
    rho = positive_number("particle_density", particle_density)
    return (np.asarray(positions, dtype=float), np.asarray(velocities, dtype=float), np.asarray(masses, dtype=float),
            rho)


def _pooled_field(positions, velocities, masses, times, grid: Grid, selected: np.ndarray, rho: float) -> PlanarField:
    """The field of the frames ``selected``, their clumps pooled into one instant."""
    n_frames = selected.size
    # Pool the clumps of all frames into one instant: the bin mean is then sum(m v) / sum(m) over the window.
    mass, momentum = bin_sums(positions[selected].reshape(1, -1, 3), velocities[selected].reshape(1, -1, 3),
                              np.tile(masses, n_frames), grid)
    shape = (grid.shape[0], grid.shape[2])
    mass = mass[0].reshape(shape)
    velocity = np.divide(momentum[0].reshape(*shape, 3), mass[..., None], out=np.full((*shape, 3), np.nan),
                         where=mass[..., None] > 0.0)
    origin, spacing = np.asarray(grid.origin), np.asarray(grid.spacing)
    x = origin[0] + (np.arange(shape[0]) + 0.5) * spacing[0]
    z = origin[2] + (np.arange(shape[1]) + 0.5) * spacing[2]
    return PlanarField(
        x=x, z=z, v_x=velocity[..., 0], v_z=velocity[..., 2],
        solid_fraction=mass / (n_frames * rho * float(np.prod(spacing))),
        window=(float(times[selected[0]]), float(times[selected[-1]])), n_frames=int(n_frames),
    )


def window_average_field(positions, velocities, masses, times, grid: Grid, window: tuple[float, float],
                         particle_density: float) -> PlanarField:
    """Depth-averaged mass-weighted velocity and solid fraction over the frames of a time window.

    Parameters
    ----------
    positions, velocities : array_like, shape (n_times, n_clumps, 3)
        Clump centres [m] and velocities [m/s]; NaN where a clump is absent.
    masses : array_like, shape (n_clumps,)
        Clump masses [kg].
    times : array_like, shape (n_times,)
        Frame times [s].
    grid : Grid
        Bins with one bin across the depth (``shape[1] == 1``), e.g. :func:`siloflow.analysis.numerics.eulerian_rtd.silo_bins`.
    window : tuple of float
        ``(start, end)`` [s].
    particle_density : float
        Solid density rho_s [kg/m^3].
    """
    positions, velocities, masses, rho = _checked_inputs(positions, velocities, masses, grid, particle_density)
    times = np.asarray(times, dtype=float)
    return _pooled_field(positions, velocities, masses, times, grid, frames_in_window(times, window), rho)


def frame_fields(positions, velocities, masses, times, grid: Grid, window: tuple[float, float],
                 particle_density: float) -> list[PlanarField]:
    """The field of each frame of a time window, as :func:`window_average_field` of that frame alone.

    The series of frames of the steady window gives the per-frame figures whose batch means carry the error of
    the steady ones (:func:`siloflow.analysis.studies.blender.errors.passage_velocity_estimates`).

    Parameters
    ----------
    positions, velocities, masses, times, grid, window, particle_density
        As in :func:`window_average_field`.

    Returns
    -------
    list of PlanarField
        One per frame with ``window[0] <= t <= window[1]``, in time order; each has ``window = (t, t)`` and
        ``n_frames = 1``.
    """
    positions, velocities, masses, rho = _checked_inputs(positions, velocities, masses, grid, particle_density)
    times = np.asarray(times, dtype=float)
    return [_pooled_field(positions, velocities, masses, times, grid, np.array([index]), rho)
            for index in frames_in_window(times, window)]


def wall_layer_depth(equivalent_diameter: float) -> float:
    """The wall layer's depth: :data:`WALL_LAYER_DIAMETERS` volume-equivalent particle diameters [m]."""
    return WALL_LAYER_DIAMETERS * positive_number("equivalent_diameter", equivalent_diameter)


def wall_layer_positions(positions, depth: float) -> np.ndarray:
    """Clump centres with the back half of the depth folded onto the front: ``y -> min(y, T - y)`` [m].

    The front and back walls are alike (one wall material, mirror images through the mid-depth plane), so the layer
    at the back wall is a second sample of what a camera sees at the front; folded, the clumps within ``d`` of either
    wall are those with ``0 <= y < d``, the bins of a grid from the front wall ``d`` deep. x, z and absent clumps
    (NaN) are kept as they are.

    Parameters
    ----------
    positions : array_like, shape (..., 3)
        Clump centres [m], y from the front wall (y = 0) to the back wall (y = T).
    depth : float
        The silo's depth T between the walls [m].

    Returns
    -------
    numpy.ndarray
        The centres with y folded, a new array of the same shape [m].
    """
    folded = np.array(positions, dtype=float)
    if folded.ndim < 1 or folded.shape[-1] != 3:
        raise ValueError(f"positions must have a last axis of 3 (x, y, z), got shape {folded.shape}")
    depth = positive_number("depth", depth)
    folded[..., 1] = np.minimum(folded[..., 1], depth - folded[..., 1])
    return folded


def discharged_mass_history(tracks: ClumpTracks, masses, mode: str, outlet_z: float = 0.0,
                            domain_z: tuple[float, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Discharged mass at every frame since the first one.

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres over the frames [m] (NaN where absent).
    masses : array_like, shape (n_clumps,)
        Clump masses [kg].
    mode : {"batch", "continuous"}
        Batch: mass above the outlet at the first frame minus that at each frame. Continuous: mass of the outlet
        crossings up to each frame (:func:`siloflow.analysis.studies.silo_recirculation.tracks.recirculation_events`, which needs ``domain_z``).
    outlet_z : float
        Height of the outlet plane [m].
    domain_z : tuple of float, optional
        Bottom and top of the periodic domain [m] (continuous mode).

    Returns
    -------
    time, discharged : numpy.ndarray
        Frame times [s] and discharged mass [kg].
    """
    masses = np.asarray(masses, dtype=float)
    if masses.shape != (tracks.n_clumps,):
        raise ValueError(f"masses must have one entry per clump ({tracks.n_clumps}), got shape {masses.shape}")
    if mode == "batch":
        above = np.where(np.isfinite(tracks.position[..., 2]) & (tracks.position[..., 2] > outlet_z), masses, 0.0)
        mass_above = above.sum(axis=1)
        return tracks.times.copy(), mass_above[0] - mass_above
    if mode == "continuous":
        if domain_z is None:
            raise ValueError("continuous mode needs domain_z, the bottom and top of the periodic domain")
        events = recirculation_events(tracks, outlet_z, domain_z[0], domain_z[1])
        # crossing rows are ordered by time
        cumulative = np.concatenate([[0.0], np.cumsum(masses[events.exit_clump_index])])
        counted = np.searchsorted(events.exit_times_all, tracks.times, side="right")
        return tracks.times.copy(), cumulative[counted]
    raise ValueError(f"mode must be 'batch' or 'continuous', got {mode!r}")


def mean_velocity_history(tracks: ClumpTracks, velocity, masses, outlet_z: float = 0.0) -> np.ndarray:
    """Mass-weighted mean vertical velocity of the clumps above the outlet plane at every frame [m/s].

    The bulk velocity of the silo content; at gravity factor f it scales with sqrt(f) where the flow does.

    Parameters
    ----------
    tracks : ClumpTracks
        Clump centres [m] (NaN where absent).
    velocity : array_like, shape (n_t, n_c, 3)
        Clump velocities [m/s].
    masses : array_like, shape (n_c,)
        Clump masses [kg].
    outlet_z : float
        Height of the outlet plane [m].
    """
    velocity = np.asarray(velocity, dtype=float)
    masses = np.asarray(masses, dtype=float)
    if velocity.shape != tracks.position.shape or masses.shape != (tracks.n_clumps,):
        raise ValueError("velocity must have the shape of the tracks' positions and masses one entry per clump")
    z = tracks.position[..., 2]
    inside = np.isfinite(z) & (z > outlet_z) & np.isfinite(velocity[..., 2])
    weight = np.where(inside, masses, 0.0)
    total = weight.sum(axis=1)
    momentum = np.where(inside, weight * velocity[..., 2], 0.0).sum(axis=1)
    return np.divide(momentum, total, out=np.full(total.shape, np.nan), where=total > 0.0)
