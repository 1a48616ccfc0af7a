"""Benchmark: the validation tier's recirculating silo, started from the flat-bottom silo's settled 270 mm assembly
(about 59,000 two-sphere clumps), on 1 and on 2 MPI ranks: which gives the shorter wall time on this machine.

The internal-flow run of ``config/validation.yaml`` is cut to a short stretch of recirculation (``--seconds`` of
simulated time, the feeder running) and started twice from the same assembly, serially and with ``mpirun -np 2`` on
the grid the deck generator chooses. The machine must be otherwise idle. Reports the wall and CPU time of each and the
speed-up over the serial run measured in the same benchmark; with two runs side by side on 2 cores, one rank each
gives at most the serial run's wall time per run, so 2 ranks pay off only for a part that has a single run.

A flat-bottom silo run that a part's deadline stopped before its fill settled (no assembly yet) is measured on its own
continuation instead: copies of the run resume from its newest restart file for ``--wall`` seconds each, on 1 rank
alone, on 2 ranks, and as two copies side by side on 1 rank each (how a part of two runs uses the 2 cores). Each
copy's rate is its steps per second of the engine's own clock (the thermo ``cpu`` column of its resumed run), which
leaves out reading the restart file; the pair's throughput is the sum of its two rates.

Run with ``python -m tests.bench.bench_mpi_assembly ASSEMBLY_RUN_DIR [results/bench/mpi_assembly.csv]``, where
``ASSEMBLY_RUN_DIR`` is a finished or part-run flat-bottom silo run of the tier (its folder holds the settled fill,
e.g. ``results/validation/results/silo_flat/<run>``); about 15 minutes on 2 cores at the default 0.05 s, or three
times ``--wall`` for a continuation.
"""

from __future__ import annotations

import argparse
import csv
import multiprocessing
import resource
import shutil
import tempfile
import time
from pathlib import Path

from siloflow.engines.config import load_config_file, validate_config
from siloflow.engines.deadline import PartDeadline, until
from siloflow.engines.interface import EngineOptions, engine_for
from siloflow.engines.layout import RUN_RECORD
from siloflow.engines.liggghts.run import attempt_logs
from siloflow.engines.liggghts.thermo import ThermoProgress
from siloflow.engines.run_files import FAILED_ATTEMPTS
from siloflow.model.cases import case_for_run
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


#: The continuation's variants: a name and the MPI ranks of each copy run side by side.
CONTINUATIONS = (("1 rank", (1,)), ("2 ranks", (2,)), ("2 runs x 1 rank", (1, 1)))


def thermo_rate(log_text: str) -> float:
    """Steps per second of the engine's clock over the last ``run`` of a LIGGGHTS log: between its first and last
    thermo rows (:class:`siloflow.engines.liggghts.thermo.ThermoProgress`), whose ``cpu`` restarts with each run."""
    parser = ThermoProgress()
    rows = [row for row in (*parser.feed(log_text), *parser.flush()) if row.cpu is not None]
    starts = [i for i in range(1, len(rows)) if rows[i].cpu < rows[i - 1].cpu]
    rows = rows[starts[-1] if starts else 0:]
    if len(rows) < 2 or rows[-1].cpu <= rows[0].cpu:
        raise ValueError("the log's last run has fewer than two thermo rows with time between them")
    return (rows[-1].step - rows[0].step) / (rows[-1].cpu - rows[0].cpu)


def _continue(run_dir: Path, ranks: int, wall_s: float) -> None:
    """Resume the copy ``run_dir`` of a stopped silo run on ``ranks`` ranks for ``wall_s`` seconds (a child's body)."""
    raw = load_config_file(REPO_ROOT / "config" / "validation.yaml")
    config = validate_config(raw)
    case = case_for_run(config, "silo_flat", run_dir.name)
    try:
        with until(time.time() + wall_s, run_dir.name):
            engine_for(config, "silo_flat").run(case, run_dir, EngineOptions(mpi_ranks=ranks))
    except PartDeadline:
        pass


def continuation_rows(run_dir: Path, scratch: Path, wall_s: float) -> list[dict]:
    """Each variant of :data:`CONTINUATIONS` on copies of the stopped run ``run_dir`` (its dumps left behind): the
    rate of each copy and their sum."""
    rows = []
    for name, ranks in CONTINUATIONS:
        copies = []
        for index, _ in enumerate(ranks):
            copy = scratch / f"{name.replace(' ', '_')}_{index}" / run_dir.name
            shutil.copytree(run_dir, copy, ignore=shutil.ignore_patterns("dumps", FAILED_ATTEMPTS, RUN_RECORD))
            (copy / "dumps").mkdir()
            copies.append(copy)
        children = [multiprocessing.Process(target=_continue, args=(copy, r, wall_s)) for copy, r in zip(copies, ranks)]
        for child in children:
            child.start()
        for child in children:
            child.join()
        rates = [thermo_rate(attempt_logs(copy)[-1].read_text(errors="replace")) for copy in copies]
        rows.append({"variant": name, "mpi_ranks": "+".join(map(str, ranks)), "steps_per_s_each": " ".join(
            f"{rate:.2f}" for rate in rates), "steps_per_s_total": sum(rates)})
    alone = rows[0]["steps_per_s_total"]
    for row in rows:
        row["throughput_vs_1_rank"] = row["steps_per_s_total"] / alone
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("assembly", type=Path, help="the flat-bottom silo run whose settled fill the runs start from")
    parser.add_argument("output", type=Path, nargs="?", default=Path("results/bench/mpi_assembly.csv"))
    parser.add_argument("--seconds", type=float, default=0.05, help="simulated time of each run (s)")
    parser.add_argument("--wall", type=float, default=300.0,
                        help="wall time of each continuation of a run stopped before its fill settled (s)")
    args = parser.parse_args(argv)
    if not (args.assembly / RUN_RECORD).is_file():
        with tempfile.TemporaryDirectory() as scratch:
            rows = continuation_rows(args.assembly, Path(scratch), args.wall)
        _write(rows, args.output)
        for row in rows:
            print(f"{row['variant']}: {row['steps_per_s_each']} steps/s ({row['steps_per_s_total']:.2f} together), "
                  f"{row['throughput_vs_1_rank']:.2f}x one rank alone")
        return 0
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
    _write(rows, args.output)
    for row in rows:
        print(f"{row['mpi_ranks']} rank(s), {row['clumps']} clumps, {row['simulated_s']:.3f} s simulated: "
              f"{row['wall_time_s']:.1f} s wall, {row['cpu_time_s']:.1f} s CPU, "
              f"speed-up {row['speedup_vs_1_rank']:.2f}x "
              f"(efficiency {row['parallel_efficiency']:.2f})")
    return 0


def _write(rows: list[dict], output: Path) -> None:
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


if __name__ == "__main__":
    raise SystemExit(main())
