"""The whole validation table in order, what the scale of a configuration cannot show, and the report page.

Pure: the adapter (``siloflow/workflow/scripts/validation_table.py``) reads every stage's files and passes them in.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from siloflow.analysis.studies.validation.rows import NO, UNKNOWN, YES

__all__ = ["scale_limits", "page_sections", "PAGE_EXPLANATION"]

PAGE_EXPLANATION = (
    "The study's comparisons from the runs of this configuration, each as value ± standard error. \"The scale shows "
    "it\" is judged from the run itself (depth, cell and outlet in particle diameters, the settled fill's force "
    "balance, the outlet windows' counting-noise ceiling, the insert's velocity ratio, and whether the figure's "
    "error resolves what it is about); the evidence column quotes those figures. Criteria: the validation section "
    "of the configuration.")


def scale_limits(rows: Sequence[Mapping]) -> list[dict]:
    """The rows whose scale does not show (or cannot be judged to show) their physics, as short notes for the
    summary page: figure, case and the evidence that decided."""
    return [{"figure": r["figure"], "case": r["case"], "note": r["evidence"]}
            for r in rows if r["scale_shows"] in (NO, UNKNOWN)]


def page_sections(rows: Sequence[Mapping]) -> list[tuple[str, str, list[dict]]]:
    """The validation page's sections ``(title, sentence, rows)`` for :func:`siloflow.analysis.report.summary.summary_html`:
    one per group, in the order the groups first appear."""
    groups: dict[str, list[dict]] = {}
    for r in rows:
        groups.setdefault(r["group"], []).append({key: r[key] for key in r if key != "group"})
    sections = []
    for group, members in groups.items():
        shown = sum(member["scale_shows"] == YES for member in members)
        sections.append((group, f"{shown} of {len(members)} rows shown at this scale.", members))
    return sections
