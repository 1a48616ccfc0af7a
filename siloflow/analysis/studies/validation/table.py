"""The whole validation table in order, the rows judged against the study's findings, and the report page.

Pure: the adapter (``siloflow/workflow/scripts/validation_table.py``) reads every stage's files and passes them in.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED, NOT_RESOLVED, REPRODUCED
from siloflow.analysis.studies.validation.rows import AT_SCALE, NO_FINDING

__all__ = ["against_the_study", "page_sections", "PAGE_EXPLANATION"]

PAGE_EXPLANATION = (
    "The study's comparisons from the runs of this configuration, each as value ± standard error. Each row that a "
    "finding of the study states carries two verdicts: its agreement with the finding (the row's 95 % interval "
    "against the study's band, or the sign or order of a trend) and whether this configuration is at the study's "
    "scale for it (judged from the configuration alone: every dimension the finding depends on, as a ratio to the "
    "study's and in particle diameters). The tolerances and bounds are in the validation section of the "
    "configuration; a row with no finding is a measurement of siloflow's own.")


def against_the_study(rows: Sequence[Mapping]) -> list[dict]:
    """The rows judged against a finding of the study, as short notes for the summary page: the finding part, the
    figure, the case, both verdicts and the reason of the agreement."""
    return [{"finding": r["finding"], "figure": r["figure"], "case": r["case"], "agreement": r["agreement"],
             "scale": r["scale"], "note": r["agreement_reason"]}
            for r in rows if r["finding"] != NO_FINDING]


def page_sections(rows: Sequence[Mapping]) -> list[tuple[str, str, list[dict]]]:
    """The validation page's sections ``(title, sentence, rows)`` for
    :func:`siloflow.analysis.report.summary.summary_html`: one per group, in the order the groups first appear."""
    groups: dict[str, list[dict]] = {}
    for r in rows:
        groups.setdefault(r["group"], []).append({key: r[key] for key in r if key != "group"})
    sections = []
    for group, members in groups.items():
        judged = [member for member in members if member["finding"] != NO_FINDING]
        counts = ", ".join(f"{sum(m['agreement'] == word for m in judged)} {word}"
                           for word in (REPRODUCED, NOT_REPRODUCED, NOT_RESOLVED))
        at_scale = sum(member["scale"] == AT_SCALE for member in judged)
        sections.append((group, f"{len(judged)} of {len(members)} rows judged against a finding of the study: "
                                f"{counts}; {at_scale} at the study's scale.", members))
    return sections
