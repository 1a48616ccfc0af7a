"""Benchmark: the validation tier's recirculating silo, started from the flat-bottom silo's settled 270 mm assembly
(about 59,000 two-sphere clumps), on 1 and on 2 MPI ranks: which gives the shorter wall time on this machine.

The internal-flow run of ``config/validation.yaml`` is cut to a short stretch of recirculation (``--seconds`` of
simulated time, the feeder running) and started twice from the same assembly, serially and with ``mpirun -np 2`` on
the grid the deck generator chooses. The machine must be otherwise idle. Reports the wall and CPU time of each and the
speed-up over the serial run measured in the same benchmark; with two runs side by side on 2 cores, one rank each
gives at most the serial run's wall time per run, so 2 ranks pay off only for a part that has a single run.

Run with ``python -m tests.bench.bench_mpi_assembly ASSEMBLY_RUN_DIR [results/bench/mpi_assembly.csv]``, where
``ASSEMBLY_RUN_DIR`` is a finished or part-run flat-bottom silo run of the tier (its folder holds the settled fill,
e.g. ``results/validation/results/silo_flat/<run>``); about 15 minutes on 2 cores at the default 0.05 s.
"""

from __future__ import annotations

import argparse
import csv
import resource
import tempfile
import time
from pathlib import Path

from siloflow.engines.config import load_config_file, validate_config
from siloflow.engines.interface import EngineOptions, engine_for
from siloflow.model.cases.silo_recirculation import build_recirculation_case
from tests.repo import REPO_ROOT

#: MPI ranks of the variants, the first the baseline.
RANKS = (1, 2)


def short_recirculation(seconds: float):
    """The tier's internal-flow recirculation case cut to about ``seconds`` of simulated time after the assembly."""
    raw = load_config_file(REPO_ROOT / "config" / "validation.yaml")
    section = raw["silo_recirculation"]
    # the nominal residence time of the tier's silo: contents over the feeder's volumetric rate W H / (B0 V)
    residence = section["width"] * section["fill_height"] / (section["outlet_width"] * section["feeder_velocity"])
    section.update(recirculations=seconds / residence, final_discharge=0.0, snapshots=[0],
                   tracer={**section["tracer"], "start_recirculations": 0.5 * seconds / residence})
    section["verification"] = {**section.get("verification", {}), "enabled": False}
    config = validate_config(raw)
    return build_recirculation_case(config, "internal_flow"), engine_for(config, "silo_recirculation")


def children_cpu_s() -> float:
    """CPU time of the finished child processes (the engine and its ranks) so far (s)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("assembly", type=Path, help="the flat-bottom silo run whose settled fill the runs start from")
    parser.add_argument("output", type=Path, nargs="?", default=Path("results/bench/mpi_assembly.csv"))
    parser.add_argument("--seconds", type=float, default=0.05, help="simulated time of each run (s)")
    args = parser.parse_args(argv)
    case, engine = short_recirculation(args.seconds)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for ranks in RANKS:
            run_dir = Path(scratch) / f"ranks_{ranks}"
            engine.write_inputs(case, run_dir, assembly_dir=args.assembly)
            cpu_before = children_cpu_s()
            start = time.perf_counter()
            record = engine.run(case, run_dir, EngineOptions(mpi_ranks=ranks))
            rows.append({"mpi_ranks": ranks, "clumps": record.n_clumps,
                         "simulated_s": case.silo.discharge_steps * record.timestep_s,
                         "wall_time_s": time.perf_counter() - start, "cpu_time_s": children_cpu_s() - cpu_before})
    serial = rows[0]
    for row in rows:
        row["speedup_vs_1_rank"] = serial["wall_time_s"] / row["wall_time_s"]
        row["parallel_efficiency"] = row["speedup_vs_1_rank"] / row["mpi_ranks"]
    args.output.parent.mkdir(parents=True, exist_ok=True)
    with open(args.output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    for row in rows:
        print(f"{row['mpi_ranks']} rank(s), {row['clumps']} clumps, {row['simulated_s']:.3f} s simulated: "
              f"{row['wall_time_s']:.1f} s wall, {row['cpu_time_s']:.1f} s CPU, "
              f"speed-up {row['speedup_vs_1_rank']:.2f}x "
              f"(efficiency {row['parallel_efficiency']:.2f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
