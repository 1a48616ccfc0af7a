"""A measured hypothesis for a finding the record does not reproduce: the same rows from two runs of a reduced case
that differ in one change (the particle stiffness, the bed height, ...), and whether the change moves each figure
towards the study, away from it, or not beyond its error.

A finding that is not reproduced, or not at the study's scale, leaves the reader asking what would move it. The
record answers with one sensitivity pair per hypothesis (:mod:`siloflow.engines.hypotheses` names them and what
each changes): a *base* run of a reduced case and a *variant* with the one change, whose validation rows
(:mod:`siloflow.analysis.studies.validation.rows`) are compared row by row here.

Verdict
-------
A change moves a row's figure by ``d = variant - base`` with the standard error ``sqrt(e_base^2 + e_variant^2)``
(independent runs) and the smaller of the two rows' degrees of freedom (a safe choice: Welch's are never fewer). Its
verdict (:func:`moved`):

- :data:`NOT_KNOWN` when a figure or the error is not known;
- :data:`NOT_MOVED` when the 95 % interval of ``d`` holds zero (Student t, or normal for within-run errors:
  :func:`~siloflow.analysis.studies.validation.rows.resolved`);
- otherwise :data:`TOWARDS` or :data:`AWAY` from what the study states (:func:`study_target`):

  - a value or ratio (:data:`~siloflow.analysis.studies.validation.findings.VALUE`, ``RATIO``): towards when the
    variant lies closer to the study's number (its point, else its band's middle; a number the study measured but
    does not quote is the configuration's, passed in ``configured``) than the base does; a move past it that ends
    farther away is away, and the reason says it passed the study's number;
  - a negligible change (``NEGLIGIBLE``): the same, the study's number being zero;
  - a power law (``POWER_LAW``): the same with the stated exponent, reversed where the study states a deviation
    from it (farther from the exponent is towards);
  - a sign (``SIGN``): towards when ``d`` has the study's sign (a larger change in the study's direction);
  - an order of several figures (``ORDER``) has no one figure to move: :data:`NO_DIRECTION`, as has a part whose
    number is the configuration's when ``configured`` does not give it.

Pure: rows in, rows out.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Mapping, Sequence

from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation.agreement import interval
from siloflow.analysis.studies.validation.findings import NEGLIGIBLE, ORDER, PARTS, POWER_LAW, RATIO, SIGN, VALUE, Part
from siloflow.analysis.studies.validation.rows import NO_FINDING, resolved, smallest_dof

__all__ = ["TOWARDS", "AWAY", "NOT_MOVED", "NOT_KNOWN", "NO_DIRECTION", "COMPARED_COLUMNS", "HYPOTHESIS_COLUMNS",
           "HYPOTHESIS_NUMBERS", "study_target", "moved", "compare_rows"]

TOWARDS, AWAY, NOT_MOVED, NOT_KNOWN, NO_DIRECTION = ("towards the study", "away from the study",
                                                     "not moved beyond its error", "not known", "no one direction")

#: The columns :func:`compare_rows` gives each compared row, in order.
COMPARED_COLUMNS = ("hypothesis", "statement", "change", "finding", "group", "figure", "case", "unit", "study",
                    "base", "base_error", "variant", "variant_error", "difference", "difference_error", "dof",
                    "moves", "reason")
#: The columns of a hypothesis's record (``docs/validation/hypotheses/<name>.csv``), in order: the compared rows, then
#: the pair's core time (h), the commits of the code that ran its runs and the date it was recorded.
HYPOTHESIS_COLUMNS = (*COMPARED_COLUMNS, "core_hours", "commit", "date")
#: The record's numeric columns.
HYPOTHESIS_NUMBERS = ("base", "base_error", "variant", "variant_error", "difference", "difference_error", "core_hours")

#: A run id in a row's case column (``sphere2-5909c6b4d9``, ``internal_flow-0b33331eab``): the two members of a pair
#: name other runs in the same place.
_RUN_ID = re.compile(r"-[0-9a-f]{10}\b")


def study_target(part: Part, configured: tuple[float, float] | None = None) -> float | None:
    """The number a figure judged against ``part`` heads for when it moves towards the study (in the part's unit):
    the study's point or its band's middle for a value or ratio, zero for a negligible change, the exponent of a power
    law; None for a sign or an order, which state no number.

    Parameters
    ----------
    part : Part
        The finding part.
    configured : tuple of float, optional
        ``(low, high)`` of a part whose number is the configuration's (:attr:`Part.configured`).

    Raises
    ------
    ValueError
        For a part whose number is the configuration's when ``configured`` is not given.
    """
    if part.kind in (SIGN, ORDER):
        return None
    if part.kind == NEGLIGIBLE:
        return 0.0
    if part.kind == POWER_LAW:
        return float(part.value)
    if part.kind in (VALUE, RATIO):
        if part.configured:
            if configured is None:
                raise ValueError(f"{part.id}: its number is the configuration's {part.configured}; pass it as configured")
            return 0.5 * (float(configured[0]) + float(configured[1]))
        return float(part.value) if part.value is not None else 0.5 * (part.band[0] + part.band[1])
    raise ValueError(f"{part.id}: no target for a {part.kind} part")  # a kind added to findings without one here


def _sign(x: float) -> int:
    return (x > 0.0) - (x < 0.0)


def moved(part: Part, base: float, variant: float, error: float, dof: float | None,
          configured: tuple[float, float] | None = None) -> tuple[str, str]:
    """Whether a change from the figure ``base`` to ``variant`` moves it towards what ``part`` states (see the module
    docstring).

    Parameters
    ----------
    part : Part
        The finding part both figures are judged against.
    base, variant : float
        The two runs' figures, in the part's unit.
    error : float
        Standard error of ``variant - base``, in the part's unit (NaN: not known).
    dof : float or None
        Its degrees of freedom; None for a within-run error (a normal quantile).
    configured : tuple of float, optional
        ``(low, high)`` of a part whose number is the configuration's; without it such a part has no direction.

    Returns
    -------
    verdict : str
        :data:`TOWARDS`, :data:`AWAY`, :data:`NOT_MOVED`, :data:`NOT_KNOWN` or :data:`NO_DIRECTION`.
    note : str
        ``"past the study's <number>"`` when a resolved move crossed the study's number, else "".
    """
    difference = variant - base
    if not all(math.isfinite(x) for x in (base, variant, error)):
        return NOT_KNOWN, ""
    if not resolved(difference, error, dof):
        return NOT_MOVED, ""
    if part.kind == ORDER or (part.configured and configured is None):
        return NO_DIRECTION, ""
    if part.kind == SIGN:
        return (TOWARDS if _sign(difference) == part.sign else AWAY), ""
    target = study_target(part, configured)
    closer = abs(variant - target) < abs(base - target)
    if part.kind == POWER_LAW and part.deviates:
        closer = abs(variant - target) > abs(base - target)
    crossed = _sign(variant - target) * _sign(base - target) < 0
    return (TOWARDS if closer else AWAY), (f"past the study's {target:.4g}" if crossed else "")


def _key(row: Mapping) -> tuple[str, str, str]:
    """What pairs a row of the base with the variant's: its table, its finding part and its case with any run id left
    out. Not its figure, whose text may quote a measured number (a depth below the measured surface)."""
    return row["group"], row["finding"], _RUN_ID.sub("", str(row["case"]))


def _keyed(rows: Sequence[Mapping], findings: Sequence[str]) -> dict[tuple, Mapping]:
    """The rows that judge a part of ``findings``, keyed by :func:`_key` and their occurrence under it: a reduced
    case's rows come in the same order in both runs."""
    keyed: dict[tuple, Mapping] = {}
    seen: Counter = Counter()
    for row in rows:
        if row["finding"] == NO_FINDING or row["finding"].split(".")[0] not in findings:
            continue
        stem = _key(row)
        keyed[(*stem, seen[stem])] = row
        seen[stem] += 1
    return keyed


def _dof(value) -> float | None:
    """A row's degrees of freedom as read back (a number, its text, "" or NaN for a within-run error)."""
    if value in ("", None):
        return None
    number = float(value)
    return None if math.isnan(number) else number


def compare_rows(name: str, statement: str, change: str, findings: Sequence[str], base_rows: Sequence[Mapping],
                 variant_rows: Sequence[Mapping],
                 configured: Mapping[str, tuple[float, float]] | None = None) -> list[dict]:
    """One compared row (:data:`COMPARED_COLUMNS`) per validation row that judges a part of ``findings``, the base
    run's figure beside the variant's and where the change moves it (see the module docstring).

    Parameters
    ----------
    name, statement, change : str
        The hypothesis's name, what it supposes, and the one change between the base and the variant.
    findings : sequence of str
        Finding ids (``"S2"``) whose rows are compared; a finding neither run judges has no row (the record's page
        says so).
    base_rows, variant_rows : sequence of mapping
        The two runs' validation rows (:data:`siloflow.analysis.studies.validation.rows.COLUMNS`, value and error as
        float, ``dof`` a number, its text or "").
    configured : mapping, optional
        ``{part id: (low, high)}`` for the parts whose number is the configuration's; a part without one has
        :data:`NO_DIRECTION`.

    Returns
    -------
    list of dict
        The compared rows, in the base's order; figure and case are the base's.

    Raises
    ------
    ValueError
        When the two runs do not judge the same parts in the same cases, or neither judges any of ``findings``.
    """
    base, variant = _keyed(base_rows, findings), _keyed(variant_rows, findings)
    if base.keys() != variant.keys():
        only = sorted({*base} ^ {*variant})
        raise ValueError(f"hypothesis {name!r}: the base and the variant do not judge the same rows; in one only: "
                         + "; ".join(f"{finding} ({group}, {case})" for group, finding, case, _ in only))
    if not base:
        raise ValueError(f"hypothesis {name!r}: no row of either run judges {', '.join(findings)}")
    compared = []
    for key, before in base.items():
        after = variant[key]
        part = PARTS[before["finding"]]
        old, new = float(before["value"]), float(after["value"])
        difference = new - old
        error = combine_independent([float(before["value_error"]), float(after["value_error"])])
        dof = smallest_dof(_dof(before["dof"]), _dof(after["dof"]))
        verdict, note = moved(part, old, new, error, dof, (configured or {}).get(part.id))
        if math.isfinite(difference) and math.isfinite(error):
            low, high = interval(difference, error, dof)
            shown = f"change {difference:.4g} ± {error:.2g} (95 %: {low:.4g} to {high:.4g})"
        else:
            shown = f"change {difference:.4g}, its error not known"
        reason = "; ".join(text for text in (shown, note, f"the study: {before['study']}") if text)
        compared.append({"hypothesis": name, "statement": statement, "change": change, "finding": before["finding"],
                         "group": before["group"], "figure": before["figure"], "case": before["case"],
                         "unit": before["unit"], "study": before["study"], "base": old,
                         "base_error": float(before["value_error"]), "variant": new,
                         "variant_error": float(after["value_error"]), "difference": difference,
                         "difference_error": error, "dof": "" if dof is None else dof, "moves": verdict,
                         "reason": reason})
    return compared
