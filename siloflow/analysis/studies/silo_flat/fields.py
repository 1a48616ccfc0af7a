"""Continuum view of a flat-bottom silo run: coarse-grained fields and the quantities compared with PIV.

Pure computation on clump frames and contact frames (:mod:`siloflow.model.frames`, :mod:`siloflow.model.contacts`);
writers live in :mod:`siloflow.analysis.io.fields` and :mod:`siloflow.analysis.studies.silo_flat.plots`. Coordinates as everywhere in
siloflow: x across the width (0 on the axis), y front to back (0 at the front wall), z up (0 at the outlet).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from siloflow.analysis.numerics.grid import Fields, Grid
from siloflow.analysis.numerics.field_ops import average_fields, depth_average
from siloflow.analysis.numerics.coarse_graining import coarse_grain, kernel_support_radius
from siloflow.model.constants import GRAVITY
from siloflow.analysis.numerics.contact_stress import contact_stress
from siloflow.analysis.numerics.janssen import janssen_vertical_stress
from siloflow.analysis.numerics.kinematic import fit_kinematic_constant, kinematic_horizontal_velocity
from siloflow.analysis.numerics.profiles import flow_channel_boundary, velocity_profile
from siloflow.analysis.numerics.uncertainty import batch_count, batch_means, combine_independent


@dataclass(frozen=True)
class FieldSettings:
    """How particles become fields.

    Attributes
    ----------
    spacing : tuple of float
        Grid spacing (dx, dy, dz) (m); stretched slightly when the silo is not a whole number of cells.
    kernel : str
        ``gaussian``, ``gaussian_shifted`` or ``lucy``.
    width : float
        Kernel width (standard deviation) (m).
    cutoff : float
        Gaussian cut-off in widths (-).
    """

    spacing: tuple[float, float, float]
    kernel: str
    width: float
    cutoff: float


def silo_grid(width: float, depth: float, top: float, spacing: Sequence[float]) -> Grid:
    """A grid whose cells tile the silo interior [-W/2, W/2] x [0, T] x [0, top].

    ``top`` is rounded up to whole cells of the requested dz; x and y spacings are stretched to the nearest
    whole number of cells when W or T is not a multiple (at most half a cell over the whole width).
    """
    dz = float(spacing[2])
    top = math.ceil(top / dz - 1e-9) * dz
    return Grid.covering((-0.5 * width, 0.0, 0.0), (0.5 * width, depth, top), tuple(spacing), adjust_spacing=True)


def clump_fields(frame, grid: Grid, settings: FieldSettings) -> Fields:
    """Coarse-grained density, velocity and kinetic stress of the clumps inside the silo (z >= 0)."""
    inside = frame.position[:, 2] >= 0.0
    return coarse_grain(
        frame.position[inside],
        frame.mass[inside],
        frame.velocity[inside],
        grid,
        settings.width,
        cutoff=settings.cutoff,
        kernel=settings.kernel,
    )


def contact_stress_field(contacts, grid: Grid, settings: FieldSettings) -> np.ndarray:
    """Contact stress tensor (Pa, compression positive) on the grid from one contact frame."""
    return contact_stress(
        grid,
        contacts.position_i,
        contacts.position_j,
        contacts.force,
        settings.width,
        cutoff=settings.cutoff,
        kernel=settings.kernel,
    )


def _rows(fields: Fields) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """x, z and the depth-averaged v_x, v_z (nx, nz) of one-layer fields."""
    grid = fields.grid
    return grid.x, grid.z, fields.velocity[:, 0, :, 0], fields.velocity[:, 0, :, 2]


def centreline_velocity(depth_averaged: Sequence[Fields], heights: Sequence[float]) -> np.ndarray:
    """v_z on the axis (x = 0) at given heights for a series of depth-averaged fields, shape (frames, heights)."""
    series = np.empty((len(depth_averaged), len(heights)))
    for i, fields in enumerate(depth_averaged):
        for j, height in enumerate(heights):
            profile = velocity_profile(fields, height)
            series[i, j] = np.interp(0.0, profile.x, profile.v_z)
    return series


def profile_mass_flow_rate(depth_averaged: Fields, height: float, depth: float) -> float:
    """Downward mass flow rate through a horizontal section (kg/s): T * integral of rho v_z dx, sign flipped.

    Uses the coarse-grained momentum density (rho v_z) rather than a fixed bulk density, so dilation of the
    flowing zone is accounted for.
    """
    grid = depth_averaged.grid
    column = _row_at_height(grid, depth_averaged.momentum_density[:, 0, :, 2], height)
    # Cells tile the width, so the midpoint sum over cell centres integrates over [-W/2, W/2].
    return float(-depth * np.sum(column) * grid.spacing[0])


def _row_at_height(grid: Grid, values: np.ndarray, height: float) -> np.ndarray:
    """(nx,) values of an (nx, nz) array of one-layer fields at ``height`` (m), linear in z per column."""
    return np.array([np.interp(height, grid.z, values[i, :]) for i in range(grid.shape[0])])


@dataclass(frozen=True)
class ProfileAnalysis:
    """Velocity profiles, flow channel boundaries and kinematic constants at the chosen heights.

    Attributes
    ----------
    heights : numpy.ndarray
        Heights above the outlet (m).
    x : numpy.ndarray
        Node x positions (m).
    v_z, v_x : numpy.ndarray
        (heights, nx) velocities (m/s).
    fcb_fractions : tuple of float
        Fractions of the centreline velocity.
    fcb_left, fcb_right : numpy.ndarray
        (heights, fractions) boundary positions (m); NaN where v_z never falls that low.
    kinematic_B : numpy.ndarray
        (heights,) kinematic constant B (m), kernel-corrected; NaN where the fit failed.
    kinematic_u : numpy.ndarray
        (heights, nx) u = -B dv_z/dx (m/s).
    """

    heights: np.ndarray
    x: np.ndarray
    v_z: np.ndarray
    v_x: np.ndarray
    fcb_fractions: tuple[float, ...]
    fcb_left: np.ndarray
    fcb_right: np.ndarray
    kinematic_B: np.ndarray
    kinematic_u: np.ndarray

    @property
    def flow_pattern_index(self) -> np.ndarray:
        """(heights,) wall velocity over centreline velocity (-): the mean v_z of the two nodes nearest the side
        walls over v_z on the axis. 1 in plug (mass) flow, 0 where the material at the walls stands still (funnel
        flow); NaN where the axis does not move."""
        centre = np.array([np.interp(0.0, self.x, row) for row in self.v_z])
        wall = 0.5 * (self.v_z[:, 0] + self.v_z[:, -1])
        moving = centre != 0.0
        return np.divide(wall, centre, out=np.full(centre.shape, np.nan), where=moving)


def analyse_profiles(
    depth_averaged: Fields,
    heights: Sequence[float],
    fractions: Sequence[float] = (0.01, 0.05, 0.10),
    subtract_wall_velocity: bool = False,
    kernel_width: float = 0.0,
) -> ProfileAnalysis:
    """Profiles, flow channel boundary and kinematic constant B at each height of time-averaged fields."""
    heights = np.asarray(heights, dtype=float)
    profiles = [velocity_profile(depth_averaged, float(z)) for z in heights]
    x = profiles[0].x
    v_z = np.array([p.v_z for p in profiles])
    v_x = np.array([p.v_x for p in profiles])
    left = np.full((heights.size, len(fractions)), np.nan)
    right = np.full_like(left, np.nan)
    b_values = np.full(heights.size, np.nan)
    u = np.zeros_like(v_z)
    for i, z in enumerate(heights):
        try:
            boundary = flow_channel_boundary(x, v_z[i], tuple(fractions), subtract_wall_velocity)
            left[i], right[i] = boundary.left, boundary.right
        except ValueError:
            pass  # no flow at this height: boundaries stay NaN
        try:
            fit = fit_kinematic_constant(x, v_z[i], float(z), kernel_width=kernel_width)
            b_values[i] = fit.B
            u[i] = kinematic_horizontal_velocity(x, v_z[i], fit.B)
        except (ValueError, RuntimeError):
            pass  # profile not Gaussian-like (e.g. plug flow near the top): B stays NaN
    return ProfileAnalysis(heights, x, v_z, v_x, tuple(fractions), left, right, b_values, u)


@dataclass(frozen=True)
class ProfileUncertainty:
    """Standard errors of the kinematic constant and of the flow channel boundary (:func:`profile_uncertainty`).

    Attributes
    ----------
    kinematic_B_error : numpy.ndarray
        (heights,) standard error of B (m); NaN where fewer than two batches give a B.
    fcb_left_error, fcb_right_error : numpy.ndarray
        (heights, fractions) standard error of the boundary positions (m); NaN where fewer than two batches
        locate the boundary.
    batches : numpy.ndarray
        (heights,) time windows whose fill covers each height (-); the errors rest on those of them that give a
        value (a fit or a boundary).
    n_batches : int
        Time windows the averaging window was cut into (-); 0 when it holds fewer than two frames.
    boundary_resolution : float
        Standard deviation of the position of a boundary inside one grid cell, ``dx / sqrt(12)`` (m).
    flow_pattern_index_error : numpy.ndarray or None
        (heights,) standard error of :attr:`ProfileAnalysis.flow_pattern_index` (-); None when not estimated.
    """

    kinematic_B_error: np.ndarray
    fcb_left_error: np.ndarray
    fcb_right_error: np.ndarray
    batches: np.ndarray
    n_batches: int
    boundary_resolution: float
    flow_pattern_index_error: np.ndarray | None = None


def _axis_density(fields: Fields, height: float) -> float:
    """Density (kg/m3) of one-layer fields on the axis x = 0 at ``height`` (m), linear in z then in x."""
    grid = fields.grid
    return float(np.interp(0.0, grid.x, _row_at_height(grid, fields.density[:, 0, :], height)))


def _standard_error(values: np.ndarray) -> float:
    """Standard error of the mean of independent values, NaN for fewer than two."""
    if values.size < 2:
        return math.nan
    return batch_means(values, n_batches=values.size).std_error


def profile_uncertainty(
    depth_series: Sequence[Fields],
    times: np.ndarray,
    window: tuple[float, float],
    heights: Sequence[float],
    fractions: Sequence[float],
    covered_density: float,
    n_batches: int = 10,
    subtract_wall_velocity: bool = False,
    kernel_width: float = 0.0,
) -> ProfileUncertainty:
    """Errors of B(z), of the flow channel boundary and of the flow-pattern index from batch means over time windows.

    The frames inside ``window`` are cut into ``K = min(n_batches, frames)`` contiguous batches of
    ``b = frames // K`` frames (the oldest ``frames % K`` frames left out, as in
    :func:`siloflow.analysis.numerics.uncertainty.batch_means`). Each batch is averaged like the whole window and
    analysed with :func:`analyse_profiles`, giving one B and one boundary per height (and fraction). The error
    is ``std(batch values, ddof=1) / sqrt(n)`` over the ``n`` batches that have a value at that height and whose
    fill covers it: in every frame of the batch the density on the axis at that height is at least
    ``covered_density``. A batch discharge empties the upper heights during the window; a batch in which the
    free surface passes a height has a profile of a different flow there (its fit can diverge), so it is left
    out rather than counted as scatter. The spread of the remaining batches still holds any slow drift of the
    flow, which makes the error conservative.

    The boundary's error adds, in quadrature, ``dx / sqrt(12)``: the standard deviation of a position known only
    to lie in one grid cell of width ``dx`` (the velocity between nodes is interpolated, not resolved).

    Parameters
    ----------
    depth_series : sequence of Fields
        Depth average of each frame (one layer of nodes), on one grid.
    times : numpy.ndarray
        Time of each frame (s).
    window : tuple of float
        The averaging window ``(t0, t1)`` (s).
    heights, fractions, subtract_wall_velocity, kernel_width
        As for :func:`analyse_profiles` (m, -, bool, m).
    covered_density : float
        Density on the axis below which a height counts as above the free surface (kg/m3), > 0.
    n_batches : int, optional
        Time windows wanted, >= 2.

    Returns
    -------
    ProfileUncertainty
        All errors NaN (and ``n_batches = 0``) when the window holds fewer than two frames.
    """
    if covered_density <= 0.0 or not math.isfinite(covered_density):
        raise ValueError(f"covered_density must be a finite number > 0, got {covered_density!r}")
    n_batches = batch_count(n_batches)
    heights = np.asarray(heights, dtype=float)
    fractions = tuple(fractions)
    resolution = depth_series[0].grid.spacing[0] / math.sqrt(12.0)
    b_error = np.full(heights.size, np.nan)
    left_error = np.full((heights.size, len(fractions)), np.nan)
    right_error = np.full_like(left_error, np.nan)
    chosen = _in_window(depth_series, times, window)
    count = min(n_batches, len(chosen))
    index_error = np.full(heights.size, np.nan)
    if count < 2:
        return ProfileUncertainty(b_error, left_error, right_error, np.zeros(heights.size, dtype=int), 0,
                                  resolution, index_error)
    b_values = np.full((count, heights.size), np.nan)
    index = np.full((count, heights.size), np.nan)
    left = np.full((count, heights.size, len(fractions)), np.nan)
    right = np.full_like(left, np.nan)
    covered = np.zeros((count, heights.size), dtype=bool)
    size = len(chosen) // count
    chosen = chosen[len(chosen) - size * count:]  # the oldest frames left out, as in batch_means
    for k in range(count):
        batch = chosen[k * size:(k + 1) * size]
        analysis = analyse_profiles(average_fields(batch), heights, fractions, subtract_wall_velocity, kernel_width)
        b_values[k], left[k], right[k] = analysis.kinematic_B, analysis.fcb_left, analysis.fcb_right
        index[k] = analysis.flow_pattern_index
        covered[k] = [all(_axis_density(f, float(z)) >= covered_density for f in batch) for z in heights]
    for i in range(heights.size):
        use = covered[:, i]
        b_error[i] = _standard_error(b_values[use & np.isfinite(b_values[:, i]), i])
        index_error[i] = _standard_error(index[use & np.isfinite(index[:, i]), i])
        for j in range(len(fractions)):
            for values, errors in ((left, left_error), (right, right_error)):
                spread = _standard_error(values[use & np.isfinite(values[:, i, j]), i, j])
                errors[i, j] = combine_independent([spread, resolution])
    return ProfileUncertainty(b_error, left_error, right_error, covered.sum(axis=0).astype(int), count, resolution,
                              index_error)


@dataclass(frozen=True)
class JanssenComparison:
    """Mean vertical stress against depth below the fill surface: from the contacts, Janssen and hydrostatic.

    Attributes
    ----------
    depth_below_surface : numpy.ndarray
        h (m), one per grid row below the surface.
    simulated : numpy.ndarray
        Cross-section mean of sigma_zz (Pa, compression positive).
    janssen : numpy.ndarray
        Janssen's sigma_v(h) (Pa).
    surface_height : float
        Fill surface height used, H (m).
    height : numpy.ndarray
        Height of each row above the floor, ``z = H - h`` (m).
    simulated_error : numpy.ndarray
        Standard error of ``simulated`` from the differences of mirror bins across the axis (Pa); NaN when
        unknown.
    hydrostatic : numpy.ndarray
        ``rho_b g h`` (Pa): the stress without any wall support.
    hydrostatic_error : numpy.ndarray
        ``g h`` times the error of rho_b (Pa); NaN when that is unknown.
    bin_pairs : int
        Mirror pairs of horizontal bins behind ``simulated_error`` (-); 0 when there is none.
    """

    depth_below_surface: np.ndarray
    simulated: np.ndarray
    janssen: np.ndarray
    surface_height: float
    height: np.ndarray
    simulated_error: np.ndarray
    hydrostatic: np.ndarray
    hydrostatic_error: np.ndarray
    bin_pairs: int


def mirror_bin_error(values, pairs: int) -> float:
    """Standard error of the mean of a profile across a symmetric silo from the differences of mirror bins.

    The stress across a symmetric, centrally filled silo has a systematic shape (high on the axis, low at the
    walls that carry part of the weight) that is not noise, so the plain spread of bin means would overstate
    the error of their mean. Mirror bins, at equal distances left and right of the axis, have the same expected
    value, so their difference is noise alone. Each half of the ``n`` values (the first and the last ``n // 2``,
    the middle one of an odd ``n`` left out) is cut into ``M = pairs`` contiguous bins of nearly equal size
    (:func:`numpy.array_split`, counted from the walls); with ``d_m`` the difference of the left and right means
    of pair ``m``, each bin's noise variance is estimated as ``sum(d_m^2) / (2 M)`` and the error of the mean
    of the ``2 M`` bins is ``sqrt(sum(d_m^2)) / (2 M)`` (``M`` degrees of freedom).

    Parameters
    ----------
    values : array_like, shape (n,)
        The profile at nodes placed symmetrically about the axis, ordered in x, in any unit.
    pairs : int
        Bins per half, ``M`` (-).

    Returns
    -------
    float
        The error, in the unit of ``values``; NaN for ``M < 1`` or more bins than values per half.
    """
    values = np.asarray(values, dtype=float)
    half = values.size // 2
    if pairs < 1 or pairs > half:
        return math.nan
    left = [part.mean() for part in np.array_split(values[:half], pairs)]
    right = [part.mean() for part in np.array_split(values[::-1][:half], pairs)]  # from the right wall inwards
    differences = np.subtract(left, right)
    return float(math.sqrt(float(np.dot(differences, differences))) / (2 * pairs))


def compare_janssen(
    stress: np.ndarray,
    grid: Grid,
    surface_height: float,
    bulk_density: float,
    width: float,
    depth: float,
    side_wall_friction: float,
    front_wall_friction: float,
    internal_friction_angle_deg: float,
    margin: float = 0.0,
    gravity: float = GRAVITY,
    bin_width: float | None = None,
    bulk_density_error: float = math.nan,
) -> JanssenComparison:
    """Cross-section mean vertical contact stress per grid row against Janssen's formula and hydrostatic.

    Rows within ``margin`` (m) of the floor or of the surface are left out (boundary rows of the kernel), and a fill
    that leaves no row is refused (ValueError naming both heights);
    ``gravity`` is g (m/s2) of the unit weight rho_b g of Janssen's formula and of the hydrostatic stress
    ``rho_b g h``.

    The DEM stress comes from one contact frame (the settled fill), so its error cannot come from frames: it
    comes from horizontal bins. The depth-averaged sigma_zz of the x columns of each row is cut, on each side of
    the axis, into ``M = floor((nx // 2) dx / bin_width)`` bins and the error is that of
    :func:`mirror_bin_error`: the differences of mirror bins, which the symmetric shape of the stress profile
    does not enter. Bins at least as wide as the kernel's support (``2 cutoff w``) share few contacts, so their
    noises are nearly independent. ``bin_width`` None, or bins wider than half the silo, give NaN errors.

    ``bulk_density_error`` (kg/m3) gives the hydrostatic stress's error ``g h`` times it; Janssen's curve is left
    without one, since its friction angles' uncertainty, not rho_b's, would dominate it.
    """
    sigma_zz = stress[..., 2, 2]
    mean = sigma_zz.mean(axis=(0, 1))
    rows = (grid.z > margin) & (grid.z < surface_height - margin)
    if not rows.any():
        raise ValueError(
            f"no grid row lies more than the kernel's reach ({margin:.4g} m) above the floor and below the settled "
            f"surface ({surface_height:.4g} m): the fill is too shallow for the Janssen comparison; fill above "
            f"{2.0 * margin:.4g} m, or narrow the kernel (silo_flat.fields.width_radii)")
    h = surface_height - grid.z[rows]
    janssen = janssen_vertical_stress(
        h, bulk_density, width, depth, side_wall_friction, front_wall_friction, internal_friction_angle_deg, gravity
    )
    pairs = 0
    if bin_width is not None:
        half = grid.shape[0] // 2
        pairs = min(half, int(math.floor(half * grid.spacing[0] / float(bin_width))))
    columns = sigma_zz.mean(axis=1)[:, rows]  # (nx, rows): depth average of each x column
    error = np.array([mirror_bin_error(columns[:, k], pairs) for k in range(columns.shape[1])])
    hydrostatic = bulk_density * gravity * h
    return JanssenComparison(
        depth_below_surface=h, simulated=mean[rows], janssen=np.asarray(janssen, dtype=float),
        surface_height=float(surface_height), height=grid.z[rows].copy(), simulated_error=error,
        hydrostatic=hydrostatic, hydrostatic_error=gravity * h * float(bulk_density_error),
        bin_pairs=max(pairs, 0),
    )


def janssen_from_contacts(
    contacts,
    grid: Grid,
    settings: FieldSettings,
    surface_height: float,
    bulk_density: float,
    width: float,
    depth: float,
    internal_friction_angle_deg: float,
    side_wall_friction_angle_deg: float,
    front_wall_friction_angle_deg: float,
    bulk_density_error: float = math.nan,
) -> tuple[np.ndarray, JanssenComparison]:
    """The contact stress of a settled fill on the grid and its comparison with Janssen's formula.

    The stress is :func:`contact_stress_field`; the comparison :func:`compare_janssen` with the rows within the
    kernel's reach (``cutoff`` widths) of the floor and of the surface left out and the error from mirror bins as
    wide as the kernel's support, so that neighbouring bins share few contacts.

    Parameters
    ----------
    contacts : siloflow.model.contacts.ContactFrame
        Pair contacts of the settled fill (positions in m, forces in N).
    grid : Grid
        Grid of the fields, tiling the silo.
    settings : FieldSettings
        The kernel: its width (m), cut-off (-) and kind.
    surface_height : float
        Fill surface height H the depths are measured from (m); the study takes the lowest point of the surface.
    bulk_density : float
        Bulk density rho_b of the fill (kg/m3).
    width, depth : float
        Silo width W and depth T (m).
    internal_friction_angle_deg, side_wall_friction_angle_deg, front_wall_friction_angle_deg : float
        Bulk friction angles of Janssen's formula (degrees): internal, side walls, front and back walls.
    bulk_density_error : float, optional
        Standard error of ``bulk_density`` (kg/m3), for the hydrostatic stress's error; NaN (default): unknown.

    Returns
    -------
    stress : numpy.ndarray, shape grid.shape + (3, 3)
        Contact stress (Pa, compression positive).
    comparison : JanssenComparison
    """
    stress = contact_stress_field(contacts, grid, settings)
    comparison = compare_janssen(
        stress, grid, surface_height, bulk_density, width, depth,
        math.tan(math.radians(side_wall_friction_angle_deg)), math.tan(math.radians(front_wall_friction_angle_deg)),
        internal_friction_angle_deg, margin=settings.cutoff * settings.width,
        bin_width=2.0 * kernel_support_radius(settings.width, settings.cutoff, settings.kernel),
        bulk_density_error=bulk_density_error)
    return stress, comparison


#: Frame times within this of a window's end count as at it (s): a frame's time since the opening is the difference
#: of two simulated times, off by round-off, and a configured window (the study's 0.5-0.7 s) ends on frame times.
WINDOW_SLACK = 1e-9


def _in_window(fields: Sequence[Fields], times: np.ndarray, window: tuple[float, float]) -> list[Fields]:
    """The fields whose time lies in [t0, t1] (to :data:`WINDOW_SLACK`), in order."""
    return [f for f, t in zip(fields, times) if window[0] - WINDOW_SLACK <= t <= window[1] + WINDOW_SLACK]


def time_average(fields: Sequence[Fields], times: np.ndarray, window: tuple[float, float]) -> Fields:
    """Mass-weighted average of the fields whose time lies in [t0, t1]."""
    chosen = _in_window(fields, times, window)
    if not chosen:
        raise ValueError(f"no frame in the averaging window {window} s")
    return average_fields(chosen)


def depth_averaged_series(fields: Sequence[Fields]) -> list[Fields]:
    """Depth averages of a series of fields."""
    return [depth_average(f) for f in fields]
