"""Benchmark: the same small flat-bottom silo on LIGGGHTS and on YADE, one core each, in one run.

The micro silo of YADE's integration tests made wider (about 700 two-sphere clumps: fill, settle, open, 0.3 s of
discharge) runs on each engine in turn. Reports each engine's throughput, sphere-steps per CPU second as the engine
itself timed the run (``Engine.measured_cost``), its ratio to LIGGGHTS' (the baseline, measured in the same
benchmark), the wall time, and the steady mass flow rate with its counting noise (3 sigma), so that the speed is
read beside what each engine computed. Writes CSV (``argv[1]``, default ``results/bench/engines.csv``).

Run with ``python -m tests.bench.bench_engines results/bench/engines.csv`` (a few minutes on one core).
"""

from __future__ import annotations

import csv
import sys
import tempfile
import time
from pathlib import Path

from siloflow.engines.interface import EngineOptions, engine_named
from tests.bench.bench_mpi import flow_rate
from tests.bench.small_silo import small_silo
from tests.conftest import MICRO_SILO

SILO = {**MICRO_SILO, "width": 0.06, "fill_height": 0.03, "outlet_width": 0.02}
ENGINES = ("liggghts", "yade")


def main(argv: list[str]) -> int:
    output = Path(argv[1] if len(argv) > 1 else "results/bench/engines.csv")
    case, _ = small_silo(SILO)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for name in ENGINES:
            engine = engine_named(name)
            run_dir = Path(scratch) / name
            engine.write_inputs(case, run_dir)
            start = time.perf_counter()
            record = engine.run(case, run_dir, EngineOptions())
            wall = time.perf_counter() - start
            rate, noise = flow_rate(engine, run_dir, record, case)
            cost = engine.measured_cost(run_dir)
            rows.append({"engine": name, "clumps": case.fill.n_clumps, "spheres": case.fill.n_clumps * case.spheres_per_clump,
                         "wall_time_s": wall, "sphere_steps_per_cpu_s": 1.0 / cost,
                         "mass_flow_rate_kg_s": rate, "flow_rate_noise_3sigma_kg_s": noise})
    baseline = rows[0]
    for row in rows:
        row["throughput_vs_liggghts"] = row["sphere_steps_per_cpu_s"] / baseline["sphere_steps_per_cpu_s"]
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    for row in rows:
        print(f"{row['engine']}: {row['sphere_steps_per_cpu_s'] / 1e6:.2f} M sphere-steps per CPU second "
              f"({row['throughput_vs_liggghts']:.2f} of LIGGGHTS'), {row['wall_time_s']:.0f} s wall; flow rate "
              f"{row['mass_flow_rate_kg_s']:.4g} +- {row['flow_rate_noise_3sigma_kg_s']:.2g} kg/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
