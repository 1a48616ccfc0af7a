"""Benchmark: one flat-bottom silo run on 1 and on 2 MPI ranks (strong scaling on this machine), and the processor
grid the deck generator chooses against LIGGGHTS' own.

The same silo (the tiny test silo made deeper and wider, about 4,000 two-sphere clumps) runs serially, with
``mpirun -np 2`` on LIGGGHTS' own grid (``processors * * *``: it splits the longest axis, here the height, so the
upper rank idles as the silo fills and again as it empties) and with ``mpirun -np 2`` on the grid the deck names
(:func:`siloflow.engines.liggghts.inputs.processor_grid`: ranks side by side across the width). Reports the wall time of
each, the speed-up (baseline: the serial run, measured in the same benchmark) and, to show the physics does not
change with the rank count, the steady mass flow rate of each with its counting noise (3 sigma of the clumps
discharged in the steady window). Prints a table and writes it as CSV (``argv[1]``, default
``results/bench/mpi.csv``).

Run with ``python -m tests.bench.bench_mpi results/bench/mpi.csv`` (a few minutes on 2 cores).
"""

from __future__ import annotations

import csv
import math
import re
import sys
import tempfile
import time
from pathlib import Path

from siloflow.model.frames import clumps_from_frame
from siloflow.analysis.numerics.flow import discharged_mass_history, mass_in_silo, steady_flow_rate
from siloflow.engines.interface import EngineOptions
from siloflow.engines.liggghts.inputs import DECK_NAME
from tests.bench.small_silo import small_silo
from tests.conftest import TINY_SILO

SILO = {**TINY_SILO, "width": 0.12, "fill_height": 0.06, "discharge_time": 0.5}
#: (label, MPI ranks, processor grid replacing the generated one or None to keep it).
VARIANTS = (("1 rank", 1, None), ("2 ranks, LIGGGHTS' grid", 2, "* * *"), ("2 ranks, generated grid", 2, None))


def flow_rate(engine, run_dir: Path, record, case) -> tuple[float, float]:
    """Steady mass flow rate (kg/s) and its counting noise (3 sigma, kg/s) of a finished run."""
    frames = [clumps_from_frame(f) for f in engine.read_frames(run_dir, record)]
    times = [f.time - record.open_time_s for f in frames]
    history = discharged_mass_history(times, [mass_in_silo(f.position[:, 2], f.mass) for f in frames])
    fit = steady_flow_rate(history.time, history.discharged_mass)
    counted = fit.mass_flow_rate * (fit.t_end - fit.t_start) / case.particle.mass
    return fit.mass_flow_rate, 3.0 * fit.mass_flow_rate / math.sqrt(max(counted, 1.0))


def main(argv: list[str]) -> int:
    output = Path(argv[1] if len(argv) > 1 else "results/bench/mpi.csv")
    case, engine = small_silo(SILO)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for label, ranks, grid in VARIANTS:
            run_dir = Path(scratch) / label.replace(" ", "_").replace("'", "")
            engine.write_inputs(case, run_dir)
            deck = run_dir / "deck" / DECK_NAME
            generated = re.search(r"^processors .*$", deck.read_text(), flags=re.MULTILINE)
            if generated is None:
                raise RuntimeError("the generated deck names no processor grid: the benchmark is out of date")
            if grid is not None:
                deck.write_text(deck.read_text().replace(generated.group(0), f"processors {grid}"))
            start = time.perf_counter()
            record = engine.run(case, run_dir, EngineOptions(mpi_ranks=ranks))
            wall = time.perf_counter() - start
            rate, noise = flow_rate(engine, run_dir, record, case)
            rows.append({"variant": label, "mpi_ranks": ranks,
                         "processors": (grid or generated.group(0).split(maxsplit=1)[1]),
                         "clumps": case.fill.n_clumps, "wall_time_s": wall,
                         "mass_flow_rate_kg_s": rate, "flow_rate_noise_3sigma_kg_s": noise})
    serial = rows[0]
    for row in rows:
        row["speedup_vs_1_rank"] = serial["wall_time_s"] / row["wall_time_s"]
        row["flow_rate_difference_kg_s"] = row["mass_flow_rate_kg_s"] - serial["mass_flow_rate_kg_s"]
        row["within_noise"] = abs(row["flow_rate_difference_kg_s"]) <= math.hypot(
            row["flow_rate_noise_3sigma_kg_s"], serial["flow_rate_noise_3sigma_kg_s"])
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    for row in rows:
        print(f"{row['variant']} (processors {row['processors']}): {row['wall_time_s']:.1f} s wall, speed-up {row['speedup_vs_1_rank']:.2f}x, "
              f"flow rate {row['mass_flow_rate_kg_s']:.5g} +- {row['flow_rate_noise_3sigma_kg_s']:.2g} kg/s, "
              f"within noise of 1 rank: {row['within_noise']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
