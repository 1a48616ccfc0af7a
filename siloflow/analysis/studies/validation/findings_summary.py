"""Each finding of the study as the record's rows judge it: the summary that opens the record's page.

A finding's status, from the rows that judge its parts (:mod:`siloflow.analysis.studies.validation.rows`):

- :data:`NOT_MEASURED`: no row judges any of its parts;
- :data:`NOT_AT_SCALE`: rows judge it, but none at the study's scale (its rows are results at another scale, listed
  apart when they disagree);
- else, over its rows at the study's scale: :data:`~siloflow.analysis.studies.validation.agreement.NOT_REPRODUCED`
  when one is; :data:`~siloflow.analysis.studies.validation.agreement.REPRODUCED` when every part of the finding has
  a row at scale and every such row is; :data:`~siloflow.analysis.studies.validation.agreement.NOT_RESOLVED`
  otherwise (a part unresolved, or not measured at scale).

Pure: rows in, statuses out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED, NOT_RESOLVED, REPRODUCED
from siloflow.analysis.studies.validation.findings import FINDINGS, Finding
from siloflow.analysis.studies.validation.rows import AT_SCALE

__all__ = ["NOT_AT_SCALE", "NOT_MEASURED", "STATUSES", "FindingStatus", "finding_status", "finding_statuses",
           "chapter_counts"]

NOT_AT_SCALE, NOT_MEASURED = "not at the study's scale", "not measured"
#: The statuses in the order the summary counts them.
STATUSES = (REPRODUCED, NOT_REPRODUCED, NOT_RESOLVED, NOT_AT_SCALE, NOT_MEASURED)


@dataclass(frozen=True)
class FindingStatus:
    """A finding's status and the rows behind it.

    Attributes
    ----------
    finding : Finding
    status : str
        One of :data:`STATUSES`.
    rows : tuple of mapping
        Every row that judges one of its parts.
    unmeasured : tuple of str
        Its parts no row at the study's scale judges.
    """

    finding: Finding
    status: str
    rows: tuple
    unmeasured: tuple[str, ...]


def finding_status(finding: Finding, rows: Sequence[Mapping]) -> FindingStatus:
    """The status of ``finding`` from the record's ``rows`` (see the module docstring)."""
    own = tuple(row for row in rows if row["finding"].split(".")[0] == finding.id)
    at_scale = [row for row in own if row["scale"] == AT_SCALE]
    measured = {row["finding"] for row in at_scale}
    unmeasured = tuple(part.id for part in finding.parts if part.id not in measured)
    if not own:
        status = NOT_MEASURED
    elif not at_scale:
        status = NOT_AT_SCALE
    elif any(row["agreement"] == NOT_REPRODUCED for row in at_scale):
        status = NOT_REPRODUCED
    elif not unmeasured and all(row["agreement"] == REPRODUCED for row in at_scale):
        status = REPRODUCED
    else:
        status = NOT_RESOLVED
    return FindingStatus(finding, status, own, unmeasured)


def finding_statuses(rows: Sequence[Mapping], findings: Sequence[Finding] = FINDINGS) -> list[FindingStatus]:
    """:func:`finding_status` of every finding, in the study's order."""
    return [finding_status(finding, rows) for finding in findings]


def chapter_counts(statuses: Sequence[FindingStatus]) -> dict[int, dict[str, int]]:
    """``{chapter: {status: findings}}`` over :data:`STATUSES`, chapters in order."""
    counts: dict[int, dict[str, int]] = {}
    for entry in statuses:
        chapter = counts.setdefault(entry.finding.chapter, {status: 0 for status in STATUSES})
        chapter[entry.status] += 1
    return dict(sorted(counts.items()))
