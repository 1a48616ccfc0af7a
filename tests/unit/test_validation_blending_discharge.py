"""The validation rows of the recirculating silo that read the VRR "at the end of Nr = 4 recirculations" (B2-B4, B6):
the discharge after the recirculations when the summary has one (§6.4.2), the pass at constant head otherwise, on
hand-built summaries with exact answers. The helpers are those of ``test_validation_blending.py``."""

import math

import pytest

from siloflow.analysis.numerics.reference_spread import combine_seeds
from siloflow.analysis.studies.validation import blending
from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED, NOT_RESOLVED, REPRODUCED
from siloflow.analysis.studies.validation.blending import recirculation_rows
from siloflow.analysis.studies.validation.rows import NO_FINDING
# _internal: the passes at constant head, entry 4 is 12, 10, 3 for the single layers
from tests.unit.test_validation_blending import TOLERANCES, _internal, _layout, _one, _rows
from tests.unit.test_validation_blending import _summary as _blending_summary


def _summary(pattern, layouts, discharge=None, recirculations=6.1, **extra):
    """The blending rows' summary, with the discharge after the recirculations where given."""
    extra = extra if discharge is None else {**extra, "final_discharge": discharge}
    return _blending_summary(pattern, layouts, recirculations, **extra)


def _discharge(vrr, nr=4.02, faded=True, at_ceiling=(), relative=0.1):
    """A ``final_discharge`` entry: ``vrr`` maps layout names to the discharge's VRR."""
    return {"recirculations": nr, "start_s": 8.04, "end_s": 9.54, "window_s": 0.1, "reference_clumps_per_window": 40.0,
            "fade_fraction": 0.5, "threshold_clumps": 20.0, "faded": faded, "crossings": 620, "reentries": 0,
            "layouts": {name: {"blue_fraction": 0.5, "vrr": value, "vrr_error": relative * value, "sigma_out": 0.1,
                               "windows": 15, "clumps": 600, "left_out_fraction": 20 / 620, "vrr_ceiling": 40.0,
                               "at_ceiling": name in at_ceiling}
                        for name, value in vrr.items()}}


def _run(summary, dof=None):
    return {"case": {"run_id": summary["flow_pattern"]}, "summary": summary, "rtd": [], "note": "one seed", "dof": dof}


#: The discharge's VRR per layout: the single layers 9, 7.5 and 20, the sub-layers 6 (3) and 5 (5).
DISCHARGE = {"blue13": 9.0, "blue25": 7.5, "blue50": 20.0, "blue50_3layers": 6.0, "blue50_5layers": 5.0}


def test_b4_takes_the_discharge_s_vrr_and_keeps_the_pass_at_constant_head_as_a_row_with_no_finding():
    rows = recirculation_rows([_run(_summary("internal_flow", _internal(), _discharge(DISCHARGE)))], TOLERANCES)
    b4 = _rows(rows, "B4.internal")
    assert len(b4) == 3  # exactly one row per batch judged
    small, half = _one(rows, "B4.internal", "blue13:"), _one(rows, "B4.internal", "blue50:")
    assert (small["value"], small["value_error"]) == (9.0, pytest.approx(0.9))
    assert small["figure"] == "VRR of the discharge after Nr = 4.02 (blue13: blue 13 %, 1 layer)"
    assert small["differs"] == "" and small["agreement"] == REPRODUCED  # 9 +- 0.9 within 8-13
    assert half["value"] == 20.0 and half["agreement"] == NOT_REPRODUCED
    assert small["evidence"].startswith("discharge after Nr = 4.02 recirculations from t = 8.04 s: 15 windows of "
                                        "0.1 s to t = 9.54 s, 600 clumps, 3.2% of its outflow left out")
    assert "Nr 4: 12 ± 0.12" in small["evidence"]  # the passes still listed
    # the pass after 4 recirculations at constant head, siloflow's own measurement
    constant = [entry for entry in rows if "at constant head" in entry["figure"]]
    assert len(constant) == 3 and {entry["finding"] for entry in constant} == {NO_FINDING}
    pass4 = next(entry for entry in constant if "blue13:" in entry["figure"])
    assert pass4["figure"] == "VRR of the pass 4 <= Nr < 5 at constant head, siloflow's (blue13: blue 13 %, 1 layer)"
    assert (pass4["value"], pass4["agreement"], pass4["study"]) == (12.0, NO_FINDING, blending.CONSTANT_HEAD_STUDY)
    assert "§6.4.2" in pass4["study"]


def test_the_other_end_of_nr_4_readings_take_the_discharge_and_b2_slower_stays_on_the_passes():
    semi = {"blue13": _layout(0.13, 1, [2.0, 3.0, 4.0, 4.5, 5.0]), "blue50": _layout(0.5, 1, [2.0, 3.0, 3.5, 3.8, 4.0])}
    rows = recirculation_rows([
        _run(_summary("internal_flow", _internal(), _discharge(DISCHARGE))),
        _run(_summary("semi_mass_flow", semi, _discharge({"blue13": 5.0, "blue50": 4.0}, nr=3.9)))], TOLERANCES)
    # B2.grows: the discharge's VRR minus the first pass's, 9 - 2, errors 0.9 and 0.02
    grows = [entry for entry in _rows(rows, "B2.grows") if entry["case"] == "internal_flow" and "blue13:" in
             entry["figure"]][0]
    assert grows["value"] == pytest.approx(7.0) and grows["value_error"] == pytest.approx(math.hypot(0.9, 0.02))
    assert grows["figure"].startswith("Change of VRR from Nr = 0 to the discharge after Nr = 4.02")
    assert grows["differs"] == ""
    # B3.internal: 20 - 9 > 0 against the study's decrease
    b3 = _one(rows, "B3.internal")
    assert b3["value"] == pytest.approx(11.0) and b3["agreement"] == NOT_REPRODUCED
    assert b3["figure"] == "Change of VRR of the discharge after Nr = 4.02 from the 13 % to the 50 % batch"
    # B6: 5, 6, 20 for 5, 3, 1 layers: the wrong order
    b6 = [entry for entry in _rows(rows, "B6") if entry["case"] == "internal_flow"][0]
    assert b6["value"] == 5.0 and b6["agreement"] == NOT_REPRODUCED and b6["differs"] == ""
    assert b6["figure"] == "VRR of the discharge after Nr = 4.02 of the 50 % batch in 5, 3 and 1 layers"
    # B3.stronger_in_internal: 9 / 20 - 1 in internal flow against 5 / 4 - 1 in semi-mass flow
    stronger = _one(rows, "B3.stronger_in_internal")
    assert stronger["value"] == pytest.approx(9.0 / 20.0 - 1.0) and stronger["agreement"] == NOT_REPRODUCED
    assert "of the discharge after Nr = 3.90" in stronger["figure"] and stronger["differs"] == ""
    # B2.slower_after_2 needs Nr = 0, 2 and 4 of one kind: the passes, and it says so
    slower = [entry for entry in _rows(rows, "B2.slower_after_2") if "blue13:" in entry["figure"]][0]
    assert slower["value"] == pytest.approx((12.0 - 8.0) - (8.0 - 2.0)) and blending.SLOWER_PASSES in slower["differs"]


def test_without_a_final_discharge_the_rows_say_they_read_a_pass_at_constant_head():
    rows = recirculation_rows([_run(_summary("internal_flow", _internal()))], TOLERANCES)
    assert not [entry for entry in rows if "at constant head, siloflow's" in entry["figure"]]
    small = _one(rows, "B4.internal", "blue13:")
    assert small["value"] == 12.0 and small["figure"].startswith("VRR at Nr = 4")
    assert small["differs"] == blending.CONSTANT_HEAD
    assert "not of the discharge after Nr recirculations (§6.4.2)" in small["differs"]
    for finding in ("B2.grows", "B3.internal", "B6"):
        assert all(entry["differs"].startswith(blending.CONSTANT_HEAD) for entry in _rows(rows, finding)), finding
    # a run of fewer passes says both
    short = recirculation_rows([_run(_summary("internal_flow", {"blue13": _layout(0.13, 1, [2.0, 6.0, 8.0])},
                                              recirculations=3.05))], TOLERANCES)
    differs = _one(short, "B4.internal")["differs"]
    assert differs.startswith(blending.CONSTANT_HEAD) and "not at Nr = 4" in differs


def test_a_discharge_after_another_nr_cut_short_or_at_the_ceiling_says_so():
    layouts = {"blue13": _layout(0.13, 1, [2.0, 5.0, 8.0, 10.0, 12.0, 12.5])}
    far = _one(recirculation_rows([_run(_summary("internal_flow", layouts, _discharge({"blue13": 9.0}, nr=5.1)))],
                                  TOLERANCES), "B4.internal")
    assert far["differs"] == ("discharge after Nr = 5.10 recirculations, not 4 (silo_recirculation.recirculations "
                              "sets it)")
    near = _one(recirculation_rows([_run(_summary("internal_flow", layouts, _discharge({"blue13": 9.0}, nr=3.6)))],
                                   TOLERANCES), "B4.internal")
    assert near["differs"] == ""  # the nearest whole Nr is 4
    cut = _one(recirculation_rows([_run(_summary("internal_flow", layouts, _discharge({"blue13": 9.0}, faded=False)))],
                                  TOLERANCES), "B4.internal")
    assert "ends before the discharge's outflow fades" in cut["differs"] and "first 1.5 s" in cut["differs"]
    ceiling = recirculation_rows([_run(_summary("internal_flow", layouts,
                                                _discharge({"blue13": 9.0}, at_ceiling=("blue13",))))], TOLERANCES)
    assert _one(ceiling, "B4.internal")["agreement"] == NOT_RESOLVED
    assert "VRR of the discharge is at the counting-noise ceiling" in _one(ceiling, "B4.internal")["agreement_reason"]
    assert _one(ceiling, "B2.grows")["agreement"] == NOT_RESOLVED


def test_a_layout_missing_from_the_discharge_falls_back_on_its_pass():
    rows = recirculation_rows([_run(_summary("internal_flow", _internal(), _discharge({"blue13": 9.0})))], TOLERANCES)
    assert _one(rows, "B4.internal", "blue13:")["value"] == 9.0
    medium = _one(rows, "B4.internal", "blue25:")
    assert medium["value"] == 10.0 and medium["differs"] == blending.CONSTANT_HEAD
    b3 = _one(rows, "B3.internal")  # 9 from the discharge, 3 from the pass: said in its figure and differs
    assert b3["value"] == pytest.approx(3.0 - 9.0) and "discharges and passes" in b3["figure"]
    assert blending.CONSTANT_HEAD in b3["differs"]


def test_the_seeds_of_a_discharge_combine_like_any_figure():
    layouts = {"blue13": _layout(0.13, 1, [2.0, 5.0, 8.0, 10.0, 12.0])}
    seeds = [_summary("internal_flow", layouts, _discharge({"blue13": value}, relative=0.01)) for value in (8.0, 10.0)]
    combined, spread = combine_seeds(seeds)
    entry = combined["final_discharge"]["layouts"]["blue13"]
    assert entry["vrr"] == 9.0 and entry["vrr_error"] == pytest.approx(1.0)  # the seeds' standard error, sd / sqrt(2)
    assert spread[("final_discharge", "layouts", "blue13", "vrr")] == pytest.approx(math.sqrt(2.0) / 9.0)
    assert _one(recirculation_rows([_run(combined, dof=1.0)], TOLERANCES), "B4.internal")["value"] == 9.0


def test_the_discharge_s_nr_is_also_given_in_the_study_s_nominal_residence_times():
    # Nr = 4.02 measured residence times of 2.0 s: 8.04 s, or 6.432 nominal residence times of 1.25 s
    summary = _summary("internal_flow", _internal(), _discharge(DISCHARGE), nominal_residence_time_s=1.25)
    small = _one(recirculation_rows([_run(summary)], TOLERANCES), "B4.internal", "blue13:")
    assert small["evidence"].startswith(
        "discharge after Nr = 4.02 recirculations (in the study's nominal residence time W H / (B0 V_out) = 1.25 s "
        "(the channel as dense as the fill) that Nr = 6.43) from t = 8.04 s: ")
    assert small["value"] == 9.0 and small["differs"] == ""  # judged as before: the row's Nr is the measured one
