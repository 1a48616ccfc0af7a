"""Velocity profiles across the silo: profiles at a height, flow channel boundary, flow rate, comparison.

Pure functions on numpy arrays and :class:`siloflow.analysis.numerics.grid.Fields`; no file I/O. All
quantities are SI: lengths in m, velocities in m/s, densities in kg/m3. The kinematic model fitted to
the profiles is :mod:`siloflow.analysis.numerics.kinematic`, Janssen's stress :mod:`siloflow.analysis.numerics.janssen`.

Coordinates follow the project convention: x across the silo width (x = 0 on the axis),
y front-to-back depth (y = 0 the front wall), z up with z = 0 at the outlet plane. A
vertical velocity ``v_z`` is signed: negative for downward flow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import trapezoid

from siloflow.model.checks import finite_array, positive_number
from siloflow.analysis.numerics.grid import Fields

__all__ = [
    "VelocityProfile",
    "FlowChannelBoundary",
    "ProfileErrors",
    "checked_profile",
    "velocity_profile",
    "flow_channel_boundary",
    "profile_flow_rate",
    "profile_errors",
]


# --------------------------------------------------------------------------- validation


def checked_profile(x, v, v_name: str = "v_z", min_points: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """A profile ``v(x)`` as float arrays: finite, of equal shape, ``x`` strictly increasing, enough points."""
    x = finite_array("x", x)
    v = finite_array(v_name, v)
    if x.shape != v.shape:
        raise ValueError(f"x and {v_name} must have the same shape, got {x.shape} and {v.shape}")
    if x.size < min_points:
        raise ValueError(f"x must have at least {min_points} points, got {x.size}")
    if np.any(np.diff(x) <= 0.0):
        raise ValueError("x must be strictly increasing")
    return x, v


# --------------------------------------------------------------------------- results


@dataclass(frozen=True, eq=False)
class VelocityProfile:
    """Horizontal profiles of the velocity at one height.

    Attributes
    ----------
    z : float
        Height of the profile above the outlet plane [m].
    x : numpy.ndarray, shape (nx,)
        Node x coordinates [m].
    v_x : numpy.ndarray, shape (nx,)
        Horizontal velocity across the width [m/s].
    v_z : numpy.ndarray, shape (nx,)
        Vertical velocity [m/s] (negative downward).
    """

    z: float
    x: np.ndarray
    v_x: np.ndarray
    v_z: np.ndarray


@dataclass(frozen=True, eq=False)
class FlowChannelBoundary:
    """Where the vertical velocity falls to given fractions of its centreline value.

    Attributes
    ----------
    fractions : numpy.ndarray, shape (k,)
        Fractions f of the centreline speed [-].
    left, right : numpy.ndarray, shape (k,)
        x of the boundary left (x < 0) and right (x > 0) of the axis [m]; NaN where the
        speed does not fall to ``f`` times the centreline speed inside the profile (the flow
        channel reaches the wall there, e.g. mass flow).
    centreline_speed : float
        ``|v_z(x = 0)|`` after the optional wall-velocity subtraction [m/s].
    wall_velocity : float
        Velocity subtracted from the profile (0 unless ``subtract_wall_velocity``) [m/s].
    """

    fractions: np.ndarray
    left: np.ndarray
    right: np.ndarray
    centreline_speed: float
    wall_velocity: float

    @property
    def width(self) -> np.ndarray:
        """Width of the flow channel ``right - left`` per fraction [m] (NaN if a side is open)."""
        return self.right - self.left


@dataclass(frozen=True)
class ProfileErrors:
    """Differences between a simulated and a measured profile sampled at the same points.

    Attributes
    ----------
    mean_error_percent : float
        ``100 * mean|s - m| / mean|m|`` [%]: the mean absolute error relative to the mean
        magnitude of the measured profile (not a mean of pointwise relative errors, which
        diverge where the measured velocity vanishes near the walls).
    rms_error : float
        ``sqrt(mean((s - m)^2))`` in the unit of the profiles.
    max_abs_error : float
        ``max|s - m|`` in the unit of the profiles.
    n_points : int
        Number of points compared.
    fraction_within_uncertainty : float or None
        Fraction of points with ``|s - m| <= u`` [-]; None without an uncertainty.
    normalised_rms : float or None
        ``sqrt(mean(((s - m) / u)^2))`` [-] (below about 1 means agreement within the
        measurement uncertainty); None without an uncertainty.
    """

    mean_error_percent: float
    rms_error: float
    max_abs_error: float
    n_points: int
    fraction_within_uncertainty: float | None = None
    normalised_rms: float | None = None


# --------------------------------------------------------------------------- profiles


def velocity_profile(fields_or_2d, z_value: float, method: str = "linear") -> VelocityProfile:
    """Horizontal profiles ``v_z(x)`` and ``v_x(x)`` at a height, from depth-averaged fields.

    Parameters
    ----------
    fields_or_2d : Fields or tuple
        Either a :class:`~siloflow.analysis.numerics.grid.Fields` with one node layer in y (from
        :func:`~siloflow.analysis.numerics.field_ops.depth_average` or
        :func:`~siloflow.analysis.numerics.field_ops.front_wall_slice`), or a tuple
        ``(x, z, v_x, v_z)`` with node coordinates x (nx,), z (nz,) [m] and velocity
        components of shape (nx, nz) [m/s].
    z_value : float
        Height above the outlet plane [m], within the range of the node rows.
    method : {"linear", "nearest"}, optional
        ``"linear"`` (default): linear interpolation between the two node rows that bracket
        ``z_value`` (exact at a row). ``"nearest"``: the row nearest to ``z_value``.

    Returns
    -------
    VelocityProfile
        ``z`` is ``z_value`` for linear interpolation and the row height for ``"nearest"``.

    Notes
    -----
    Masked nodes of a Fields (no particles) carry velocity 0 and are interpolated as 0.
    """
    if isinstance(fields_or_2d, Fields):
        grid = fields_or_2d.grid
        if grid.shape[1] != 1:
            raise ValueError(
                f"fields_or_2d must have one node layer in y (use depth_average or front_wall_slice), "
                f"got {grid.shape[1]} layers"
            )
        x = grid.x
        z = grid.z
        v_x = fields_or_2d.velocity[:, 0, :, 0]
        v_z = fields_or_2d.velocity[:, 0, :, 2]
    else:
        try:
            x, z, v_x, v_z = fields_or_2d
        except (TypeError, ValueError):
            raise ValueError("fields_or_2d must be a Fields or a tuple (x, z, v_x, v_z)") from None
        x = finite_array("x", x)
        z = finite_array("z", z)
        v_x = finite_array("v_x", v_x, ndim=2)
        v_z = finite_array("v_z", v_z, ndim=2)
        for name, array in (("v_x", v_x), ("v_z", v_z)):
            if array.shape != (x.size, z.size):
                raise ValueError(f"{name} must have shape ({x.size}, {z.size}) = (len(x), len(z)), got {array.shape}")
        if z.size < 1 or np.any(np.diff(z) <= 0.0):
            raise ValueError("z must be non-empty and strictly increasing")
    z_value = float(z_value)
    if not math.isfinite(z_value):
        raise ValueError(f"z_value must be finite, got {z_value!r}")
    if method not in ("linear", "nearest"):
        raise ValueError(f"method must be 'linear' or 'nearest', got {method!r}")

    if method == "nearest":
        row = int(np.argmin(np.abs(z - z_value)))
        return VelocityProfile(z=float(z[row]), x=x.copy(), v_x=v_x[:, row].copy(), v_z=v_z[:, row].copy())

    tolerance = 1e-12 * max(1.0, float(np.max(np.abs(z))))
    if z_value < z[0] - tolerance or z_value > z[-1] + tolerance:
        raise ValueError(
            f"z_value = {z_value!r} m lies outside the node rows [{z[0]!r}, {z[-1]!r}] m; "
            "use method='nearest' to take the nearest row"
        )
    if z.size == 1:
        return VelocityProfile(z=z_value, x=x.copy(), v_x=v_x[:, 0].copy(), v_z=v_z[:, 0].copy())
    upper = int(np.clip(np.searchsorted(z, z_value, side="right"), 1, z.size - 1))
    lower = upper - 1
    t = float(np.clip((z_value - z[lower]) / (z[upper] - z[lower]), 0.0, 1.0))
    return VelocityProfile(
        z=z_value,
        x=x.copy(),
        v_x=(1.0 - t) * v_x[:, lower] + t * v_x[:, upper],
        v_z=(1.0 - t) * v_z[:, lower] + t * v_z[:, upper],
    )


def _crossing(x_start: float, a_start: float, xs: np.ndarray, speeds: np.ndarray, target: float) -> float:
    """First x along (x_start, xs...) where the speed falls to ``target``; linear interpolation."""
    x_previous, a_previous = x_start, a_start
    for x_node, a_node in zip(xs, speeds):
        if a_node <= target:
            return float(x_previous + (a_previous - target) / (a_previous - a_node) * (x_node - x_previous))
        x_previous, a_previous = x_node, a_node
    return math.nan


def flow_channel_boundary(
    x,
    v_z,
    fractions=(0.01, 0.05, 0.10),
    subtract_wall_velocity: bool = False,
) -> FlowChannelBoundary:
    """Flow channel boundary: where ``|v_z|`` falls to fractions of its centreline value.

    Parameters
    ----------
    x : array_like, shape (n,)
        Node x coordinates, strictly increasing, spanning x = 0 [m].
    v_z : array_like, shape (n,)
        Vertical velocity at those nodes [m/s].
    fractions : sequence of float, optional
        Fractions f in (0, 1) of the centreline speed (default 1 %, 5 %, 10 %).
    subtract_wall_velocity : bool, optional
        First subtract the wall velocity, the mean of ``v_z`` at the two outermost nodes
        (for a silo where the material slides along the walls, e.g. mass flow).

    Returns
    -------
    FlowChannelBoundary

    Notes
    -----
    The centreline value is ``v_z`` linearly interpolated to x = 0. Walking outward from
    x = 0 on each side, the boundary is the first place where ``|v_z|`` falls to
    ``f |v_z(0)|``, found by linear interpolation between the last node above and the first
    node at or below that level (the centreline point counts as the first node).
    """
    x, v = checked_profile(x, v_z)
    fractions = finite_array("fractions", np.atleast_1d(np.asarray(fractions, dtype=float)))
    if fractions.size == 0 or np.any((fractions <= 0.0) | (fractions >= 1.0)):
        raise ValueError(f"fractions must be non-empty and each in (0, 1), got {fractions.tolist()}")
    if not x[0] <= 0.0 <= x[-1]:
        raise ValueError(f"x must span the axis x = 0, got [{x[0]!r}, {x[-1]!r}]")
    wall_velocity = 0.5 * (v[0] + v[-1]) if subtract_wall_velocity else 0.0
    v = v - wall_velocity
    speed = np.abs(v)
    centre = abs(float(np.interp(0.0, x, v)))
    if centre == 0.0:
        raise ValueError("v_z: the centreline velocity is zero (after any wall-velocity subtraction)")
    right_side = x > 0.0
    left_side = x < 0.0
    left = np.empty(fractions.size)
    right = np.empty(fractions.size)
    for index, fraction in enumerate(fractions):
        target = fraction * centre
        right[index] = _crossing(0.0, centre, x[right_side], speed[right_side], target)
        left[index] = _crossing(0.0, centre, x[left_side][::-1], speed[left_side][::-1], target)
    return FlowChannelBoundary(
        fractions=fractions, left=left, right=right, centreline_speed=centre, wall_velocity=float(wall_velocity)
    )


# --------------------------------------------------------------------------- flow rate


def profile_flow_rate(x, v_z, bulk_density: float, depth: float, bounds: tuple[float, float] | None = None) -> float:
    """Mass flow rate through a horizontal plane from a vertical velocity profile.

    ``W = -rho_b T integral v_z dx``, positive for downward flow (``v_z < 0``).

    Parameters
    ----------
    x : array_like, shape (n,)
        Node x coordinates, strictly increasing [m].
    v_z : array_like, shape (n,)
        Depth-averaged vertical velocity [m/s] (negative downward).
    bulk_density : float
        Bulk density rho_b of the flowing material [kg/m3].
    depth : float
        Silo depth T [m].
    bounds : tuple of float, optional
        Walls ``(x_left, x_right)`` [m] to integrate between. Default: the trapezoid rule
        between the first and last node only. With bounds (which must enclose the nodes),
        the profile is extended to each wall with the value of the outermost node; for
        nodes at the cell centres of a grid tiling the width this is exactly the midpoint
        rule ``sum v_z dx`` over the cells.

    Returns
    -------
    float
        Mass flow rate [kg/s], positive for net downward flow.
    """
    x, v = checked_profile(x, v_z, min_points=1 if bounds is not None else 2)
    bulk_density = positive_number("bulk_density", bulk_density)
    depth = positive_number("depth", depth)
    if bounds is not None:
        try:
            left, right = (float(b) for b in bounds)
        except (TypeError, ValueError):
            raise ValueError(f"bounds must be two numbers (x_left, x_right), got {bounds!r}") from None
        if not (math.isfinite(left) and math.isfinite(right)) or left > x[0] or right < x[-1]:
            raise ValueError(f"bounds must be finite and enclose the nodes [{x[0]!r}, {x[-1]!r}], got {bounds!r}")
        x = np.concatenate([[left], x, [right]])
        v = np.concatenate([[v[0]], v, [v[-1]]])
    integral = float(trapezoid(v, x))
    return -bulk_density * depth * integral


# --------------------------------------------------------------------------- comparison


def profile_errors(simulated, measured, uncertainty=None) -> ProfileErrors:
    """Compare a simulated profile with a measured one sampled at the same points.

    Parameters
    ----------
    simulated, measured : array_like, shape (n,)
        Profiles at the same n points (interpolate one onto the other first), any unit.
    uncertainty : float or array_like, shape (n,), optional
        Measurement uncertainty u (> 0), scalar or per point, same unit.

    Returns
    -------
    ProfileErrors
        Mean error in % of the mean measured magnitude, RMS and maximum absolute error and,
        with an uncertainty, the fraction of points within it and the RMS in units of it.
    """
    simulated = finite_array("simulated", simulated)
    measured = finite_array("measured", measured)
    if simulated.shape != measured.shape or simulated.size == 0:
        raise ValueError(
            f"simulated and measured must be non-empty and of equal length, got {simulated.size} and {measured.size}"
        )
    scale = float(np.mean(np.abs(measured)))
    if scale == 0.0:
        raise ValueError("measured is zero everywhere; a relative error is undefined")
    difference = simulated - measured
    absolute = np.abs(difference)
    within = None
    normalised = None
    if uncertainty is not None:
        u = np.asarray(uncertainty, dtype=float)
        if u.ndim == 0:
            u = np.full(measured.shape, float(u))
        if u.shape != measured.shape or not np.all(np.isfinite(u)) or np.any(u <= 0.0):
            raise ValueError(f"uncertainty must be a number > 0 or {measured.size} numbers > 0")
        within = float(np.mean(absolute <= u))
        normalised = float(np.sqrt(np.mean((difference / u) ** 2)))
    return ProfileErrors(
        mean_error_percent=100.0 * float(np.mean(absolute)) / scale,
        rms_error=float(np.sqrt(np.mean(difference**2))),
        max_abs_error=float(np.max(absolute)),
        n_points=int(measured.size),
        fraction_within_uncertainty=within,
        normalised_rms=normalised,
    )
