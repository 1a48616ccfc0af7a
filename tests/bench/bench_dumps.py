"""Benchmark: reading particle dumps.

Writes a 100,000-sphere dump in the layout LIGGGHTS writes (binary and ASCII legacy VTK POLYDATA) and
times siloflow's direct parser against pyvista's reader (VTK's own legacy reader) on the same file, in
the same run. Prints a table and writes it to ``results/bench/dumps.csv``; figures are ratios against
the pyvista baseline, so they hold when the machine's speed drifts.

Run with ``make bench``.
"""

from __future__ import annotations

import csv
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from engines.liggghts.dumps import parse_legacy_vtk_polydata, write_legacy_vtk_polydata

N_SPHERES = 100_000
REPEATS = 5


def synthetic_dump_fields(n: int, seed: int = 7):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-0.075, 0.075, size=(n, 3)).astype(np.float32)
    fields = {
        "id": np.arange(1, n + 1, dtype=np.int32),
        "id_multisphere": (np.arange(n, dtype=np.int32) // 2) + 1,
        "type": np.ones(n, dtype=np.int32),
        "mass": np.full(n, 1.836e-5),
        "v": rng.normal(size=(n, 3)),
        "f": rng.normal(size=(n, 3)),
        "radius": np.full(n, 0.0015),
        "omega": rng.normal(size=(n, 3)),
    }
    return points, fields


def best_and_median(function, repeats: int = REPEATS) -> tuple[float, float]:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times), statistics.median(times)


def main(output: Path = Path("results/bench/dumps.csv")) -> list[dict]:
    import pyvista

    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        points, fields = synthetic_dump_fields(N_SPHERES)
        for binary in (True, False):
            path = Path(scratch) / f"dump_{'binary' if binary else 'ascii'}.vtk"
            write_legacy_vtk_polydata(path, points, fields, binary=binary)
            content = path.read_bytes()
            _, baseline = best_and_median(lambda: pyvista.read(path))
            _, ours = best_and_median(lambda: parse_legacy_vtk_polydata(path.read_bytes(), str(path)))
            rows.append(
                {
                    "benchmark": f"read {'binary' if binary else 'ascii'} dump, {N_SPHERES} spheres",
                    "file_MB": round(len(content) / 1e6, 2),
                    "siloflow_median_s": round(ours, 4),
                    "pyvista_median_s": round(baseline, 4),
                    "speedup_vs_pyvista": round(baseline / ours, 2),
                    "siloflow_spheres_per_s": round(N_SPHERES / ours),
                }
            )
    binary_row, ascii_row = rows
    binary_row["binary_over_ascii_speed"] = round(ascii_row["siloflow_median_s"] / binary_row["siloflow_median_s"], 1)
    ascii_row["binary_over_ascii_speed"] = ""
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    width = max(len(r["benchmark"]) for r in rows)
    print(f"{'benchmark':<{width}}  {'MB':>6}  {'siloflow s':>10}  {'pyvista s':>9}  {'ratio':>6}")
    for row in rows:
        print(
            f"{row['benchmark']:<{width}}  {row['file_MB']:>6}  {row['siloflow_median_s']:>10}  "
            f"{row['pyvista_median_s']:>9}  {row['speedup_vs_pyvista']:>6}"
        )
    print(f"binary dumps parse {binary_row['binary_over_ascii_speed']}x faster than ASCII; table: {output}")
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/bench/dumps.csv"))
