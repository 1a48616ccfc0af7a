"""Continuum view of a flat-bottom silo run: coarse-grained fields and the quantities compared with PIV.

Pure computation on clump frames and contact frames (:mod:`analysis.data.frames`, :mod:`analysis.data.contacts`);
writers live in :mod:`analysis.io.fields` and :mod:`analysis.studies.silo_flat.plots`. Coordinates as everywhere in
siloflow: x across the width (0 on the axis), y front to back (0 at the front wall), z up (0 at the outlet).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from analysis.numerics.grid import Fields, Grid
from analysis.numerics.field_ops import average_fields, depth_average
from analysis.numerics.coarse_graining import coarse_grain
from analysis.data.constants import GRAVITY
from analysis.numerics.contact_stress import contact_stress
from analysis.numerics.janssen import janssen_vertical_stress
from analysis.numerics.kinematic import fit_kinematic_constant, kinematic_horizontal_velocity
from analysis.numerics.profiles import flow_channel_boundary, velocity_profile


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
    momentum = depth_averaged.momentum_density[:, 0, :, 2]
    column = np.array([np.interp(height, grid.z, momentum[i, :]) for i in range(grid.shape[0])])
    # Cells tile the width, so the midpoint sum over cell centres integrates over [-W/2, W/2].
    return float(-depth * np.sum(column) * grid.spacing[0])


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
class JanssenComparison:
    """Mean vertical stress against depth below the fill surface, from the contacts and from Janssen.

    Attributes
    ----------
    depth_below_surface : numpy.ndarray
        h (m), one per grid row below the surface.
    simulated : numpy.ndarray
        Cross-section mean of sigma_zz (Pa, compression positive).
    janssen : numpy.ndarray
        Janssen's sigma_v(h) (Pa).
    surface_height : float
        Fill surface height used (m).
    """

    depth_below_surface: np.ndarray
    simulated: np.ndarray
    janssen: np.ndarray
    surface_height: float


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
) -> JanssenComparison:
    """Cross-section mean vertical contact stress per grid row against Janssen's formula.

    Rows within ``margin`` (m) of the floor or of the surface are left out (boundary rows of the kernel);
    ``gravity`` is g (m/s2) of the formula's unit weight rho_b g.
    """
    sigma_zz = stress[..., 2, 2]
    mean = sigma_zz.mean(axis=(0, 1))
    rows = (grid.z > margin) & (grid.z < surface_height - margin)
    h = surface_height - grid.z[rows]
    janssen = janssen_vertical_stress(
        h, bulk_density, width, depth, side_wall_friction, front_wall_friction, internal_friction_angle_deg, gravity
    )
    return JanssenComparison(h, mean[rows], np.asarray(janssen, dtype=float), float(surface_height))


def time_average(fields: Sequence[Fields], times: np.ndarray, window: tuple[float, float]) -> Fields:
    """Mass-weighted average of the fields whose time lies in [t0, t1]."""
    chosen = [f for f, t in zip(fields, times) if window[0] <= t <= window[1]]
    if not chosen:
        raise ValueError(f"no frame in the averaging window {window} s")
    return average_fields(chosen)


def depth_averaged_series(fields: Sequence[Fields]) -> list[Fields]:
    """Depth averages of a series of fields."""
    return [depth_average(f) for f in fields]
