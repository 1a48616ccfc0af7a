"""Silo discharge: bulk density, discharged mass, mass flow rate, Beverloo.

Pure functions on numpy arrays; no file I/O (readers and writers live at the edges).
All quantities are SI: lengths in m, masses in kg, times in s, densities in kg/m3.

Coordinates follow the project convention: x across the silo width (x = 0 on the
axis), y front-to-back depth (0 <= y <= T), z up with z = 0 at the outlet plane
(the silo floor).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import linregress

from siloflow.model.constants import GRAVITY
from siloflow.model.checks import finite_array, non_negative_number, per_particle_values, positive_number
from siloflow.analysis.numerics.uncertainty import Estimate, batch_means

__all__ = [
    "BulkDensity",
    "DischargeHistory",
    "FlowRateFit",
    "beverloo_mass_flow_rate",
    "column_surface_heights",
    "filling_bulk_density",
    "slab_bulk_density",
    "mass_in_silo",
    "discharged_mass_history",
    "steady_flow_rate",
    "volumetric_flow_rate",
]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class BulkDensity:
    """Filling bulk density of the settled fill.

    Attributes
    ----------
    density : float
        Bulk density [kg/m3].
    measured_height : float
        Measurement height z_m above the floor [m]; the control volume is W * T * z_m.
    mass : float
        Mass of the clumps whose centre lies in the control volume [kg].
    volume : float
        Control volume W * T * z_m [m3].
    """

    density: float
    measured_height: float
    mass: float
    volume: float


@dataclass(frozen=True)
class DischargeHistory:
    """Discharged mass against time since the outlet opened.

    Attributes
    ----------
    time : numpy.ndarray
        Time since the outlet opened, ``times - times[0]`` [s].
    discharged_mass : numpy.ndarray
        Mass that has left the silo, ``masses_in_silo[0] - masses_in_silo`` [kg].
    """

    time: np.ndarray
    discharged_mass: np.ndarray


@dataclass(frozen=True)
class FlowRateFit:
    """Ordinary least-squares fit of discharged mass over the steady window.

    Attributes
    ----------
    mass_flow_rate : float
        Fitted slope d(discharged mass)/dt [kg/s].
    standard_error : float
        Standard error of the slope [kg/s].
    t_start, t_end : float
        Steady window used for the fit [s].
    n_points : int
        Number of samples inside the window.
    intercept : float
        Fitted discharged mass at t = 0 [kg]; the fitted line is
        ``intercept + mass_flow_rate * t``.
    """

    mass_flow_rate: float
    standard_error: float
    t_start: float
    t_end: float
    n_points: int
    intercept: float


# --------------------------------------------------------------------------- Beverloo


def beverloo_mass_flow_rate(
    bulk_density: float,
    outlet_width: float,
    outlet_length: float,
    particle_diameter: float,
    discharge_coefficient: float = 0.58,
    shape_coefficient: float = 1.5,
    gravity: float = GRAVITY,
) -> float:
    """Beverloo mass flow rate through a slot outlet.

    ``W = C * rho_b * sqrt(g) * L * (B0 - k d)**1.5``

    Parameters
    ----------
    bulk_density : float
        Bulk density rho_b of the flowing material [kg/m3].
    outlet_width : float
        Slot width B0, across the silo width [m].
    outlet_length : float
        Slot length L, here the full silo depth T [m].
    particle_diameter : float
        Particle (equivalent) diameter d [m].
    discharge_coefficient : float, optional
        Beverloo coefficient C [-] (default 0.58).
    shape_coefficient : float, optional
        Empty-annulus coefficient k [-] (default 1.5).
    gravity : float, optional
        Gravitational acceleration g [m/s2] (default :data:`siloflow.model.constants.GRAVITY`).

    Returns
    -------
    float
        Mass flow rate [kg/s].

    Raises
    ------
    ValueError
        If an argument is not a finite positive number (k may be 0), or if the
        effective outlet width ``B0 - k d`` is not positive.
    """
    bulk_density = positive_number("bulk_density", bulk_density)
    outlet_width = positive_number("outlet_width", outlet_width)
    outlet_length = positive_number("outlet_length", outlet_length)
    particle_diameter = positive_number("particle_diameter", particle_diameter)
    discharge_coefficient = positive_number("discharge_coefficient", discharge_coefficient)
    shape_coefficient = non_negative_number("shape_coefficient", shape_coefficient)
    gravity = positive_number("gravity", gravity)

    effective_width = outlet_width - shape_coefficient * particle_diameter
    if effective_width <= 0.0:
        raise ValueError(
            f"outlet too small for particles: B0 - k d = {effective_width:.6g} m "
            f"(outlet_width B0 = {outlet_width:.6g} m, k = {shape_coefficient:.6g}, d = {particle_diameter:.6g} m)"
        )
    return (
        discharge_coefficient
        * bulk_density
        * math.sqrt(gravity)
        * outlet_length
        * effective_width**1.5
    )


def volumetric_flow_rate(mass_flow_rate: float, bulk_density: float) -> float:
    """Volumetric flow rate of bulk material.

    Parameters
    ----------
    mass_flow_rate : float
        Mass flow rate [kg/s].
    bulk_density : float
        Bulk density [kg/m3].

    Returns
    -------
    float
        Volumetric flow rate ``mass_flow_rate / bulk_density`` [m3/s].
    """
    mass_flow_rate = float(mass_flow_rate)
    if not math.isfinite(mass_flow_rate):
        raise ValueError(f"mass_flow_rate must be finite, got {mass_flow_rate!r}")
    bulk_density = positive_number("bulk_density", bulk_density)
    return mass_flow_rate / bulk_density


# --------------------------------------------------------------------------- fill


def column_surface_heights(x, z, radius, width: float, n_columns: int) -> np.ndarray:
    """Free-surface height of the fill in vertical columns across the width.

    The width ``[-W/2, W/2]`` is split into ``n_columns`` equal columns; each
    particle belongs to the column containing its centre (a centre exactly on
    ``+W/2`` belongs to the last column). Particles whose centre lies outside the
    width are ignored.

    Parameters
    ----------
    x, z : array_like, shape (n,)
        Particle centre coordinates [m].
    radius : float or array_like, shape (n,)
        Particle radius, added to z to get the particle top [m].
    width : float
        Silo width W [m].
    n_columns : int
        Number of columns (>= 1).

    Returns
    -------
    numpy.ndarray, shape (n_columns,)
        Highest particle top ``z + radius`` per column [m]; NaN for an empty column.
    """
    x = finite_array("x", x)
    z = finite_array("z", z)
    if x.shape != z.shape:
        raise ValueError(f"x and z must have the same shape, got {x.shape} and {z.shape}")
    radius = per_particle_values("radius", radius, x.size)
    width = positive_number("width", width)
    if isinstance(n_columns, bool) or int(n_columns) != n_columns or n_columns < 1:
        raise ValueError(f"n_columns must be an integer >= 1, got {n_columns!r}")
    n_columns = int(n_columns)

    half_width = 0.5 * width
    inside = (x >= -half_width) & (x <= half_width)
    column_index = np.floor((x[inside] + half_width) / width * n_columns).astype(np.intp)
    # x == +W/2 would fall into a column past the end.
    column_index = np.minimum(column_index, n_columns - 1)

    heights = np.full(n_columns, -np.inf)
    np.maximum.at(heights, column_index, z[inside] + radius[inside])
    heights[np.isneginf(heights)] = np.nan
    return heights


def filling_bulk_density(
    clump_position,
    clump_mass,
    width: float,
    depth: float,
    surface_margin: float,
    n_columns: int | None = None,
    radius=None,
) -> BulkDensity:
    """Bulk density of the settled fill, excluding the heap on top.

    A centrally filled silo has a heap (a free surface at the angle of repose)
    on top of the fill, so ``total mass / (W T H)`` depends on how H is chosen.
    Instead the density is measured in a control volume that the fill covers
    completely: the box ``[-W/2, W/2] x [0, T] x [0, z_m)`` with

        ``z_m = min(column surface heights) - surface_margin``,

    i.e. a margin below the lowest point of the free surface (found per column
    by :func:`column_surface_heights`, normally at a side wall). The density is
    the mass of the clumps whose centre lies in ``0 <= z < z_m`` divided by
    ``W * T * z_m``. Counting whole clumps by their centre makes an error of at
    most one layer of clumps at ``z = z_m``, which averages out for a random
    packing and vanishes when ``z_m`` falls between layers of a lattice. The margin
    should be at least a particle diameter so that the loose top layer and the
    roughness of the surface are excluded. Wall effects (lower packing density
    next to the walls) are part of the measured bulk density, as in the
    experiment (mass of a known filled volume).

    Parameters
    ----------
    clump_position : array_like, shape (n, 3)
        Clump centre (centre of mass) positions [m].
    clump_mass : float or array_like, shape (n,)
        Clump masses [kg].
    width : float
        Silo width W [m].
    depth : float
        Silo depth T (front to back) [m].
    surface_margin : float
        Distance below the lowest surface height where the control volume ends [m].
    n_columns : int, optional
        Number of columns used to find the lowest surface height. Default: 10.
        Each column must contain particles (a column should be a few particle
        diameters wide).
    radius : float or array_like, shape (n,), optional
        Clump bounding radius added to z for the surface height [m]. Default 0
        (surface through the clump centres; then the margin must cover it).

    Returns
    -------
    BulkDensity
        Density [kg/m3], measured height z_m [m], mass [kg], volume [m3].

    Raises
    ------
    ValueError
        If inputs are malformed, a column is empty (the fill does not cover the
        floor: fewer columns are needed), or ``z_m <= 0`` (margin too large).
    """
    positions = finite_array("clump_position", clump_position, ndim=2)
    if positions.shape[1] != 3 or positions.shape[0] == 0:
        raise ValueError(f"clump_position must have shape (n, 3) with n >= 1, got {positions.shape}")
    n_clumps = positions.shape[0]
    masses = per_particle_values("clump_mass", clump_mass, n_clumps)
    width = positive_number("width", width)
    depth = positive_number("depth", depth)
    surface_margin = non_negative_number("surface_margin", surface_margin)
    if n_columns is None:
        n_columns = 10
    if radius is None:
        radius = 0.0

    heights = column_surface_heights(positions[:, 0], positions[:, 2], radius, width, n_columns)
    if np.any(np.isnan(heights)):
        empty = np.flatnonzero(np.isnan(heights)).tolist()
        raise ValueError(
            f"n_columns = {n_columns}: columns {empty} contain no clumps; the fill does not "
            "cover the floor or the columns are too narrow"
        )
    measured_height = float(np.min(heights)) - surface_margin
    if measured_height <= 0.0:
        raise ValueError(
            f"surface_margin = {surface_margin:.6g} m leaves no control volume: lowest surface "
            f"height {float(np.min(heights)):.6g} m, measurement height {measured_height:.6g} m"
        )

    z = positions[:, 2]
    in_control_volume = (z >= 0.0) & (z < measured_height)
    mass = float(np.sum(masses[in_control_volume]))
    volume = width * depth * measured_height
    return BulkDensity(
        density=mass / volume, measured_height=measured_height, mass=mass, volume=volume
    )


def slab_bulk_density(clump_z, clump_mass, area: float, measured_height: float, slab_thickness: float) -> Estimate:
    """Bulk density of the fill below a height and its standard error from the spread over horizontal slabs.

    The layer ``0 <= z < z_m`` (the control volume of :func:`filling_bulk_density`) is cut into
    ``K = floor(z_m / slab_thickness)`` horizontal slabs of equal thickness ``z_m / K``; each slab's density is
    the mass of the clumps whose centre lies in it over ``area * z_m / K``. Their mean is the density of the
    whole layer (equal thicknesses), and its standard error is ``std(slab densities, ddof=1) / sqrt(K)``
    (:func:`siloflow.analysis.numerics.uncertainty.batch_means` with one slab per batch).

    Why slabs: the density of one settled fill is uncertain through the packing's local fluctuations (and the
    centre counting at the cut ``z = z_m``), not through its volume, which is exact once ``z_m`` is chosen
    below the surface; the free surface's roughness does not enter this estimator at all. Slabs a few particle
    diameters thick hold nearly independent samples of the packing, since its density correlations decay
    within a few diameters. A systematic change of density with height (compaction under the fill's own
    weight, the ordered layers on the floor) adds to the spread, so the error is then conservative: it says
    how well the one number describes the whole fill.

    Parameters
    ----------
    clump_z : array_like, shape (n,)
        Clump centre heights [m] (clumps outside ``[0, z_m)`` are ignored).
    clump_mass : float or array_like, shape (n,)
        Clump masses [kg].
    area : float
        Horizontal cross-section W * T of the fill [m2], > 0.
    measured_height : float
        Top of the layer ``z_m`` [m], > 0.
    slab_thickness : float
        Smallest slab thickness [m], > 0 (a few particle diameters).

    Returns
    -------
    Estimate
        Density and its standard error [kg/m3]; ``method="slab spread"``, ``n = K``, ``dof = K - 1``. A layer
        thinner than two slabs gives one slab and a NaN (unknown) error.

    Raises
    ------
    ValueError
        On malformed input.
    """
    z = finite_array("clump_z", clump_z)
    masses = per_particle_values("clump_mass", clump_mass, z.size)
    area = positive_number("area", area)
    measured_height = positive_number("measured_height", measured_height)
    slab_thickness = positive_number("slab_thickness", slab_thickness)
    n_slabs = max(1, int(math.floor(measured_height / slab_thickness)))
    edges = np.linspace(0.0, measured_height, n_slabs + 1)
    inside = (z >= 0.0) & (z < measured_height)
    # searchsorted on the interior edges: a centre exactly on an edge belongs to the slab above it
    slab = np.searchsorted(edges[1:-1], z[inside], side="right")
    densities = np.bincount(slab, weights=masses[inside], minlength=n_slabs) / (area * measured_height / n_slabs)
    if n_slabs < 2:
        return Estimate(value=float(densities[0]), std_error=math.nan, n=1, method="slab spread")
    spread = batch_means(densities, n_batches=n_slabs)
    return Estimate(value=spread.value, std_error=spread.std_error, n=n_slabs, method="slab spread",
                    dof=n_slabs - 1)


# --------------------------------------------------------------------------- discharge


def mass_in_silo(clump_z, clump_mass, outlet_plane: float = 0.0) -> float:
    """Mass of the clumps still in the silo.

    Parameters
    ----------
    clump_z : array_like, shape (n,)
        Clump centre heights [m].
    clump_mass : float or array_like, shape (n,)
        Clump masses [kg].
    outlet_plane : float, optional
        Height of the outlet plane [m] (default 0, the silo floor).

    Returns
    -------
    float
        Total mass of the clumps with centre at or above the outlet plane [kg].
    """
    clump_z = finite_array("clump_z", clump_z)
    masses = per_particle_values("clump_mass", clump_mass, clump_z.size)
    outlet_plane = float(outlet_plane)
    if not math.isfinite(outlet_plane):
        raise ValueError(f"outlet_plane must be finite, got {outlet_plane!r}")
    return float(np.sum(masses[clump_z >= outlet_plane]))


def discharged_mass_history(times, masses_in_silo) -> DischargeHistory:
    """Discharged mass against time since the outlet opened.

    Parameters
    ----------
    times : array_like, shape (n,)
        Simulation times of the frames, strictly increasing; ``times[0]`` is the
        moment the outlet opened [s].
    masses_in_silo : array_like, shape (n,)
        Mass in the silo at each time, e.g. from :func:`mass_in_silo` [kg].

    Returns
    -------
    DischargeHistory
        ``time = times - times[0]`` [s], ``discharged_mass = masses_in_silo[0] - masses_in_silo`` [kg].
    """
    times = finite_array("times", times)
    masses = finite_array("masses_in_silo", masses_in_silo)
    if times.size == 0:
        raise ValueError("times must contain at least one sample")
    if times.shape != masses.shape:
        raise ValueError(
            f"times and masses_in_silo must have equal lengths, got {times.size} and {masses.size}"
        )
    if np.any(np.diff(times) <= 0.0):
        raise ValueError("times must be strictly increasing")
    return DischargeHistory(time=times - times[0], discharged_mass=masses[0] - masses)


def steady_flow_rate(
    time,
    discharged_mass,
    window: tuple[float, float] | None = None,
    fraction_window: tuple[float, float] = (0.2, 0.8),
) -> FlowRateFit:
    """Steady mass flow rate: least-squares slope of discharged mass over time (:func:`scipy.stats.linregress`).

    Batch discharge has a start-up transient (the flow accelerates after the
    outlet opens) and an end phase (when the free surface reaches the outlet
    the rate drops). Between them the rate of a silo is nearly constant
    (independent of fill height, which is what Beverloo describes), so the
    slope is fitted only over a steady window:

    * ``window=(t0, t1)``: the samples with ``t0 <= t <= t1``;
    * otherwise an automatic window, from the first time the discharged mass
      reaches ``fraction_window[0]`` of its final value to the first time it
      reaches ``fraction_window[1]`` of it. Using fractions of the discharged mass
      (not of the time) places the window inside the steady phase whatever the
      duration of the run.

    Parameters
    ----------
    time : array_like, shape (n,)
        Time since the outlet opened, strictly increasing [s].
    discharged_mass : array_like, shape (n,)
        Discharged mass [kg].
    window : tuple of float, optional
        Explicit fit window ``(t0, t1)`` [s].
    fraction_window : tuple of float, optional
        Fractions of the final discharged mass bounding the automatic window,
        ``0 <= f0 < f1 <= 1`` (default ``(0.2, 0.8)``).

    Returns
    -------
    FlowRateFit
        Slope [kg/s], its standard error [kg/s], the window [s], the number of
        samples, and the intercept [kg].

    Raises
    ------
    ValueError
        On malformed input, or if fewer than 3 samples lie in the window (the
        standard error needs n - 2 >= 1 degrees of freedom).
    """
    time = finite_array("time", time)
    mass = finite_array("discharged_mass", discharged_mass)
    if time.shape != mass.shape:
        raise ValueError(
            f"time and discharged_mass must have equal lengths, got {time.size} and {mass.size}"
        )
    if time.size == 0:
        raise ValueError("time must contain at least one sample")
    if np.any(np.diff(time) <= 0.0):
        raise ValueError("time must be strictly increasing")

    if window is not None:
        if len(window) != 2:
            raise ValueError(f"window must be (t0, t1), got {window!r}")
        t_start, t_end = float(window[0]), float(window[1])
        if not (math.isfinite(t_start) and math.isfinite(t_end)) or t_end <= t_start:
            raise ValueError(f"window must be finite with t0 < t1, got {window!r}")
        window_description = f"window = ({t_start:.6g}, {t_end:.6g}) s"
    else:
        if len(fraction_window) != 2:
            raise ValueError(f"fraction_window must be (f0, f1), got {fraction_window!r}")
        f_low, f_high = float(fraction_window[0]), float(fraction_window[1])
        if not (0.0 <= f_low < f_high <= 1.0):
            raise ValueError(f"fraction_window must satisfy 0 <= f0 < f1 <= 1, got {fraction_window!r}")
        final_mass = float(mass[-1])
        if final_mass <= 0.0:
            raise ValueError(
                f"fraction_window: final discharged mass is {final_mass:.6g} kg; nothing was discharged"
            )
        # argmax on a boolean array gives the first True; the final sample always qualifies.
        t_start = float(time[np.argmax(mass >= f_low * final_mass)])
        t_end = float(time[np.argmax(mass >= f_high * final_mass)])
        window_description = (
            f"fraction_window = ({f_low:.6g}, {f_high:.6g}) -> window ({t_start:.6g}, {t_end:.6g}) s"
        )

    in_window = (time >= t_start) & (time <= t_end)
    n_points = int(np.count_nonzero(in_window))
    if n_points < 3:
        raise ValueError(f"{window_description} holds {n_points} samples; at least 3 are needed")

    t_fit, m_fit = time[in_window], mass[in_window]
    fit = linregress(t_fit, m_fit)
    # linregress derives the slope's standard error from r, and 1 - r^2 cancels: on an exactly constant
    # discharge it returns ~5e-11 kg/s instead of 0 (tests/unit/test_silo_metrics.py). The residual form is
    # exact there and equal to linregress's to round-off on noisy data.
    residuals = m_fit - (fit.intercept + fit.slope * t_fit)
    centred = t_fit - t_fit.mean()
    standard_error = math.sqrt(float(np.dot(residuals, residuals)) / (n_points - 2) / float(np.dot(centred, centred)))
    return FlowRateFit(
        mass_flow_rate=float(fit.slope),
        standard_error=standard_error,
        t_start=t_start,
        t_end=t_end,
        n_points=n_points,
        intercept=float(fit.intercept),
    )
