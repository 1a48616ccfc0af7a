"""Benchmark: rendering and PIV of one 1000 x 1400 px front-wall frame pair, against a baseline measured in the same
run: OpenPIV's single pass with the final (40 px) windows. Rows: rendering both images, single-pass PIV (baseline),
the default two-pass multipass with window deformation; each the best of three repeats, with its ratio to the
baseline and the RMS error of the recovered uniform shift (3.3, -1.7) px, so that speed is read beside accuracy.
Writes CSV (``argv[1]``, default ``results/bench/piv.csv``).

Run with ``python -m tests.bench.bench_piv results/bench/piv.csv`` (about ten seconds).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.piv.synthetic import piv_displacements, render_particle_image

WIDTH, HEIGHT = 1000, 1400
SHIFT = np.array([3.3, -1.7])


def _best(function, repeats: int = 3):
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def main(argv: list[str]) -> int:
    output = Path(argv[1] if len(argv) > 1 else "results/bench/piv.csv")
    rng = np.random.default_rng(0)
    # particles of 10 px diameter (a 3.3 mm sphere at 0.33 mm/px) covering about half the image
    n = int(0.5 * WIDTH * HEIGHT / (np.pi * 25.0))
    points = np.column_stack([rng.uniform(-10, WIDTH + 10, n), rng.uniform(-10, HEIGHT + 10, n)])

    def render():
        a = render_particle_image(points, 5.0, (HEIGHT, WIDTH), blur_px=0.7)
        b = render_particle_image(points + SHIFT, 5.0, (HEIGHT, WIDTH), blur_px=0.7)
        return a, b

    render_time, (image_a, image_b) = _best(render)
    rows = []
    for name, passes in (("single pass, 40 px (baseline)", 1), ("multipass 80 -> 40 px (default)", 2)):
        seconds, (x, y, u, v, valid) = _best(lambda: piv_displacements(image_a, image_b, 40, 20, passes))
        error = np.sqrt(np.mean((u - SHIFT[0]) ** 2 + (v - SHIFT[1]) ** 2))
        rows.append({"step": f"PIV, {name}", "seconds": seconds, "vectors": int(u.size), "rms_error_px": float(error)})
    rows.insert(0, {"step": "render two 1000 x 1400 images", "seconds": render_time, "vectors": 0,
                    "rms_error_px": float("nan")})
    baseline = rows[1]["seconds"]
    for row in rows:
        row["ratio_to_single_pass"] = row["seconds"] / baseline
    write_flow_table(output, rows)
    for row in rows:
        print(f"{row['step']}: {row['seconds']:.3f} s ({row['ratio_to_single_pass']:.2f} x single pass), "
              f"{row['vectors']} vectors, RMS error {row['rms_error_px']:.3f} px")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
