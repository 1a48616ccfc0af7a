"""A measured hypothesis for a finding the record does not reproduce: the same rows from two runs of a reduced case
that differ in one change (the particle stiffness, the bed height, ...), and whether the change moves each figure
towards the study, away from it, or not beyond its error.

A finding that is not reproduced, or not at the study's scale, leaves the reader asking what would move it. The
record answers with one sensitivity pair per hypothesis (:mod:`siloflow.engines.hypotheses` names them and what
each changes): a *base* run of a reduced case and a *variant* with the one change, whose validation rows
(:mod:`siloflow.analysis.studies.validation.rows`) are compared row by row here.

Direction
---------
A change moves a row's figure by ``d = variant - base`` with the standard error ``sqrt(e_base^2 + e_variant^2)``
(independent runs) and the smaller of the two rows' degrees of freedom. It is :data:`NOT_MOVED` when its 95 %
interval holds zero (Student t, or normal for within-run errors: :func:`~siloflow.analysis.studies.validation.rows.resolved`).
Otherwise it moves the figure :data:`TOWARDS` the study when ``d`` has the sign of the study's direction from the
base figure, :data:`AWAY` when it has the other sign:

- a value or ratio (:data:`~siloflow.analysis.studies.validation.findings.VALUE`, ``RATIO``): towards the centre of
  the study's band (its point, or its band's middle; a number the study measured but does not quote is the
  configuration's, passed in ``configured``);
- a sign (``SIGN``): the study's sign (a larger change in the study's direction);
- a negligible change (``NEGLIGIBLE``): towards zero;
- a power law (``POWER_LAW``): towards the stated exponent, or away from it where the study states a deviation.

An order of several figures (``ORDER``) has no one figure to move: :data:`NO_DIRECTION`, with the difference still
given. Pure: rows in, rows out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation.agreement import interval
from siloflow.analysis.studies.validation.findings import NEGLIGIBLE, ORDER, PARTS, POWER_LAW, RATIO, SIGN, VALUE, Part
from siloflow.analysis.studies.validation.rows import NO_FINDING, resolved, smallest_dof

__all__ = ["TOWARDS", "AWAY", "NOT_MOVED", "NO_DIRECTION", "COMPARED_COLUMNS", "HYPOTHESIS_COLUMNS",
           "HYPOTHESIS_NUMBERS", "study_direction", "moved", "compare_rows"]

TOWARDS, AWAY, NOT_MOVED, NO_DIRECTION = ("towards the study", "away from the study", "not moved beyond its error",
                                          "no one direction")

#: The columns :func:`compare_rows` gives each compared row, in order.
COMPARED_COLUMNS = ("hypothesis", "statement", "change", "finding", "group", "figure", "case", "unit", "study",
                    "base", "base_error", "variant", "variant_error", "difference", "difference_error", "dof",
                    "moves", "reason")
#: The columns of a hypothesis's record (``docs/validation/hypotheses/<name>.csv``), in order: the compared rows, then
#: the pair's core time (h), the commit of the code that recorded it and the date.
HYPOTHESIS_COLUMNS = (*COMPARED_COLUMNS, "core_hours", "commit", "date")
#: The record's numeric columns.
HYPOTHESIS_NUMBERS = ("base", "base_error", "variant", "variant_error", "difference", "difference_error", "core_hours")


def study_direction(part: Part, base: float, configured: tuple[float, float] | None = None) -> int | None:
    """The sign (+1 or -1) of a move from the figure ``base`` towards what ``part`` states; 0 where ``base`` is
    already the study's point (every move leads away); None for an order, which has no one figure.

    Parameters
    ----------
    part : Part
        The finding part the figure is judged against.
    base : float
        The base run's figure, in the part's unit.
    configured : tuple of float, optional
        ``(low, high)`` of a part whose number is the configuration's (:attr:`Part.configured`).
    """
    if part.kind == ORDER:
        return None
    if part.kind == SIGN:
        return part.sign
    if part.kind == NEGLIGIBLE:
        target = 0.0
    elif part.kind == POWER_LAW:
        sign = _sign(float(part.value) - base)
        return -sign if part.deviates else sign
    elif part.kind in (VALUE, RATIO):
        if part.configured:
            if configured is None:
                raise ValueError(f"{part.id}: its number is the configuration's {part.configured}; pass it as configured")
            target = 0.5 * (float(configured[0]) + float(configured[1]))
        else:
            target = float(part.value) if part.value is not None else 0.5 * (part.band[0] + part.band[1])
    else:  # a kind added to findings.PART_KINDS without a direction here
        raise ValueError(f"{part.id}: no direction for a {part.kind} part")
    return _sign(target - base)


def _sign(x: float) -> int:
    return (x > 0.0) - (x < 0.0)


def moved(difference: float, error: float, dof: float | None, direction: int | None) -> str:
    """Whether a change of ``difference`` (standard error ``error``, ``dof`` degrees of freedom or None for a normal
    quantile) moves a figure :data:`TOWARDS` the study (its sign is ``direction``), :data:`AWAY` from it, or
    :data:`NOT_MOVED` beyond its error (also when the error is not known); :data:`NO_DIRECTION` for ``direction``
    None."""
    if direction is None:
        return NO_DIRECTION
    if not resolved(difference, error, dof):
        return NOT_MOVED
    return TOWARDS if direction != 0 and _sign(difference) == direction else AWAY


def _keyed(rows: Sequence[Mapping], findings: Sequence[str]) -> dict[tuple, Mapping]:
    """The rows that judge a part of ``findings``, keyed by (group, figure, finding part, occurrence): a reduced
    case's rows come in the same order with the same figures in both runs, while their case columns name other run
    ids."""
    keyed: dict[tuple, Mapping] = {}
    for row in rows:
        if row["finding"] == NO_FINDING or row["finding"].split(".")[0] not in findings:
            continue
        stem = (row["group"], row["figure"], row["finding"])
        occurrence = sum(key[:3] == stem for key in keyed)
        keyed[(*stem, occurrence)] = row
    return keyed


def _dof(value) -> float | None:
    return None if value in ("", None) or (isinstance(value, float) and math.isnan(value)) else float(value)


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
        Finding ids (``"S2"``) whose rows are compared.
    base_rows, variant_rows : sequence of mapping
        The two runs' validation rows (:data:`siloflow.analysis.studies.validation.rows.COLUMNS`, value and error as
        float, ``dof`` a number or "").
    configured : mapping, optional
        ``{part id: (low, high)}`` for the parts whose number is the configuration's; a part without one has
        :data:`NO_DIRECTION`, as has a row whose base figure is not known.

    Raises
    ------
    ValueError
        When the two runs do not judge the same parts by the same figures, or neither judges one of ``findings``.
    """
    base, variant = _keyed(base_rows, findings), _keyed(variant_rows, findings)
    if base.keys() != variant.keys():
        only = sorted({*base} ^ {*variant})
        raise ValueError(f"hypothesis {name!r}: the base and the variant do not judge the same rows; in one only: "
                         + "; ".join(f"{figure} ({finding})" for _, figure, finding, _ in only))
    if not base:
        raise ValueError(f"hypothesis {name!r}: no row of either run judges {', '.join(findings)}")
    compared = []
    for key, before in base.items():
        after = variant[key]
        part = PARTS[before["finding"]]
        difference = float(after["value"]) - float(before["value"])
        error = combine_independent([float(before["value_error"]), float(after["value_error"])])
        dof = smallest_dof(_dof(before["dof"]), _dof(after["dof"]))
        known = math.isfinite(float(before["value"])) and (not part.configured or part.id in (configured or {}))
        direction = study_direction(part, float(before["value"]), (configured or {}).get(part.id)) if known else None
        verdict = moved(difference, error, dof, direction)
        if math.isfinite(difference) and math.isfinite(error):
            low, high = interval(difference, error, dof)
            shown = f"change {difference:.4g} ± {error:.2g} (95 %: {low:.4g} to {high:.4g})"
        else:
            shown = f"change {difference:.4g}, its error not known"
        reason = f"{shown}; the study: {before['study']}"
        compared.append({"hypothesis": name, "statement": statement, "change": change, "finding": before["finding"],
                         "group": before["group"], "figure": before["figure"], "case": before["case"],
                         "unit": before["unit"], "study": before["study"], "base": float(before["value"]),
                         "base_error": float(before["value_error"]), "variant": float(after["value"]),
                         "variant_error": float(after["value_error"]), "difference": difference,
                         "difference_error": error, "dof": "" if dof is None else dof, "moves": verdict,
                         "reason": reason})
    return compared
