"""One row of the validation table, and the arithmetic of errors the rows share.

A row is a plain dict (it goes to CSV and to the record's page unchanged)::

    {"group": "Flat-bottom silo", "figure": "Filling bulk density", "case": "sphere2-1234abcd",
     "finding": "S2", "value": 640.1, "value_error": 2.2, "dof": 2, "unit": "kg/m3",
     "study": "622.7, 618 to 627.4", "agreement": "not reproduced",
     "agreement_reason": "S2: 640.1 ± 2.2 (95 %: ...) lies outside ...", "differs": "",
     "scale": "not at scale", "scale_reason": "fill height ...", "evidence": "mean of 3 seeds; ..."}

Each row carries two verdicts, each decided by its own rule:

- ``agreement`` (:mod:`siloflow.analysis.studies.validation.agreement`): whether the figure reproduces the finding
  part ``finding`` (:mod:`siloflow.analysis.studies.validation.findings`), from the figure, its error and degrees of
  freedom; :data:`NO_FINDING` for a figure no finding of the study states (a measurement of siloflow's own).
- ``scale`` (:func:`with_scale`): whether the run is at the study's scale for that finding, from the configuration
  alone (:func:`siloflow.analysis.studies.validation.scale.scale_verdict`) and from ``differs``, which says how the row's
  quantity is defined or sampled otherwise than the study's ("" when as the study's). It never reads a value.

``dof`` is the degrees of freedom of ``value_error``: seeds - 1 for an error from a spread between seeds, ``""`` for
a within-run error from many samples (a normal quantile). Pure: numbers in, dicts out.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

from siloflow.model.checks import number_or_nan
from siloflow.analysis.studies.validation.agreement import Agreement, AgreementTolerances, quantile, relative_error
from siloflow.analysis.studies.validation.findings import PARTS

__all__ = ["COLUMNS", "NO_FINDING", "AT_SCALE", "NOT_AT_SCALE", "joined", "row", "with_scale", "precise", "plus_minus",
           "resolved", "resolution", "smallest_dof"]

#: The columns of a group's rows, in order.
COLUMNS = ("group", "figure", "case", "finding", "value", "value_error", "dof", "unit", "study", "agreement",
           "agreement_reason", "differs", "scale", "scale_reason", "evidence")
#: The agreement and the scale of a row that no finding of the study states.
NO_FINDING = "-"
AT_SCALE, NOT_AT_SCALE = "at scale", "not at scale"


def joined(texts) -> str:
    """The non-empty texts (clauses of a ``differs`` or ``evidence`` cell), each once, in order, joined by "; "."""
    return "; ".join(dict.fromkeys(text for text in texts if text))


def row(group: str, figure: str, case: str, value, error, unit: str, evidence: str, *, dof: float | None = None,
        finding: str | None = None, agreement: Agreement | None = None, study: str | None = None,
        differs: str = "") -> dict:
    """One table row (see the module docstring).

    Parameters
    ----------
    group, figure, case : str
        The table it belongs to, what it measures, and which run(s) or curve.
    value, error : float
        The figure and its standard error (NaN when unknown), in ``unit``.
    unit : str
    evidence : str
        The run's figures a reader needs to judge the row (steadiness, seeds, counts).
    dof : float or None
        Degrees of freedom of ``error`` (seeds - 1); None for a within-run error.
    finding : str, optional
        The finding part judged (a key of :data:`~siloflow.analysis.studies.validation.findings.PARTS`); None for a
        figure no finding states.
    agreement : Agreement, optional
        The verdict on ``finding`` (required with it, refused without).
    study : str, optional
        What the study states, for a row with no finding (by default the part's :meth:`Part.stated`).
    differs : str
        How the quantity is defined or sampled otherwise than the study's, "" when as the study's.
    """
    if finding is not None and finding not in PARTS:
        raise KeyError(f"no finding part {finding!r}")
    if (finding is None) != (agreement is None):
        raise ValueError("a row has an agreement exactly when it names a finding part")
    if dof is not None and not dof > 0:
        raise ValueError(f"dof must be > 0 or None, got {dof!r}")
    return {"group": group, "figure": figure, "case": case, "finding": finding or NO_FINDING,
            "value": number_or_nan(value), "value_error": number_or_nan(error), "dof": "" if dof is None else dof,
            "unit": unit, "study": study if study is not None else (PARTS[finding].stated() if finding else "-"),
            "agreement": agreement.verdict if agreement else NO_FINDING,
            "agreement_reason": agreement.reason if agreement else "", "differs": differs,
            "scale": NO_FINDING, "scale_reason": "", "evidence": evidence}


def with_scale(rows: Sequence[Mapping], judge: Callable[[str, bool], object]) -> list[dict]:
    """The rows with their scale verdicts: ``judge(finding_id, definition_as_study)`` returns a
    :class:`~siloflow.analysis.studies.validation.scale.ScaleVerdict` (the configuration bound in, e.g.
    ``lambda f, d: scale_verdict(f, kind, config, d)``); a row with no finding keeps :data:`NO_FINDING`. The row's
    value is never passed."""
    judged = []
    for entry in rows:
        entry = dict(entry)
        if entry["finding"] != NO_FINDING:
            verdict = judge(entry["finding"].split(".")[0], not entry["differs"])
            entry["scale"] = AT_SCALE if verdict.at_study_scale else NOT_AT_SCALE
            entry["scale_reason"] = verdict.text + (f" (this row: {entry['differs']})" if entry["differs"] else "")
        judged.append(entry)
    return judged


def resolved(difference: float, error: float, dof: float | None) -> bool | None:
    """Whether ``|difference|`` exceeds its 95 % reach ``q error`` (Student t with ``dof``, normal for None);
    None when the error is not known."""
    if not math.isfinite(error) or not math.isfinite(difference):
        return None
    return abs(difference) > quantile(dof) * error


def resolution(difference: float, error: float, dof: float | None) -> str:
    """Evidence text for :func:`resolved`, e.g. ``resolved at 95 % (q 4.303, t 2 dof)``."""
    seen = resolved(difference, error, dof)
    q = f"q {quantile(dof):.4g}, " + ("normal" if dof is None else f"t {dof:g} dof")
    return f"{'unknown' if seen is None else 'resolved' if seen else 'not resolved'} at 95 % ({q})"


def precise(value: float, error: float, tolerances: AgreementTolerances) -> tuple[bool | None, str]:
    """Whether a figure resolves what it measures: its standard error at most ``max_relative_error`` of its
    magnitude (None when the value or the error is not known), and the evidence clause that says so, e.g.
    ``relative error 34 % (at most 25 %)``."""
    limit = f"(at most {tolerances.max_relative_error * 100:g} %)"
    if not math.isfinite(error) or not math.isfinite(value):
        return None, f"relative error not known {limit}"
    relative = relative_error(error, value)
    shown = f"{relative * 100:.2g} %" if math.isfinite(relative) else "unbounded"
    return error <= tolerances.max_relative_error * abs(value), f"relative error {shown} {limit}"


def plus_minus(value: float, error: float, digits: int = 3) -> str:
    """``value ± error`` for evidence text (``value ±?`` when the error is not known)."""
    if not math.isfinite(error):
        return f"{value:.{digits}g} ±?"
    return f"{value:.{digits}g} ± {error:.2g}"


def smallest_dof(*dofs: float | None) -> float | None:
    """The degrees of freedom of a figure combining errors of several runs: the smallest known (None, a normal
    quantile, when every error is a within-run one)."""
    known = [d for d in dofs if d is not None]
    return min(known) if known else None

