"""Whether a measured figure reproduces a finding of the study: one rule per kind of finding part.

Each rule takes the measured figure(s), their standard errors and degrees of freedom, the finding part
(:mod:`siloflow.analysis.studies.validation.findings`) and the :class:`AgreementTolerances`, and returns an
:class:`Agreement`: :data:`REPRODUCED`, :data:`NOT_REPRODUCED` or :data:`NOT_RESOLVED`, with a one-line reason that
quotes the numbers. Pure: numbers in, verdicts out.

Intervals
---------
Every interval is the two-sided 95 % one, ``value -+ q error`` (:meth:`Estimate.interval`). ``q`` is the Student t
quantile with ``dof`` degrees of freedom (a mean over N seeds: ``dof = N - 1``; 4.303 for 3 seeds), or the normal
1.960 for ``dof=None`` (a within-run error from many samples, e.g. batch means of a long steady window). An error
that is not known (NaN, e.g. one seed) resolves nothing: the verdict is "not resolved".

Precision and steadiness only ever turn a verdict into "not resolved", never into "reproduced".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from siloflow.analysis.numerics.uncertainty import Estimate, combine_independent, line_slope
from siloflow.analysis.studies.validation.findings import NEGLIGIBLE, ORDER, POWER_LAW, RATIO, SIGN, VALUE, Part

__all__ = ["REPRODUCED", "NOT_REPRODUCED", "NOT_RESOLVED", "CONFIDENCE", "Agreement", "AgreementTolerances",
           "quantile", "interval", "study_band", "value_in_band", "ratio_in_band", "sign_of_change", "in_order",
           "negligible", "power_law_exponent", "power_law", "ratio", "relative_error", "capped"]

REPRODUCED, NOT_REPRODUCED, NOT_RESOLVED = "reproduced", "not reproduced", "not resolved"
#: Confidence level of every interval (-).
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Agreement:
    """A verdict on one finding part.

    Attributes
    ----------
    verdict : str
        :data:`REPRODUCED`, :data:`NOT_REPRODUCED` or :data:`NOT_RESOLVED`.
    reason : str
        One line quoting the measured numbers and the study's.
    """

    verdict: str
    reason: str


@dataclass(frozen=True)
class AgreementTolerances:
    """The tolerances of the rules (the ``validation.agreement`` configuration section; all dimensionless).

    Attributes
    ----------
    about_relative : float
        Half-width of the band of an "about" figure, as a fraction of it.
    no_band_relative : float
        Half-width of the band of a number the study states with no band, as a fraction of it.
    negligible_relative : float
        Largest "negligible" change, as a fraction of the reference value.
    plateau_relative : float
        Largest change of a curve that "levels off", as a fraction of its value where it does.
    uniform_relative : float
        Largest deviation of a "uniform" velocity from the section's mean, as a fraction of the mean.
    exponent_absolute : float
        Half-width of the band of a power law's exponent.
    max_relative_error : float
        Largest standard error, as a fraction of the value, of a figure that resolves what it measures (the
        ``validation`` section's own key, shared with the rows' :class:`Criteria`).
    """

    about_relative: float = 0.10
    no_band_relative: float = 0.10
    negligible_relative: float = 0.05
    plateau_relative: float = 0.10
    uniform_relative: float = 0.20
    exponent_absolute: float = 0.05
    max_relative_error: float = 0.25

    @classmethod
    def from_config(cls, section: Mapping) -> "AgreementTolerances":
        """From the validated ``validation`` configuration section (its ``agreement`` keys and
        ``max_relative_error``)."""
        return cls(**{key: float(section[key] if key == "max_relative_error" else section["agreement"][key])
                      for key in cls.__dataclass_fields__})

    def __getitem__(self, key: str) -> float:
        """The tolerance a finding part names (``tolerances["about_relative"]``)."""
        if key not in self.__dataclass_fields__:
            raise KeyError(f"no tolerance {key!r}; the tolerances are {', '.join(self.__dataclass_fields__)}")
        return getattr(self, key)


def ratio(a: float, ua: float, b: float, ub: float) -> tuple[float, float]:
    """``a / b`` and its first-order standard error for independent ``a`` and ``b`` (NaN when b is 0)."""
    if b == 0.0:
        return math.nan, math.nan
    value = a / b
    return value, abs(value) * combine_independent([relative_error(ua, a), relative_error(ub, b)])


def relative_error(error: float, value: float) -> float:
    """``error / |value|`` (-): 0 for an exact zero, NaN for an error on a zero value."""
    if value == 0.0:
        return math.nan if error else 0.0
    return error / abs(value)


def quantile(dof: float | None) -> float:
    """The two-sided 95 % quantile: Student t with ``dof`` degrees of freedom (> 0), normal for None (-)."""
    if dof is not None and not dof > 0:
        raise ValueError(f"dof must be > 0 (seeds - 1) or None (normal), got {dof!r}")
    return float(stats.t.ppf(0.5 + 0.5 * CONFIDENCE, math.inf if dof is None else dof))


def interval(value: float, error: float, dof: float | None) -> tuple[float, float]:
    """The 95 % interval ``value -+ quantile(dof) error`` (:meth:`Estimate.interval`), in the unit of ``value``;
    ``(nan, nan)`` when the error is NaN."""
    quantile(dof)  # refuses a bad dof
    estimate = Estimate(value=value, std_error=error, n=1 if dof is None else math.ceil(dof) + 1,
                        method="within run" if dof is None else "seeds", dof=math.inf if dof is None else dof)
    return estimate.interval(CONFIDENCE)


def study_band(part: Part, tolerances: AgreementTolerances,
               configured: tuple[float, float] | None = None) -> tuple[float, float]:
    """The band a VALUE, RATIO or POWER_LAW part is judged against, in the part's unit.

    The study's band (``part.band``, else the point ``part.value``; ``configured`` for a part whose number is in
    the configuration), widened by the part's tolerance: by ``tolerance * |end|`` for a ``*_relative`` key, by
    ``tolerance`` for an ``*_absolute`` one.
    """
    if part.configured:
        if configured is None:
            raise ValueError(f"{part.id}: its number is the configuration's {part.configured}; pass it as configured")
        low, high = configured
    else:
        low, high = part.band or (part.value, part.value)
        if low is None:
            raise ValueError(f"{part.id} is a {part.kind} part: it states no number")
    if part.tolerance is None:
        return float(low), float(high)
    widen = tolerances[part.tolerance]
    if part.tolerance.endswith("_absolute"):
        return float(low) - widen, float(high) + widen
    return float(low) - widen * abs(low), float(high) + widen * abs(high)


def _check(part: Part, *kinds: str) -> None:
    if part.kind not in kinds:
        raise ValueError(f"{part.id} is a {part.kind} part; this rule judges {' or '.join(kinds)} parts")


def _shown(value: float, error: float, dof: float | None) -> str:
    q = f"q {quantile(dof):.4g}, " + ("normal" if dof is None else f"t {dof:g} dof")
    low, high = interval(value, error, dof)
    return f"{value:.4g} ± {error:.2g} (95 %: {low:.4g} to {high:.4g}, {q})"


def _unknown(part: Part, *numbers: float) -> Agreement | None:
    if all(math.isfinite(n) for n in numbers):
        return None
    listed = ", ".join(f"{n:g}" for n in numbers)
    return Agreement(NOT_RESOLVED, f"{part.id}: a value or its error is not known ({listed})")


def _against_band(part: Part, value: float, error: float, dof, band, tolerances, steady: bool) -> Agreement:
    if unknown := _unknown(part, value, error):
        return unknown
    low, high = interval(value, error, dof)
    shown = f"{part.id}: {_shown(value, error, dof)}"
    span = f"{band[0]:.4g} to {band[1]:.4g}"
    study = f"the study's {span}" if part.tolerance is None else f"{span} (the study's {part.stated()})"
    if high < band[0] or low > band[1]:
        return Agreement(NOT_REPRODUCED, f"{shown} lies outside {study}")
    limit = tolerances.max_relative_error
    if error > limit * abs(value) or not steady:
        why = f"relative error above {limit * 100:g} %" if error > limit * abs(value) else "not steady"
        return Agreement(NOT_RESOLVED, f"{shown} overlaps {study}, but {why}")
    return Agreement(REPRODUCED, f"{shown} overlaps {study}")


def value_in_band(value: float, error: float, dof: float | None, part: Part, tolerances: AgreementTolerances, *,
                  steady: bool = True, configured: tuple[float, float] | None = None) -> Agreement:
    """A value against the study's band (VALUE or RATIO part; :func:`study_band`).

    The 95 % interval entirely outside the band: not reproduced. Otherwise a figure whose standard error exceeds
    ``max_relative_error`` of its magnitude, or that is not steady, is not resolved; else it is reproduced.

    Parameters
    ----------
    value, error : float
        The measured figure and its standard error, in the part's unit (error NaN when not known).
    dof : float or None
        Degrees of freedom of ``error`` (seeds - 1), None for a within-run error from many samples.
    part : Part
        The finding part.
    tolerances : AgreementTolerances
    steady : bool, optional
        Whether the run was steady over the window the figure comes from.
    configured : tuple of float, optional
        ``(low, high)`` in the part's unit, for a part whose number is in the configuration (``part.configured``).
    """
    _check(part, VALUE, RATIO)
    return _against_band(part, value, error, dof, study_band(part, tolerances, configured), tolerances, steady)


def ratio_in_band(numerator: float, numerator_error: float, denominator: float, denominator_error: float,
                  dof: float | None, part: Part, tolerances: AgreementTolerances, *, steady: bool = True) -> Agreement:
    """A ratio of two measured figures against the study's band (RATIO part), as :func:`value_in_band`.

    The two figures are taken as independent: the ratio ``r = a / b`` has the first-order error
    ``|r| sqrt((ua / a)^2 + (ub / b)^2)`` (:func:`ratio`); ``dof`` is
    that of the two errors (the smaller, when they differ). A zero denominator gives an unknown ratio.
    """
    _check(part, RATIO)
    value, error = ratio(numerator, numerator_error, denominator, denominator_error)
    return _against_band(part, value, error, dof, study_band(part, tolerances), tolerances, steady)


def capped(agreement: Agreement, why: str) -> Agreement:
    """The verdict at most "not resolved" when ``why`` says that a figure it rests on is only a bound (a VRR at its
    counting-noise ceiling), whichever way it went; unchanged when ``why`` is empty."""
    if not why or agreement.verdict == NOT_RESOLVED:
        return agreement
    return Agreement(NOT_RESOLVED, f"{agreement.reason}; not resolved: {why}")


def _steady_or_not_resolved(agreement: Agreement, steady: bool) -> Agreement:
    """A "reproduced" of a figure that was not steady is "not resolved"; any other verdict stands."""
    if steady or agreement.verdict != REPRODUCED:
        return agreement
    return Agreement(NOT_RESOLVED, f"{agreement.reason}; but not steady")


def sign_of_change(change: float, error: float, dof: float | None, part: Part, *, steady: bool = True) -> Agreement:
    """The sign of a change (SIGN part): resolved, ``|change| > q error``, with the study's sign: reproduced (not
    resolved when the figures were not ``steady``); resolved with the other sign: not reproduced; else not resolved.
    Change and error in the part's unit."""
    _check(part, SIGN)
    if unknown := _unknown(part, change, error):
        return unknown
    q = quantile(dof)
    shown = f"{part.id}: change {_shown(change, error, dof)}; study: {part.stated()}"
    if abs(change) <= q * error:
        return Agreement(NOT_RESOLVED, f"{shown}; |change| <= {q:.4g} × error")
    return _steady_or_not_resolved(
        Agreement(REPRODUCED if math.copysign(1.0, change) == part.sign else NOT_REPRODUCED, shown), steady)


def in_order(values: Sequence[float], errors: Sequence[float], dof: float | None, part: Part) -> Agreement:
    """An order of figures (ORDER part), ``values`` and ``errors`` given in the part's order (largest first).

    Each adjacent pair's difference ``v_i - v_(i+1)`` has the error ``sqrt(e_i^2 + e_(i+1)^2)`` (independent
    figures). Every pair resolved (``|difference| > q error``) in the study's order: reproduced; any pair resolved
    in the opposite order: not reproduced; else not resolved.
    """
    _check(part, ORDER)
    if len(values) != len(part.order) or len(errors) != len(part.order):
        raise ValueError(f"{part.id}: give one value and one error for each of {part.order}")
    if unknown := _unknown(part, *values, *errors):
        return unknown
    q = quantile(dof)
    pairs = []
    for i in range(len(values) - 1):
        difference = values[i] - values[i + 1]
        reach = q * combine_independent([errors[i], errors[i + 1]])
        pairs.append((difference, reach, part.order[i], part.order[i + 1]))
    shown = f"{part.id}: " + "; ".join(f"{a} - {b} = {d:.3g} (q × error {r:.2g})" for d, r, a, b in pairs)
    if any(d < -r for d, r, _, _ in pairs):
        return Agreement(NOT_REPRODUCED, f"{shown}: a pair resolved against the study's {part.stated()}")
    if all(d > r for d, r, _, _ in pairs):
        return Agreement(REPRODUCED, f"{shown}: every pair resolved in the study's order")
    return Agreement(NOT_RESOLVED, f"{shown}: a pair not resolved")


def negligible(change: float, error: float, dof: float | None, reference: float, part: Part,
               tolerances: AgreementTolerances, *, steady: bool = True) -> Agreement:
    """A change the study calls negligible (or a level curve, a uniform velocity; NEGLIGIBLE part).

    The limit is ``tolerance * |reference|`` (the part's tolerance key), ``reference`` being the value the change is
    relative to, in the unit of ``change`` (its own error is left out: it moves the limit at second order only).
    The 95 % interval of the change inside ``-+ limit``: reproduced; entirely outside it: not reproduced; else not
    resolved; a "reproduced" of figures that were not ``steady`` is "not resolved".
    """
    _check(part, NEGLIGIBLE)
    if unknown := _unknown(part, change, error, reference):
        return unknown
    limit = tolerances[part.tolerance] * abs(reference)
    low, high = interval(change, error, dof)
    shown = (f"{part.id}: change {_shown(change, error, dof)}, negligible within ± {limit:.3g} "
             f"({part.tolerance} {tolerances[part.tolerance]:g} of {reference:.4g})")
    if -limit <= low and high <= limit:
        return _steady_or_not_resolved(Agreement(REPRODUCED, f"{shown}: inside"), steady)
    if high < -limit or low > limit:
        return Agreement(NOT_REPRODUCED, f"{shown}: entirely outside")
    return Agreement(NOT_RESOLVED, f"{shown}: partly outside")


def power_law_exponent(factors: Sequence[float], values: Sequence[float],
                       errors: Sequence[float] | None = None) -> tuple[float, float]:
    """The exponent ``p`` of ``values = c factors^p`` and its standard error, by least squares on logarithms.

    With ``errors`` (standard errors of ``values``, same unit), a weighted fit of ``ln v`` on ``ln f`` with the
    first-order errors ``e / v`` of ``ln v`` as known sigmas (:func:`numpy.polyfit`, unscaled covariance; NaN when
    an error is NaN). Without, an unweighted fit whose error comes from the scatter about the line
    (:func:`scipy.stats.linregress`, ``n - 2`` degrees of freedom; NaN for two points).

    Parameters
    ----------
    factors : sequence of float
        The scale factors (e.g. gravity over 9.81 m/s2), > 0, at least two distinct (-).
    values : sequence of float
        The figure at each factor, > 0, any unit.
    errors : sequence of float, optional
        Their standard errors, in the unit of ``values``.
    """
    f, v = np.asarray(factors, dtype=float), np.asarray(values, dtype=float)
    if f.ndim != 1 or f.shape != v.shape or np.unique(f).size < 2 or np.any(f <= 0) or np.any(v <= 0):
        raise ValueError("factors and values must be equal 1-D lists of positive numbers, with two factors at least")
    x, y = np.log(f), np.log(v)
    if errors is None:
        return line_slope(x, y)
    sigma = np.asarray(errors, dtype=float)
    if sigma.shape != v.shape or np.any(sigma < 0) or np.any(np.isinf(sigma)):
        raise ValueError("errors must be one standard error >= 0 (or NaN, unknown) for each value")
    sigma = sigma / v
    if np.any(np.isnan(sigma)) or np.any(sigma == 0):
        # an unknown error leaves the exponent's unknown too
        return line_slope(x, y)[0], math.nan
    return line_slope(x, y, sigma)


def power_law(factors: Sequence[float], values: Sequence[float], errors: Sequence[float] | None,
              dof: float | None, part: Part, tolerances: AgreementTolerances, *, steady: bool = True) -> Agreement:
    """A scaling (POWER_LAW part): the measured exponent (:func:`power_law_exponent`) against the study's
    ``part.value -+ exponent_absolute``.

    A part that scales is judged as :func:`value_in_band`. A part that deviates (``part.deviates``) is reproduced
    when the exponent's 95 % interval lies entirely outside the band (and the run was steady), not reproduced when
    it lies entirely inside it, else not resolved. ``dof`` is that of ``errors``; without errors it is ``n - 2``.
    """
    _check(part, POWER_LAW)
    exponent, error = power_law_exponent(factors, values, errors)
    if errors is None:
        dof = len(values) - 2 if len(values) > 2 else None
    band = study_band(part, tolerances)
    if not part.deviates:
        return _against_band(part, exponent, error, dof, band, tolerances, steady)
    if unknown := _unknown(part, exponent, error):
        return unknown
    low, high = interval(exponent, error, dof)
    shown = f"{part.id}: exponent {_shown(exponent, error, dof)}, scaling band {band[0]:.3g} to {band[1]:.3g}"
    if high < band[0] or low > band[1]:
        if not steady:
            return Agreement(NOT_RESOLVED, f"{shown}: deviates, but not steady")
        return Agreement(REPRODUCED, f"{shown}: deviates")
    if band[0] <= low and high <= band[1]:
        return Agreement(NOT_REPRODUCED, f"{shown}: scales, no deviation")
    return Agreement(NOT_RESOLVED, f"{shown}: deviation not resolved")
