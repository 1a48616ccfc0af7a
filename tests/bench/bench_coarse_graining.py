"""Benchmark: coarse graining a particle frame onto the study's grid.

100,000 particles uniformly in a 150 x 40 x 300 mm box (the planar silo), grid 6/4/6 mm
(25 x 10 x 50 nodes), Gaussian kernel w = 4.5 mm cut off at 3 w. On the same frame, in the same
run, it times

- siloflow's compiled path (numba; warmed up first, so compile time is excluded and reported
  separately),
- siloflow's numpy fallback,
- the straightforward peer :func:`coarse_grain_ckdtree`: ``scipy.spatial.cKDTree`` on the
  particles, ``query_ball_point`` of every grid node within the cut-off radius, the kernel
  evaluated per (node, particle) pair, with the same discrete normalisation (per particle, the
  weights over the nodes sum to one), so the fields must agree to round-off;

and then a 500,000-particle frame with the compiled path. Figures: kernel evaluations per
second (pairs within the cut-off / time), speed-up against the peer (target >= 20x), the largest
difference of density, momentum density and kinetic stress against the peer relative to each
field's largest magnitude (target <= 1e-9), and the 500k-particle time (target < 1 s on one core).
Prints a table and writes it as CSV (``argv[1]``, default ``results/bench/coarse_graining.csv``).

Run with ``python -m tests.bench.bench_coarse_graining results/bench/coarse_graining.csv``.
"""

from __future__ import annotations

import csv
import itertools
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from siloflow.analysis.numerics.coarse_graining import HAVE_NUMBA, coarse_grain
from siloflow.analysis.numerics.grid import Grid

N_PARTICLES = 100_000
N_LARGE = 500_000
WIDTH = 0.0045  # 3 radii of a 3 mm sphere [m]
CUTOFF = 3.0
BOX_LOWER = (-0.075, 0.0, 0.0)
BOX_UPPER = (0.075, 0.04, 0.3)
SPEEDUP_TARGET = 20.0
DIFFERENCE_TARGET = 1e-9
LARGE_TIME_TARGET = 1.0


def synthetic_frame(n: int, seed: int = 7):
    """n particles uniformly in the silo box, pellet-like masses, velocities of a draining silo."""
    rng = np.random.default_rng(seed)
    positions = rng.uniform(BOX_LOWER, BOX_UPPER, size=(n, 3))
    masses = rng.uniform(1.6e-5, 2.0e-5, n)
    velocities = rng.normal(scale=0.02, size=(n, 3))
    velocities[:, 2] -= 0.2 * np.exp(-positions[:, 0] ** 2 / (2 * 0.02**2))
    return positions, masses, velocities


def coarse_grain_ckdtree(positions, masses, velocities, grid: Grid, width: float, cutoff: float = CUTOFF,
                         nodes_per_query: int = 2000):
    """Reference coarse graining with a k-d tree (the straightforward peer; Gaussian kernel only).

    Every grid node queries the particles within ``cutoff * width``; each (node, particle) pair
    gets ``exp(-r^2 / (2 w^2))``; each particle's weights are divided by their sum over the
    nodes (discrete normalisation), and the weighted sums of m, m v and m v v give density,
    momentum density and the kinetic stress ``sum m v v phi / V - p p / rho`` (compression
    positive). Particles outside the grid box are ignored. It does not handle a kernel too
    narrow to reach any node (siloflow's binning fallback); the benchmark kernel always reaches.

    Returns
    -------
    tuple
        ``(density (nx, ny, nz), momentum_density (nx, ny, nz, 3), kinetic_stress (nx, ny, nz, 3, 3),
        number of (node, particle) pairs within the cut-off)``.
    """
    positions = np.asarray(positions, float)
    masses = np.broadcast_to(np.asarray(masses, float), (positions.shape[0],))
    velocities = np.asarray(velocities, float)
    inside = np.all((positions >= grid.lower) & (positions <= grid.upper), axis=1)
    positions, masses, velocities = positions[inside], masses[inside], velocities[inside]
    n = positions.shape[0]
    nodes = grid.node_positions().reshape(-1, 3)
    tree = cKDTree(positions)
    radius = cutoff * width

    pair_nodes, pair_particles, pair_weights = [], [], []
    for start in range(0, nodes.shape[0], nodes_per_query):
        block = nodes[start : start + nodes_per_query]
        neighbours = tree.query_ball_point(block, r=radius)
        counts = np.fromiter((len(item) for item in neighbours), dtype=np.int64, count=len(neighbours))
        particles = np.fromiter(itertools.chain.from_iterable(neighbours), dtype=np.int64, count=int(counts.sum()))
        node_index = np.repeat(np.arange(start, start + block.shape[0]), counts)
        offset = nodes[node_index] - positions[particles]
        pair_nodes.append(node_index)
        pair_particles.append(particles)
        pair_weights.append(np.exp(-np.einsum("ij,ij->i", offset, offset) / (2.0 * width * width)))
    pair_nodes = np.concatenate(pair_nodes)
    pair_particles = np.concatenate(pair_particles)
    pair_weights = np.concatenate(pair_weights)

    normaliser = np.bincount(pair_particles, weights=pair_weights, minlength=n)
    weights = pair_weights / normaliser[pair_particles]
    volume = grid.cell_volume
    shape = grid.shape

    def node_sum(per_particle):
        return np.bincount(pair_nodes, weights=weights * per_particle[pair_particles], minlength=grid.n_nodes)

    density = node_sum(masses).reshape(shape) / volume
    momentum = np.stack([node_sum(masses * velocities[:, a]) for a in range(3)], axis=-1).reshape(shape + (3,)) / volume
    kinetic = np.empty(shape + (3, 3))
    occupied = density > 0.0
    for a in range(3):
        for b in range(a, 3):
            second = node_sum(masses * velocities[:, a] * velocities[:, b]).reshape(shape) / volume
            fluctuation = np.where(
                occupied, second - momentum[..., a] * momentum[..., b] / np.where(occupied, density, 1.0), 0.0
            )
            kinetic[..., a, b] = kinetic[..., b, a] = fluctuation
    return density, momentum, kinetic, int(pair_nodes.size)


def timed(function, repeats: int):
    """(result of the last call, best time, median time) over ``repeats`` calls [s]."""
    times = []
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return result, min(times), statistics.median(times)


def relative_difference(fields, reference) -> float:
    """Largest |difference| of each field, relative to that field's largest magnitude; max over fields."""
    density, momentum, kinetic = reference
    pairs = ((fields.density, density), (fields.momentum_density, momentum), (fields.kinetic_stress, kinetic))
    return max(float(np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs))) for ours, theirs in pairs)


def main(output: Path = Path("results/bench/coarse_graining.csv")) -> list[dict]:
    grid = Grid.covering(BOX_LOWER, BOX_UPPER)
    positions, masses, velocities = synthetic_frame(N_PARTICLES)
    label = f"{N_PARTICLES} particles, grid {'x'.join(map(str, grid.shape))}, w 4.5 mm, cut-off 3w"

    peer, peer_best, peer_median = timed(
        lambda: coarse_grain_ckdtree(positions, masses, velocities, grid, WIDTH, CUTOFF), repeats=1
    )
    *peer_fields, pairs = peer
    rows = [
        {
            "benchmark": label,
            "method": "scipy cKDTree peer",
            "best_s": round(peer_best, 4),
            "median_s": round(peer_median, 4),
            "kernel_evals_per_s": round(pairs / peer_median),
            "speedup_vs_peer": 1.0,
            "max_rel_diff_vs_peer": 0.0,
            "target": "",
            "meets_target": "",
        }
    ]

    def row(method, fields, best, median, target_speedup):
        speedup = peer_median / median
        difference = relative_difference(fields, peer_fields)
        meets = difference <= DIFFERENCE_TARGET and (target_speedup is None or speedup >= target_speedup)
        target = f"diff <= {DIFFERENCE_TARGET:g}" + (f", speed-up >= {target_speedup:g}x" if target_speedup else "")
        return {
            "benchmark": label,
            "method": method,
            "best_s": round(best, 4),
            "median_s": round(median, 4),
            "kernel_evals_per_s": round(pairs / median),
            "speedup_vs_peer": round(speedup, 1),
            "max_rel_diff_vs_peer": float(f"{difference:.3g}"),
            "target": target,
            "meets_target": meets,
        }

    compile_time = None
    if HAVE_NUMBA:
        start = time.perf_counter()
        coarse_grain(positions[:10], masses[:10], velocities[:10], grid, WIDTH, CUTOFF, backend="numba")
        compile_time = time.perf_counter() - start
        compiled, best, median = timed(
            lambda: coarse_grain(positions, masses, velocities, grid, WIDTH, CUTOFF, backend="numba"), repeats=5
        )
        rows.append(row("siloflow compiled (numba)", compiled, best, median, SPEEDUP_TARGET))
    fallback, best, median = timed(
        lambda: coarse_grain(positions, masses, velocities, grid, WIDTH, CUTOFF, backend="numpy"), repeats=2
    )
    rows.append(row("siloflow numpy fallback", fallback, best, median, None))

    if HAVE_NUMBA:
        large = synthetic_frame(N_LARGE, seed=8)
        _, best, median = timed(lambda: coarse_grain(*large, grid, WIDTH, CUTOFF, backend="numba"), repeats=3)
        rows.append(
            {
                "benchmark": f"{N_LARGE} particles, same grid and kernel",
                "method": "siloflow compiled (numba)",
                "best_s": round(best, 4),
                "median_s": round(median, 4),
                "kernel_evals_per_s": round(pairs * N_LARGE / N_PARTICLES / median),
                "speedup_vs_peer": "",
                "max_rel_diff_vs_peer": "",
                "target": f"median < {LARGE_TIME_TARGET:g} s (compile excluded)",
                "meets_target": median < LARGE_TIME_TARGET,
            }
        )

    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)

    print(f"{label}; {pairs} kernel evaluations (node-particle pairs within the cut-off); "
          f"{os.cpu_count()} CPUs, single-threaded")
    header = f"{'method':<27} {'particles':>9} {'median s':>9} {'best s':>8} {'evals/s':>10} {'vs peer':>8} {'max rel diff':>12}  target met"
    print(header)
    for item in rows:
        particles = N_LARGE if item["benchmark"].startswith(str(N_LARGE)) else N_PARTICLES
        speedup = f"{item['speedup_vs_peer']}x" if item["speedup_vs_peer"] != "" else ""
        print(
            f"{item['method']:<27} {particles:>9} {item['median_s']:>9} {item['best_s']:>8} "
            f"{item['kernel_evals_per_s']:>10.3g} {speedup:>8} {str(item['max_rel_diff_vs_peer']):>12}  "
            f"{item['meets_target']}"
        )
    if compile_time is not None:
        print(f"numba first call (compile or cache load, excluded above): {compile_time:.2f} s")
    print(f"table: {output}")
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/bench/coarse_graining.csv"))
