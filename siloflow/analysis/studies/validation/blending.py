"""Validation rows of blending: the recirculating silo (thesis ch. 6, findings B1-B8) here, the multi-flow blender
(ch. 7, M1-M4) is :mod:`siloflow.analysis.studies.validation.blender`.

Each row is judged against a finding part (:mod:`siloflow.analysis.studies.validation.findings`) by the rule of its
kind (:mod:`siloflow.analysis.studies.validation.agreement`); ``differs`` says where the row's quantity is defined or
sampled otherwise than the study's. No row decides its scale (added later from the configuration alone).

Recirculation number and VRR
----------------------------
The analysis (:func:`siloflow.analysis.studies.silo_recirculation.vrr.vrr_by_recirculation`) counts ``Nr = (t -
t_open) / t_res`` in holdup residence times (the silo's contents over its throughput, the study's t_rm, §6.2.3.3)
and writes one VRR per pass: entry ``k`` of ``vrr_by_recirculation`` is the VRR of the outlet windows with ``k <= Nr
< k + 1``, the pass that follows ``k`` recirculations, at the constant head the re-entry keeps. The study's "Nr = 0"
(without recirculation, B5) is entry 0. Its VRR "at the end of Nr = 4 recirculations" (B3, B4, B6, and the end of the
growth of B2.grows) is that of the outflow of the discharge after the recirculations, once the re-entry stops
(§6.4.2, Fig. 6.9): a run with a final discharge writes it under ``final_discharge``
(:mod:`siloflow.analysis.studies.silo_recirculation.final_discharge`), and those rows take it; the pass at constant
head is then a row of its own with no finding. A run without one gives entry 4 (its last pass when it covers
fewer, and says so), and the rows say in ``differs`` that it is a pass at constant head, not the discharge after
the recirculations. B2.slower_after_2 needs Nr = 0, 2 and 4 of one kind and a run has one discharge, so it stays on
the passes and says so. A VRR near the counting-noise ceiling of the outlet windows (``vrr_at_ceiling``, or the
discharge's ``at_ceiling``) is a lower bound of the true VRR, not a measurement: every row it enters is at most "not
resolved".

Inputs are per-run mappings ``{"case": case.json, "summary": blending.json, "rtd": rtd.csv rows, "note": str, "dof":
float | None}``: ``note`` is the evidence about the run's seeds (appended to every row's evidence), ``dof`` the
degrees of freedom of the run's errors (seeds - 1; None for within-run errors).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.analysis.studies.validation import agreement as rules
from siloflow.analysis.studies.validation.agreement import AgreementTolerances, capped, ratio
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.analysis.studies.validation.rows import joined, plus_minus, row, smallest_dof

__all__ = ["RECIRCULATION_GROUP", "MADE", "UNMADE", "rtd_peak", "recirculation_rows"]

RECIRCULATION_GROUP = "Recirculating silo (blending)"
#: The study's flow patterns (``blending.json`` ``flow_pattern``) and the suffix of their finding parts.
PATTERNS = {"internal_flow": "internal", "semi_mass_flow": "semi_mass"}
#: The study's batch sizes, blue volume over silo volume (§6.4) (-).
STUDY_BATCHES = (0.13, 0.25, 0.5)
#: The Nr at which the study reads the VRR (B2-B4, B6) and its midpoint for the "slower after" part (B2).
NR_STUDY, NR_MIDDLE = 4, 2
#: How far the Nr of a run's final discharge may lie from :data:`NR_STUDY` and still be the study's (-): the study's
#: own run is "about 4 recirculations" (12 s of a 2.75 s residence time, §6.2.3.3), so the nearest whole Nr counts.
NR_DISCHARGE_TOLERANCE = 0.5
#: ``differs`` of a VRR of a recirculation pass where the study's is of the discharge after the recirculations.
CONSTANT_HEAD = ("VRR of the pass k <= Nr < k + 1 of the recirculating run, at constant head, not of the discharge "
                 "after Nr recirculations (§6.4.2): the run has no final discharge "
                 "(silo_recirculation.final_discharge > 0 adds it)")
#: ``differs`` of B2.slower_after_2, which takes three passes of one run.
SLOWER_PASSES = (f"gains of the VRR of the passes at constant head (k <= Nr < k + 1), not of the discharges after 0, "
                 f"{NR_MIDDLE} and {NR_STUDY} recirculations (§6.4.2): a run has one final discharge")
#: ``study`` of the row of the last pass at constant head beside the discharge's VRR.
CONSTANT_HEAD_STUDY = ("- (siloflow's: the study reads the VRR of the discharge after the recirculations, "
                       "§6.4.2)")
#: The finding parts of ch. 6 these rows make (each given the runs it needs): all of them.
MADE = ("B1.semi_mass", "B1.internal", "B2.grows", "B2.slower_after_2", "B3.internal",
        "B3.stronger_in_internal", "B4.semi_mass", "B4.internal", "B5", "B6", "B7.semi_mass",
        "B7.internal", "B8.internal", "B8.semi_mass")
#: Every part of ch. 6 can be made.
UNMADE = MappingProxyType({})


def rtd_peak(times, density, t_mean: float, t_mean_error: float) -> tuple[float, float]:
    """The RTD's peak in normalised time, theta = t_peak / t_mean, and its standard error (-).

    The peak is the bin of largest E(t) (the first of equal ones); its time is known to a bin, so its error is
    the bin width over sqrt(12), combined with the relative error of the time scale.

    Parameters
    ----------
    times : array_like, shape (n,)
        Bin centres, equally spaced (s).
    density : array_like, shape (n,)
        E(t) at each bin (1/s).
    t_mean, t_mean_error : float
        The time scale theta is taken in (the study's t_rm) and its standard error (s).
    """
    t = np.asarray(times, dtype=float)
    e = np.asarray(density, dtype=float)
    if t.ndim != 1 or t.shape != e.shape or t.size < 2:
        raise ValueError("times and density must be equal 1-D arrays of at least two bins")
    peak = float(t[int(np.argmax(e))])
    width = float(t[1] - t[0])
    return ratio(peak, width / math.sqrt(12.0), t_mean, t_mean_error)


def _tail(*notes: str) -> str:
    text = "; ".join(note for note in notes if note)
    return f"; {text}" if text else ""


class _End(NamedTuple):
    """The VRR the study reads at the end of :data:`NR_STUDY` recirculations, as one run gives it (:meth:`_Run.end`).

    ``nr`` is the Nr it is at: a pass's whole number, or the discharge's Nr; ``where`` and ``to`` name it in figures
    ("VRR {where}", "from Nr = 0 to {to}"); ``bound`` says why it is only a lower bound ("" for a measurement);
    ``evidence`` describes the discharge ("" for a pass).
    """

    value: float
    error: float
    nr: float
    discharge: bool
    where: str
    to: str
    bound: str
    differs: str
    evidence: str


def _where(ends: Sequence[_End]) -> str:
    """The figure text of where several VRRs at the end of the recirculations are read."""
    if all(end.discharge for end in ends):
        return f"of the discharge after Nr = {min(end.nr for end in ends):.2f}"
    if not any(end.discharge for end in ends):
        return f"at Nr = {min(int(end.nr) for end in ends)}"
    return f"at the end of about {round(min(end.nr for end in ends))} recirculations (discharges and passes)"


class _Run:
    """One recirculation run as the rows read it: its pattern, layouts, final discharge, note and degrees of
    freedom."""

    def __init__(self, run: Mapping):
        self.summary, self.rtd = run["summary"], list(run.get("rtd") or ())
        self.pattern = str(self.summary["flow_pattern"])
        self.suffix = PATTERNS.get(self.pattern)
        self.note, self.dof = str(run.get("note") or ""), run.get("dof")
        self.layouts = self.summary["layouts"]
        self.discharge = self.summary.get("final_discharge") or None
        limit, factor = float(self.summary["vrr_sampling_limit"]), float(self.summary["vrr_ceiling_factor"])
        self.windows = (f"outlet windows of {float(self.summary['clumps_per_window']):.0f} clumps: counting-noise "
                        f"ceiling {limit:.0f}, a VRR above {limit / factor:.0f} is a lower bound")

    def nominal(self, t: float, what: str) -> str:
        """The evidence clause of a time ``t`` (s) read in the study's nominal residence time (§6.2.3.3: W H / (B0
        V_out), the channel as dense as the fill) beside the measured one the row takes: ``what`` is its name; "" when
        the summary has no nominal time."""
        nominal = number_or_nan(self.summary.get("nominal_residence_time_s"))
        if not math.isfinite(nominal) or nominal <= 0:
            return ""
        return (f"in the study's nominal residence time W H / (B0 V_out) = {nominal:.3g} s (the channel as dense as "
                f"the fill) {what} = {t / nominal:.3g}")

    def part(self, finding: str) -> str | None:
        """The pattern's part of a finding (``"B4"`` -> ``"B4.internal"``), None for a pattern the study did not run."""
        return f"{finding}.{self.suffix}" if self.suffix else None

    def layout(self, fraction: float, sublayers: int) -> tuple[str, Mapping] | None:
        """The layout of that blue fraction (-) and number of sub-layers, by name, or None."""
        for name, layout in self.layouts.items():
            if math.isclose(float(layout["blue_fraction"]), fraction) and int(layout["sublayers"]) == sublayers:
                return name, layout
        return None

    def vrr(self, layout: Mapping, nr: int) -> tuple[float, float, int, str]:
        """The VRR of the pass after ``nr`` recirculations (the last pass when the run has fewer), its error, the
        Nr taken and why it is only a bound ("" when a measurement)."""
        values = layout["vrr_by_recirculation"]
        errors = layout.get("vrr_by_recirculation_error") or [None] * len(values)
        taken = min(nr, len(values) - 1)
        bound = (f"the VRR at Nr = {taken} is at the counting-noise ceiling ({self.windows})"
                 if layout["vrr_at_ceiling"][taken] else "")
        return number_or_nan(values[taken]), number_or_nan(errors[taken]), taken, bound

    def end(self, name: str, layout: Mapping) -> _End:
        """The VRR at the end of :data:`NR_STUDY` recirculations: the final discharge's where the summary has it for
        this layout (the study's, §6.4.2), else the pass's at constant head (:meth:`vrr`), with ``differs`` saying
        so."""
        discharge = (self.discharge or {}).get("layouts", {}).get(name)
        if discharge is None:
            value, error, nr, bound = self.vrr(layout, NR_STUDY)
            return _End(value, error, nr, False, f"at Nr = {nr}", f"{nr}", bound, joined((CONSTANT_HEAD,
                        self.short(nr, NR_STUDY))), "")
        common = self.discharge  # the figures every layout of the discharge shares
        nr = float(common["recirculations"])
        start, end = number_or_nan(common.get("start_s")), number_or_nan(common.get("end_s"))
        ceiling = number_or_nan(discharge.get("vrr_ceiling"))
        far = "" if abs(nr - NR_STUDY) <= NR_DISCHARGE_TOLERANCE else (
            f"discharge after Nr = {nr:.2f} recirculations, not {NR_STUDY} (silo_recirculation.recirculations sets "
            "it)")
        cut = "" if common.get("faded", True) else (
            f"the run ends before the discharge's outflow fades: its VRR is of the first {end - start:.3g} s of it (a "
            "longer silo_recirculation.final_discharge sees it all)")
        bound = (f"the VRR of the discharge is at the counting-noise ceiling of its windows ({ceiling:.0f})"
                 if discharge.get("at_ceiling") else "")
        nominal = self.nominal(nr * number_or_nan(self.summary.get("residence_time_s")), "that Nr")
        evidence = (
            f"discharge after Nr = {nr:.2f} recirculations{f' ({nominal})' if nominal else ''} from t = {start:.4g} s: "
            f"{number_or_nan(discharge.get('windows')):.0f} windows of {number_or_nan(common.get('window_s')):.3g} s "
            f"to t = {end:.4g} s, {number_or_nan(discharge.get('clumps')):.0f} clumps, "
            f"{number_or_nan(discharge.get('left_out_fraction')):.1%} of its outflow left out (windows from the stop "
            f"of the re-entry up to the first with fewer than {number_or_nan(common.get('threshold_clumps')):.1f} "
            "clumps, "
            f"{number_or_nan(common.get('fade_fraction')):g} of a recirculating window's "
            f"{number_or_nan(common.get('reference_clumps_per_window')):.0f}); counting-noise ceiling {ceiling:.0f}")
        return _End(number_or_nan(discharge["vrr"]), number_or_nan(discharge.get("vrr_error")), nr, True,
                    f"of the discharge after Nr = {nr:.2f}", f"the discharge after Nr = {nr:.2f}", bound,
                    joined((far, cut)), evidence)

    def short(self, nr: int, wanted: int) -> str:
        """The ``differs`` clause of a VRR read at ``nr`` instead of ``wanted``."""
        if nr == wanted:
            return ""
        return (f"VRR at Nr = {nr}, the last pass of a run covering {float(self.summary['recirculations']):.2f} "
                f"recirculations, not at Nr = {wanted} (silo_recirculation.recirculations >= {wanted + 1} reaches "
                "it)")

    def listing(self, layout: Mapping) -> str:
        """Every pass's VRR, for evidence."""
        errors = layout.get("vrr_by_recirculation_error") or [None] * len(layout["vrr_by_recirculation"])
        return "; ".join(f"Nr {k}: {plus_minus(number_or_nan(v), number_or_nan(e))}{' (ceiling)' if c else ''}"
                         for k, (v, e, c) in enumerate(zip(layout["vrr_by_recirculation"], errors,
                                                           layout["vrr_at_ceiling"])))


def _label(layout: Mapping, name: str) -> str:
    sublayers = int(layout["sublayers"])
    return (f"{name}: blue {float(layout['blue_fraction']) * 100:g} %, "
            f"{sublayers} {'layer' if sublayers == 1 else 'sub-layers'}")


def _judged(figure: str, case: str, value: float, error: float, unit: str, evidence: str, dof, part: str | None,
            judge, differs: str = "") -> dict:
    """A row judged against ``part`` by ``judge(Part)``; a row with no finding when the run's pattern is not one of
    the study's (``part`` None)."""
    if part is None:
        return row(RECIRCULATION_GROUP, figure, case, value, error, unit, evidence, dof=dof,
                   study="- (a flow pattern the study did not run)", differs=differs)
    return row(RECIRCULATION_GROUP, figure, case, value, error, unit, evidence, dof=dof, finding=part,
               agreement=judge(PARTS[part]), differs=differs)


def _run_rows(run: _Run, tolerances: AgreementTolerances) -> list[dict]:
    """B4, B2 (both parts) per layout, B3.internal, B6, B7, B8 and B1 of one run."""
    rows, tail, dof, case = [], _tail(run.note), run.dof, run.pattern
    nr_text = ("Nr in holdup residence times (contents over throughput); Nr = k is the pass after k recirculations, "
               "windows with k <= Nr < k + 1")
    for name, layout in run.layouts.items():
        label, listing = _label(layout, name), run.listing(layout)
        end = run.end(name, layout)
        last, last_error, nr, bound = run.vrr(layout, NR_STUDY)
        first, first_error, _, first_bound = run.vrr(layout, 0)
        evidence = f"{listing}; {nr_text}; {run.windows}{tail}"
        end_evidence = f"{end.evidence}; {evidence}" if end.evidence else evidence
        if int(layout["sublayers"]) == 1:
            batch = float(layout["blue_fraction"])
            other = "" if any(math.isclose(batch, b) for b in STUDY_BATCHES) else (
                f"batch {batch * 100:g} %, not one of the study's 13, 25, 50 %")
            rows.append(_judged(
                f"VRR {end.where} ({label})", case, end.value, end.error, "-", end_evidence, dof, run.part("B4"),
                # a VRR at its ceiling is capped with that reason, rather than called not steady
                lambda p: capped(rules.value_in_band(end.value, end.error, dof, p, tolerances), end.bound),
                differs=joined((end.differs, other))))
            if end.discharge:
                # the pass at constant head stays, as siloflow's own measurement beside the study's figure
                rows.append(row(RECIRCULATION_GROUP, f"VRR of the pass {nr} <= Nr < {nr + 1} at constant head, "
                                f"siloflow's ({label})", case, last, last_error, "-", joined((bound, evidence)),
                                dof=dof, study=CONSTANT_HEAD_STUDY, differs=run.short(nr, NR_STUDY)))
        if end.nr >= 1:
            change = end.value - first, combine_independent([end.error, first_error])
            why = joined((first_bound, end.bound))
            rows.append(_judged(f"Change of VRR from Nr = 0 to {end.to} ({label})", case, *change, "-", end_evidence,
                                dof, "B2.grows", lambda p: capped(rules.sign_of_change(*change, dof, p), why),
                                differs=end.differs))
        if nr > NR_MIDDLE:
            rows.append(_slower(run, layout, label, nr, evidence))
    rows += _batch_rows(run, tolerances, nr_text)
    rows += _rtd_rows(run, tolerances)
    if "bulk_density_drop" in run.summary:
        summary = run.summary
        drop, error = float(summary["bulk_density_drop"]), number_or_nan(summary.get("bulk_density_drop_error"))
        low, high = summary["bulk_density_slab_m"]
        flowing = plus_minus(float(summary["flowing_bulk_density_kg_m3"]),
                             number_or_nan(summary.get("flowing_bulk_density_kg_m3_error")), 4)
        rows.append(_judged(
            "Drop of bulk density while recirculating, 1 - flowing / filling", case, drop, error, "-",
            f"slab {low * 1000:.0f}-{high * 1000:.0f} mm above the outlet (the study names no region): filling "
            f"{float(summary['settled_bulk_density_kg_m3']):.1f} kg/m3 (the fill at rest), flowing {flowing} kg/m3 "
            f"(batch means of {int(summary.get('bulk_density_batches', 0))} batches){tail}", dof, run.part("B1"),
            lambda p: rules.value_in_band(drop, error, dof, p, tolerances)))
    return rows


def _slower(run: _Run, layout: Mapping, label: str, nr: int, evidence: str) -> dict:
    """B2.slower_after_2: the VRR gain from Nr = 2 to 4 minus that from 0 to 2; with a run of fewer passes the gain
    from 2 to its last Nr, scaled to two recirculations (so that it is the study's figure at Nr = 4)."""
    dof = run.dof
    (v0, e0, _, b0), (v2, e2, _, b2), (vn, en, _, bn) = (run.vrr(layout, k) for k in (0, NR_MIDDLE, nr))
    scale = (NR_STUDY - NR_MIDDLE) / (nr - NR_MIDDLE)
    change = scale * (vn - v2) - (v2 - v0)
    # v2 enters both gains: its error counts with the weight (scale + 1), the two ends' with theirs.
    error = combine_independent([scale * en, (scale + 1.0) * e2, e0])
    differs = joined((SLOWER_PASSES, "" if nr == NR_STUDY else (
        f"gain from Nr = {NR_MIDDLE} to {nr} times {scale:g}, not from {NR_MIDDLE} to {NR_STUDY}: "
        + run.short(nr, NR_STUDY))))
    why = "; ".join(filter(None, (b0, b2, bn)))
    return _judged(f"VRR gain from Nr = {NR_MIDDLE} to {NR_STUDY} minus gain from 0 to {NR_MIDDLE} ({label})",
                   run.pattern, change, error, "-", evidence, dof, "B2.slower_after_2",
                   lambda p: capped(rules.sign_of_change(change, error, dof, p), why), differs=differs)


def _batch_rows(run: _Run, tolerances: AgreementTolerances, nr_text: str) -> list[dict]:
    """B3.internal (internal flow) and B6 (either pattern) of one run."""
    rows, dof, tail = [], run.dof, _tail(run.note)
    small, half = run.layout(0.13, 1), run.layout(0.5, 1)
    if run.suffix == "internal" and small and half:
        ends = a, b = run.end(*small), run.end(*half)
        change = b.value - a.value, combine_independent([a.error, b.error])
        rows.append(_judged(
            f"Change of VRR {_where(ends)} from the 13 % to the 50 % batch", run.pattern, *change, "-",
            joined((f"13 %: {plus_minus(a.value, a.error)}, 50 %: {plus_minus(b.value, b.error)}",
                     *(end.evidence for end in ends), nr_text, run.windows)) + tail, dof,
            "B3.internal", lambda p: capped(rules.sign_of_change(*change, dof, p), joined(end.bound for end in ends)),
            differs=joined(end.differs for end in ends)))
    layers = [run.layout(0.5, n) for n in (5, 3, 1)]
    if all(layers):
        taken = [run.end(*layer) for layer in layers]
        values, errors = [t.value for t in taken], [t.error for t in taken]
        why = joined(t.bound for t in taken)
        rows.append(_judged(
            f"VRR {_where(taken)} of the 50 % batch in 5, 3 and 1 layers", run.pattern, values[0], errors[0], "-",
            "; ".join(f"{n}: {plus_minus(v, e)}" for n, v, e in zip((5, 3, 1), values, errors))
            + " (value column: 5 sub-layers); " + joined((*(t.evidence for t in taken), nr_text, run.windows))
            + tail, dof, "B6", lambda p: capped(rules.in_order(values, errors, dof, p), why),
            differs=joined(t.differs for t in taken)))
    return rows


def _rtd_rows(run: _Run, tolerances: AgreementTolerances) -> list[dict]:
    """B7 (theta of the RTD's peak) and B8 (t_s / t_d) of the tracer marked by particle id."""
    rows, summary, dof, tail = [], run.summary, run.dof, _tail(run.note)
    ids = summary["rtd_particle_ids"]
    exited = number_or_nan(ids.get("fraction_exited"))
    tracer = f"{int(ids['n_tracer'])} tracer clumps" + (f", {exited:.0%} of them out" if math.isfinite(exited) else "")
    chosen = [entry for entry in run.rtd if entry["method"] == "particle_ids"]
    if chosen:
        if "residence_time_s" in summary:
            # The study's t_rm (§6.2.3.3) is the silo's contents over its flow rate: the holdup over the throughput.
            t_rm, t_rm_error = float(summary["residence_time_s"]), number_or_nan(summary.get("residence_time_s_error"))
            scale, differs = f"t_rm = holdup / throughput = {plus_minus(t_rm, t_rm_error)} s", ""
        else:
            t_rm, t_rm_error = float(ids["t_mean_s"]), number_or_nan(ids.get("t_mean_s_error"))
            scale = f"t_mean of the tracer = {plus_minus(t_rm, t_rm_error)} s"
            differs = ("theta = t / the RTD's mean (the tracers out by the end of the run), not t / t_rm, the silo's "
                       "contents over its flow rate (§6.2.3.3): the summary has no residence_time_s")
        times = [float(entry["time_s"]) for entry in chosen]
        theta, theta_error = rtd_peak(times, [float(entry["E_per_s"]) for entry in chosen], t_rm, t_rm_error)
        rows.append(_judged(
            "Theta of the RTD's peak, t_peak / t_rm", run.pattern, theta, theta_error, "-",
            f"peak at {theta * t_rm:.3g} s of {len(chosen)} bins of {times[1] - times[0]:.3g} s (error: a bin over "
            f"sqrt(12)); {scale}; {joined((run.nominal(theta * t_rm, 'its theta'), tracer))}{tail}", dof,
            run.part("B7"),
            lambda p: rules.value_in_band(theta, theta_error, dof, p, tolerances), differs=differs))
    first, first_error = float(ids["t_s_over_t_d"]), number_or_nan(ids.get("t_s_over_t_d_error"))
    differs = "" if not exited < 1.0 else (
        f"t_d is the last exit of the {exited:.0%} of the tracer out by the end of the run, not its complete discharge")
    rows.append(_judged(
        "First appearance over discharge time of the tracer, t_s / t_d", run.pattern, first, first_error, "-",
        f"t_s {plus_minus(float(ids['t_s']), number_or_nan(ids.get('t_s_error')))} s, t_d "
        f"{plus_minus(float(ids['t_d']), number_or_nan(ids.get('t_d_error')))} s, residence times of the tracer's "
        f"passes from their entry at the top; {tracer}{tail}", dof, run.part("B8"),
        lambda p: rules.value_in_band(first, first_error, dof, p, tolerances), differs=differs))
    return rows


def _pattern_rows(internal: _Run, semi: _Run, tolerances: AgreementTolerances) -> list[dict]:
    """B3.stronger_in_internal and B5: the two flow patterns compared."""
    rows, dof = [], smallest_dof(internal.dof, semi.dof)
    case = f"{internal.pattern} vs {semi.pattern}"
    tail = _tail(f"{internal.pattern}: {internal.note}" if internal.note else "",
                 f"{semi.pattern}: {semi.note}" if semi.note else "")
    effects, reads, ends = [], [], []
    for run in (internal, semi):
        small, half = run.layout(0.13, 1), run.layout(0.5, 1)
        if small and half:
            pair = a, b = run.end(*small), run.end(*half)
            ends += pair
            value, error = ratio(a.value, a.error, b.value, b.error)
            differs = joined(end.differs for end in pair)
            effects.append((value - 1.0, error, joined(end.bound for end in pair),
                            differs and f"{run.pattern}: {differs}"))
            reads.append(joined((f"{run.pattern}: 13 % {plus_minus(a.value, a.error)} / 50 % "
                                  f"{plus_minus(b.value, b.error)} - 1 = {plus_minus(value - 1.0, error)}",
                                  *(end.evidence for end in pair))))
    if len(effects) == 2:
        values, errors = [e[0] for e in effects], [e[1] for e in effects]
        why = joined(e[2] for e in effects)
        rows.append(row(RECIRCULATION_GROUP, f"Batch effect VRR(13 %) / VRR(50 %) - 1 {_where(ends)}, internal vs "
                                             "semi-mass flow", case, values[0], errors[0], "-",
                        "; ".join(reads) + f" (value column: internal flow){tail}", dof=dof,
                        finding="B3.stronger_in_internal",
                        agreement=capped(rules.in_order(values, errors, dof, PARTS["B3.stronger_in_internal"]), why),
                        differs=joined(e[3] for e in effects)))
    for name, layout in internal.layouts.items():
        if int(layout["sublayers"]) != 1:
            continue
        other = semi.layout(float(layout["blue_fraction"]), 1)
        if other is None:
            continue
        (a, ea, _, ba), (b, eb, _, bb) = internal.vrr(layout, 0), semi.vrr(other[1], 0)
        why = "; ".join(filter(None, (ba, bb)))
        rows.append(row(RECIRCULATION_GROUP, f"VRR at Nr = 0, internal over semi-mass flow ({_label(layout, name)})",
                        case, *ratio(a, ea, b, eb), "-",
                        f"internal {plus_minus(a, ea)}, semi-mass {plus_minus(b, eb)}; Nr = 0 is the first pass, "
                        f"0 <= Nr < 1{tail}", dof=dof, finding="B5",
                        agreement=capped(rules.ratio_in_band(a, ea, b, eb, dof, PARTS["B5"], tolerances,
                                                              steady=not why), why)))
    return rows


def recirculation_rows(runs: Sequence[Mapping], tolerances: AgreementTolerances) -> list[dict]:
    """The rows of the recirculating silo: per run B4 (VRR at the end of 4 recirculations per batch: of the final
    discharge when the run has one, with the last pass at constant head beside it as a row with no finding, else of
    the pass at Nr = 4), B2 (its growth, per layout),
    B3.internal, B6, B7 (theta of the RTD's peak), B8 (t_s / t_d) and B1 (drop of bulk density); with both flow
    patterns, B3.stronger_in_internal and B5 (VRR at Nr = 0, internal over semi-mass flow, per batch).

    Parameters
    ----------
    runs : sequence of mapping
        One per flow pattern: ``{"case", "summary", "rtd", "note", "dof"}`` (see the module docstring).
    tolerances : AgreementTolerances

    Returns
    -------
    list of dict
        Rows of :func:`~siloflow.analysis.studies.validation.rows.row`, run by run, then the comparisons.
    """
    chosen = [_Run(run) for run in runs]
    patterns = [run.pattern for run in chosen]
    if len(set(patterns)) != len(patterns):
        raise ValueError(f"one run per flow pattern (its seeds combined), got {patterns}")
    rows = [entry for run in chosen for entry in _run_rows(run, tolerances)]
    by_pattern = {run.suffix: run for run in chosen if run.suffix}
    if len(by_pattern) == 2:
        rows += _pattern_rows(by_pattern["internal"], by_pattern["semi_mass"], tolerances)
    return rows
