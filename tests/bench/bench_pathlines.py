"""Benchmark: virtual tracers through a series of Eulerian velocity fields (RTD from fields).

50,000 tracers on a lattice near the top of a 127 x 107 x 31 grid (cells 6 x 4 x 6 mm, values at
the cell centres), 5 time levels 0.5 s apart of a smooth synthetic silo field (downward flow with a
Gaussian central channel, convergence towards the axis near the outlet, a small depth-wise drift,
and a speed that changes between the levels), Heun (RK2) with a fixed dt = 2 ms until the tracers
cross the outlet plane z = 0 or max_time = 3 s (the slow tracers near the walls do not exit: NaN).

On the same seeds and fields, in the same run, it times

- siloflow's compiled integrator :func:`siloflow.analysis.numerics.pathlines.integrate_pathlines` (numba; warmed up
  first, so compilation is excluded and reported separately) on all 50,000 tracers and on the
  peer's subset,
- the straightforward peer :func:`integrate_with_scipy`: the same scheme, stage times, clamping
  and crossing interpolation, with the spatial interpolation done by
  ``scipy.interpolate.RegularGridInterpolator`` (linear; positions clamped to the node hull, which
  is siloflow's rule) on each time level and the same linear blend in time, vectorised over the
  tracers still inside.

The peer is slow, so it runs on a subset (every 10th tracer, 5,000 tracers, each followed until it
exits or max_time, exactly as in the full run). Speeds are tracer steps per second (steps actually
integrated, summed over tracers); the speed-up is against the peer on the same subset (target
>= 10x). The residence times of the subset are compared with siloflow's, tracer by tracer
(largest relative difference, target <= 1e-9; NaN must match NaN). Prints a table and writes it
as CSV (``argv[1]``, default ``results/bench/pathlines.csv``).

Run with ``python -m tests.bench.bench_pathlines results/bench/pathlines.csv``.
"""

from __future__ import annotations

import csv
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from siloflow.analysis.numerics.pathlines import HAVE_NUMBA, EXITED, NOT_EXITED, OUTSIDE, integrate_pathlines, time_levels
from siloflow.analysis.numerics.tracer_seeds import lattice_seeds

SHAPE = (127, 107, 31)
SPACING = (0.006, 0.004, 0.006)
ORIGIN = (-SHAPE[0] * SPACING[0] / 2.0, 0.0, 0.0)
TIMES = np.arange(5) * 0.5
SEED_COUNTS = (100, 50, 10)  # 50,000 tracers
DT = 0.002
MAX_TIME = 3.0
OUTLET_Z = 0.0
PEER_STRIDE = 10
SPEEDUP_TARGET = 10.0
DIFFERENCE_TARGET = 1e-9


def synthetic_fields(shape=SHAPE, spacing=SPACING, origin=ORIGIN, times=TIMES) -> np.ndarray:
    """Velocity series (n_times, nx, ny, nz, 3) of a draining silo with a central flow channel [m/s]."""
    axes = [origin[a] + (np.arange(shape[a]) + 0.5) * spacing[a] for a in range(3)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    depth = shape[1] * spacing[1]
    channel = np.exp(-(x**2) / (2.0 * 0.06**2))
    fields = np.empty((len(times),) + tuple(shape) + (3,))
    for level, t in enumerate(times):
        speed = 1.0 + 0.25 * math.sin(2.0 * math.pi * t / 2.0)
        fields[level, ..., 0] = -speed * 0.8 * x * np.exp(-z / 0.04) * (1.0 + 0.1 * np.cos(np.pi * y / depth))
        fields[level, ..., 1] = 0.01 * np.sin(np.pi * y / depth) * np.cos(8.0 * x)
        fields[level, ..., 2] = -speed * (0.02 + 0.3 * channel) * (1.0 + 0.5 * np.exp(-z / 0.03))
    return fields


def integrate_with_scipy(seeds, t0, velocities, times, origin, spacing, dt, outlet_z, max_time, method="rk2"):
    """Reference integrator: siloflow's scheme with scipy's RegularGridInterpolator in space.

    Same stage times ``t0 + n dt``, same time levels and weights (:func:`siloflow.analysis.numerics.pathlines.time_levels`),
    positions clamped to the hull of the cell-centre nodes before the (linear) interpolation,
    Heun or Euler, crossing time interpolated linearly within the step, NaN for seeds outside the
    box or at/below the outlet and for tracers not out within ``max_time``.

    Returns
    -------
    tuple
        ``(residence_time (n,), status (n,), tracer steps integrated)``.
    """
    seeds = np.asarray(seeds, float)
    velocities = np.asarray(velocities, float)
    origin = np.asarray(origin, float)
    spacing = np.asarray(spacing, float)
    shape = velocities.shape[1:4]
    nodes = [origin[a] + (np.arange(shape[a]) + 0.5) * spacing[a] for a in range(3)]
    low = np.array([axis[0] for axis in nodes])
    high = np.array([axis[-1] for axis in nodes])
    interpolators = [
        RegularGridInterpolator(nodes, field, method="linear", bounds_error=False, fill_value=None)
        for field in velocities
    ]

    def velocity(k, w, points):
        clamped = np.clip(points, low, high)
        value = interpolators[k](clamped)
        if w != 0.0:
            value = value * (1.0 - w) + interpolators[k + 1](clamped) * w
        return value

    total_steps = max(1, int(math.ceil(max_time / dt - 1.0e-9)))
    k_steps, w_steps = time_levels(times, t0 + np.arange(total_steps + 1) * dt)
    n = seeds.shape[0]
    upper = origin + np.array(shape) * spacing
    active = np.all((seeds >= origin) & (seeds <= upper), axis=1) & (seeds[:, 2] > outlet_z)
    residence = np.full(n, np.nan)
    status = np.full(n, OUTSIDE, dtype=np.int8)
    index = np.flatnonzero(active)
    position = seeds[index].copy()
    steps = 0
    for step in range(total_steps):
        if index.size == 0:
            break
        steps += index.size
        u = velocity(int(k_steps[step]), float(w_steps[step]), position)
        if method == "euler":
            new = position + dt * u
        else:
            u2 = velocity(int(k_steps[step + 1]), float(w_steps[step + 1]), position + dt * u)
            new = position + 0.5 * dt * (u + u2)
        crossed = new[:, 2] <= outlet_z
        if np.any(crossed):
            z, zn = position[crossed, 2], new[crossed, 2]
            residence[index[crossed]] = (step + (z - outlet_z) / (z - zn)) * dt
            status[index[crossed]] = EXITED
            keep = ~crossed
            index, new = index[keep], new[keep]
        position = new
    status[index] = NOT_EXITED
    late = residence > max_time
    residence[late] = np.nan
    status[late] = NOT_EXITED
    return residence, status, steps


def max_relative_difference(ours: np.ndarray, reference: np.ndarray) -> float:
    """Largest |ours - reference| / |reference| over tracers; inf if the NaN patterns differ."""
    if not np.array_equal(np.isnan(ours), np.isnan(reference)):
        return math.inf
    both = ~np.isnan(reference)
    if not np.any(both):
        return 0.0
    return float(np.max(np.abs(ours[both] - reference[both]) / np.abs(reference[both])))


def timed(function, repeats: int):
    """(result of the last call, best time, median time) over ``repeats`` calls [s]."""
    times = []
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return result, min(times), statistics.median(times)


def main(output: Path = Path("results/bench/pathlines.csv")) -> list[dict]:
    fields = synthetic_fields()
    lower = np.array(ORIGIN)
    upper = lower + np.array(SHAPE) * np.array(SPACING)
    seeds = lattice_seeds((lower[0] + 0.06, 0.01, 0.15), (upper[0] - 0.06, upper[1] - 0.01, 0.18), count=SEED_COUNTS)
    subset = seeds[::PEER_STRIDE]
    common = dict(velocities=fields, times=TIMES, origin=ORIGIN, spacing=SPACING, dt=DT, outlet_z=OUTLET_Z,
                  max_time=MAX_TIME, method="rk2")
    label = (f"grid {'x'.join(map(str, SHAPE))}, {len(TIMES)} time levels, RK2 dt {DT * 1e3:g} ms, "
             f"max {MAX_TIME:g} s")

    (peer_residence, peer_status, peer_steps), peer_best, peer_median = timed(
        lambda: integrate_with_scipy(subset, 0.0, **common), repeats=1
    )
    peer_rate = peer_steps / peer_median
    rows = [
        {
            "benchmark": label,
            "method": "scipy RegularGridInterpolator peer",
            "tracers": subset.shape[0],
            "tracer_steps": peer_steps,
            "best_s": round(peer_best, 3),
            "median_s": round(peer_median, 3),
            "tracer_steps_per_s": round(peer_rate),
            "speedup_vs_peer": 1.0,
            "exited_fraction": round(float(np.mean(peer_status == EXITED)), 4),
            "max_rel_diff_residence_vs_peer": 0.0,
            "target": "",
            "meets_target": "",
        }
    ]
    compile_time = None
    backends = ["numba", "numpy"] if HAVE_NUMBA else ["numpy"]
    for backend in backends:
        if backend == "numba":
            start = time.perf_counter()
            integrate_pathlines(subset[:10], 0.0, **common, backend="numba")
            compile_time = time.perf_counter() - start
        name = "siloflow compiled (numba)" if backend == "numba" else "siloflow numpy fallback"
        repeats = 3 if backend == "numba" else 1
        result, best, median = timed(lambda: integrate_pathlines(subset, 0.0, **common, backend=backend), repeats)
        rate = result.tracer_steps / median
        speedup = rate / peer_rate
        difference = max_relative_difference(result.residence_time, peer_residence)
        target_speedup = SPEEDUP_TARGET if backend == "numba" else None
        meets = difference <= DIFFERENCE_TARGET and (target_speedup is None or speedup >= target_speedup)
        rows.append(
            {
                "benchmark": label,
                "method": name,
                "tracers": subset.shape[0],
                "tracer_steps": result.tracer_steps,
                "best_s": round(best, 3),
                "median_s": round(median, 3),
                "tracer_steps_per_s": round(rate),
                "speedup_vs_peer": round(speedup, 1),
                "exited_fraction": round(result.fraction_exited, 4),
                "max_rel_diff_residence_vs_peer": float(f"{difference:.3g}"),
                "target": f"diff <= {DIFFERENCE_TARGET:g}"
                + (f", speed-up >= {target_speedup:g}x" if target_speedup else ""),
                "meets_target": meets,
            }
        )
    if HAVE_NUMBA:
        full, best, median = timed(lambda: integrate_pathlines(seeds, 0.0, **common, backend="numba"), repeats=2)
        subset_full = full.residence_time[::PEER_STRIDE]
        difference = max_relative_difference(subset_full, peer_residence)
        rate = full.tracer_steps / median
        rows.append(
            {
                "benchmark": label,
                "method": "siloflow compiled (numba), all tracers",
                "tracers": seeds.shape[0],
                "tracer_steps": full.tracer_steps,
                "best_s": round(best, 3),
                "median_s": round(median, 3),
                "tracer_steps_per_s": round(rate),
                "speedup_vs_peer": round(rate / peer_rate, 1),
                "exited_fraction": round(full.fraction_exited, 4),
                "max_rel_diff_residence_vs_peer": float(f"{difference:.3g}"),
                "target": f"diff <= {DIFFERENCE_TARGET:g} (peer's subset), speed-up >= {SPEEDUP_TARGET:g}x",
                "meets_target": difference <= DIFFERENCE_TARGET and rate / peer_rate >= SPEEDUP_TARGET,
            }
        )

    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)

    print(f"{label}; {seeds.shape[0]} tracers, peer on every {PEER_STRIDE}th; {os.cpu_count()} CPUs, single-threaded")
    print(f"{'method':<39} {'tracers':>7} {'steps':>10} {'median s':>9} {'steps/s':>9} {'vs peer':>8} "
          f"{'exited':>6} {'max rel diff':>12}  target met")
    for item in rows:
        print(
            f"{item['method']:<39} {item['tracers']:>7} {item['tracer_steps']:>10} {item['median_s']:>9} "
            f"{item['tracer_steps_per_s']:>9.3g} {str(item['speedup_vs_peer']) + 'x':>8} "
            f"{item['exited_fraction']:>6} {str(item['max_rel_diff_residence_vs_peer']):>12}  {item['meets_target']}"
        )
    if compile_time is not None:
        print(f"numba first call (compile or cache load, excluded above): {compile_time:.2f} s")
    print(f"table: {output}")
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/bench/pathlines.csv"))
