"""The validation record kept in the repository (``docs/validation/``): each group's table rows, the runs behind
them, and the page that renders them.

A group's record is what the pipeline writes (``make validate GROUP=<name>``): ``table.csv`` (its rows of the
validation table, :data:`siloflow.analysis.studies.validation.rows.COLUMNS`), ``runs.csv`` (one provenance row per
run, :data:`RUN_COLUMNS`), a few plots, the products its rows are computed from and what re-derives them.
:func:`record_page` renders every group's record as one Markdown page: the study it compares with
(:data:`STUDY_PARAGRAPH`), whether the study is reproduced (:func:`findings_section`), then each group's freshness
against the configuration and its rows. Pure: the readers and writers are
:mod:`siloflow.analysis.io.validation_record`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from siloflow.model.checks import number_or_nan
from siloflow.model.record import RunRecord
from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED
from siloflow.analysis.studies.validation.findings_summary import FindingStatus, chapter_counts, finding_statuses, STATUSES
from siloflow.analysis.studies.validation.rows import AT_SCALE, NO_FINDING, plus_minus
from siloflow.analysis.studies.validation.scale import ScaleVerdict

YES, NO = "yes", "no"

__all__ = ["STUDY_PARAGRAPH", "RUN_COLUMNS", "GroupRecord", "provenance_row", "run_wall_time", "simulated_time",
           "record_page", "findings_section", "hypotheses_section"]

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
               "earlier_attempts_s", "attempts", "attempt_times_s", "cores", "date")


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
        The products it keeps, by their paths in the workflow's working directory: those its rows are computed from
        and those of its runs other groups read (:data:`siloflow.engines.layout.READ_PRODUCTS`).
    derivation : dict or None
        What re-derives its rows from those products (case kind, configuration keys, products by name, the digest of
        the row code that wrote them); None for a record written before it was kept.
    """

    rows: list = field(default_factory=list)
    runs: list = field(default_factory=list)
    plots: list = field(default_factory=list)
    products: list = field(default_factory=list)
    derivation: dict | None = None


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
                   earlier_attempts_s: Sequence[float], date: str, attempts: int | None = None) -> dict:
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
        The commit of siloflow's code that ran the run (its last attempt's, :mod:`siloflow.engines.provenance`;
        ``-dirty`` appended with uncommitted changes).
    wall_time_s : float
        Wall time of the run step (s), Snakemake's benchmark of it: its last attempt only.
    earlier_attempts_s : sequence of float
        Time each of its attempts before the last took (s), oldest first: those set aside to start afresh and those
        resumed from its restart files (:meth:`siloflow.engines.interface.Engine.earlier_attempt_seconds`); none when
        it ran in one go.
    date : str
        When the run finished (ISO 8601 date).
    attempts : int, optional
        How many attempts the run step made (its provenance file's); None when the run does not say.
    """
    return {"run_id": record.run_id, "group": group, "case": record.case, "engine": record.engine, "engine_version": engine_version,
            "seeds": " ".join(str(int(seed)) for seed in seeds), "commit": commit,
            "simulated_time_s": simulated_time(record), "wall_time_s": float(wall_time_s),
            "earlier_attempts_s": math.fsum(earlier_attempts_s),
            "attempts": "" if attempts is None else int(attempts),
            "attempt_times_s": " ".join(f"{float(s):.1f}" for s in (*earlier_attempts_s, wall_time_s)), "cores": int(record.mpi_ranks), "date": date}


def run_wall_time(run: Mapping) -> float:
    """Wall time a recorded run took over all its attempts (s): the run step's last attempt, plus those before it (a
    record written before ``earlier_attempts_s`` existed counts the last attempt only)."""
    earlier = number_or_nan(run.get("earlier_attempts_s"))
    return float(run["wall_time_s"]) + (earlier if math.isfinite(earlier) else 0.0)


def earlier_attempt_times(run: Mapping) -> list[float]:
    """Wall time of each of a recorded run's attempts before its last (s), oldest first: those of
    ``attempt_times_s`` but the last; a record that lists no attempt times gives its ``earlier_attempts_s`` as one
    attempt (none when it is zero or unknown)."""
    listed = str(run.get("attempt_times_s") or "").split()
    if listed:
        return [float(value) for value in listed[:-1]]
    earlier = number_or_nan(run.get("earlier_attempts_s"))
    return [earlier] if math.isfinite(earlier) and earlier > 0 else []


def _attempts_sentence(runs: Sequence[Mapping]) -> str:
    """What the runs' attempts before their last took, when some run was interrupted or its record does not say."""
    earlier = [number_or_nan(run.get("earlier_attempts_s")) for run in runs]
    unknown = sum(not math.isfinite(value) for value in earlier)
    interrupted = [value for value in earlier if math.isfinite(value) and value > 0]
    sentences = []
    if interrupted:
        sentences.append(f"{len(interrupted)} run(s) ran in more than one attempt (carried over parts, or interrupted "
                         f"and run again); their attempts before the last took {_hours(math.fsum(interrupted))}, "
                         "counted in the group's times above.")
    if unknown:
        sentences.append(f"For {unknown} run(s) the record gives the time of the last attempt only.")
    return " ".join(sentences)


def _estimated(made: Sequence[Mapping], estimates: Mapping[str, float], planned: float = math.nan) -> str:
    """The cost model's estimate of a group's recorded runs beside their recorded core time: like with like, over the
    recorded runs the configuration still plans (a run whose id changed is another run). When it plans none of them,
    the estimate of the runs it plans instead (``planned``, CPU s), said to be of other runs; "-" without either."""
    held = [run for run in made if run["run_id"] in estimates]
    if not held:
        return "-" if not math.isfinite(planned) else f"{_hours(planned)} for the runs now planned, none recorded"
    estimate = math.fsum(estimates[run["run_id"]] for run in held)
    recorded = math.fsum(run_wall_time(run) * int(run["cores"]) for run in held)
    shown = f"{_hours(estimate)} ({estimate / recorded:.2f})" if recorded > 0 else _hours(estimate)
    return shown if len(held) == len(made) else f"{shown}, {len(held)} of {len(made)} runs"


def _run_commit(run: Mapping) -> str:
    """The code that ran a run, as the page gives it: a provenance row written before runs noted their own commit
    (no ``attempts``) holds the commit that wrote the record, which the page says."""
    commit = str(run["commit"])
    if str(run.get("attempts") or "") == "" and not commit.startswith("unknown"):
        return f"unknown (the record was written by {commit})"
    return commit


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
    brief = f"{difference.label} {difference.ratio:.2g}"
    if difference.run_diameters is not None and "particle diameters" in difference.threshold:
        brief += f", {difference.run_diameters:.1f} particle diameters"
    return brief


def _measured(row: Mapping) -> str:
    """A row's figure beside the study's, for the summary's lists."""
    return (f"{_cell(row['figure'])} ({_cell(row['case'])}): {_cell(_value(row))}; the study: {_cell(row['study'])}; "
            f"{_cell(row['agreement_reason'])}")


def _hypothesis_row(row: Mapping) -> str:
    """One compared row of a measured hypothesis, for the summary's list."""
    unit = f" {row['unit']}" if row["unit"] and row["unit"] != "-" else ""
    return (f"{row['finding']}: {_cell(row['figure'])} ({_cell(row['case'])}): "
            f"{plus_minus(row['base'], row['base_error'])} -> {plus_minus(row['variant'], row['variant_error'])}{unit}; "
            f"{_cell(row['reason'])}: **{row['moves']}**")


def _by_hypothesis(hypotheses: Sequence[Mapping]) -> dict[str, list[Mapping]]:
    """The recorded hypotheses' rows by hypothesis, in the order they come."""
    by_name: dict[str, list[Mapping]] = {}
    for row in hypotheses:
        by_name.setdefault(row["hypothesis"], []).append(row)
    return by_name


def _hypotheses_by_finding(hypotheses: Sequence[Mapping], planned: Mapping[str, Sequence[str]]) -> dict[str, list[str]]:
    """``{finding id: hypotheses}`` for the finding table: each recorded hypothesis beside the findings its rows judge,
    each planned one not recorded yet beside the findings it is for, marked so."""
    by_finding: dict[str, list[str]] = {}
    recorded = _by_hypothesis(hypotheses)
    for name, rows in recorded.items():
        for finding_id in dict.fromkeys(row["finding"].split(".")[0] for row in rows):
            by_finding.setdefault(finding_id, []).append(name)
    for name, findings in planned.items():
        for finding_id in findings if name not in recorded else ():
            by_finding.setdefault(finding_id, []).append(f"{name} (not recorded)")
    return by_finding


def hypotheses_section(hypotheses: Sequence[Mapping], planned: Mapping[str, Sequence[str]]) -> list[str]:
    """The measured hypotheses (:mod:`siloflow.analysis.studies.validation.hypothesis`): per hypothesis recorded, what
    it supposes, the one change, the pair's cost and every compared row with where the change moves it; the planned
    hypotheses not recorded yet, with the command that records each.

    Parameters
    ----------
    hypotheses : sequence of mapping
        The recorded hypotheses' rows (:data:`~siloflow.analysis.studies.validation.hypothesis.HYPOTHESIS_COLUMNS`).
    planned : mapping
        ``{name: finding ids}`` of every hypothesis siloflow defines (:data:`siloflow.engines.hypotheses.HYPOTHESES`).

    Returns
    -------
    list of str
        Markdown lines.
    """
    lines = ["### Measured hypotheses", "",
             "For a finding not reproduced, or not at the study's scale: one change that could move it, run as a pair "
             "on a reduced case (the base, and the variant with the change) and compared row by row. A change moves "
             "a figure towards the study (closer to its number, or in its sign) or away from it when its 95 % interval "
             "excludes zero; its error is the two rows' errors combined, within-run ones where a member ran one seed. "
             "The pair's figures are the reduced case's, not the tier's.", ""]
    by_name = _by_hypothesis(hypotheses)
    for name, rows in by_name.items():
        first = rows[0]
        findings = sorted({row["finding"].split(".")[0] for row in rows})
        lines.append(f"- **{name}** ({', '.join(findings)}; the pair {first['core_hours']:.2f} core-h, code "
                     f"{first['commit']}, {first['date']}): {_cell(first['statement'])} The change: "
                     f"{_cell(first['change'])}.")
        lines += [f"  - {_hypothesis_row(row)}" for row in rows]
        unjudged = [finding for finding in planned.get(name, ()) if finding not in findings]
        if unjudged:
            lines.append(f"  - no row of the pair judges {', '.join(unjudged)}")
    waiting = [name for name in planned if name not in by_name]
    if waiting:
        lines += [f"- {name} ({', '.join(planned[name])}): not recorded yet: `make hypothesis NAME={name}`"
                  for name in waiting]
    if not by_name and not waiting:
        lines.append("None.")
    return lines


def findings_section(statuses: Sequence[FindingStatus], verdicts: Mapping[str, ScaleVerdict],
                     unmade: Mapping[str, str], config_name: str, hypotheses: Sequence[Mapping] = (),
                     planned_hypotheses: Mapping[str, Sequence[str]] | None = None) -> list[str]:
    """The summary that opens the page: per chapter, how many findings are reproduced, not reproduced, not resolved,
    not at the study's scale or not measured (:mod:`siloflow.analysis.studies.validation.findings_summary`); the
    findings not reproduced, each row's figure beside the study's; the disagreements at another scale; every finding
    with its status and its scale; the parts no row measures, with why.

    Parameters
    ----------
    statuses : sequence of FindingStatus
        Every finding of the study, in its order, as the record's rows judge it.
    verdicts : mapping
        ``{finding id: ScaleVerdict}`` of ``config_name``'s dimensions (the definition taken as the study's: whether a
        row computes its quantity so is the row's to say).
    unmade : mapping
        ``{part id: why no row of this tier measures it, and what would}``.
    config_name : str
        The configuration, as the page names it.
    hypotheses : sequence of mapping
        The measured hypotheses' rows (:func:`hypotheses_section`).
    planned_hypotheses : mapping, optional
        ``{name: finding ids}`` of the hypotheses siloflow defines.

    Returns
    -------
    list of str
        Markdown lines.
    """
    counts = chapter_counts(statuses)
    lines = [
        "## Does siloflow reproduce the study?",
        "",
        f"Each row below judges one part of a finding of the study, by two verdicts fixed before the runs. "
        f"*Agreement*: whether the row's 95 % interval (Student t for a spread between few seeds) overlaps the "
        "study's band (not reproduced when it lies entirely outside), or a trend has the study's sign or order, by "
        "the rule of the finding's kind (the band where "
        "the study gives none: `validation.agreement` of the configuration reference); precision and steadiness only "
        "ever make a verdict \"not resolved\". *Scale*: whether the runs of "
        f"`{config_name}` are at the study's scale for the finding, from the configuration alone (every dimension it "
        "depends on as a ratio to the study's and in particle diameters: `validation.scale`) and from whether the row "
        "defines and samples its quantity as the study does; a verdict never reads a result. A finding is reproduced "
        "when every part has a row at the study's scale and all reproduce it; not reproduced when a row at scale "
        "disagrees; rows at another scale are results there, listed apart.",
        "",
        "| chapter | " + " | ".join(STATUSES) + " |",
        "|---|" + "---|" * len(STATUSES),
    ]
    lines += [f"| {chapter} | " + " | ".join(str(count[status]) for status in STATUSES) + " |"
              for chapter, count in counts.items()]
    failed = [entry for entry in statuses if entry.status == NOT_REPRODUCED]
    lines += ["", "### Findings not reproduced", ""]
    if not failed:
        lines.append("None at the study's scale.")
    for entry in failed:
        lines.append(f"- **{entry.finding.id}** ({entry.finding.section}): {_cell(entry.finding.statement)}")
        lines += [f"  - {_measured(row)}" for row in entry.rows
                  if row["scale"] == AT_SCALE and row["agreement"] == NOT_REPRODUCED]
    elsewhere = [row for entry in statuses for row in entry.rows
                 if row["scale"] != AT_SCALE and row["agreement"] == NOT_REPRODUCED]
    lines += ["", "### Disagreements at another scale", "",
              "Rows not at the study's scale whose figure lies outside the study's band or has the other sign: "
              "results at this scale, not verdicts on the study.", ""]
    lines += [f"- {row['finding']}: {_measured(row)}" for row in elsewhere] or ["None."]
    lines += ["", *hypotheses_section(hypotheses, planned_hypotheses or {})]
    tested = _hypotheses_by_finding(hypotheses, planned_hypotheses or {})
    lines += ["", "### Every finding", "",
              "| finding | thesis | status | rows | at the study's scale (dimensions) | what differs (ratio to the study's) "
              "| measured hypotheses |",
              "|---|---|---|---|---|---|---|"]
    for entry in statuses:
        verdict = verdicts.get(entry.finding.id)
        differs = "; ".join(_difference_brief(d) for d in verdict.differences) if verdict else ""
        at_scale = "-" if verdict is None else YES if verdict.at_study_scale else NO
        lines.append(f"| {entry.finding.id} | {entry.finding.section} | {entry.status} | {len(entry.rows)} | "
                     f"{at_scale} | {_cell(differs or '-')} | {', '.join(tested.get(entry.finding.id, [])) or '-'} |")
    measured = {row["finding"] for entry in statuses for row in entry.rows}
    missing = [(part.id, unmade.get(part.id, "its group's rows in this record predate it: re-derive or record the "
                                             "group again")) for entry in statuses for part in entry.finding.parts
               if part.id not in measured]
    lines += ["", "### Parts no row measures", ""]
    lines += [f"- {part}: {_cell(reason)}" for part, reason in missing] or ["None."]
    return lines


def _figure_width(count: int) -> str:
    """The width of each of a group's ``count`` figures on its line of the page: two side by side, one alone at the
    page's width."""
    return "100%" if count == 1 else "49%"


def _group_core_s(record: GroupRecord, part_walls: Mapping[str, float]) -> float:
    """CPU time of the runs a group's record holds that its parts make, over all their attempts (s)."""
    return math.fsum(run_wall_time(run) * int(run["cores"]) for run in record.runs if run["group"] in part_walls)


def budget_lines(groups: Mapping[str, GroupRecord], status: Mapping[str, str], wall_s: Mapping[str, Mapping[str, float]],
                 planned_core_s: Mapping[str, float], hypotheses: Sequence[Mapping], cores: int,
                 tier_budget_core_s: float, part_budget_s: float) -> list[str]:
    """The tier against its budgets: the core time the complete groups recorded plus the estimate of what the others
    plan, against ``tier_budget_core_s`` (CPU s); the longest part of a complete group against ``part_budget_s`` (s of
    wall time on ``cores`` cores); the measured hypotheses' recorded core time, counted apart.

    Returns
    -------
    list of str
        Markdown lines (one paragraph).
    """
    complete = [name for name, state in status.items() if state == "complete"]
    recorded = math.fsum(_group_core_s(groups.get(name, GroupRecord()), wall_s.get(name, {})) for name in complete)
    rest = [name for name in status if name not in complete]
    estimated = math.fsum(planned_core_s.get(name, 0.0) for name in rest)
    total = recorded + estimated
    verdict = "within it" if total <= tier_budget_core_s else f"over it by {_hours(total - tier_budget_core_s)}"
    text = (f"**Budget**: the complete groups recorded {_hours(recorded)} of core time"
            + (f" and the runs the other groups plan are estimated at {_hours(estimated)}" if rest else "")
            + f": {_hours(total)} against the tier's {_hours(tier_budget_core_s)} on {cores} cores, {verdict}.")
    parts = [(part, seconds) for name in complete for part, seconds in wall_s.get(name, {}).items()]
    if parts:
        part, longest = max(parts, key=lambda item: item[1])
        text += (f" The longest part of a complete group, {part}, took {_hours(longest)} of wall time, "
                 + ("within" if longest <= part_budget_s else "over") + f" a part's {_hours(part_budget_s)}.")
    by_name = _by_hypothesis(hypotheses)
    if by_name:
        spent = math.fsum(float(rows[0]["core_hours"]) for rows in by_name.values()) * 3600.0
        text += (f" The measured hypotheses are counted apart: {len(by_name)} recorded, {_hours(spent)} of core "
                 "time.")
    return [text]


def record_page(groups: Mapping[str, GroupRecord], status: Mapping[str, str], full_scale_core_s: Mapping[str, float],
                wall_s: Mapping[str, Mapping[str, float]], cores: int, config_name: str, full_scale_config: str,
                parts: Mapping[str, Sequence[str]] | None = None,
                estimated_core_s: Mapping[str, float] | None = None,
                verdicts: Mapping[str, ScaleVerdict] | None = None, unmade: Mapping[str, str] | None = None,
                planned_core_s: Mapping[str, float] | None = None, hypotheses: Sequence[Mapping] = (),
                planned_hypotheses: Mapping[str, Sequence[str]] | None = None,
                budgets: tuple[float, float] | None = None) -> str:
    """The record's page (Markdown): the study it compares with (:data:`STUDY_PARAGRAPH`), then per group its
    freshness, runs and rows with their two verdicts, and for the rows not at the study's scale, what the study's scale
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
        ``{run id: CPU s}``: each run ``config_name`` plans as its cost model estimates it; a group's recorded runs
        that it still plans are shown beside their recorded core time with the ratio (none: "-").
    verdicts : mapping, optional
        ``{finding id: ScaleVerdict}`` of ``config_name``'s dimensions; with it, the page opens with the summary of
        :func:`findings_section`.
    unmade : mapping, optional
        ``{part id: why no row measures it}`` for that summary.
    planned_core_s : mapping, optional
        ``{group: CPU s}`` of the runs ``config_name`` plans for each group, shown where it plans none of the recorded
        runs.
    hypotheses, planned_hypotheses
        The measured hypotheses' rows and ``{name: finding ids}`` of those siloflow defines, for the summary
        (:func:`hypotheses_section`).
    budgets : (float, float), optional
        The tier's budget of core time (CPU s) and a part's of wall time (s): with them, a paragraph under the groups'
        table weighs the tier against both (:func:`budget_lines`).

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
        "by `make validate GROUP=<name>` from the runs' own files: nothing here is typed in. `make validate-status` "
        "lists the groups that are complete, stale (a run id no longer matches what the configuration plans, or the "
        "code that writes the rows changed) or missing.",
        "",
    ]
    if verdicts is not None:
        rows = [row for record in groups.values() for row in record.rows]
        section = findings_section(finding_statuses(rows), verdicts, unmade or {}, config_name, hypotheses,
                                   planned_hypotheses)
        stale = [name for name, state in status.items() if state != "complete"]
        if stale:
            # the summary counts what the record holds: say which of it the configuration no longer plans as recorded
            section[4:4] = [f"Not complete against `{config_name}` and today's row code: {', '.join(stale)} "
                            "(see [The groups](#the-groups)); the summary counts the rows their records hold, and a "
                            "record written by older row code judges nothing until its group is recorded again.", ""]
        lines += [*section, "", "## The groups", ""]
    lines += [
        f"| group | status | runs it makes | core time | estimated (estimate / recorded) | wall time on {cores} cores "
        "(per part) | rows | judged against a finding | at the study's scale |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, state in status.items():
        record, part_walls = groups.get(name, GroupRecord()), wall_s.get(name, {})
        made = [run for run in record.runs if run["group"] in part_walls]
        core = _group_core_s(record, part_walls)
        judged = sum(row["finding"] != NO_FINDING for row in record.rows)
        shown = sum(row["scale"] == AT_SCALE for row in record.rows)
        wall = ", ".join(_hours(s) if part == name else f"{part} {_hours(s)}" for part, s in part_walls.items())
        estimated = _estimated(made, estimated_core_s or {}, (planned_core_s or {}).get(name, math.nan))
        lines.append(f"| {name} | {state} | {len(made)} | {_hours(core) if made else '-'} | {estimated} | "
                     f"{wall if made else '-'} | {len(record.rows)} | {judged} | {shown} |")
    if budgets is not None:
        lines += ["", *budget_lines(groups, status, wall_s, planned_core_s or {}, hypotheses, cores, *budgets)]
    for name, state in status.items():
        record = groups.get(name)
        command = ", then ".join(f"`make validate GROUP={part}`" for part in (parts or {}).get(name, [name]))
        lines += ["", f"## {name}", ""]
        if record is None:
            lines.append(f"Not recorded yet: {command}.")
            continue
        if state != "complete":
            lines += [f"**Stale**: the runs below are not those `{config_name}` now plans, or the code that writes the "
                      f"rows changed since they were recorded; {command} brings the record up to date "
                      "(`make validate-status` says which).", ""]
        engines = sorted({f"{run['engine']} {run['engine_version']}" for run in record.runs})
        commits = sorted({_run_commit(run) for run in record.runs})
        dates = sorted(str(run["date"]) for run in record.runs)
        cores = sorted({int(run["cores"]) for run in record.runs})
        lines.append(f"{len(record.runs)} runs on {', '.join(engines)}, {'/'.join(map(str, cores))} core(s) each, "
                     f"code {', '.join(commits)}, {dates[0]} to {dates[-1]}; run ids and seeds in "
                     f"[`{name}/runs.csv`]({name}/runs.csv)." if record.runs else "No runs recorded.")
        attempts = _attempts_sentence(record.runs)
        if attempts:
            lines[-1] += " " + attempts
        # the figures first, beside the rows they support; then one short line per row; its evidence folded below
        if record.plots:
            lines += ["", " ".join(f'<img src="{name}/{plot}" alt="{plot}" width="{_figure_width(len(record.plots))}">'
                                   for plot in record.plots)]
        lines += ["", "| table | figure | case | value | finding | study | agreement | scale |",
                  "|---|---|---|---|---|---|---|---|"]
        lines += [f"| {_cell(row['group'])} | {_cell(row['figure'])} | {_cell(row['case'])} | "
                  f"{_cell(_value(row))} | {row['finding']} | {_cell(row['study'] or '-')} | "
                  f"{row['agreement']} | {row['scale']} |" for row in record.rows]
        elsewhere = [row for row in record.rows if row["scale"] not in (AT_SCALE, NO_FINDING)]
        if elsewhere:
            cost = full_scale_core_s.get(name, math.nan)
            lines += ["", f"Rows not at the study's scale ({len(elsewhere)}): each names what differs; the study's "
                      f"full scale (`{full_scale_config}`) runs this group in about {cost / 86400.0:.3g} core-days "
                      f"(`make estimate CONFIG={full_scale_config}`)."]
        if record.rows:
            lines += ["", '<details markdown="1">', f"<summary>Why each row is judged so: its evidence "
                      f"({len(record.rows)} rows)</summary>", "", "| figure | case | finding | why, and evidence |",
                      "|---|---|---|---|"]
            for row in record.rows:
                why = "; ".join(_cell(text) for text in (row["agreement_reason"], row["scale_reason"], row["evidence"])
                                if text)
                lines.append(f"| {_cell(row['figure'])} | {_cell(row['case'])} | {row['finding']} | {why} |")
            lines += ["", "</details>"]
    return "\n".join(lines) + "\n"
