"""Validation rows of the Jenike calibration (thesis ch. 4): each judged against a finding part C1-C7 where the study
states one, else a measurement with no finding (the other lid, the other shear speed, the calibrated coefficients).

Rows (see :mod:`siloflow.analysis.studies.validation.rows`), by section (:data:`SECTIONS`):

- ``curves``: on each shape's internal and wall chart at rolling friction 0, C1 (bulk minus particle friction at
  0.1; the bulk friction at 0 when swept), C2 and C3 (the rise to the knee, the change over the plateau, the plateau
  value, the mobilised wall friction at 0.1, the two clumps' plateaus alike); on the two-sphere clump's internal
  charts at rolling friction 0 and 0.1, C6;
- ``comparisons``: C5 (rotation blocked against free), C4 (each extra restitution against the base one), and the
  other lid, the other shear velocities and the pour variant (samples poured at their own particle friction) against
  the configured ones (no finding);
- ``calibrated``: C7 (the bulk friction angles at the study's chosen inputs), with the calibrated particle sliding
  friction coefficients and the chart's angle nearest an unreachable target (no finding).

Where the sweep lacks the particle friction a finding names, a row takes the swept point nearest it (ties to the
higher one: the side of the plateau, which starts at the knee) and says so in ``differs``, unless that point is
nearer the one the finding's other part names (C5, C6: one part is not judged at the other's point); a value the
study reads between two swept points (C7) is interpolated linearly on the chart. No row chooses its points from
the values. A row whose shear tests did not all reach a steady window (``window_method`` of each point,
:func:`siloflow.calibration.friction.bulk_friction_of_shear`) can be "not resolved" at most: a bulk friction averaged
over a shear that never reached a plateau is a transient. Scale is not judged here: the record adds it from the
configuration.

Inputs are the rows of ``calibration/bulk_friction.csv`` as read (strings are fine) and the calibration's
``parameters.yaml`` as read (:mod:`siloflow.calibration.inversion`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from types import MappingProxyType

from siloflow.model.cases.jenike_sweep import configured_pour
from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation import agreement as rules
from siloflow.analysis.studies.validation.agreement import AgreementTolerances, ratio
from siloflow.analysis.studies.validation.findings import NEGLIGIBLE, PARTS, SIGN
from siloflow.analysis.studies.validation.rows import plus_minus, resolution, row

__all__ = ["SECTIONS", "MADE", "UNMADE", "calibration_rows"]

GROUP = "Calibration (Jenike cell)"
#: The kinds of calibration rows (:func:`calibration_rows`' ``sections``).
SECTIONS = ("curves", "comparisons", "calibrated")
#: The parts these rows can never make from the validation tier's data (config/validation.yaml), and what would
#: make them: each is made by the same code from a sweep that holds its points.
UNMADE = MappingProxyType({
    "C1.finite_at_zero": "needs a sweep point at particle friction 0: jenike.sweep.sliding_friction is [0.1, 0.3, "
                         "0.5, 0.8] in config/validation.yaml",
    "C3.sphere": "needs the sphere's wall test: jenike.sweep.wall_test_shapes is [sphere2] in config/validation.yaml "
                 "(null, or a list with sphere, runs it)",
    "C3.sphere4": "needs the four-sphere clump's wall test: jenike.sweep.wall_test_shapes is [sphere2] in "
                  "config/validation.yaml (null, or a list with sphere4, runs it)",
    "C7.perspex": "needs the Perspex wall test: jenike.sweep.tests is [internal, aluminium] in "
                  "config/validation.yaml (add perspex; its measured angle is calibration.targets_deg.perspex)",
})
#: The finding parts these rows make from the validation tier's data: the other parts of C1-C7.
MADE = tuple(part for part in PARTS if part[:2] in {f"C{i}" for i in range(1, 8)} and part not in UNMADE)
#: The shapes the study ran (§4.2); a curve of another shape states no finding of the study.
STUDY_SHAPES = ("sphere", "sphere2", "sphere4")
#: The study's sweep of particle and particle-wall friction: 0 to 1 in steps of 0.1 (§4.3.1.2) (-).
STUDY_SWEEP = tuple(round(0.1 * step, 1) for step in range(11))
#: Where each chart levels off, as the findings read the study (-): C2's "about 0.4"; C3 names no knee and is read
#: from 0.5, the first step above both wall plateaus (findings.py), so its plateau value is taken from there too.
KNEE = {"internal": 0.4, "wall": 0.5}
#: The study's chosen particle-scale friction of the two-sphere clump at rolling friction 0.1, per test (§4.6) (-).
STUDY_CHOICE = {"internal": 0.35, "aluminium": 0.17, "perspex": 0.20}
CHOSEN_SHAPE, CHOSEN_ROLLING = "sphere2", 0.1
_SAME = 1e-9  # swept frictions are read back from text: equal within this (-)


# ----------------------------------------------------------------------------------------------- the sweep's points

def _flag(value) -> bool:
    return str(value) == "True"


def _mu(entry: Mapping) -> float:
    return float(entry["particle_friction"])


def _bulk(entry: Mapping) -> tuple[float, float]:
    return float(entry["bulk_friction"]), number_or_nan(entry.get("bulk_friction_error"))


def _same(a: float, b: float) -> bool:
    return abs(a - b) < _SAME


def _chart(entry: Mapping) -> str:
    """``internal``, or the wall material of a wall test."""
    return "internal" if entry["test"] == "internal" else str(entry["wall_material"])


def _kind(chart: str) -> str:
    return "internal" if chart == "internal" else "wall"


def _name(chart: str) -> str:
    return "particle friction" if chart == "internal" else "particle-wall friction"


def _curves(rows: Sequence[Mapping], keep: Callable[[Mapping], bool]) -> dict[tuple, list[Mapping]]:
    """The points ``keep`` selects, per curve ``(shape, chart, rolling friction)``, by particle friction."""
    curves: dict[tuple, list] = {}
    for entry in rows:
        if keep(entry):
            curves.setdefault((str(entry["shape"]), _chart(entry), float(entry["rolling_friction"])), []).append(entry)
    return {key: sorted(entries, key=_mu) for key, entries in sorted(curves.items())}


def _case(key: tuple) -> str:
    shape, chart, rolling = key
    return f"{shape}, {chart}, rolling {rolling:g}"


def _points(entries: Sequence[Mapping]) -> str:
    return "; ".join(f"{_mu(entry):g}: {plus_minus(*_bulk(entry))}" for entry in entries)


def _nearest(entries: Sequence[Mapping], target: float) -> Mapping:
    """The swept point nearest ``target``; of two as near, the higher (the plateau's side of a knee). Rounded so
    that 0.3 and 0.5 are as near 0.4, whatever the binary fractions say."""
    return min(entries, key=lambda entry: (round(abs(_mu(entry) - target), 9), -_mu(entry)))


def _pair(base: Sequence[Mapping], other: Sequence[Mapping], target: float) -> tuple[Mapping, Mapping] | None:
    """The points of two curves at their common particle friction nearest ``target``, or None with none common."""
    by_mu = {round(_mu(entry), 9): entry for entry in base}
    common = [entry for entry in other if round(_mu(entry), 9) in by_mu]
    if not common:
        return None
    chosen = _nearest(common, target)
    return by_mu[round(_mu(chosen), 9)], chosen


def _steady(entries: Sequence[Mapping]) -> tuple[bool, str]:
    """Whether every shear test of ``entries`` reached a steady window, and the evidence. A test that does not say
    is not taken as steady: only a steady window supports a verdict of "reproduced"."""
    methods = [entry.get("window_method") or None for entry in entries]
    steady = sum(method == "steady" for method in methods)
    text = f"steady shear window in {steady} of {len(methods)} shear tests"
    if steady == len(methods):
        return True, text
    return False, text + (" (the others do not say)" if None in methods else " (the others a transient)")


def _angle_deg(bulk: float, error: float) -> tuple[float, float]:
    """The friction angle ``atan(bulk)`` (deg) and its first-order standard error ``error / (1 + bulk^2)`` (deg)."""
    return math.degrees(math.atan(bulk)), math.degrees(error / (1.0 + bulk * bulk))


# ------------------------------------------------------------------------------------------------------- the rows

def calibration_rows(bulk_rows: Sequence[Mapping], parameters: Mapping | None, base_restitution: float, lid: str,
                     shear_velocity: float, targets: Mapping[str, tuple[float, float]],
                     tolerances: AgreementTolerances, dof: float | None,
                     sections: Sequence[str] = SECTIONS) -> list[dict]:
    """The calibration's validation rows (see the module docstring).

    Parameters
    ----------
    bulk_rows : sequence of mapping
        Rows of ``calibration/bulk_friction.csv``: shape, test (``internal`` or ``wall``), wall_material, lid,
        rolling_friction, restitution, rotation_blocked, shear_velocity (m/s), particle_friction, bulk_friction,
        bulk_friction_error (-), window_method.
    parameters : mapping or None
        The calibration's ``parameters.yaml`` as read; needed for the ``calibrated`` rows only.
    base_restitution : float
        The sweep's base restitution (-): the charts' points.
    lid : str
        The configured lid: the charts' points; points with the other lid are the lid comparison.
    shear_velocity : float
        The configured shear velocity (m/s): the charts' points; points at another are the shear-speed study.
    targets : mapping
        ``{"internal" or wall material: (low, high)}``: the configured measured angles -+ calibration.tolerance_deg
        (deg), the bands of C7.aluminium and C7.perspex.
    tolerances : AgreementTolerances
    dof : float or None
        Degrees of freedom of the points' errors: seeds - 1 when a spread between seeds is in them, None for
        within-run errors only.
    sections : sequence of str
        Which rows (:data:`SECTIONS`), each of which may be asked for alone.
    """
    unknown = sorted(set(sections) - set(SECTIONS))
    if unknown:
        raise ValueError(f"unknown calibration row sections {', '.join(unknown)}; "
                         f"the sections are {', '.join(SECTIONS)}")
    if "calibrated" in sections and parameters is None:
        raise ValueError("the calibrated rows need the calibration's parameters")
    configured = {"rotation": lambda e: not _flag(e["rotation_blocked"]), "lid": lambda e: e["lid"] == lid,
                  "restitution": lambda e: _same(float(e["restitution"]), base_restitution),
                  "speed": lambda e: _same(float(e["shear_velocity"]), shear_velocity),
                  "pour": configured_pour}

    def on_chart(entry, varied=()):
        """Whether an entry is on the chart in every dimension but the ``varied`` ones (a check varies one)."""
        return all(test(entry) for name, test in configured.items() if name not in varied)

    charts = _curves(bulk_rows, on_chart)
    rows = []
    if "curves" in sections:
        rows += _curve_rows(charts, tolerances, dof)
    if "comparisons" in sections:
        # the two clumps' charts are made by different groups: the checks group, which reads both, compares them
        clumps = [_plateau(charts[key], "internal") if key in charts else None
                  for key in (("sphere2", "internal", 0.0), ("sphere4", "internal", 0.0))]
        if None not in clumps:
            rows.append(_clumps_row(*clumps, tolerances, dof))
        rows += _comparison_rows(bulk_rows, charts, on_chart, base_restitution, lid, shear_velocity, tolerances, dof)
    if "calibrated" in sections:
        rows += _chosen_rows(charts, parameters, targets, tolerances, dof)
        rows += _calibrated_rows(parameters, charts, dof)
    return rows


# ------------------------------------------------------------------------------------------- curves: C1-C3, C6

def _curve_rows(charts: Mapping[tuple, list], tolerances: AgreementTolerances, dof: float | None) -> list[dict]:
    rows, plateaus = [], {}
    for key, entries in charts.items():
        shape, chart, rolling = key
        # C1-C3 are stated at zero rolling friction for the study's three shapes
        if shape not in STUDY_SHAPES or rolling != 0.0:
            continue
        if chart == "internal":
            rows += _c1_rows(key, entries, dof)
            rows += _step_rows("C2.rises", key, entries, 0.0, KNEE["internal"], tolerances, dof)
            rows += _step_rows("C2.levels_off", key, entries, KNEE["internal"], 1.0, tolerances, dof)
        else:
            rows += _mobilised_rows(key, entries, tolerances, dof)
            rows += _step_rows("C3.levels_off", key, entries, KNEE["wall"], 1.0, tolerances, dof)
        plateau = _plateau(entries, chart)
        if plateau is not None:
            plateaus[key] = plateau
            rows.append(_plateau_row(f"{'C2' if chart == 'internal' else 'C3'}.{shape}", key, plateau, tolerances,
                                     dof))
    zero, rolled = charts.get((CHOSEN_SHAPE, "internal", 0.0)), charts.get((CHOSEN_SHAPE, "internal", CHOSEN_ROLLING))
    if zero and rolled:
        case = f"{CHOSEN_SHAPE}, internal, rolling 0 and {CHOSEN_ROLLING:g}"
        what = (f"rolling {CHOSEN_ROLLING:g}", "rolling 0")
        rows += _contrast_rows("C6.friction_0_1", case, zero, rolled, 0.1, 0.5, what, tolerances, dof)
        rows += _contrast_rows("C6.friction_0_5", case, zero, rolled, 0.5, 0.1, what, tolerances, dof)
    return rows


def _c1_rows(key: tuple, entries: Sequence[Mapping], dof: float | None) -> list[dict]:
    """C1: bulk minus particle friction at 0.1 ("low particle friction" read as the sweep's first step), and the
    bulk friction at particle friction 0 only where swept (a nearer point would be the first part again)."""
    point = _nearest(entries, 0.1)
    mu, (bulk, error) = _mu(point), _bulk(point)
    steady, steady_text = _steady([point])
    part = PARTS["C1.above_particle_friction"]
    rows = [row(GROUP, f"Bulk friction - particle friction at particle friction {mu:g}", _case(key), bulk - mu, error,
                "-", f"{steady_text}; bulk friction {plus_minus(bulk, error)} at particle friction {mu:g}", dof=dof,
                finding=part.id, agreement=rules.sign_of_change(bulk - mu, error, dof, part, steady=steady),
                differs="" if _same(mu, 0.1) else f"at the swept particle friction {mu:g} nearest the study's 0.1")]
    zero = [entry for entry in entries if _same(_mu(entry), 0.0)]
    if zero:
        (bulk, error), (steady, steady_text) = _bulk(zero[0]), _steady(zero)
        part = PARTS["C1.finite_at_zero"]
        rows.append(row(GROUP, "Bulk friction at particle friction 0", _case(key), bulk, error, "-", steady_text,
                        dof=dof, finding=part.id,
                        agreement=rules.sign_of_change(bulk, error, dof, part, steady=steady)))
    return rows


def _step_rows(part_id: str, key: tuple, entries: Sequence[Mapping], start: float, end: float,
               tolerances: AgreementTolerances, dof: float | None) -> list[dict]:
    """The change of bulk friction from the swept point nearest ``start`` to the one nearest ``end`` (-): its sign
    (a SIGN part), or its size against the value at the first point (a NEGLIGIBLE part); none when both are one
    point."""
    first, last = _nearest(entries, start), _nearest(entries, end)
    if first is last:
        return []
    (low, low_error), (high, high_error) = _bulk(first), _bulk(last)
    change, error = high - low, combine_independent([low_error, high_error])
    steady, steady_text = _steady([first, last])
    part, name = PARTS[part_id], _name(key[1])
    if part.kind == SIGN:
        verdict = rules.sign_of_change(change, error, dof, part, steady=steady)
    else:
        verdict = rules.negligible(change, error, dof, low, part, tolerances, steady=steady)
    used = _mu(first), _mu(last)
    swapped = [f"{mu:g} instead of the study's {study:g}" for mu, study in zip(used, (start, end))
               if not _same(mu, study)]
    differs = f"the swept {name} {', '.join(swapped)}" if swapped else ""
    return [row(GROUP, f"Change of bulk friction, {name} {used[0]:g} to {used[1]:g}", _case(key), change, error, "-",
                f"{steady_text}; {name} -> bulk friction {_points([first, last])}", dof=dof, finding=part_id,
                agreement=verdict, differs=differs)]


def _mobilised_rows(key: tuple, entries: Sequence[Mapping], tolerances: AgreementTolerances,
                    dof: float | None) -> list[dict]:
    """C3.mobilised: bulk wall friction over the particle-wall friction at 0.1 (the latter exact, an input)."""
    point = _nearest(entries, 0.1)
    mu, (bulk, error) = _mu(point), _bulk(point)
    steady, steady_text = _steady([point])
    part = PARTS["C3.mobilised"]
    return [row(GROUP, f"Bulk wall friction / particle-wall friction at {mu:g}", _case(key),
                *ratio(bulk, error, mu, 0.0), "-", f"{steady_text}; bulk wall friction {plus_minus(bulk, error)}",
                dof=dof, finding=part.id,
                agreement=rules.ratio_in_band(bulk, error, mu, 0.0, dof, part, tolerances, steady=steady),
                differs="" if _same(mu, 0.1) else
                f"at the swept particle-wall friction {mu:g} nearest the study's 0.1")]


def _plateau(entries: Sequence[Mapping], chart: str) -> tuple | None:
    """A curve's plateau: the mean bulk friction of its points at or past the knee (:data:`KNEE`) and its standard
    error ``sqrt(sum e_i^2) / n`` (independent points) (-), the points, and how they differ from the study's (the
    knee to 1 in steps of 0.1); None without a point there."""
    knee = KNEE[_kind(chart)]
    used = [entry for entry in entries if _mu(entry) >= knee - _SAME]
    if not used:
        return None
    values, errors = zip(*(_bulk(entry) for entry in used))
    study = [mu for mu in STUDY_SWEEP if mu >= knee - _SAME]
    swept = [_mu(entry) for entry in used]
    as_study = len(swept) == len(study) and all(map(_same, swept, study))
    differs = "" if as_study else (f"the mean of the swept {_name(chart)} {', '.join(f'{mu:g}' for mu in swept)}, "
                                   f"not of the study's {knee:g} to 1 in steps of 0.1")
    return sum(values) / len(values), combine_independent(errors) / len(used), used, differs


def _plateau_row(part_id: str, key: tuple, plateau: tuple, tolerances: AgreementTolerances,
                 dof: float | None) -> dict:
    value, error, used, differs = plateau
    steady, steady_text = _steady(used)
    name = _name(key[1])
    return row(GROUP, f"Plateau bulk {'wall ' if key[1] != 'internal' else ''}friction ({name} >= "
               f"{KNEE[_kind(key[1])]:g})", _case(key), value, error, "-",
               f"{steady_text}; mean of {name} -> bulk friction {_points(used)}", dof=dof, finding=part_id,
               agreement=rules.value_in_band(value, error, dof, PARTS[part_id], tolerances, steady=steady),
               differs=differs)


def _clumps_row(two: tuple, four: tuple, tolerances: AgreementTolerances, dof: float | None) -> dict:
    """C2.clumps_alike: the four-sphere clump's plateau over the two-sphere clump's."""
    steady, steady_text = _steady([*two[2], *four[2]])
    differs = "; ".join(f"{shape}: {plateau[3]}" for shape, plateau in (("sphere2", two), ("sphere4", four))
                        if plateau[3])
    return row(GROUP, "Plateau bulk friction, four-sphere / two-sphere clump", "sphere4 / sphere2, internal, rolling 0",
               *ratio(four[0], four[1], two[0], two[1]), "-",
               f"{steady_text}; plateaus sphere4 {plus_minus(*four[:2])}, sphere2 {plus_minus(*two[:2])}", dof=dof,
               finding="C2.clumps_alike", differs=differs,
               agreement=rules.ratio_in_band(four[0], four[1], two[0], two[1], dof, PARTS["C2.clumps_alike"],
                                             tolerances, steady=steady))


def _contrast_rows(part_id: str, case: str, base: Sequence[Mapping], other: Sequence[Mapping], target: float,
                   rival: float, what: tuple[str, str], tolerances: AgreementTolerances,
                   dof: float | None) -> list[dict]:
    """The bulk friction of ``other`` against ``base`` (two curves that differ in one input, named by ``what``) at
    their common particle friction nearest ``target``: the difference against the base value (a NEGLIGIBLE part)
    or the ratio (a RATIO part) (-). None when that point is nearer ``rival``, the particle friction of the
    finding's other part: it would judge one part at the other's point."""
    pair = _pair(base, other, target)
    if pair is None or abs(_mu(pair[0]) - rival) < abs(_mu(pair[0]) - target) - _SAME:
        return []
    (low, low_error), (high, high_error) = _bulk(pair[0]), _bulk(pair[1])
    mu, part = _mu(pair[0]), PARTS[part_id]
    steady, steady_text = _steady(pair)
    evidence = f"{steady_text}; {what[0]} {plus_minus(high, high_error)}, {what[1]} {plus_minus(low, low_error)}"
    differs = ("" if _same(mu, target) else
               f"at the common swept particle friction {mu:g} nearest the study's {target:g}")
    if part.kind == NEGLIGIBLE:
        change, error = high - low, combine_independent([low_error, high_error])
        return [row(GROUP, f"Bulk friction, {what[0]} - {what[1]} at particle friction {mu:g}", case, change,
                    error, "-", evidence, dof=dof, finding=part_id, differs=differs,
                    agreement=rules.negligible(change, error, dof, low, part, tolerances, steady=steady))]
    return [row(GROUP, f"Bulk friction, {what[0]} / {what[1]} at particle friction {mu:g}", case,
                *ratio(high, high_error, low, low_error), "-", evidence, dof=dof, finding=part_id, differs=differs,
                agreement=rules.ratio_in_band(high, high_error, low, low_error, dof, part, tolerances, steady=steady))]


# ------------------------------------------------------------------------------------------ comparisons: C4, C5

def _comparison_rows(bulk_rows: Sequence[Mapping], charts: Mapping[tuple, list], on_chart, base_restitution: float,
                     lid: str, shear_velocity: float, tolerances: AgreementTolerances, dof: float | None) -> list[dict]:
    rows = []
    blocked = _curves(bulk_rows, lambda e: _flag(e["rotation_blocked"]) and on_chart(e, ("rotation",)))
    for key, entries in blocked.items():
        base, what = charts.get(key, []), ("rotation blocked", "free")
        if key[1] == "internal":
            rows += _contrast_rows("C5.friction_0_1", _case(key), base, entries, 0.1, 0.5, what, tolerances, dof)
            rows += _contrast_rows("C5.friction_0_5", _case(key), base, entries, 0.5, 0.1, what, tolerances, dof)
        else:
            rows += _difference_rows(key, base, entries, what, "the study blocked rotations in its internal test "
                                     "only (§4.5.2)", dof)
    restitutions = sorted({float(e["restitution"]) for e in bulk_rows if on_chart(e, ("restitution",))
                           and not _same(float(e["restitution"]), base_restitution)})
    for restitution in restitutions:
        extra = _curves(bulk_rows, lambda e, r=restitution: _same(float(e["restitution"]), r)
                        and on_chart(e, ("restitution",)))
        for key, entries in extra.items():
            rows += _restitution_rows(key, charts.get(key, []), entries, restitution, base_restitution, tolerances, dof)
    other = "servo" if lid == "rigid" else "rigid"
    for key, entries in _curves(bulk_rows, lambda e: e["lid"] != lid and on_chart(e, ("lid",))).items():
        rows += _difference_rows(key, charts.get(key, []), entries, (f"{other} lid", f"{lid} lid"),
                                 "the study ran no servo lid; it compared its free-rotating particle lid "
                                 "with servo results of the literature (§4.3.2, §4.4.2)", dof)
    speeds = sorted({float(e["shear_velocity"]) for e in bulk_rows if on_chart(e, ("speed",))
                     and not _same(float(e["shear_velocity"]), shear_velocity)})
    for speed in speeds:
        slower = _curves(bulk_rows, lambda e, v=speed: _same(float(e["shear_velocity"]), v) and on_chart(e, ("speed",)))
        for key, entries in slower.items():
            rows += _difference_rows(key, charts.get(key, []), entries,
                                     (f"shear velocity {speed:g}", f"{shear_velocity:g} m/s"),
                                     "the study sheared at 3 mm/s only (§4.3.1.3)", dof)
    for key, entries in _curves(bulk_rows, lambda e: not configured_pour(e) and on_chart(e, ("pour",))).items():
        rows += _difference_rows(key, charts.get(key, []), entries, ("poured at its own friction", "as configured"),
                                 "the study poured every sample at particle friction 0.1 without rolling friction "
                                 "(§4.3.1.2-§4.3.1.3)", dof)
    return rows


def _mean_difference(base: Sequence[Mapping], other: Sequence[Mapping]) -> tuple | None:
    """The mean difference ``other - base`` over the curves' common particle frictions and its standard error
    ``sqrt(sum e_i^2) / n`` (-), the base curve's mean there (-), and the points (base and other); None with none
    common."""
    by_mu = {round(_mu(entry), 9): entry for entry in base}
    pairs = [(by_mu[round(_mu(entry), 9)], entry) for entry in other if round(_mu(entry), 9) in by_mu]
    if not pairs:
        return None
    differences = [_bulk(b)[0] - _bulk(a)[0] for a, b in pairs]
    errors = [combine_independent([_bulk(a)[1], _bulk(b)[1]]) for a, b in pairs]
    level = sum(_bulk(a)[0] for a, _ in pairs) / len(pairs)
    return sum(differences) / len(pairs), combine_independent(errors) / len(pairs), level, pairs


def _difference_text(pairs: Sequence[tuple], what: tuple[str, str]) -> str:
    steady, steady_text = _steady([entry for pair in pairs for entry in pair])
    listing = "; ".join(f"{_mu(a):g}: {what[0]} {plus_minus(*_bulk(b))}, {what[1]} {plus_minus(*_bulk(a))}"
                        for a, b in pairs)
    return f"{steady_text}; at particle friction {listing}"


def _difference_rows(key: tuple, base: Sequence[Mapping], other: Sequence[Mapping], what: tuple[str, str],
                     study: str, dof: float | None) -> list[dict]:
    """A comparison no finding states: the mean difference and whether it is resolved (no verdict)."""
    found = _mean_difference(base, other)
    if found is None:
        return []
    difference, error, _, pairs = found
    return [row(GROUP, f"Bulk friction, {what[0]} - {what[1]}", _case(key), difference, error, "-",
                f"{_difference_text(pairs, what)}; mean {plus_minus(difference, error)}: "
                f"{resolution(difference, error, dof)}", dof=dof, study=study)]


def _restitution_rows(key: tuple, base: Sequence[Mapping], other: Sequence[Mapping], restitution: float,
                      base_restitution: float, tolerances: AgreementTolerances, dof: float | None) -> list[dict]:
    """C4 on an internal curve: the mean change from the base restitution against the base value; a wall curve's
    change is a measurement (the study checked the bulk internal friction)."""
    what = (f"restitution {restitution:g}", f"{base_restitution:g}")
    if key[1] != "internal":
        return _difference_rows(key, base, other, what, "the study checked restitution on the internal test only "
                                "(§4.4.1)", dof)
    found = _mean_difference(base, other)
    if found is None:
        return []
    change, error, level, pairs = found
    steady = _steady([entry for pair in pairs for entry in pair])[0]
    swept = ", ".join(f"{_mu(a):g}" for a, _ in pairs)
    part = PARTS["C4"]
    return [row(GROUP, f"Bulk friction, {what[0]} - {what[1]}", _case(key), change, error, "-",
                f"{_difference_text(pairs, what)}; mean {plus_minus(change, error)} against the mean base value "
                f"{level:.4g}", dof=dof, finding=part.id,
                agreement=rules.negligible(change, error, dof, level, part, tolerances, steady=steady),
                differs=f"restitution {restitution:g} against {base_restitution:g} at particle friction {swept}, not "
                        "the study's 1e-4 against 1")]


# ------------------------------------------------------------------------- calibrated: C7 and the coefficients

def _at(entries: Sequence[Mapping], x: float, name: str) -> tuple | None:
    """A chart's bulk friction at particle friction ``x`` and its standard error (-), the points it rests on, and
    how it differs from a value read at ``x``: the swept point, else linear between the two bracketing ones (error
    ``sqrt(((1 - w) e1)^2 + (w e2)^2)``, w the weight of the upper point); None outside the swept range."""
    exact = [entry for entry in entries if _same(_mu(entry), x)]
    if exact:
        return (*_bulk(exact[0]), exact[:1], "")
    below = [entry for entry in entries if _mu(entry) < x]
    above = [entry for entry in entries if _mu(entry) > x]
    if not below or not above:
        return None
    a, b = below[-1], above[0]
    w = (x - _mu(a)) / (_mu(b) - _mu(a))
    (low, low_error), (high, high_error) = _bulk(a), _bulk(b)
    return (low + w * (high - low), combine_independent([(1.0 - w) * low_error, w * high_error]), [a, b],
            f"interpolated linearly between the swept {name} {_mu(a):g} and {_mu(b):g} ({x:g} is not swept)")


def _chosen_rows(charts: Mapping[tuple, list], parameters: Mapping, targets: Mapping[str, tuple[float, float]],
                 tolerances: AgreementTolerances, dof: float | None) -> list[dict]:
    """C7: the bulk friction angles of the two-sphere clump at the study's chosen inputs (§4.6). The internal one
    at rolling friction 0.1, as the study; the wall ones at the calibration's rolling friction (the study does not
    state the particle-wall rolling friction), each against its configured measured angle."""
    rows = []
    rolling = float(parameters["rolling_friction"])
    tests = [("internal", CHOSEN_ROLLING)] + [(material, rolling) for material in ("aluminium", "perspex")]
    for test, rolls in tests:
        part = PARTS[f"C7.{test}"]
        if part.configured and test not in targets:
            continue
        key = (CHOSEN_SHAPE, test, rolls)
        found = _at(charts.get(key, []), STUDY_CHOICE[test], _name(test))
        if found is None:
            continue
        bulk, error, used, differs = found
        angle, angle_error = _angle_deg(bulk, error)
        steady, steady_text = _steady(used)
        band = targets.get(test)
        measured = f"; the configured measured angle {band[0]:.4g} to {band[1]:.4g} deg" if band else ""
        figure = "Bulk internal friction angle" if test == "internal" else f"Bulk wall friction angle on {test}"
        rows.append(row(GROUP, f"{figure} at {_name(test)} {STUDY_CHOICE[test]:g}", _case(key), angle, angle_error,
                        "deg", f"{steady_text}; atan of bulk friction {plus_minus(bulk, error)} from "
                        f"{_points(used)}{measured}",
                        dof=dof, finding=part.id, differs=differs,
                        agreement=rules.value_in_band(angle, angle_error, dof, part, tolerances, steady=steady,
                                                      configured=band if part.configured else None)))
    return rows


def _bracketing(entries: Sequence[Mapping], lower: float, upper: float) -> list[Mapping]:
    """The points of a curve a coefficient read between ``lower`` and ``upper`` rests on: those inside the band
    and the nearest on either side of it (a transient far from the band does not make the coefficient one)."""
    frictions = [_mu(entry) for entry in entries]
    below = [index for index, value in enumerate(frictions) if value < lower]
    above = [index for index, value in enumerate(frictions) if value > upper]
    return list(entries[below[-1] if below else 0:(above[0] if above else len(entries) - 1) + 1])


def _study_choice(test: str) -> str:
    if test not in STUDY_CHOICE:
        return "the study calibrated no such contact (§4.6)"
    return f"the study's chosen {STUDY_CHOICE[test]:g} (§4.6)"


def _calibrated_rows(parameters: Mapping, charts: Mapping[tuple, list], dof: float | None) -> list[dict]:
    """The calibrated particle sliding friction of each target, and the chart's angle nearest an unreachable one:
    siloflow's own inversion, which the study did by reading its charts (no finding)."""
    shape, rolling = parameters["shape"], float(parameters["rolling_friction"])
    found = [("internal", parameters.get("particle_particle")),
             *sorted((parameters.get("particle_wall") or {}).items())]
    rows = []
    for test, result in found:
        if not result:
            continue
        clipped = bool(result.get("band_clipped"))
        # the chart the coefficient was read from, and on it the points its band lies between
        entries = _bracketing(charts.get((shape, test, rolling), []), result["lower"], result["upper"])
        steady_text = _steady(entries)[1] if entries else "no shear test of this chart in the table"
        label = "particle-particle" if test == "internal" else f"particle-{test}"
        rows.append(row(GROUP, f"Calibrated particle sliding friction ({label})", f"{shape}, rolling {rolling:g}",
                        result["sliding_friction"], number_or_nan(result.get("sliding_friction_error")), "-",
                        f"{steady_text}; reproduces the measured {float(parameters['targets_deg'][test]):g} deg +- "
                        f"{float(parameters['tolerance_deg']):g} deg; band {result['lower']:.3g} to "
                        f"{result['upper']:.3g}{' (clipped at the swept range)' if clipped else ''}", dof=dof,
                        study=_study_choice(test)))
    for test, message in sorted((parameters.get("unreachable") or {}).items()):
        entries = charts.get((shape, test, rolling), [])
        if entries:
            rows.append(_unreachable_row(parameters, test, message, entries, dof))
    return rows


def _unreachable_row(parameters: Mapping, test: str, message: str, entries: Sequence[Mapping],
                     dof: float | None) -> dict:
    """A target no particle friction of the chart reproduces: the chart's end nearest it (deg), and whether the gap
    is resolved. The end is judged on its two outermost points (their steadiness shows the level)."""
    target = float(parameters["targets_deg"][test])
    # atan is increasing: the target lies above the chart when its tangent exceeds the largest bulk friction
    above = math.tan(math.radians(target)) > max(_bulk(entry)[0] for entry in entries)
    end = (max if above else min)(entries, key=lambda entry: _bulk(entry)[0])
    angle, error = _angle_deg(*_bulk(end))
    gap = target - angle
    label = "particle-particle" if test == "internal" else f"particle-{test}"
    return row(GROUP, f"Bulk friction angle nearest the unreachable target ({label})",
               f"{parameters['shape']}, rolling {float(parameters['rolling_friction']):g}", angle, error, "deg",
               f"{_steady(entries[-2:] if above else entries[:2])[1]}; {message}; the chart's "
               f"{'highest' if above else 'lowest'} point, at {_name(test)} {_mu(end):g}, lies "
               f"{plus_minus(abs(gap), error)} deg {'below' if above else 'above'} the measured {target:g} deg: "
               f"{resolution(gap, error, dof)}", dof=dof, study=_study_choice(test))
