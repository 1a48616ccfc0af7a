"""What a configuration will cost before it runs: every run it defines, estimated, and the disk check.

``python -m engines.planning config/thesis.yaml`` (``make estimate CONFIG=...``) prints the table. The workflow
refuses to start runs whose estimated output does not fit on the disk of ``results/`` (:func:`ensure_disk_space`),
unless ``estimates.disk_check`` is false.
"""

from __future__ import annotations

import dataclasses
import shutil
import statistics
import sys
from pathlib import Path

from engines.cases import CASE_BUILDERS
from engines.config import load_config
from engines.interface import engine_for
from engines.estimates import (
    CostModel,
    RunEstimate,
    check_disk_space,
    estimate_case,
    estimate_rows,
    format_bytes,
    format_duration,
    total_dump_bytes,
)
from engines.layout import RUN_RECORD, run_dir

def cost_model(config: dict) -> CostModel:
    """The cost model of a validated configuration (``estimates`` section)."""
    section = config["estimates"]
    return CostModel(seconds_per_sphere_step=section["seconds_per_sphere_step"],
                     settle_fraction=section["settle_fraction"])


def config_estimates(config: dict, model: CostModel | None = None) -> list[RunEstimate]:
    """Estimates of every engine run a validated configuration defines (calibration sweep, silo runs with their
    parametric variants, recirculation runs, blender runs), in that order; ``model`` defaults to the config's."""
    model, ranks = model or cost_model(config), config["engine"]["mpi_ranks"]
    return [estimate_case(case, ranks, model) for build in CASE_BUILDERS.values() for case in build(config).values()]


def measured_cost_model(config: dict, estimates: list[RunEstimate], results: str | Path) -> tuple[CostModel, int] | None:
    """The config's cost model with the CPU time per sphere-step measured on this machine, and from how many runs.

    The measure is the median over the runs of ``estimates`` that have finished under ``results`` (their run
    record written), each timed by its own engine (:meth:`engines.interface.Engine.measured_cost`); None when
    none has finished or none left timing.
    """
    measured = []
    for estimate in estimates:
        directory = run_directory(results, estimate)
        if (directory / RUN_RECORD).exists():
            value = engine_for(config, estimate.kind).measured_cost(directory)
            if value is not None:
                measured.append(value)
    if not measured:
        return None
    model = dataclasses.replace(cost_model(config), seconds_per_sphere_step=statistics.median(measured))
    return model, len(measured)


def run_directory(results: str | Path, estimate: RunEstimate) -> Path:
    """Directory of the run an estimate describes."""
    return Path(run_dir(estimate.kind, estimate.run_id, str(results)))


def pending(estimates: list[RunEstimate], results: str | Path) -> list[RunEstimate]:
    """The estimates whose run has not finished yet (no ``run.json``)."""
    return [e for e in estimates if not (run_directory(results, e) / RUN_RECORD).exists()]


def free_bytes(path: str | Path) -> int:
    """Free space on the file system that holds ``path`` (or its nearest existing parent) [bytes]."""
    path = Path(path).resolve()
    while not path.exists():
        path = path.parent
    return shutil.disk_usage(path).free


def ensure_disk_space(estimates: list[RunEstimate], results: str | Path, free: int | None = None) -> float:
    """Refuse (:class:`engines.estimates.InsufficientDiskSpace`) when the pending runs would not fit on the disk
    of ``results``; returns the margin in bytes. ``free`` overrides the measured free space (tests)."""
    waiting = pending(estimates, results)
    names = ", ".join(e.run_id for e in waiting[:3]) + (f" and {len(waiting) - 3} more" if len(waiting) > 3 else "")
    available = free_bytes(results) if free is None else free
    return check_disk_space(total_dump_bytes(waiting), available, str(Path(results).resolve()), names or "(none)")


def check_run_disk_space(config: dict, estimate: RunEstimate, run_dir: str | Path) -> float | None:
    """Before one engine run: refuse when its estimated output exceeds the free space where it writes
    (unless ``estimates.disk_check`` is false); returns the margin in bytes, None when not checked."""
    if not config["estimates"]["disk_check"]:
        return None
    return check_disk_space(estimate.dump_bytes, free_bytes(run_dir), str(Path(run_dir).resolve()), estimate.run_id)


def preflight(config: dict, estimate: RunEstimate, run_dir: str | Path) -> str:
    """Check the disk for one engine run (:func:`check_run_disk_space`) and say what it will cost, for its log."""
    check_run_disk_space(config, estimate, run_dir)
    return (f"estimate for {estimate.run_id}: {estimate.clumps} clumps, {estimate.steps} steps "
            f"({estimate.simulated_time_s:.3g} s simulated), about {format_duration(estimate.wall_time_s)} on "
            f"{estimate.mpi_ranks} rank(s) and {format_bytes(estimate.dump_bytes)} of dumps")


def estimate_table(estimates: list[RunEstimate]) -> str:
    """The estimate rows as an aligned text table."""
    rows = estimate_rows(estimates)
    columns = list(rows[0])
    cells = [[str(row[c]) if not isinstance(row[c], float) else f"{row[c]:.3g}" for c in columns] for row in rows]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(columns)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(columns, widths))]
    lines += ["  ".join(v.ljust(w) for v, w in zip(r, widths)) for r in cells]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Print the estimate table of a configuration file and the free space of ``results/``."""
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) not in (1, 2):
        print("usage: python -m engines.planning CONFIG [RESULTS_DIR]", file=sys.stderr)
        return 2
    config = load_config(argv[0])
    results = argv[1] if len(argv) == 2 else "results"
    estimates = config_estimates(config)
    model = cost_model(config)
    measured = measured_cost_model(config, estimates, results)
    if measured is None:
        source = "estimates.seconds_per_sphere_step of the config: no run of it has finished here yet"
    else:
        model, count = measured
        estimates = config_estimates(config, model)
        source = (f"measured on this machine, the median of {count} finished run(s) under {results}/; the config "
                  f"says {cost_model(config).seconds_per_sphere_step:.3g}")
    print(f"Estimates for {argv[0]} (cost model: {model.seconds_per_sphere_step:.3g} s per sphere and step on one "
          f"core, {source}; {config['engine']['mpi_ranks']} MPI rank(s) per run; settling at "
          f"{model.settle_fraction:.0%} of its longest time)")
    print(estimate_table(estimates))
    waiting = pending(estimates, results)
    print(f"\n{len(waiting)} of {len(estimates)} runs still to do; they need about "
          f"{format_bytes(total_dump_bytes(waiting))}; {format_bytes(free_bytes(results))} free for {results}/")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
