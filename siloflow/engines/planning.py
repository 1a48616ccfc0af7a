"""What a configuration will cost before it runs, and what its finished runs then took.

``siloflow estimate --config CONFIG`` (``make estimate CONFIG=...``) prints the estimate of every run the
configuration defines and, once some of them have finished in its results folder, each one's estimated CPU time
against what its engine measured (:func:`comparison_rows`, :func:`estimate_report`). The workflow refuses to start runs whose estimated output
does not fit on the disk of ``results/`` (:func:`ensure_disk_space`), unless ``estimates.disk_check`` is false.
"""

from __future__ import annotations

import dataclasses
import math
import shutil
import statistics
from pathlib import Path

from siloflow.model.record import RunRecordError, read_run_record
from siloflow.model.cases import cases_of, run_roles
from siloflow.model.cases.common import engine_kind
from siloflow.model.cases.kinds import configured_kinds
from siloflow.engines.config import ENGINE_ONLY_KEYS
from siloflow.engines.interface import engine_for
from siloflow.model.cost import CostModel, MeasuredWork, RunEstimate, on_ranks
from siloflow.engines.estimates import (
    check_disk_space,
    estimate_case,
    estimate_rows,
    format_bytes,
    format_duration,
    total_dump_bytes,
)
from siloflow.engines.layout import RUN_RECORD, run_dir
from siloflow.engines.validation_groups import (PART_CORES, assign, cost_lines, group_costs, lone_runs, part_costs,
                                               split_groups)


def cost_model(config: dict) -> CostModel:
    """The cost model of a validated configuration (``estimates`` section)."""
    section = config["estimates"]
    return CostModel(seconds_per_sphere_step=section["seconds_per_sphere_step"],
                     settle_fraction=section["settle_fraction"],
                     parallel_efficiency=section["parallel_efficiency"],
                     kind_seconds_per_sphere_step=dict(section["seconds_per_sphere_step_by_case"]))


def config_estimates(config: dict, model: CostModel | None = None) -> list[RunEstimate]:
    """Estimates of every engine run a validated configuration defines (calibration sweep, silo runs with their
    parametric variants, recirculation runs, blender runs, each with its replicates), in that order; ``model``
    defaults to the config's."""
    model, ranks = model or cost_model(config), config["engine"]["mpi_ranks"]
    return [estimate_case(case, ranks, model) for kind in configured_kinds() for case in cases_of(config, kind).values()]


def run_priorities(estimates: list[RunEstimate]) -> dict[str, int]:
    """The Snakemake priority of each case kind's engine runs: the kind whose longest run costs most comes first.

    With two runs at a time, the run that starts last sets the end: starting the longest runs first lets the short
    ones fill the other core meanwhile instead of leaving one core idle at the end. Snakemake takes priorities per
    rule, so a kind ranks by its longest run.

    Parameters
    ----------
    estimates : list of RunEstimate
        The runs of a configuration (:func:`config_estimates`).

    Returns
    -------
    dict
        ``{kind: priority}`` with priorities 1, 2, ... in the order of the kinds' longest estimated runs (CPU s);
        a kind without runs is absent (its rule takes Snakemake's default, 0).
    """
    longest: dict[str, float] = {}
    for estimate in estimates:
        longest[estimate.kind] = max(longest.get(estimate.kind, 0.0), estimate.core_seconds)
    return {kind: rank for rank, kind in enumerate(sorted(longest, key=lambda kind: (longest[kind], kind)), start=1)}


def run_directory(results: str | Path, estimate: RunEstimate) -> Path:
    """Directory of the run an estimate describes."""
    return Path(run_dir(estimate.kind, estimate.run_id, str(results)))


def measured_runs(config: dict, estimates: list[RunEstimate],
                  results: str | Path) -> list[tuple[RunEstimate, MeasuredWork]]:
    """The runs of ``estimates`` that have finished under ``results`` (their run record written) and left timing,
    each with the CPU time and sphere-steps its own engine measured (:meth:`siloflow.engines.interface.Engine.measured_work`),
    in the order of ``estimates``."""
    measured = []
    for estimate in estimates:
        directory = run_directory(results, estimate)
        if (directory / RUN_RECORD).exists():
            work = engine_for(config, estimate.kind).measured_work(directory)
            if work is not None:
                measured.append((estimate, work))
    return measured


def measured_cost_model(config: dict, estimates: list[RunEstimate], results: str | Path) -> tuple[CostModel, int] | None:
    """The config's cost model with the CPU time per sphere-step measured on this machine, and from how many runs.

    The measure is the median over the finished runs (:func:`measured_runs`) of each run's CPU time over its
    sphere-steps, both as its engine measured them (the sphere count taken over time); None when none has finished
    or none left timing.
    """
    measured = measured_runs(config, estimates, results)
    if not measured:
        return None
    return calibrated_model(cost_model(config), measured), len(measured)


def calibrated_model(model: CostModel, measured: list[tuple[RunEstimate, MeasuredWork]]) -> CostModel:
    """``model`` with the median over ``measured`` (at least one run) of each run's CPU seconds per sphere-step, and
    for each case kind with a finished run the median over that kind's runs: a kind not measured yet keeps the cost
    the configuration gives it, or takes the overall median when it gives none."""
    median = statistics.median(work.seconds_per_sphere_step for _, work in measured)
    by_kind = {kind: statistics.median(work.seconds_per_sphere_step for estimate, work in measured
                                       if estimate.kind == kind)
               for kind in dict.fromkeys(estimate.kind for estimate, _ in measured)}
    return dataclasses.replace(model, seconds_per_sphere_step=median,
                               kind_seconds_per_sphere_step={**model.kind_seconds_per_sphere_step, **by_kind})


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
    """Refuse (:class:`siloflow.engines.estimates.InsufficientDiskSpace`) when the pending runs would not fit on the disk
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
            f"({estimate.simulated_time_s:.3g} s simulated, {estimate.sphere_steps:.3g} sphere-steps), about "
            f"{format_duration(estimate.wall_time_s)} on {estimate.mpi_ranks} rank(s) and "
            f"{format_bytes(estimate.dump_bytes)} of dumps")


# ---------------------------------------------------------------------------------------------- estimate vs measured


#: Columns of :func:`comparison_rows`, in order.
COMPARISON_COLUMNS = ("run", "kind", "estimated_cpu_s", "measured_cpu_s", "ratio", "estimated_sphere_steps",
                      "measured_sphere_steps", "work_ratio", "steps_ratio", "measured_rate")


def run_steps(results: str | Path, estimate: RunEstimate) -> int | None:
    """The last step a finished run reached, from its run record (the largest ``step`` of its stages), or None when
    the record is unreadable or names no step."""
    try:
        record = read_run_record(run_directory(results, estimate) / RUN_RECORD)
    except (OSError, RunRecordError):
        return None
    steps = [stage["step"] for stage in record.stages.values() if isinstance(stage.get("step"), (int, float))]
    return int(max(steps)) if steps else None


def comparison_rows(measured: list[tuple[RunEstimate, MeasuredWork]],
                    steps: list[int | None] | None = None) -> list[dict]:
    """Estimated against measured CPU time, one row per finished run.

    Columns (:data:`COMPARISON_COLUMNS`): run, kind, estimated_cpu_s (the estimate's core time, CPU s),
    measured_cpu_s (CPU s the engine timed), ratio (estimated over measured CPU time, -), estimated_sphere_steps and
    measured_sphere_steps (work, sphere-steps), work_ratio (estimated over measured work, -: how well the estimate
    counted the spheres and steps, whatever the machine's speed), steps_ratio (estimated steps over those the run
    made, -; nan when ``steps`` does not give them: chiefly how long the fill took to settle) and measured_rate
    (sphere-steps per CPU second the run achieved, 1/s). ``ratio`` is ``work_ratio`` times the measured over the
    estimated time per sphere-step.

    Parameters
    ----------
    measured : list of (RunEstimate, MeasuredWork)
        Each finished run's estimate and measurement (:func:`measured_runs`).
    steps : list of int or None, optional
        The steps each run made (:func:`run_steps`), in the same order.

    Returns
    -------
    list of dict
    """
    steps = steps if steps is not None else [None] * len(measured)
    if len(steps) != len(measured):
        raise ValueError(f"steps has {len(steps)} entries for {len(measured)} runs")
    rows = []
    for (estimate, work), made in zip(measured, steps):
        rows.append({
            "run": estimate.run_id,
            "kind": estimate.kind,
            "estimated_cpu_s": estimate.core_seconds,
            "measured_cpu_s": work.cpu_seconds,
            "ratio": estimate.core_seconds / work.cpu_seconds if work.cpu_seconds > 0 else math.nan,
            "estimated_sphere_steps": estimate.sphere_steps,
            "measured_sphere_steps": work.sphere_steps,
            "work_ratio": estimate.sphere_steps / work.sphere_steps if work.sphere_steps > 0 else math.nan,
            "steps_ratio": estimate.steps / made if made else math.nan,
            "measured_rate": work.sphere_steps / work.cpu_seconds if work.cpu_seconds > 0 else math.nan,
        })
    return rows


def comparison_total(measured: list[tuple[RunEstimate, MeasuredWork]]) -> tuple[float, float, float]:
    """Estimated and measured CPU time of the finished runs together (core-hours) and their ratio (-; nan without
    measured time)."""
    estimated = math.fsum(estimate.core_seconds for estimate, _ in measured) / 3600.0
    taken = math.fsum(work.cpu_seconds for _, work in measured) / 3600.0
    return estimated, taken, estimated / taken if taken > 0 else math.nan


def _cell(value) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.3g}"
    return str(value)


def _table(rows: list[dict]) -> str:
    """Rows of equal keys as an aligned text table, floats to 3 significant digits."""
    columns = list(rows[0])
    cells = [[_cell(row[c]) for c in columns] for row in rows]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(columns)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(columns, widths)).rstrip()]
    lines += ["  ".join(v.ljust(w) for v, w in zip(r, widths)).rstrip() for r in cells]
    return "\n".join(lines)


def estimate_table(estimates: list[RunEstimate]) -> str:
    """The estimate rows as an aligned text table."""
    return _table(estimate_rows(estimates))


def comparison_table(rows: list[dict]) -> str:
    """The comparison rows as an aligned text table, CPU times formatted (s, min, h)."""
    shown = [{**row, "estimated_cpu_s": format_duration(row["estimated_cpu_s"]),
              "measured_cpu_s": format_duration(row["measured_cpu_s"])} for row in rows]
    names = {"estimated_cpu_s": "estimated_cpu", "measured_cpu_s": "measured_cpu"}
    return _table([{names.get(key, key): value for key, value in row.items()} for row in shown])


def comparison_report(measured: list[tuple[RunEstimate, MeasuredWork]], steps: list[int | None],
                      apriori: CostModel, calibrated: CostModel | None = None) -> str:
    """The comparison the planner prints: a row per finished run (:func:`comparison_rows`, estimated with
    ``apriori``, the config's cost model, as before the runs) and a total line; with ``calibrated`` (the model with
    the measured median time per sphere-step) a second total line, as the table now estimates."""
    rows = comparison_rows(measured, steps)
    estimated, taken, ratio = comparison_total(measured)
    lines = [
        f"Estimated (with the config's {apriori.seconds_per_sphere_step:.3g} s per sphere-step, as before the runs) "
        f"against measured CPU time of the {len(measured)} finished run(s); ratio = estimated / measured",
        comparison_table(rows),
        f"total: estimated {estimated:.3g} core-h, measured {taken:.3g} core-h, ratio {ratio:.3g}",
    ]
    if calibrated is not None:
        scale = calibrated.seconds_per_sphere_step / apriori.seconds_per_sphere_step
        lines.append(f"total with the measured median {calibrated.seconds_per_sphere_step:.3g} s per sphere-step: "
                     f"estimated {estimated * scale:.3g} core-h, ratio {ratio * scale:.3g}")
    return "\n".join(lines)


def group_runs(config: dict, estimates: list[RunEstimate]) -> dict[str, list[RunEstimate]]:
    """The runs each validation group makes, of a configuration's ``estimates``
    (:func:`siloflow.engines.validation_groups.assign`); a run that would leave a part's cores idle through all its
    parts is estimated on the ranks that use them (:func:`siloflow.engines.validation_groups.lone_runs`) where its
    engine takes MPI ranks, and the workflow runs it so (:func:`run_ranks`)."""
    roles = {run: role for kind in configured_kinds() for run, role in run_roles(config, kind).items()}
    made = assign(estimates, roles)
    # the runs beside each other as the parts run them, whatever their engine; only those an engine runs on MPI
    # ranks take the idle cores
    wider = lone_runs(made)
    model = cost_model(config)
    return {name: [on_ranks(e, wider[e.run_id], model) if e.run_id in wider and _takes_ranks(config, e.kind) else e
                   for e in runs]
            for name, runs in made.items()}


def _takes_ranks(config: dict, kind: str) -> bool:
    """Whether the engine that runs case kind ``kind`` runs on MPI ranks (``engine.mpi_ranks`` is its own)."""
    return ("engine", "mpi_ranks") in ENGINE_ONLY_KEYS[engine_kind(config, kind)]


def run_ranks(made: dict[str, list[RunEstimate]]) -> dict[str, int]:
    """``{run id: MPI ranks}`` of the validation groups' runs (:func:`group_runs`): what the workflow gives each run
    step (its threads) and so its engine."""
    return {e.run_id: e.mpi_ranks for runs in made.values() for e in runs}


def estimate_report(config: dict, label: str, results: str | Path, cores: int) -> str:
    """The estimate the command line prints for a validated configuration (``label`` names it): the estimate table,
    the cost of each validation group on ``cores`` cores, the free space of ``results`` and, for the runs that have
    finished there, estimated against measured CPU time."""
    apriori = cost_model(config)
    estimates = config_estimates(config, apriori)
    measured = measured_runs(config, estimates, results)
    model = apriori
    if not measured:
        source = "estimates.seconds_per_sphere_step of the config: no run of it has finished here yet"
    else:
        model = calibrated_model(apriori, measured)
        source = (f"measured on this machine, the median of {len(measured)} finished run(s) under {results}/; the "
                  f"config says {apriori.seconds_per_sphere_step:.3g}")
    # the parts and each run's ranks come from the config's own cost model, as the workflow's, so that measuring a
    # run never moves a run to another part
    planned = group_runs(config, estimates)
    parts, ranks = split_groups(planned), run_ranks(planned)
    made = planned if not measured else {name: [on_ranks(e, ranks[e.run_id], model) for e in runs]
                                         for name, runs in group_runs(config, config_estimates(config, model)).items()}
    lines = [f"Estimates for {label} (cost model: {model.seconds_per_sphere_step:.3g} s per sphere-step on one "
             f"core, {source}; {config['engine']['mpi_ranks']} MPI rank(s) per run, a validation run alone through "
             f"its parts on {PART_CORES}; settling at {model.settle_fraction:.0%} of its longest time)",
             estimate_table([e for runs in made.values() for e in runs]), ""]
    lines += cost_lines(group_costs(made, cores), cores, part_costs(parts, made, cores))
    waiting = pending(estimates, results)
    lines.append(f"\n{len(waiting)} of {len(estimates)} runs still to do; they need about "
                 f"{format_bytes(total_dump_bytes(waiting))}; {format_bytes(free_bytes(results))} free for {results}/")
    if measured:
        steps = [run_steps(results, estimate) for estimate, _ in measured]
        lines += ["", comparison_report(measured, steps, apriori, model)]
    return "\n".join(lines)
