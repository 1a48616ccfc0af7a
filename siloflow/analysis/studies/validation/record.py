"""The validation record kept in the repository (``docs/validation/``): each group's table rows, the runs behind
them, and the page that renders them.

A group's record is three things the pipeline writes (``make validate GROUP=<name>``): ``table.csv`` (its rows of
the validation table, :data:`siloflow.analysis.studies.validation.rows.COLUMNS`), ``runs.csv`` (one provenance row per run,
:data:`RUN_COLUMNS`) and a few plots. :func:`record_page` renders every group's record as one Markdown page, which
opens with the study it compares with (:data:`STUDY_PARAGRAPH`), with each group's freshness against the
configuration and, for the rows the scale does not show, what would show them and at what cost. Pure: the readers
and writers are :mod:`siloflow.analysis.io.validation_record`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from siloflow.model.checks import number_or_nan
from siloflow.model.record import RunRecord
from siloflow.analysis.studies.validation.findings import Finding
from siloflow.analysis.studies.validation.rows import NO, UNKNOWN, YES, plus_minus
from siloflow.analysis.studies.validation.scale import ScaleVerdict

__all__ = ["STUDY_PARAGRAPH", "RUN_COLUMNS", "GroupRecord", "provenance_row", "run_wall_time", "simulated_time",
           "record_page"]

#: The page's opening paragraph: the study the record compares with, by the thesis's own chapters and sections.
STUDY_PARAGRAPH = (
    "The record compares siloflow with a published study: a PhD thesis on DEM and PIV of HDPE pellet flow and "
    "blending in planar silos and a multi-flow blender, done with EDEM 2.7; siloflow runs the study's method on "
    "LIGGGHTS and YADE instead ([What siloflow reproduces](../index.md#what-siloflow-reproduces)). The pellets are "
    "multisphere clumps with rolling friction (§4.2), calibrated by Jenike direct shear tests (ch. 4: the calibration "
    "groups); the flat-bottom silo is validated against PIV (ch. 3 and 5: the silo groups); blending in the "
    "recirculating silo is measured by residence time distributions and variance reduction ratios (ch. 6: the "
    "blending group); the multi-flow blender has a cone-in-cone insert and a blending tube (ch. 7 and App. A: the "
    "blender group). Section numbers are the thesis's. The \"study\" column quotes the study's figure or finding "
    "that a row is judged against, \"-\" where the study gives none.")

#: The columns of a group's ``runs.csv``, in order.
RUN_COLUMNS = ("run_id", "group", "case", "engine", "engine_version", "seeds", "commit", "simulated_time_s", "wall_time_s",
               "earlier_attempts_s", "cores", "date")


@dataclass(frozen=True)
class GroupRecord:
    """One group's record as read back.

    Attributes
    ----------
    rows : list of dict
        Its validation table rows.
    runs : list of dict
        Its provenance rows (:data:`RUN_COLUMNS`).
    plots : list of str
        Its plot file names, relative to the group's folder.
    products : list of str
        The products of its runs that other groups read, by their paths in the workflow's working directory
        (:data:`siloflow.engines.layout.READ_PRODUCTS`).
    """

    rows: list = field(default_factory=list)
    runs: list = field(default_factory=list)
    plots: list = field(default_factory=list)
    products: list = field(default_factory=list)


def simulated_time(record: RunRecord) -> float:
    """The simulated time a run reached (s): its latest stage's step times its time step, or where a stage gives no
    step, its ``time``; NaN when no stage gives either. The step comes first because a run resumed from a restart
    file counts its steps on while LIGGGHTS starts its clock again at zero."""
    times = []
    for stage in record.stages.values():
        step = stage.get("step")
        if isinstance(step, (int, float)):
            times.append(float(step) * record.timestep_s)
        elif isinstance(stage.get("time"), (int, float)):
            times.append(float(stage["time"]))
    return max(times) if times else math.nan


def provenance_row(record: RunRecord, group: str, engine_version: str, seeds: Sequence[int], commit: str, wall_time_s: float,
                   earlier_attempts_s: float, date: str) -> dict:
    """One row of ``runs.csv`` for a finished run.

    Parameters
    ----------
    record : RunRecord
        The run's record (run id, case kind, engine, MPI ranks, stages).
    group : str
        The validation group that makes the run, or its part as `make validate GROUP=` names it when the group runs
        in parts (a group's rows may also draw on the runs of a group it reads).
    engine_version : str
        The engine's installed version.
    seeds : sequence of int
        The random seeds the engine was given.
    commit : str
        The commit of siloflow's code that wrote the record (``-dirty`` appended with uncommitted changes).
    wall_time_s : float
        Wall time of the run step (s), Snakemake's benchmark of it: its last attempt only.
    earlier_attempts_s : float
        Time its attempts before the last took (s): those resumed from its restart files and those set aside to
        start afresh (:meth:`siloflow.engines.interface.Engine.earlier_attempts_seconds`); 0 when it ran in one go.
    date : str
        When the run finished (ISO 8601 date).
    """
    return {"run_id": record.run_id, "group": group, "case": record.case, "engine": record.engine, "engine_version": engine_version,
            "seeds": " ".join(str(int(seed)) for seed in seeds), "commit": commit,
            "simulated_time_s": simulated_time(record), "wall_time_s": float(wall_time_s),
            "earlier_attempts_s": float(earlier_attempts_s), "cores": int(record.mpi_ranks), "date": date}


def run_wall_time(run: Mapping) -> float:
    """Wall time a recorded run took over all its attempts (s): the run step's last attempt, plus those before it (a
    record written before ``earlier_attempts_s`` existed counts the last attempt only)."""
    earlier = number_or_nan(run.get("earlier_attempts_s"))
    return float(run["wall_time_s"]) + (earlier if math.isfinite(earlier) else 0.0)


def _attempts_sentence(runs: Sequence[Mapping]) -> str:
    """What the runs' attempts before their last took, when some run was interrupted or its record does not say."""
    earlier = [number_or_nan(run.get("earlier_attempts_s")) for run in runs]
    unknown = sum(not math.isfinite(value) for value in earlier)
    interrupted = [value for value in earlier if math.isfinite(value) and value > 0]
    sentences = []
    if interrupted:
        sentences.append(f"{len(interrupted)} run(s) were interrupted and run again; their attempts before the last "
                         f"took {_hours(math.fsum(interrupted))}, counted in the group's times above.")
    if unknown:
        sentences.append(f"For {unknown} run(s) the record gives the time of the last attempt only.")
    return " ".join(sentences)


def _value(row: Mapping) -> str:
    value, error = number_or_nan(row["value"]), number_or_nan(row["value_error"])
    if not math.isfinite(value):
        return "not measured"
    unit = f" {row['unit']}" if row["unit"] and row["unit"] != "-" else ""
    return plus_minus(value, error) + unit


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _hours(seconds: float) -> str:
    return f"{seconds / 3600.0:.2f} h"


def _difference_brief(difference) -> str:
    """A dimension that differs, in a table cell: its ratio to the study's, and its particle diameters where a floor in
    particle diameters bears on it (``fill height 0.37``, ``depth 0.31, 3.8 particle diameters``)."""
    brief = f"{difference.name.replace('_', ' ')} {difference.ratio:.2g}"
    if difference.run_diameters is not None and "particle diameters" in difference.threshold:
        brief += f", {difference.run_diameters:.1f} particle diameters"
    return brief


def findings_scale_section(verdicts: Sequence[tuple[Finding, ScaleVerdict]], config_name: str) -> list[str]:
    """The page's section on the study's findings: for each, whether ``config_name``'s runs are at the study's scale
    for it, judged from the configuration alone (:func:`siloflow.analysis.studies.validation.scale.scale_verdict`),
    with each dimension that differs as a ratio to the study's; then a count per chapter.

    Parameters
    ----------
    verdicts : sequence of (Finding, ScaleVerdict)
        Every finding of the study, in its order, with its verdict on the configuration's dimensions.
    config_name : str
        The configuration, as the page names it.

    Returns
    -------
    list of str
        Markdown lines.
    """
    chapters: dict[int, list[int]] = {}
    for finding, verdict in verdicts:
        counts = chapters.setdefault(finding.chapter, [0, 0])
        counts[0 if verdict.at_study_scale else 1] += 1
    lines = [
        "## The study's findings at this scale",
        "",
        f"Whether the runs of `{config_name}` are at the study's scale for each of its findings, judged from the "
        "configuration alone, never from a result: every dimension the finding depends on as a ratio to the study's "
        "(`validation.scale` of the configuration reference gives the bounds and their reasons), and in particle "
        "diameters. A finding the tier is not at the scale of can still be measured; its rows are results at another scale. The groups' rows below still carry one "
        "verdict each, \"scale shows\", judged from the runs themselves.",
        "",
        "| chapter | at the study's scale | not at the study's scale |",
        "|---|---|---|",
    ]
    lines += [f"| {chapter} | {counts[0]} | {counts[1]} |" for chapter, counts in sorted(chapters.items())]
    lines += ["", "| finding | thesis | at the study's scale | what differs (ratio to the study's) |", "|---|---|---|---|"]
    for finding, verdict in verdicts:
        differs = "; ".join(_difference_brief(difference) for difference in verdict.differences) or "-"
        if not verdict.definition_as_study:
            differs = f"{differs}; the quantity is not defined as the study's"
        lines.append(f"| {finding.id} | {finding.section} | {YES if verdict.at_study_scale else NO} | "
                     f"{_cell(differs)} |")
    return lines


def record_page(groups: Mapping[str, GroupRecord], status: Mapping[str, str], full_scale_core_s: Mapping[str, float],
                wall_s: Mapping[str, Mapping[str, float]], cores: int, config_name: str, full_scale_config: str,
                parts: Mapping[str, Sequence[str]] | None = None,
                estimated_core_s: Mapping[str, float] | None = None,
                findings_scale: Sequence[tuple[Finding, ScaleVerdict]] = ()) -> str:
    """The record's page (Markdown): the study it compares with (:data:`STUDY_PARAGRAPH`), then per group its
    freshness, runs and rows, and for each row the scale does not show, what scale would show it and what that scale
    costs.

    Parameters
    ----------
    groups : mapping
        ``{group: GroupRecord}`` of the groups recorded (absent: none yet).
    status : mapping
        ``{group: "complete" | "stale" | "missing"}`` for every group, in the order of the page
        (:func:`siloflow.engines.validation_groups.group_status`).
    full_scale_core_s : mapping
        ``{group: CPU s}`` of each group at the study's full scale (the estimate of ``full_scale_config``).
    wall_s : mapping
        ``{group: {part: s}}``: the wall time on ``cores`` cores of the runs each part of each group makes (a group in
        one part: its own name), from their measured times; a run of the record belongs to the group whose parts
        name it.
    cores : int
        The cores ``wall_s`` is for.
    config_name, full_scale_config : str
        The configuration the record comes from and the full-scale one, as the page names them.
    parts : mapping, optional
        ``{group: [part]}``: what `make validate GROUP=` takes for each group the configuration runs in parts (a
        group absent runs whole).
    estimated_core_s : mapping, optional
        ``{group: CPU s}``: each group's runs as ``config_name``'s cost model estimates them, shown beside the
        recorded core time with their ratio (a group absent: "-").
    findings_scale : sequence of (Finding, ScaleVerdict), optional
        The study's findings with whether ``config_name`` is at their scale (:func:`findings_scale_section`), shown
        before the groups; none: no such section.

    Returns
    -------
    str
    """
    lines = [
        "# The validation record",
        "",
        STUDY_PARAGRAPH,
        "",
        f"The study's comparisons at the validation scale (`{config_name}`), each as value ± standard error, written "
        "by `make validate GROUP=<name>` from the runs' own files: nothing here is typed in. \"Scale shows\" is judged "
        "from the run itself; the evidence column quotes the figures that decided. `make validate-status` lists the "
        "groups that are complete, stale (a run id no longer matches what the configuration plans) or missing.",
        "",
    ]
    if findings_scale:
        lines += [*findings_scale_section(findings_scale, config_name), "", "## The groups", ""]
    lines += [
        f"| group | status | runs it makes | core time | estimated (estimate / recorded) | wall time on {cores} cores "
        "(per part) | rows | shown at this scale |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, state in status.items():
        record, part_walls = groups.get(name, GroupRecord()), wall_s.get(name, {})
        made = [run for run in record.runs if run["group"] in part_walls]
        core = math.fsum(run_wall_time(run) * int(run["cores"]) for run in made)
        shown = sum(row["scale_shows"] == YES for row in record.rows)
        wall = ", ".join(_hours(s) if part == name else f"{part} {_hours(s)}" for part, s in part_walls.items())
        estimate = (estimated_core_s or {}).get(name, math.nan)
        estimated = "-" if not math.isfinite(estimate) else (
            f"{_hours(estimate)} ({estimate / core:.2f})" if made and core > 0 else _hours(estimate))
        lines.append(f"| {name} | {state} | {len(made)} | {_hours(core) if made else '-'} | {estimated} | "
                     f"{wall if made else '-'} | {len(record.rows)} | {shown} |")
    for name, state in status.items():
        record = groups.get(name)
        command = ", then ".join(f"`make validate GROUP={part}`" for part in (parts or {}).get(name, [name]))
        lines += ["", f"## {name}", ""]
        if record is None:
            lines.append(f"Not recorded yet: {command}.")
            continue
        if state != "complete":
            lines += [f"**Stale**: the runs below are not those `{config_name}` now plans; {command} brings the "
                      "record up to date.", ""]
        engines = sorted({f"{run['engine']} {run['engine_version']}" for run in record.runs})
        commits = sorted({str(run["commit"]) for run in record.runs})
        dates = sorted(str(run["date"]) for run in record.runs)
        cores = sorted({int(run["cores"]) for run in record.runs})
        lines.append(f"{len(record.runs)} runs on {', '.join(engines)}, {'/'.join(map(str, cores))} core(s) each, "
                     f"code {', '.join(commits)}, {dates[0]} to {dates[-1]}; run ids and seeds in "
                     f"[`{name}/runs.csv`]({name}/runs.csv)." if record.runs else "No runs recorded.")
        attempts = _attempts_sentence(record.runs)
        if attempts:
            lines[-1] += " " + attempts
        lines += ["", "| table | figure | case | value | study | scale shows | evidence |",
                  "|---|---|---|---|---|---|---|"]
        for row in record.rows:
            lines.append(f"| {_cell(row['group'])} | {_cell(row['figure'])} | {_cell(row['case'])} | "
                         f"{_cell(_value(row))} | {_cell(row['study_value'] or '-')} | {row['scale_shows']} | "
                         f"{_cell(row['evidence'])} |")
        unshown = [row for row in record.rows if row["scale_shows"] in (NO, UNKNOWN)]
        if unshown:
            cost = full_scale_core_s.get(name, math.nan)
            lines += ["", f"Rows this scale does not show ({len(unshown)}): each would need the scale its evidence "
                      f"names; the study's full scale (`{full_scale_config}`) runs this group in about "
                      f"{cost / 86400.0:.3g} core-days (`make estimate CONFIG={full_scale_config}`).", ""]
            lines += [f"- {_cell(row['figure'])} ({_cell(row['case'])}): {_cell(row['evidence'])}" for row in unshown]
        if record.plots:
            lines += [""] + [f"![{plot}]({name}/{plot})" for plot in record.plots]
    return "\n".join(lines) + "\n"
