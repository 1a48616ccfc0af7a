"""One row of the validation table, its verdict words and the arithmetic of errors the rows share.

A row is a plain dict (it goes to CSV and to the report page unchanged)::

    {"group": "Silo", "figure": "Filling bulk density", "case": "sphere2-1234abcd", "value": 640.1,
     "value_error": 2.2, "unit": "kg/m3", "study_value": "667", "scale_shows": "yes",
     "evidence": "depth 40 mm = 12.0 particle diameters (>= 10); the settled fill carries 0.999 of its weight"}

``scale_shows`` says whether the scale of the run shows the physics the row is about, judged from the run's own
figures (quoted in ``evidence``): :data:`YES`, :data:`NO`, or :data:`UNKNOWN` when an error needed for the
judgement is not known. Pure: numbers in, dicts out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent

__all__ = ["YES", "NO", "UNKNOWN", "COLUMNS", "Criteria", "row", "verdict", "ratio", "resolved", "precise",
           "plus_minus"]

YES, NO, UNKNOWN = "yes", "no", "unknown"

#: The columns of validation.csv, in order.
COLUMNS = ("group", "figure", "case", "value", "value_error", "unit", "study_value", "scale_shows", "evidence")


@dataclass(frozen=True)
class Criteria:
    """The thresholds of the verdicts (the ``validation`` section of the configuration; all dimensionless).

    Attributes
    ----------
    coverage_factor : float
        Standard errors a difference must exceed to count as resolved.
    min_cell_diameters, min_depth_diameters, min_outlet_diameters : float
        Smallest Jenike cell diameter, silo depth and outlet width in volume-equivalent particle diameters.
    mass_flow_velocity_ratio : float
        Smallest exterior-annulus over tube velocity of a blender insert in mass flow.
    mass_flow_configuration : str
        The blender configuration designed for mass flow.
    max_relative_error : float
        Largest standard error, as a fraction of the value, of a figure that resolves what it measures.
    """

    coverage_factor: float = 2.0
    min_cell_diameters: float = 20.0
    min_depth_diameters: float = 10.0
    min_outlet_diameters: float = 6.0
    mass_flow_velocity_ratio: float = 0.5
    max_relative_error: float = 0.25
    mass_flow_configuration: str = "converging"

    @classmethod
    def from_config(cls, section: Mapping) -> "Criteria":
        """From the validated ``validation`` configuration section."""
        return cls(**{key: section[key] if key == "mass_flow_configuration" else float(section[key])
                      for key in cls.__dataclass_fields__})


def row(group: str, figure: str, case: str, value, error, unit: str, study_value: str, shows: str,
        evidence: str) -> dict:
    """One table row (see the module docstring); ``value`` and ``error`` as numbers (NaN when unknown)."""
    if shows not in (YES, NO, UNKNOWN):
        raise ValueError(f"shows must be {YES!r}, {NO!r} or {UNKNOWN!r}, got {shows!r}")
    return {"group": group, "figure": figure, "case": case, "value": number_or_nan(value),
            "value_error": number_or_nan(error), "unit": unit, "study_value": study_value, "scale_shows": shows,
            "evidence": evidence}


def verdict(*conditions) -> str:
    """YES when every condition holds, NO when one fails; a None condition (not decidable) gives UNKNOWN unless
    another already fails."""
    if any(condition is False for condition in conditions):
        return NO
    if any(condition is None for condition in conditions):
        return UNKNOWN
    return YES


def resolved(difference: float, error: float, k: float) -> bool | None:
    """Whether ``|difference| > k error``; None when the error is not known."""
    if not math.isfinite(error) or not math.isfinite(difference):
        return None
    return abs(difference) > k * error


def precise(value: float, error: float, criteria: Criteria) -> tuple[bool | None, str]:
    """Whether a figure resolves what it measures: its standard error at most ``criteria.max_relative_error`` of
    its magnitude (None when the value or the error is not known), and the evidence clause that says so, e.g.
    ``relative error 34 % (at most 25 %)``."""
    limit = f"(at most {criteria.max_relative_error * 100:g} %)"
    if not math.isfinite(error) or not math.isfinite(value):
        return None, f"relative error not known {limit}"
    relative = _relative(error, value)
    shown = f"{relative * 100:.2g} %" if math.isfinite(relative) else "unbounded"
    return error <= criteria.max_relative_error * abs(value), f"relative error {shown} {limit}"


def ratio(a: float, ua: float, b: float, ub: float) -> tuple[float, float]:
    """``a / b`` and its first-order standard error for independent ``a`` and ``b`` (NaN when b is 0)."""
    if b == 0.0:
        return math.nan, math.nan
    value = a / b
    return value, abs(value) * combine_independent([_relative(ua, a), _relative(ub, b)])


def _relative(error: float, value: float) -> float:
    if value == 0.0:
        return math.nan if error else 0.0
    return error / abs(value)


def plus_minus(value: float, error: float, digits: int = 3) -> str:
    """``value ± error`` for evidence text (``value ±?`` when the error is not known)."""
    if not math.isfinite(error):
        return f"{value:.{digits}g} ±?"
    return f"{value:.{digits}g} ± {error:.2g}"
