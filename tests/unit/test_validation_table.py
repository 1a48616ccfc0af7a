"""The validation table's rows: the two verdicts, the flat-bottom silo's rows, the findings' summary, the pages."""

import math

import pytest

from siloflow.analysis.report.summary import summary_html
from siloflow.analysis.studies.validation.agreement import (NOT_REPRODUCED, NOT_RESOLVED, REPRODUCED, Agreement,
                                                            AgreementTolerances)
from siloflow.analysis.studies.validation.findings import FINDINGS, finding
from siloflow.analysis.studies.validation.findings_summary import (NOT_AT_SCALE, NOT_MEASURED, chapter_counts,
                                                                   finding_status, finding_statuses)
from siloflow.analysis.studies.validation.group_rows import MADE, UNMADE, seed_dof
from siloflow.analysis.studies.validation.rows import (AT_SCALE, NO_FINDING, NOT_AT_SCALE as ROW_NOT_AT_SCALE,
                                                       precise, resolution, resolved, row, with_scale)
from siloflow.analysis.studies.validation.scale import scale_verdict
from siloflow.analysis.studies.validation.silo import (SiloRun, front_wall_series_rows, heights_clause, silo_rows,
                                                       stress_gradient, window_clause)
from siloflow.analysis.studies.validation.table import against_the_study, page_sections
from siloflow.analysis.numerics.reference_spread import SeedSpread
from siloflow.engines.config import validate_config

TOLERANCES = AgreementTolerances()


def _row(finding_id, verdict=REPRODUCED, value=1.0, differs=""):
    return row("G", "figure", "case", value, 0.1, "-", "evidence", dof=2.0, finding=finding_id,
               agreement=Agreement(verdict, f"{finding_id}: why"), differs=differs)


# --------------------------------------------------------------------------- the two verdicts


def test_a_row_names_its_finding_part_and_takes_the_part_s_statement_as_the_study_column():
    entry = _row("S2")
    assert entry["finding"] == "S2" and entry["study"] == finding("S2").parts[0].stated()
    assert entry["agreement"] == REPRODUCED and entry["dof"] == 2.0 and entry["scale"] == NO_FINDING
    plain = row("G", "f", "c", 1.0, 0.1, "-", "evidence", study="the configured C")
    assert (plain["finding"], plain["agreement"], plain["study"]) == (NO_FINDING, NO_FINDING, "the configured C")
    with pytest.raises(ValueError, match="exactly when"):
        row("G", "f", "c", 1.0, 0.1, "-", "e", finding="S2")
    with pytest.raises(KeyError):
        row("G", "f", "c", 1.0, 0.1, "-", "e", finding="S9", agreement=Agreement(REPRODUCED, ""))


def test_the_scale_verdict_is_the_same_whatever_the_row_s_value():
    config = validate_config({})
    judge = lambda f, d: scale_verdict(f, "silo_flat", config, d)  # noqa: E731
    verdicts = {(entry["scale"], entry["scale_reason"])
                for value in (-1e6, 0.0, 0.5, 622.7, 1e9, math.nan)
                for verdict in (REPRODUCED, NOT_REPRODUCED, NOT_RESOLVED)
                for entry in with_scale([_row("S2", verdict, value)], judge)}
    assert len(verdicts) == 1
    (scale, reason), = verdicts
    assert scale in (AT_SCALE, ROW_NOT_AT_SCALE) and reason == scale_verdict("S2", "silo_flat", config, True).text


def test_a_row_defined_otherwise_than_the_study_is_not_at_its_scale_and_says_how():
    config = validate_config({})
    (entry,) = with_scale([_row("S1.janssen", differs="at z = 40 mm, not 120 mm")],
                          lambda f, d: scale_verdict(f, "silo_flat", config, d))
    assert entry["scale"] == ROW_NOT_AT_SCALE and entry["scale_reason"].endswith("(this row: at z = 40 mm, not 120 mm)")
    (plain,) = with_scale([row("G", "f", "c", 1.0, 0.1, "-", "e")], lambda f, d: pytest.fail("judged"))
    assert plain["scale"] == NO_FINDING


def test_resolution_uses_the_t_quantile_of_the_degrees_of_freedom():
    # 2 dof: q = 4.303; normal: 1.960
    assert resolved(0.4, 0.1, 2.0) is False and resolved(0.45, 0.1, 2.0) is True
    assert resolved(0.2, 0.1, None) is True and resolved(1.0, math.nan, None) is None
    assert resolution(0.4, 0.1, 2.0) == "not resolved at 95 % (q 4.303, t 2 dof)"
    assert seed_dof(SeedSpread({}, 3)) == 2.0 and seed_dof(SeedSpread({}, 1)) is None


def test_precise_judges_the_relative_error_against_its_limit_and_quotes_both():
    assert precise(2.0, 0.4, TOLERANCES) == (True, "relative error 20 % (at most 25 %)")
    assert precise(2.0, 0.6, TOLERANCES)[0] is False and precise(1.0, math.nan, TOLERANCES)[0] is None


def test_every_part_of_every_finding_is_made_by_a_row_or_says_why_not():
    parts = {part.id for entry in FINDINGS for part in entry.parts}
    assert set(MADE) | set(UNMADE) == parts and not set(MADE) & set(UNMADE)
    assert all(reason for reason in UNMADE.values())


# --------------------------------------------------------------------------- the flat-bottom silo


def _janssen(depths, stress, hydrostatic, janssen=None, error=1.0):
    return [{"depth_below_surface_m": d, "z_m": 0.1 - d, "sigma_v_dem_Pa": s, "sigma_v_dem_Pa_error": error,
             "sigma_v_janssen_Pa": (janssen or stress)[i], "hydrostatic_pa": h, "hydrostatic_pa_error": 0.0}
            for i, (d, s, h) in enumerate(zip(depths, stress, hydrostatic))]


STUDY_FIELDS = {"average_window_s": [0.5, 0.7], "average_window_source": "silo_flat.fields.average_window"}


def _silo(density=650.0, problems=(), index=(0.5, 0.02), run_id="base", b=(0.008, 0.006), window=STUDY_FIELDS):
    case = {"run_id": run_id, "depth_m": 0.04, "width_m": 0.15, "outlet_width_m": 0.04,
            "equivalent_diameter_m": 0.004}
    flow = {"filling_bulk_density_kg_m3": density, "filling_bulk_density_kg_m3_error": 2.0,
            "mass_flow_rate_kg_s": 0.3, "mass_flow_rate_kg_s_error": 0.006, "beverloo_mass_flow_rate_kg_s": 0.25,
            "beverloo_ratio": 1.2, "beverloo_ratio_error": 0.03,
            "beverloo": {"discharge_coefficient": 0.58, "shape_coefficient": 1.5},
            "steady_window": [0.2, 0.8], "steady_window_start_s": 0.31, "steady_window_end_s": 1.24}
    fields = {"flow_pattern_index": {"0.02": 0.1, "0.04": index[0]},
              "flow_pattern_index_error": {"0.02": 0.01, "0.04": index[1]}, **window}
    balance = {"support_ratio": 0.999, "problems": list(problems)}
    depths = [0.01 * k for k in range(1, 7)]
    # rho g = 6000 Pa/m; the DEM follows it near the surface (slope 6000) and saturates below (slope 1500)
    stress = [6000.0 * d if d <= 0.02 else 120.0 + 3000.0 * (d - 0.02) if d <= 0.04 else 180.0 + 1500.0 * (d - 0.04)
              for d in depths]
    # Janssen: 0.8 of the DEM at the two shallowest depths, the DEM between, 1/1.05 of it at the deepest
    janssen = [0.8 * value for value in stress[:2]] + stress[2:-1] + [stress[-1] / 1.05]
    return SiloRun(case, flow, fields, balance, janssen=_janssen(depths, stress, [6000.0 * d for d in depths], janssen),
                   kinematic=[{"z_m": 0.02, "B_m": b[0], "B_m_error": 0.0004, "batches": 8},
                              {"z_m": 0.06, "B_m": b[1], "B_m_error": 0.0003, "batches": 4}],
                   boundary=[{"z_m": 0.02, "fraction": 0.1, "x_left_m": -0.03, "x_right_m": 0.05,
                              "x_left_m_error": 0.003, "x_right_m_error": 0.004}])


def test_stress_gradient_is_the_weighted_slope_with_its_error():
    slope, error = stress_gradient([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], [0.1, 0.1, 0.1])
    assert slope == pytest.approx(10.0) and error == pytest.approx(0.1 / math.sqrt(0.02), rel=1e-12)
    two = stress_gradient([0.0, 0.5], [1.0, 2.0], [0.0, 0.0])
    assert two[0] == 2.0 and math.isnan(two[1])
    with pytest.raises(ValueError):
        stress_gradient([0.1, 0.1], [1.0, 2.0], [0.1, 0.1])


def test_silo_rows_judge_density_stress_and_b_against_the_study():
    table = {r["figure"]: r for r in silo_rows(_silo(), TOLERANCES, 2.0, "mean of 3 seeds")}
    density = table["Filling bulk density"]
    # the study's DEM: 6.6 % below 666.7 +- 5 kg/m3, i.e. 618.0 to 627.4; 650 +- 4.303 x 2 lies above it
    assert density["finding"] == "S2" and density["agreement"] == NOT_REPRODUCED
    assert density["evidence"].endswith("mean of 3 seeds")
    near = table["Stress gradient near the surface / unit weight"]
    assert near["finding"] == "S1.linear_near_surface" and near["value"] == pytest.approx(1.0)
    assert near["agreement"] == REPRODUCED
    # Janssen's own slope over the same two shallowest depths: 0.8 x 6000 Pa/m
    assert "Janssen's curve over the same depths: 4800 Pa/m (0.800 of rho g; the DEM's gradient 1.250 of it)" in (
        near["evidence"])
    saturates = table["Change of the stress gradient, bottom - top of the fill"]
    assert saturates["value"] == pytest.approx(1500.0 - 6000.0) and saturates["agreement"] == REPRODUCED
    janssen = table["Vertical stress / Janssen, 60 mm below the surface"]
    assert janssen["value"] == pytest.approx(1.05) and janssen["agreement"] == REPRODUCED
    b = table["Change of the kinematic constant B, z = 60 - 20 mm"]
    assert b["value"] == pytest.approx(-0.002) and b["value_error"] == pytest.approx(0.0005)
    assert b["finding"] == "S5.dem" and b["agreement"] == NOT_RESOLVED  # 0.002 < 4.303 x 0.0005
    assert table["Beverloo discharge coefficient C (k = 1.5)"]["finding"] == NO_FINDING
    # B rising with height is resolved against the study's decrease: a result, never a scale word
    rising = {r["finding"]: r for r in silo_rows(_silo(b=(0.004, 0.010)), TOLERANCES, None)}
    assert rising["S5.dem"]["agreement"] == NOT_REPRODUCED


def test_the_window_clause_is_empty_for_the_study_s_window_and_names_any_other():
    flow = {"steady_window": [0.2, 0.8], "steady_window_start_s": 0.31, "steady_window_end_s": 1.24}
    assert window_clause(STUDY_FIELDS, flow) == ""
    # the steady window, recorded as such: its mass fractions and their times
    steady = {"average_window_s": [0.31, 1.24], "average_window_source": "silo_flat.steady_window"}
    assert window_clause(steady, flow) == ("profiles averaged over the discharged-mass window 0.2-0.8 "
                                           "(t = 0.31-1.24 s), not the study's 0.5-0.7 s (§5.4.3.4)")
    configured = {"average_window_s": [0.4, 0.9], "average_window_source": "silo_flat.fields.average_window"}
    assert window_clause(configured, flow, "velocities", "§5.5.2") == (
        "velocities averaged over t = 0.4-0.9 s after opening, not the study's 0.5-0.7 s (§5.5.2)")
    # a fields.json written before the source was recorded: the steady window where its times are the flow's
    assert window_clause({"average_window_s": [0.31, 1.24]}, flow) == window_clause(steady, flow)
    assert window_clause({"average_window_s": [0.4, 0.9]}, flow) == window_clause(configured, flow)
    assert window_clause({}, flow) == ("profiles averaged over a window fields.json does not record, not the study's "
                                       "0.5-0.7 s (§5.4.3.4)")


def test_the_heights_clause_is_empty_for_the_study_s_profile_heights_in_any_order():
    assert heights_clause([0.12, 0.02, 0.08, 0.04]) == ""
    assert heights_clause([0.02, 0.04, 0.06], "B fitted at") == (
        "B fitted at 20, 40, 60 mm, not the study's 20, 40, 80, 120 mm (§5.4.3.4)")
    assert heights_clause([0.02, 0.04, 0.08, 0.12, 0.16]).startswith("at 20, 40, 80, 120, 160 mm, not")


def test_the_rows_of_the_averaged_fields_say_when_their_window_and_heights_are_not_the_study_s():
    steady = {"average_window_s": [0.31, 1.24], "average_window_source": "silo_flat.steady_window"}
    table = {r["figure"]: r for r in silo_rows(_silo(window=steady), TOLERANCES, None)}
    b = table["Change of the kinematic constant B, z = 60 - 20 mm"]
    assert b["differs"] == ("profiles averaged over the discharged-mass window 0.2-0.8 (t = 0.31-1.24 s), not the "
                            "study's 0.5-0.7 s (§5.4.3.4); B fitted at 20, 60 mm, not the study's 20, 40, 80, 120 mm "
                            "(§5.4.3.4)")
    channel = table["Flow channel half-width (0.1 of centreline v_z) at z = 20 mm"]
    assert channel["differs"].startswith("velocities averaged over the discharged-mass window 0.2-0.8")
    # at the study's window only the heights differ
    study = {r["figure"]: r for r in silo_rows(_silo(), TOLERANCES, None)}
    assert study["Change of the kinematic constant B, z = 60 - 20 mm"]["differs"] == (
        "B fitted at 20, 60 mm, not the study's 20, 40, 80, 120 mm (§5.4.3.4)")
    assert study["Flow channel half-width (0.1 of centreline v_z) at z = 20 mm"]["differs"] == ""


def test_a_fill_that_fails_its_balance_is_never_reproduced():
    table = {r["finding"]: r for r in silo_rows(_silo(density=622.0, problems=["planes"]), TOLERANCES, None)}
    assert table["S2"]["agreement"] == NOT_RESOLVED and "planes" in table["S2"]["evidence"]
    good = {r["finding"]: r for r in silo_rows(_silo(density=622.0), TOLERANCES, None)}
    assert good["S2"]["agreement"] == REPRODUCED


def test_front_wall_series_judges_the_index_change_and_the_frictionless_stress():
    series = [("mu_fw=0.2", _silo(index=(0.5, 0.02)), "mean of 3 seeds"), ("mu_fw=0", _silo(index=(0.8, 0.03)), "one seed"),
              ("mu_fw=1", _silo(index=(0.3, 0.04)), "one seed"), ("periodic", _silo(index=(0.9, 0.02)), "one seed")]
    rows = front_wall_series_rows(series, 0.045, TOLERANCES, None)
    assert [r["value"] for r in rows[:4]] == [0.5, 0.8, 0.3, 0.9]
    change = next(r for r in rows if r["finding"] == "S6.towards_internal_flow")
    assert change["value"] == pytest.approx(-0.5) and change["value_error"] == pytest.approx(0.05)
    assert change["agreement"] == REPRODUCED and change["differs"] == "at z = 40 mm, not 120 mm"
    # a run of the series averaged over another window says so, on its own row and on the change it enters
    series[2] = ("mu_fw=1", _silo(index=(0.3, 0.04), window={"average_window_s": [0.4, 0.9]}), "one seed")
    rows = front_wall_series_rows(series, 0.045, TOLERANCES, None)
    change = next(r for r in rows if r["finding"] == "S6.towards_internal_flow")
    other = "velocities averaged over t = 0.4-0.9 s after opening, not the study's 0.5-0.7 s (§5.5.2)"
    assert change["differs"] == f"at z = 40 mm, not 120 mm; {other}"
    assert [r["differs"] for r in rows[:4]] == ["", "", other, ""]
    hydrostatic = next(r for r in rows if r["finding"] == "S6.hydrostatic")
    assert hydrostatic["case"] == "mu_fw=0" and hydrostatic["value"] == pytest.approx(210.0 / 360.0)
    assert hydrostatic["agreement"] == NOT_REPRODUCED


# --------------------------------------------------------------------------- the summary and the pages


def test_a_finding_is_reproduced_only_when_every_part_has_a_row_at_scale_that_reproduces_it():
    s2 = finding("S2")
    at = lambda entry: {**entry, "scale": AT_SCALE}  # noqa: E731
    off = lambda entry: {**entry, "scale": ROW_NOT_AT_SCALE}  # noqa: E731
    assert finding_status(s2, []).status == NOT_MEASURED
    assert finding_status(s2, [off(_row("S2", NOT_REPRODUCED))]).status == NOT_AT_SCALE
    assert finding_status(s2, [at(_row("S2"))]).status == REPRODUCED
    assert finding_status(s2, [at(_row("S2")), at(_row("S2", NOT_REPRODUCED))]).status == NOT_REPRODUCED
    s5 = finding("S5")
    half = finding_status(s5, [at(_row("S5.dem"))])
    assert half.status == NOT_RESOLVED and half.unmeasured == ("S5.experiment",)
    counts = chapter_counts(finding_statuses([at(_row("S2"))]))
    assert counts[5][REPRODUCED] == 1 and counts[5][NOT_MEASURED] == 5 and sum(counts[4].values()) == 7


def test_the_report_page_counts_verdicts_per_group_and_lists_rows_against_the_study():
    rows = [{**_row("S2", NOT_REPRODUCED), "group": "Silo", "scale": AT_SCALE},
            {**row("Silo", "C", "c1", 2.0, 0.1, "-", "measured"), "group": "Silo"},
            {**_row("B4.internal", NOT_RESOLVED), "group": "Blending", "scale": ROW_NOT_AT_SCALE}]
    sections = page_sections(rows)
    assert [s[0] for s in sections] == ["Silo", "Blending"]
    assert sections[0][1] == ("1 of 2 rows judged against a finding of the study: 0 reproduced, 1 not reproduced, "
                              "0 not resolved; 1 at the study's scale.")
    notes = against_the_study(rows)
    assert [note["finding"] for note in notes] == ["S2", "B4.internal"] and notes[0]["note"] == "S2: why"
    page = summary_html("validation", sections, intro="How to read it.")
    assert "<p>How to read it.</p>" in page and "not reproduced" in page
