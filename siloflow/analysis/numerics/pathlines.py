"""Virtual tracers advected through a series of Eulerian velocity fields (RTD from fields).

Pure computation on numpy arrays; no file I/O. SI units: positions in m, velocities in m/s,
times in s.

The method of thesis ch. 6 ("RTD from Eulerian fields"): bin-averaged (coarse-grained)
velocities are saved at instants ``t_k``; virtual tracers seeded on a lattice
(:func:`siloflow.analysis.numerics.tracer_seeds.lattice_seeds`) are integrated through the interpolated field,
and the residence time of a tracer is the time it takes to cross the outlet plane ``z = outlet_z``.
The residence times feed :func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times` (NaN marks tracers that
never left).

Fields and interpolation
------------------------
``velocities`` has shape ``(n_times, nx, ny, nz, 3)``: the velocity at the cell centres of a regular
lattice (the nodes of :class:`siloflow.analysis.numerics.grid.Grid`), node (i, j, k) at
``origin + (i + 0.5, j + 0.5, k + 0.5) * spacing``, at the strictly increasing instants ``times``.

- In space the velocity is **trilinear** between the 8 surrounding nodes. Outside the hull of
  the nodes (within half a cell of the box faces, or beyond them) the position is **clamped** to
  the hull per axis before interpolating: the velocity there is that of the nearest boundary
  node plane (constant extrapolation, never linear extrapolation). An axis with a single node
  is constant along it.
- In time the velocity is **linear** between ``times[k]`` and ``times[k + 1]`` and held constant
  before ``times[0]`` and after ``times[-1]`` (a single instant is a steady field).

Integration
-----------
Fixed step ``dt`` from ``t0``; stage times are ``t0 + n dt`` (not accumulated).

- ``"euler"``: ``x_{n+1} = x_n + dt v(x_n, t_n)`` (the scheme written in the study).
- ``"rk2"`` (default): Heun's method, ``k1 = v(x_n, t_n)``, ``k2 = v(x_n + dt k1, t_{n+1})``,
  ``x_{n+1} = x_n + dt (k1 + k2) / 2``: second order, exact for fields that are uniform in space
  and linear in time over a step.

A tracer exits at the first step that takes it from ``z > outlet_z`` to ``z <= outlet_z``; its
crossing time is interpolated linearly within that step,
``t_exit = t_n + dt (z_n - outlet_z) / (z_n - z_{n+1})``, and its residence time is
``t_exit - t0``. Tracers are integrated for ``ceil(max_time / dt)`` steps; a tracer that has not
crossed with a residence time ``<= max_time`` gets NaN. Seeds outside the closed grid box or
at/below the outlet plane are not integrated (NaN). Tracers that leave the box sideways keep
moving with the clamped boundary velocity.

Backends
--------
The inner loop (tracers x steps) runs compiled with numba (``@njit``, single-threaded), or with
``backend="numpy"`` in a vectorised numpy fallback with the same interpolation and scheme (same
results to round-off). The compiled loop advances a few
tracers in turn, one step each, so that the CPU overlaps their independent work; every tracer
still goes through exactly the operations it would alone. On the benchmark of
``tests/bench/bench_pathlines.py`` (127 x 107 x 31 grid, 5 time levels, RK2) it makes about 1.5e7
tracer steps per second on one core, some 15 times scipy's ``RegularGridInterpolator`` doing the
same interpolation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from siloflow.model.checks import compute_backend, finite_array, finite_number, points3, positive_number, vector3


__all__ = [
    "HAVE_NUMBA",
    "EXITED",
    "NOT_EXITED",
    "OUTSIDE",
    "METHODS",
    "PathlineResult",
    "integrate_pathlines",
    "time_levels",
    "interpolate_velocity",
]

EXITED = 0
"""Status of a tracer that crossed the outlet plane within ``max_time``."""
NOT_EXITED = 1
"""Status of a tracer still above the outlet plane after ``max_time``."""
OUTSIDE = 2
"""Status of a seed outside the grid box or at/below the outlet plane (not integrated)."""

METHODS = ("rk2", "euler")

HAVE_NUMBA = True
"""numba is a declared dependency; kept so callers can list the backends they may ask for."""


# --------------------------------------------------------------------------- result


@dataclass(frozen=True, eq=False)
class PathlineResult:
    """Residence times (and optionally paths) of virtual tracers.

    Attributes
    ----------
    residence_time : numpy.ndarray, shape (n,)
        Time from ``t0`` to the crossing of ``z = outlet_z`` [s]; NaN for tracers that did not
        exit within ``max_time`` or were seeded outside.
    exit_position : numpy.ndarray, shape (n, 3)
        Point where the path crosses the outlet plane (linear within the step) [m]; NaN rows
        where ``residence_time`` is NaN.
    status : numpy.ndarray of int8, shape (n,)
        :data:`EXITED`, :data:`NOT_EXITED` or :data:`OUTSIDE`.
    n_steps : numpy.ndarray of int64, shape (n,)
        Steps integrated per tracer (0 for seeds outside).
    t0 : float
        Release time [s].
    dt : float
        Time step [s].
    method : str
        ``"rk2"`` or ``"euler"``.
    outlet_z : float
        Height of the outlet plane [m].
    max_time : float
        Longest residence time followed [s].
    history_time : numpy.ndarray, shape (r,) or None
        Times of the recorded positions ``t0 + j record_every dt`` [s] (None when not recorded).
    history : numpy.ndarray, shape (r, n, 3) or None
        Recorded positions [m]; NaN after a tracer has exited and for seeds outside.
    """

    residence_time: np.ndarray
    exit_position: np.ndarray
    status: np.ndarray
    n_steps: np.ndarray
    t0: float
    dt: float
    method: str
    outlet_z: float
    max_time: float
    history_time: np.ndarray | None = None
    history: np.ndarray | None = None

    @property
    def exit_time(self) -> np.ndarray:
        """Absolute exit times ``t0 + residence_time`` [s] (NaN where not exited)."""
        return self.t0 + self.residence_time

    @property
    def exited(self) -> np.ndarray:
        """Mask of the tracers that exited, shape (n,)."""
        return self.status == EXITED

    @property
    def fraction_exited(self) -> float:
        """Fraction of all seeds that exited [-] (0 for no seeds)."""
        return float(np.mean(self.exited)) if self.status.size else 0.0

    @property
    def tracer_steps(self) -> int:
        """Total number of tracer steps integrated (the work done)."""
        return int(self.n_steps.sum())


# --------------------------------------------------------------------------- validation


def _velocity_series(velocities, times) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(velocities)
    if v.ndim != 5 or v.shape[-1] != 3 or min(v.shape[:4]) < 1:
        raise ValueError(f"velocities must have shape (n_times, nx, ny, nz, 3), got {v.shape}")
    v = np.ascontiguousarray(v, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise ValueError("velocities must contain only finite numbers")
    t = finite_array("times", times, ndim=1)
    if t.shape != (v.shape[0],):
        raise ValueError(f"times must have shape ({v.shape[0]},) (one per velocity field), got {t.shape}")
    if np.any(np.diff(t) <= 0.0):
        raise ValueError("times must be strictly increasing")
    return v, t


# --------------------------------------------------------------------------- interpolation


def time_levels(times, t) -> tuple[np.ndarray, np.ndarray]:
    """Field index ``k`` and weight ``w`` of the linear time interpolation at instants ``t``.

    The field at ``t`` is ``(1 - w) V[k] + w V[k + 1]``; ``w = 0`` (and only ``V[k]`` is used)
    before ``times[0]`` (``k = 0``), at or after ``times[-1]`` (``k = n_times - 1``) and on an instant.

    Parameters
    ----------
    times : array_like, shape (n_times,)
        Strictly increasing field instants [s].
    t : array_like, shape (m,)
        Query instants [s].

    Returns
    -------
    k : numpy.ndarray of int64, shape (m,)
    w : numpy.ndarray of float, shape (m,)
    """
    times = finite_array("times", times, ndim=1)
    if times.size == 0 or np.any(np.diff(times) <= 0.0):
        raise ValueError("times must be a non-empty, strictly increasing array")
    t = finite_array("t", t, ndim=1)
    n = times.size
    k = np.searchsorted(times, t, side="right") - 1
    k = np.clip(k, 0, n - 1).astype(np.int64)
    w = np.zeros(t.size)
    inside = (t > times[0]) & (t < times[-1])
    if n > 1:
        ki = k[inside]
        w[inside] = (t[inside] - times[ki]) / (times[ki + 1] - times[ki])
    k[t <= times[0]] = 0
    k[t >= times[-1]] = n - 1
    w[w == 0.0] = 0.0
    return k, w


def _interpolate_numpy(v: np.ndarray, k: int, w: float, origin: np.ndarray, inv_spacing: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Trilinear (clamped) in space, linear in time; same operations as the compiled kernel."""
    shape = np.array(v.shape[1:4])
    s = (points - origin) * inv_spacing - 0.5
    s = np.minimum(np.maximum(s, 0.0), shape - 1)
    i0 = s.astype(np.int64)
    i0 = np.minimum(i0, np.maximum(shape - 2, 0))
    f = s - i0
    i1 = np.minimum(i0 + 1, shape - 1)
    fx, fy, fz = f[:, 0:1], f[:, 1:2], f[:, 2:3]
    gx, gy, gz = 1.0 - fx, 1.0 - fy, 1.0 - fz
    x0, y0, z0 = i0[:, 0], i0[:, 1], i0[:, 2]
    x1, y1, z1 = i1[:, 0], i1[:, 1], i1[:, 2]

    def level(field):
        c00 = field[x0, y0, z0] * gx + field[x1, y0, z0] * fx
        c10 = field[x0, y1, z0] * gx + field[x1, y1, z0] * fx
        c01 = field[x0, y0, z1] * gx + field[x1, y0, z1] * fx
        c11 = field[x0, y1, z1] * gx + field[x1, y1, z1] * fx
        c0 = c00 * gy + c10 * fy
        c1 = c01 * gy + c11 * fy
        return c0 * gz + c1 * fz

    value = level(v[k])
    if w != 0.0:
        value = value * (1.0 - w) + level(v[k + 1]) * w
    return value


def interpolate_velocity(points, t: float, velocities, times, origin, spacing) -> np.ndarray:
    """Velocity of the field series at ``points`` and instant ``t`` (the interpolation of the integrator).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Positions [m].
    t : float
        Instant [s].
    velocities : array_like, shape (n_times, nx, ny, nz, 3)
        Velocities at the cell centres [m/s].
    times : array_like, shape (n_times,)
        Field instants [s], strictly increasing.
    origin, spacing : array_like, shape (3,)
        Lower corner of the box and cell size [m].

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Velocity [m/s]: trilinear with clamping in space, linear in time (module docstring).
    """
    pts = points3("points", points)
    v, t_levels = _velocity_series(velocities, times)
    origin = vector3("origin", origin, positive=False, scalar_to_all=True)
    spacing = vector3("spacing", spacing, positive=True, scalar_to_all=True)
    k, w = time_levels(t_levels, [finite_number("t", t)])
    return _interpolate_numpy(v, int(k[0]), float(w[0]), origin, 1.0 / spacing, pts)


@numba.njit(cache=True, nogil=True, inline="always")
def _blend(f, b, sx, sy, sz, fx, fy, fz, gx, gy, gz):  # pragma: no cover
    """Trilinear blend of the 8 values ``f[b + {0, sx} + {0, sy} + {0, sz}]`` (flat field, node strides)."""
    c00 = f[b] * gx + f[b + sx] * fx
    c10 = f[b + sy] * gx + f[b + sx + sy] * fx
    c01 = f[b + sz] * gx + f[b + sx + sz] * fx
    c11 = f[b + sy + sz] * gx + f[b + sx + sy + sz] * fx
    c0 = c00 * gy + c10 * fy
    c1 = c01 * gy + c11 * fy
    return c0 * gz + c1 * fz

@numba.njit(cache=True, nogil=True, inline="always")
def _sample(f, shape, k, w, ox, oy, oz, ix, iy, iz, x, y, z):  # pragma: no cover
    """Velocity at (x, y, z) for time level k with weight w (same operations as :func:`_interpolate_numpy`).

    ``f`` is the flattened field of shape (nx, ny, nz, n_times, 3): the time axis sits next to the
    components so that both time levels of a node share cache lines. Offsets are unsigned, so
    the compiled code does no negative-index wraparound.
    """
    nx = shape[0]
    ny = shape[1]
    nz = shape[2]
    nt = shape[3]
    sx = min(max((x - ox) * ix - 0.5, 0.0), nx - 1.0)
    sy = min(max((y - oy) * iy - 0.5, 0.0), ny - 1.0)
    sz = min(max((z - oz) * iz - 0.5, 0.0), nz - 1.0)
    x0 = min(int(sx), max(nx - 2, 0))
    y0 = min(int(sy), max(ny - 2, 0))
    z0 = min(int(sz), max(nz - 2, 0))
    fx = sx - x0
    fy = sy - y0
    fz = sz - z0
    gx = 1.0 - fx
    gy = 1.0 - fy
    gz = 1.0 - fz
    step_z = np.uint64(3 * nt)
    step_y = np.uint64(nz) * step_z
    step_x = np.uint64(ny) * step_y
    dx = step_x if nx > 1 else np.uint64(0)
    dy = step_y if ny > 1 else np.uint64(0)
    dz = step_z if nz > 1 else np.uint64(0)
    b = np.uint64(x0) * step_x + np.uint64(y0) * step_y + np.uint64(z0) * step_z + np.uint64(3 * k)
    ux = _blend(f, b, dx, dy, dz, fx, fy, fz, gx, gy, gz)
    uy = _blend(f, b + np.uint64(1), dx, dy, dz, fx, fy, fz, gx, gy, gz)
    uz = _blend(f, b + np.uint64(2), dx, dy, dz, fx, fy, fz, gx, gy, gz)
    if w != 0.0:
        rest = 1.0 - w
        b += np.uint64(3)
        ux = ux * rest + _blend(f, b, dx, dy, dz, fx, fy, fz, gx, gy, gz) * w
        uy = uy * rest + _blend(f, b + np.uint64(1), dx, dy, dz, fx, fy, fz, gx, gy, gz) * w
        uz = uz * rest + _blend(f, b + np.uint64(2), dx, dy, dz, fx, fy, fz, gx, gy, gz) * w
    return ux, uy, uz

_LANES = 8
"""Tracers advanced in lockstep by the compiled loop (independent work for the CPU to overlap)."""

@numba.njit(cache=True, nogil=True)
def _integrate_compiled(
    seeds, v, origin, inv_spacing, k_steps, w_steps, dt, outlet_z, euler, record_every,
    active, history, residence, exit_position, status, n_steps,
):  # pragma: no cover
    """Compiled integration loop; see :func:`integrate_pathlines`. Outputs are filled in place.

    ``v`` has shape (nx, ny, nz, n_times, 3). A step of one tracer depends on its previous step,
    so a single tracer leaves the CPU waiting on memory and arithmetic latency; ``_LANES``
    tracers are therefore advanced one step each in turn, and a lane whose tracer has finished
    takes the next tracer. Every tracer goes through exactly the same operations as alone.
    """
    ox, oy, oz = origin[0], origin[1], origin[2]
    ix, iy, iz = inv_spacing[0], inv_spacing[1], inv_spacing[2]
    shape = v.shape
    flat = v.ravel()
    total_steps = k_steps.size - 1
    n_seeds = seeds.shape[0]
    lane_p = np.full(_LANES, -1, dtype=np.int64)
    lane_n = np.zeros(_LANES, dtype=np.int64)
    lane_x = np.zeros(_LANES)
    lane_y = np.zeros(_LANES)
    lane_z = np.zeros(_LANES)
    following = 0
    busy = 0
    while True:
        # fill idle lanes with the next active seeds
        for lane in range(_LANES):
            if lane_p[lane] >= 0:
                continue
            while following < n_seeds and not active[following]:
                following += 1
            if following >= n_seeds:
                continue
            p = following
            following += 1
            lane_p[lane] = p
            lane_n[lane] = 0
            lane_x[lane] = seeds[p, 0]
            lane_y[lane] = seeds[p, 1]
            lane_z[lane] = seeds[p, 2]
            busy += 1
            if record_every > 0:
                history[0, p, 0] = seeds[p, 0]
                history[0, p, 1] = seeds[p, 1]
                history[0, p, 2] = seeds[p, 2]
        if busy == 0:
            break
        for lane in range(_LANES):
            p = lane_p[lane]
            if p < 0:
                continue
            n = lane_n[lane]
            x = lane_x[lane]
            y = lane_y[lane]
            z = lane_z[lane]
            ux, uy, uz = _sample(flat, shape, k_steps[n], w_steps[n], ox, oy, oz, ix, iy, iz, x, y, z)
            if euler:
                xn = x + dt * ux
                yn = y + dt * uy
                zn = z + dt * uz
            else:
                px = x + dt * ux
                py = y + dt * uy
                pz = z + dt * uz
                vx, vy, vz = _sample(flat, shape, k_steps[n + 1], w_steps[n + 1], ox, oy, oz, ix, iy, iz, px, py, pz)
                xn = x + 0.5 * dt * (ux + vx)
                yn = y + 0.5 * dt * (uy + vy)
                zn = z + 0.5 * dt * (uz + vz)
            if zn <= outlet_z:
                frac = (z - outlet_z) / (z - zn)
                residence[p] = (n + frac) * dt
                exit_position[p, 0] = x + frac * (xn - x)
                exit_position[p, 1] = y + frac * (yn - y)
                exit_position[p, 2] = outlet_z
                status[p] = 0
                n_steps[p] = n + 1
                lane_p[lane] = -1
                busy -= 1
                continue
            n += 1
            lane_n[lane] = n
            lane_x[lane] = xn
            lane_y[lane] = yn
            lane_z[lane] = zn
            if record_every > 0 and n % record_every == 0:
                row = n // record_every
                history[row, p, 0] = xn
                history[row, p, 1] = yn
                history[row, p, 2] = zn
            if n == total_steps:
                status[p] = 1
                n_steps[p] = total_steps
                lane_p[lane] = -1
                busy -= 1


def _integrate_numpy(
    seeds, v, origin, inv_spacing, k_steps, w_steps, dt, outlet_z, euler, record_every,
    active, history, residence, exit_position, status, n_steps,
):
    """Vectorised fallback of :func:`_integrate_compiled` (same outputs, filled in place)."""
    index = np.flatnonzero(active)
    position = seeds[index].copy()
    if record_every > 0:
        history[0, index] = position
    total_steps = k_steps.size - 1
    for n in range(total_steps):
        if index.size == 0:
            break
        u = _interpolate_numpy(v, int(k_steps[n]), float(w_steps[n]), origin, inv_spacing, position)
        if euler:
            new = position + dt * u
        else:
            predicted = position + dt * u
            u2 = _interpolate_numpy(v, int(k_steps[n + 1]), float(w_steps[n + 1]), origin, inv_spacing, predicted)
            new = position + 0.5 * dt * (u + u2)
        crossed = new[:, 2] <= outlet_z
        if np.any(crossed):
            z, zn = position[crossed, 2], new[crossed, 2]
            frac = (z - outlet_z) / (z - zn)
            who = index[crossed]
            residence[who] = (n + frac) * dt
            exit_position[who, 0:2] = position[crossed, 0:2] + frac[:, None] * (new[crossed, 0:2] - position[crossed, 0:2])
            exit_position[who, 2] = outlet_z
            status[who] = EXITED
            n_steps[who] = n + 1
            keep = ~crossed
            index, position, new = index[keep], position[keep], new[keep]
        position = new
        if record_every > 0 and (n + 1) % record_every == 0:
            history[(n + 1) // record_every, index] = position
    status[index] = NOT_EXITED
    n_steps[index] = total_steps


# --------------------------------------------------------------------------- integration


def integrate_pathlines(
    seeds,
    t0: float,
    velocities,
    times,
    origin,
    spacing,
    dt: float,
    outlet_z: float,
    max_time: float,
    method: str = "rk2",
    record_every: int = 0,
    backend: str = "auto",
) -> PathlineResult:
    """Advect virtual tracers through a series of velocity fields until they cross the outlet plane.

    See the module docstring for the interpolation (trilinear in space with clamping to the
    boundary nodes, linear in time), the schemes and the crossing time.

    Parameters
    ----------
    seeds : array_like, shape (n, 3)
        Release positions [m] (e.g. :func:`siloflow.analysis.numerics.tracer_seeds.lattice_seeds`).
    t0 : float
        Release time [s] (on the clock of ``times``).
    velocities : array_like, shape (n_times, nx, ny, nz, 3)
        Velocity at the cell centres at each instant [m/s] (converted to C-contiguous float64).
    times : array_like, shape (n_times,)
        Strictly increasing instants of the fields [s].
    origin : array_like, shape (3,)
        Lower corner of the grid box (``Grid.origin``) [m].
    spacing : array_like, shape (3,) or float
        Cell size (``Grid.spacing``) [m], > 0.
    dt : float
        Time step [s], > 0.
    outlet_z : float
        Height of the outlet plane [m]; tracers move down through it.
    max_time : float
        Longest residence time followed [s], > 0; ``ceil(max_time / dt)`` steps.
    method : {"rk2", "euler"}, optional
        Heun (default) or explicit Euler.
    record_every : int, optional
        Record positions every this many steps (0, the default: no history). The history holds
        ``ceil(max_time / dt) // record_every + 1`` rows of ``n`` positions: mind the memory.
    backend : {"auto", "numba", "numpy"}, optional
        Compiled loop (the default) or the numpy fallback.

    Returns
    -------
    PathlineResult

    Raises
    ------
    ValueError
        Naming the argument with a wrong shape, a non-finite value or an invalid option.
    """
    pts = points3("seeds", seeds)
    v, t_levels = _velocity_series(velocities, times)
    origin = vector3("origin", origin, positive=False, scalar_to_all=True)
    spacing = vector3("spacing", spacing, positive=True, scalar_to_all=True)
    t0 = finite_number("t0", t0)
    dt = positive_number("dt", dt)
    outlet_z = finite_number("outlet_z", outlet_z)
    max_time = positive_number("max_time", max_time)
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if isinstance(record_every, (bool, np.bool_)) or int(record_every) != record_every or record_every < 0:
        raise ValueError(f"record_every must be an integer >= 0, got {record_every!r}")
    record_every = int(record_every)
    backend = compute_backend(backend, HAVE_NUMBA)

    total_steps = max(1, int(math.ceil(max_time / dt - 1.0e-9)))
    k_steps, w_steps = time_levels(t_levels, t0 + np.arange(total_steps + 1) * dt)
    upper = origin + np.array(v.shape[1:4]) * spacing
    n = pts.shape[0]
    active = np.all((pts >= origin) & (pts <= upper), axis=1) & (pts[:, 2] > outlet_z)

    residence = np.full(n, np.nan)
    exit_position = np.full((n, 3), np.nan)
    status = np.full(n, OUTSIDE, dtype=np.int8)
    n_steps = np.zeros(n, dtype=np.int64)
    if record_every > 0:
        rows = total_steps // record_every + 1
        history = np.full((rows, n, 3), np.nan)
        history_time = t0 + np.arange(rows) * record_every * dt
    else:
        history = np.empty((0, 0, 3))
        history_time = None

    inv_spacing = 1.0 / spacing
    arguments = (
        pts, v, origin, inv_spacing, k_steps, w_steps, dt, outlet_z, method == "euler", record_every,
        active, history, residence, exit_position, status, n_steps,
    )
    if backend == "numba":
        # time axis next to the components: both time levels of a node share cache lines
        interleaved = np.ascontiguousarray(np.moveaxis(v, 0, 3))
        _integrate_compiled(pts, interleaved, *arguments[2:])
    else:
        _integrate_numpy(*arguments)

    late = residence > max_time
    if np.any(late):
        residence[late] = np.nan
        exit_position[late] = np.nan
        status[late] = NOT_EXITED
    return PathlineResult(
        residence_time=residence,
        exit_position=exit_position,
        status=status,
        n_steps=n_steps,
        t0=t0,
        dt=dt,
        method=method,
        outlet_z=outlet_z,
        max_time=max_time,
        history_time=history_time,
        history=history if record_every > 0 else None,
    )
