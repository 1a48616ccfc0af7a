"""Validation rows of the calibration: the bulk-friction curves of the Jenike sweep and the checks around them.

Rows (see :mod:`siloflow.analysis.studies.validation.rows`):

- one per calibration curve (shape, test, rolling friction): bulk friction at the largest particle friction;
  the scale shows the curve's physics when the cell is wide in particle diameters and the curve is seen to stop
  rising (its first step resolved, its last step not);
- rotation blocked against free rotation, the other lid against the configured one, each extra restitution
  against the base one and each other shear velocity against the configured one, on the same sweep points;
- the calibrated particle-scale friction coefficients, and for a target no swept particle friction reproduces, the
  chart's bulk friction angle nearest it.

Every row says whether the shear tests it draws on reached a steady window (``window_method`` of each point,
:func:`siloflow.calibration.friction.bulk_friction_of_shear`): a bulk friction averaged over the second half of a shear that
never reached a plateau is a transient, and the row's scale does not show the physics.

Inputs are the rows of ``calibration/bulk_friction.csv`` as read (strings are fine) and the calibration's
``parameters.yaml`` as read.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation.rows import NO, Criteria, plus_minus, precise, resolved, row, verdict

__all__ = ["SECTIONS", "calibration_rows"]

GROUP = "Calibration (Jenike cell)"
#: The study's chosen particle-scale friction of the two-sphere clump (thesis ch. 4).
STUDY_FRICTION = {"internal": "0.35", "aluminium": "0.17", "perspex": "0.2"}


_RESOLVED = {True: "resolved", False: "not resolved", None: "unknown"}


def _flag(value) -> bool:
    return str(value) == "True"


def _point(entry: Mapping) -> tuple[float, float, float]:
    return (float(entry["particle_friction"]), float(entry["bulk_friction"]),
            number_or_nan(entry.get("bulk_friction_error")))


def _entries(rows: Sequence[Mapping], keep) -> dict[tuple, list[Mapping]]:
    """The sweep points ``keep`` selects, per curve (shape, test, rolling friction), by particle friction."""
    curves: dict[tuple, list] = {}
    for entry in rows:
        if keep(entry):
            key = (entry["shape"], entry["test"], float(entry["rolling_friction"]))
            curves.setdefault(key, []).append(entry)
    return {key: sorted(entries, key=_point) for key, entries in sorted(curves.items())}


def _curves(rows: Sequence[Mapping], keep) -> dict[tuple, list[tuple[float, float, float]]]:
    return {key: [_point(entry) for entry in entries] for key, entries in _entries(rows, keep).items()}


def _steady(entries: Sequence[Mapping]) -> tuple[bool | None, str]:
    """Whether every shear test of ``entries`` reached a steady window (None when one does not say), and the
    evidence text."""
    if not entries:
        return None, "no shear test of this curve in the table"
    methods = [entry.get("window_method") or None for entry in entries]
    steady = sum(method == "steady" for method in methods)
    text = f"steady shear window in {steady} of {len(methods)} shear tests"
    if None in methods:
        return None, text + " (the others do not say)"
    return steady == len(methods), text if steady == len(methods) else text + " (the others a transient)"


def _not(condition):
    return None if condition is None else not condition


def _cell_text(cell_diameter: float, diameter: float, criteria: Criteria) -> tuple[bool, str]:
    ratio = cell_diameter / diameter
    return ratio >= criteria.min_cell_diameters, (
        f"cell {cell_diameter * 1000:.0f} mm = {ratio:.1f} particle diameters (>= {criteria.min_cell_diameters:g})")


def _both(a: bool | None, b: bool | None) -> bool | None:
    """Both conditions: False when one fails, None when one is not known, else True."""
    return False if False in (a, b) else None if None in (a, b) else True


def _judged(cell: tuple[bool, str], entries: Sequence[Mapping]) -> tuple[bool | None, str]:
    """The cell's judgement joined with the steadiness of the shear tests a row draws on."""
    steady_ok, steady_text = _steady(entries)
    return _both(cell[0], steady_ok), f"{cell[1]}; {steady_text}"


def _rise(step: tuple[float, float], k: float) -> bool | None:
    """Whether a step of a curve (its change and that change's standard error) is a rise resolved at ``k`` standard
    errors: True, False (no resolved rise, a resolved fall included), None when its error is not known."""
    changes = resolved(*step, k)
    return None if changes is None else changes and step[0] > 0.0


def _curve_row(label: str, key: tuple, entries: list, cell_ok: bool, cell_text: str, criteria: Criteria) -> dict:
    shape, test, rolling = key
    points = [_point(entry) for entry in entries]
    cell_ok, cell_text = _judged((cell_ok, cell_text), entries)
    k = criteria.coverage_factor
    text = "; ".join(f"{mu:g}: {plus_minus(b, e)}" for mu, b, e in points)
    mu, bulk, error = points[-1]
    if len(points) < 3:
        return row(GROUP, f"Bulk friction at particle friction {mu:g} ({label})", f"{shape}, {test}, rolling {rolling:g}",
                   bulk, error, "-", "", NO, f"{cell_text}; particle friction -> bulk friction {text}; fewer than "
                   "three points cannot show where bulk friction stops rising")
    first = (points[1][1] - points[0][1], combine_independent([points[1][2], points[0][2]]))
    last = (points[-1][1] - points[-2][1], combine_independent([points[-1][2], points[-2][2]]))
    # a step resolved from zero is a rise only when it is positive: a curve that falls at its end has passed its
    # maximum, so it stopped rising too
    first_rises, last_rises, last_changes = _rise(first, k), _rise(last, k), resolved(*last, k)
    shows = verdict(cell_ok, first_rises, _not(last_rises))
    stops = ("unknown" if last_rises is None else "still rises" if last_rises else
             "stops rising and falls at its end" if last_changes else "stops rising")
    return row(GROUP, f"Bulk friction at particle friction {mu:g} ({label})", f"{shape}, {test}, rolling {rolling:g}",
               bulk, error, "-", "", shows,
               f"{cell_text}; particle friction -> bulk friction {text}; first step {plus_minus(*first)}, last step "
               f"{plus_minus(*last)}: bulk friction {stops} within the swept range")


def _paired_rows(figure: str, reference: dict, other: dict, cell_ok: bool, cell_text: str, criteria: Criteria,
                 study: str, expect_difference: bool) -> list[dict]:
    """The mean difference other - reference over their common sweep points, per curve."""
    rows = []
    for key, points in other.items():
        base = {mu: (b, e) for mu, b, e in reference.get(key, [])}
        pairs = [(b - base[mu][0], combine_independent([e, base[mu][1]]), mu) for mu, b, e in points if mu in base]
        if not pairs:
            continue
        difference = sum(d for d, _, _ in pairs) / len(pairs)
        error = combine_independent([e for _, e, _ in pairs]) / len(pairs)
        seen = resolved(difference, error, criteria.coverage_factor)
        resolution = f"{_RESOLVED[seen]} at {criteria.coverage_factor:g} standard errors"
        if expect_difference:
            shows = verdict(cell_ok, seen)
        else:
            # "insensitive" is shown only by an error small enough to have seen a change
            level = sum(base[mu][0] for _, _, mu in pairs) / len(pairs)
            small, small_text = precise(level, error, criteria)
            shows = verdict(cell_ok, _not(seen), small)
            resolution += f"; its error against the bulk friction {level:.3g}: {small_text}"
        shape, test, rolling = key
        listing = "; ".join(f"{mu:g}: {plus_minus(d, e)}" for d, e, mu in pairs)
        rows.append(row(GROUP, figure, f"{shape}, {test}, rolling {rolling:g}", difference, error, "-", study, shows,
                        f"{cell_text}; differences at particle friction {listing}; mean {plus_minus(difference, error)}"
                        f": {resolution}"))
    return rows


#: The kinds of calibration rows (:func:`calibration_rows`' ``sections``).
SECTIONS = ("curves", "comparisons", "calibrated")


def calibration_rows(bulk_rows: Sequence[Mapping], parameters: Mapping | None, cell_diameter: float,
                     particle_diameters: Mapping[str, float], base_restitution: float, lid: str,
                     shear_velocity: float, criteria: Criteria, sections: Sequence[str] = SECTIONS) -> list[dict]:
    """The calibration's validation rows.

    Parameters
    ----------
    bulk_rows : sequence of mapping
        Rows of ``calibration/bulk_friction.csv``: shape, test, lid, rolling_friction, restitution,
        rotation_blocked, particle_friction, bulk_friction, bulk_friction_error (-).
    parameters : mapping or None
        The calibration's ``parameters.yaml`` (:func:`siloflow.calibration.inversion` output) as read; needed for the
        ``calibrated`` rows only.
    cell_diameter : float
        Inner diameter of the Jenike cell (m).
    particle_diameters : mapping
        Volume-equivalent diameter of each shape (m).
    base_restitution : float
        The sweep's base restitution (-).
    lid : str
        The configured lid; rows with the other lid are the lid comparison.
    shear_velocity : float
        The configured shear velocity (m/s); rows at another are the shear-speed study.
    criteria : Criteria
    sections : sequence of str
        Which rows (:data:`SECTIONS`): each chart's curve, the checks against the charts, the calibrated
        coefficients.
    """
    unknown = sorted(set(sections) - set(SECTIONS))
    if unknown:
        raise ValueError(f"unknown calibration row sections {', '.join(unknown)}; the sections are {', '.join(SECTIONS)}")
    if "calibrated" in sections and parameters is None:
        raise ValueError("the calibrated rows need the calibration's parameters")
    configured = {"rotation": lambda e: not _flag(e["rotation_blocked"]), "lid": lambda e: e["lid"] == lid,
                  "restitution": lambda e: float(e["restitution"]) == base_restitution,
                  "speed": lambda e: float(e["shear_velocity"]) == shear_velocity}

    def chart(entry, varied=()):
        """Whether an entry is on the chart in every dimension but the ``varied`` ones (a check varies one)."""
        return all(test(entry) for name, test in configured.items() if name not in varied)

    curves = _curves(bulk_rows, chart)
    chart_entries = _entries(bulk_rows, chart)
    blocked = _entries(bulk_rows, lambda e: _flag(e["rotation_blocked"]) and chart(e, ("rotation",)))
    other_lid = _entries(bulk_rows, lambda e: e["lid"] != lid and chart(e, ("lid",)))
    restitutions = sorted({float(e["restitution"]) for e in bulk_rows if chart(e, ("restitution",))} - {base_restitution})
    speeds = sorted({float(e["shear_velocity"]) for e in bulk_rows if chart(e, ("speed",))} - {shear_velocity})
    rows = []
    for key, entries in chart_entries.items() if "curves" in sections else ():
        cell_ok, cell_text = _cell_text(cell_diameter, particle_diameters[key[0]], criteria)
        rows.append(_curve_row(f"{lid} lid", key, entries, cell_ok, cell_text, criteria))
    comparisons = [("Bulk friction, rotation blocked - free", blocked, "higher with rotation blocked", True),
                   (f"Bulk friction, {'servo' if lid == 'rigid' else 'rigid'} lid - {lid} lid", other_lid,
                    "a servo lid that cannot tilt overestimates", True)]
    for restitution in restitutions:
        extra = _entries(bulk_rows, lambda e, r=restitution: float(e["restitution"]) == r and chart(e, ("restitution",)))
        comparisons.append((f"Bulk friction, restitution {restitution:g} - {base_restitution:g}", extra,
                            "insensitive to restitution", False))
    for speed in speeds:
        slower = _entries(bulk_rows, lambda e, v=speed: float(e["shear_velocity"]) == v and chart(e, ("speed",)))
        comparisons.append((f"Bulk friction, shear velocity {speed:g} - {shear_velocity:g} m/s", slower,
                            "independent of the shear speed (quasi-static)", False))
    for figure, others, study, expect in comparisons if "comparisons" in sections else ():
        for key, entries in others.items():
            # judged on the shear tests the differences are taken from: a transient elsewhere on the chart's curve
            # is that curve's row's to report, not this one's
            compared = {_point(entry)[0] for entry in entries}
            paired = [entry for entry in chart_entries.get(key, []) if _point(entry)[0] in compared]
            cell_ok, cell_text = _judged(_cell_text(cell_diameter, particle_diameters[key[0]], criteria),
                                         [*paired, *entries])
            rows += _paired_rows(figure, curves, {key: [_point(entry) for entry in entries]}, cell_ok, cell_text,
                                 criteria, study, expect)
    if "calibrated" in sections:
        rows += _calibrated_rows(parameters, cell_diameter, particle_diameters, chart_entries, criteria)
    return rows


def _bracketing(entries: Sequence[Mapping], lower: float, upper: float) -> list[Mapping]:
    """The points of a curve (sorted by particle friction) that a coefficient read between ``lower`` and ``upper``
    rests on: those inside the band and the nearest on either side of it. A transient at a particle friction far
    from the band does not make the coefficient one."""
    frictions = [float(entry["particle_friction"]) for entry in entries]
    below = [index for index, value in enumerate(frictions) if value < lower]
    above = [index for index, value in enumerate(frictions) if value > upper]
    first = below[-1] if below else 0
    last = above[0] if above else len(entries) - 1
    return list(entries[first:last + 1])


def _calibrated_rows(parameters: Mapping, cell_diameter: float, particle_diameters: Mapping[str, float],
                     chart_entries: Mapping[tuple, list], criteria: Criteria) -> list[dict]:
    shape = parameters["shape"]
    cell = _cell_text(cell_diameter, particle_diameters[shape], criteria)
    found = [("internal", parameters.get("particle_particle"))]
    found += sorted((parameters.get("particle_wall") or {}).items())
    rows = []
    for test, result in found:
        if not result:
            continue
        target = parameters["targets_deg"].get(test)
        clipped = bool(result.get("band_clipped"))
        # the chart this coefficient was read from, and on it the points the band lies between
        entries = _curve_entries(parameters, chart_entries, test)
        cell_ok, cell_text = _judged(cell, _bracketing(entries, result["lower"], result["upper"]))
        rows.append(row(
            GROUP, f"Calibrated particle sliding friction ({'particle-particle' if test == 'internal' else 'particle-' + test})",
            f"{shape}, rolling {parameters['rolling_friction']:g}", result["sliding_friction"],
            number_or_nan(result.get("sliding_friction_error")), "-", STUDY_FRICTION.get(test, ""),
            verdict(cell_ok, not clipped),
            f"{cell_text}; reproduces the measured {target:g} deg +- {parameters['tolerance_deg']:g} deg; band "
            f"{result['lower']:.3g} to {result['upper']:.3g}{' (clipped at the swept range)' if clipped else ''}"))
    for test, message in sorted((parameters.get("unreachable") or {}).items()):
        entries = _curve_entries(parameters, chart_entries, test)
        if entries:
            rows.append(_unreachable_row(parameters, test, message, entries, cell, criteria))
    return rows


def _curve_entries(parameters: Mapping, chart_entries: Mapping[tuple, list], test: str) -> list[Mapping]:
    """The points of the chart a coefficient of ``test`` (``internal`` or a wall material) is read from: the
    calibration shape's curve of that test at the calibration's rolling friction, by particle friction."""
    kind, material = ("internal", None) if test == "internal" else ("wall", test)
    entries = chart_entries.get((parameters["shape"], kind, float(parameters["rolling_friction"])), [])
    return [entry for entry in entries if material is None or entry.get("wall_material") == material]


def _angle_deg(bulk: float, error: float) -> tuple[float, float]:
    """The friction angle ``atan(bulk)`` [deg] and its first-order standard error ``error / (1 + bulk^2)``."""
    return math.degrees(math.atan(bulk)), math.degrees(error / (1.0 + bulk * bulk))


def _unreachable_row(parameters: Mapping, test: str, message: str, entries: Sequence[Mapping],
                     cell: tuple[bool, str], criteria: Criteria) -> dict:
    """A target no particle friction of the chart reproduces: the chart's end nearest it, in degrees, and whether
    the gap exceeds its error. The end is judged on its two outermost points (their steadiness shows the level)."""
    target = float(parameters["targets_deg"][test])
    points = [_point(entry) for entry in entries]
    # atan is increasing: the target lies above the chart when its tangent exceeds the largest bulk friction
    above = math.tan(math.radians(target)) > max(bulk for _, bulk, _ in points)
    end = (max if above else min)(points, key=lambda point: point[1])
    angle, error = _angle_deg(end[1], end[2])
    cell_ok, cell_text = _judged(cell, entries[-2:] if above else entries[:2])
    gap = target - angle
    seen = resolved(gap, error, criteria.coverage_factor)
    label = "particle-particle" if test == "internal" else "particle-" + test
    return row(GROUP, f"Bulk friction angle nearest the unreachable target ({label})",
               f"{parameters['shape']}, rolling {parameters['rolling_friction']:g}", angle, error, "deg",
               f"{target:g} deg measured; particle friction {STUDY_FRICTION.get(test, '?')}", verdict(cell_ok, seen),
               f"{cell_text}; {message}; the chart's {'highest' if above else 'lowest'} point, at particle friction "
               f"{end[0]:g}, lies {plus_minus(abs(gap), error)} deg {'below' if above else 'above'} the target: "
               f"{_RESOLVED[seen]} at {criteria.coverage_factor:g} standard errors")
