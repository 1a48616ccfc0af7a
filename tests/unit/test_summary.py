"""The report's summary page: headers in words with units, figures with their uncertainty, no Python reprs,
tables that fit the page."""

import math

import numpy as np
import pytest

from siloflow.analysis.io.tables import read_table, write_flow_table
from siloflow.analysis.report.cells import format_cell, format_number, format_value_with_error
from siloflow.analysis.report.summary import (
    BLENDER_COLUMNS,
    COLUMNS,
    MEASURED_COLUMNS,
    RECIRCULATION_COLUMNS,
    SILO_FLOW_COLUMNS,
    Section,
    blender_rows,
    calibration_rows,
    column_header,
    fill_balance_rows,
    significance_rows,
    recirculation_rows,
    silo_flow_rows,
    summary_html,
    summary_sections,
)
from siloflow.analysis.studies.blender.comparison import comparison_table
from siloflow.analysis.studies.silo_flat.field_comparisons import measured_comparison_rows
from siloflow.analysis.studies.silo_flat.measured import MeasuredProfile, compare_with_measurement
from test_blender_analysis import metrics

PARAMETERS = {
    "shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0,
    "particle_particle": {"sliding_friction": 0.27372, "lower": 0.24822, "upper": 0.29922, "band_clipped": False},
    "particle_wall": {"aluminium": {"sliding_friction": 0.16661, "lower": 0.15004, "upper": 0.18319,
                                    "band_clipped": True}},
    "targets_deg": {"internal": 30.0, "aluminium": 9.5},
    "unreachable": {},
    "not_tested": ["perspex"],
}


def _page(*sections):
    return summary_html("siloflow", [Section(*section) for section in sections])


# --------------------------------------------------------------------------- cells


def test_cells_are_formatted_and_escaped():
    assert format_cell(0.123456) == "0.1235"
    assert format_cell(float("nan")) == "n/a" and format_cell(None) == "n/a"
    assert format_cell(True) == "yes" and format_cell(3) == "3"
    assert format_cell("<b>") == "&lt;b&gt;"
    assert format_cell(6539.0, "count") == "6539"
    assert format_cell(np.float64(0.5), "estimate") == "0.5000 ±?"


@pytest.mark.parametrize("value, error, text", [
    (0.116844, 0.002134, "0.1168 ± 0.0021"),
    (535.92, 12.4, "536 ± 12"),
    (0.12, 0.0999, "0.12 ± 0.10"),  # the error rounds up to a third digit: back to 2 significant digits
    (0.11684466, 0.00012265, "0.11684 ± 0.00012"),
    (2.675, 0.0125, "2.675 ± 0.013"),  # half up, as the digits read
    (12345.6, 234.0, "12350 ± 230"),
    (-0.00001, 0.01, "0.000 ± 0.010"),  # no "-0.000"
    (1.23e-7, 4.5e-9, "(1.230 ± 0.045) × 10⁻⁷"),
    (0.5, float("nan"), "0.5000 ±?"),
    (0.5, None, "0.5000 ±?"),
    (0.116844, 0.0, "0.1168 ± 0"),
    (float("nan"), 0.1, "n/a"),
    (None, None, "n/a"),
])
def test_value_with_error_rounds_the_error_to_two_digits_and_the_value_to_its_place(value, error, text):
    assert format_value_with_error(value, error) == text


def test_a_negative_error_is_refused():
    with pytest.raises(ValueError, match="standard error must be >= 0"):
        format_value_with_error(1.0, -0.1)


@pytest.mark.parametrize("value, text", [(0.123456, "0.1235"), (535.9231, "535.9"), (123456.7, "123457"),
                                         (9.99996, "10.00"), (0.15004, "0.1500"), (1.2345e-7, "1.235 × 10⁻⁷"),
                                         (-3, "-3.000"), (0.0, "0")])
def test_numbers_alone_keep_four_significant_digits(value, text):
    assert format_number(value) == text


def test_mappings_and_lists_never_reach_a_cell():
    with pytest.raises(TypeError, match=r"column 'note': a dict is not a table cell value"):
        _page(("Calibration", "", [{"contact": "particle-particle", "note": {"internal": 30.0}}]))
    with pytest.raises(TypeError, match=r"column 'lower': a list is not a table cell value"):
        _page(("Calibration", "", [{"contact": "particle-particle", "lower": [0.2, 0.3]}]))


def test_flags_print_yes_or_no_also_when_read_back_from_a_csv():
    page = _page(("Calibration", "", [{"contact": "a", "band_clipped": True}, {"contact": "b", "band_clipped": "False"},
                                      {"contact": "c", "band_clipped": None}]))
    assert ('<tbody><tr><td class="text">a</td><td>yes</td></tr><tr><td class="text">b</td><td>no</td></tr>'
            '<tr><td class="text">c</td><td>n/a</td></tr></tbody>') in page


# --------------------------------------------------------------------------- headers


def test_headers_are_words_with_units():
    assert column_header("mass_flow_rate_kg_s") == "Flow rate (kg/s)"
    assert column_header("filling_bulk_density_kg_m3") == "Filling bulk density (kg/m³)"
    assert column_header("rms_error_m_s") == "RMS error (m/s)"
    assert column_header("beverloo_ratio") == "Flow rate / Beverloo"  # dimensionless: no unit
    assert column_header("vrr_nr3") == "VRR after recirculation 3"
    assert column_header("vrr_at_0.5_tm") == "VRR, sine period 0.5 t_m"
    for key, column in COLUMNS.items():
        assert column.header and "_" not in column.header.split(" ")[0], key


def test_a_key_without_a_header_is_refused_naming_it():
    with pytest.raises(ValueError, match=r"no header for the column 'friction_mu'"):
        _page(("Calibration", "", [{"contact": "particle-particle", "friction_mu": 0.3}]))
    with pytest.raises(ValueError, match=r"'vrr_nrx'"):
        column_header("vrr_nrx")


def test_every_column_the_stages_write_has_a_header():
    for key in SILO_FLOW_COLUMNS + MEASURED_COLUMNS + RECIRCULATION_COLUMNS + BLENDER_COLUMNS:
        column_header(key)
    for row in calibration_rows(PARAMETERS):
        for key in row:
            column_header(key)
    # The blender comparison's columns all reach the page (none is dropped for want of a header).
    comparison = comparison_table([metrics("diverging", 2.0, 5.0)])
    assert blender_rows(comparison) == comparison
    profile = MeasuredProfile(z=0.1, window="steady", x=np.array([0.0, 0.01]), v_z=np.array([-0.1, -0.05]),
                              v_x=np.zeros(2), uncertainty=None)
    (measured,) = measured_comparison_rows([compare_with_measurement([0.0, 0.01], [-0.1, -0.06], profile)])
    assert tuple(measured) == MEASURED_COLUMNS


# --------------------------------------------------------------------------- tables and page


def test_errors_merge_into_their_value_cell():
    page = _page(("Silo validation", "flow", [
        {"run_id": "a", "mass_flow_rate_kg_s": 0.116844, "mass_flow_rate_kg_s_error": 0.002134},
        {"run_id": "b", "mass_flow_rate_kg_s": 0.2, "mass_flow_rate_kg_s_error": None},
        {"run_id": "c", "mass_flow_rate_kg_s": 0.3},
    ]))
    assert ('<thead><tr><th scope="col">Run</th><th scope="col">Flow rate (kg/s)</th></tr></thead>'
            '<tbody><tr><td class="text">a</td><td>0.1168 ± 0.0021</td></tr>'
            '<tr><td class="text">b</td><td>0.2000 ±?</td></tr>'
            '<tr><td class="text">c</td><td>0.3000 ±?</td></tr></tbody>') in page
    assert "_error" not in page


def test_a_number_that_is_not_an_estimate_prints_without_a_marker_unless_it_has_an_error():
    page = _page(("Silo validation", "flow", [
        {"run_id": "a", "beverloo_mass_flow_rate_kg_s": 0.076516},
        {"run_id": "b", "beverloo_mass_flow_rate_kg_s": 0.076516},
        {"run_id": "c", "beverloo_mass_flow_rate_kg_s": 0.5, "beverloo_mass_flow_rate_kg_s_error": 0.01},
    ]))
    assert ('<td class="text">a</td><td>0.07652 ±?</td></tr><tr><td class="text">b</td><td>0.07652 ±?</td>'
            '</tr><tr><td class="text">c</td><td>0.500 ± 0.010</td>') in page
    page = _page(("Silo validation", "flow", [{"run_id": "a", "beverloo_mass_flow_rate_kg_s": 0.076516},
                                              {"run_id": "b", "beverloo_mass_flow_rate_kg_s": 0.1}]))
    assert '<td class="text">a</td><td>0.07652</td>' in page


def test_a_wide_table_is_transposed_one_column_per_configuration():
    rows = [{"configuration": "diverging", "mass_flow_rate_kg_s": 0.011959, "mass_flow_rate_kg_s_error": 5.03e-5,
             "rtd_mean_s": 11.9576, "recirculations_to_homogenise": math.nan, "vrr_at_0.5_tm": 12.9127},
            {"configuration": "straight", "mass_flow_rate_kg_s": 0.0099266, "rtd_mean_s": 10.0626,
             "recirculations_to_homogenise": 4.61, "vrr_at_0.5_tm": 15.5236}]
    page = _page(("Blender", "configurations", rows))
    assert ('<table class="transposed"><thead><tr><th scope="col">Configuration</th><th scope="col">diverging</th>'
            '<th scope="col">straight</th></tr></thead><tbody>'
            '<tr><th scope="row">Flow rate (kg/s)</th><td>0.011959 ± 0.000050</td><td>0.009927 ±?</td></tr>'
            '<tr><th scope="row">Mean residence time t_m (s)</th><td>11.96 ±?</td><td>10.06 ±?</td></tr>'
            '<tr><th scope="row">Recirculations to homogenise</th><td>n/a</td><td>4.610</td></tr>'
            '<tr><th scope="row">VRR, sine period 0.5 t_m</th><td>12.91 ±?</td><td>15.52 ±?</td></tr>'
            '</tbody></table>') in page


def test_a_long_table_keeps_one_row_per_item_in_a_scrolling_box_on_a_page_of_1000_px():
    rows = [{"flow_pattern": pattern, "layout": "blue13", "vrr_nr1": 2.0} for pattern in ("a", "b", "c")]
    page = _page(("Blending", "VRR", rows))
    assert ('<div class="table-box"><table><thead><tr><th scope="col">Flow pattern</th>'
            '<th scope="col">Batch layout</th><th scope="col">VRR after recirculation 1</th></tr></thead>') in page
    assert "body{font-family:sans-serif;max-width:1000px;" in page
    assert ".table-box{max-width:100%;overflow-x:auto;" in page


def test_summary_page_has_one_table_per_section_with_its_legend():
    page = summary_html("siloflow", [
        ("Calibration", "chosen parameters", [{"contact": "particle-particle", "sliding_friction": 0.27}],
         "Band: the range."),
        ("Silo", "flow", [{"run_id": "a", "mass_flow_rate_kg_s": 0.1}, {"run_id": "b", "beverloo_ratio": 0.05},
                          {"run_id": "c"}]),
        ("Blender", "figures of merit", [], "never shown"),
    ])
    assert page.startswith("<!DOCTYPE html>") and page.count("<table") == 2
    assert '<th scope="col">Run</th><th scope="col">Flow rate (kg/s)</th><th scope="col">Flow rate / Beverloo</th>' in page
    assert '<td class="text">b</td><td>n/a</td><td>0.05000 ±?</td>' in page
    assert "</table></div><p class=\"legend\">Band: the range.</p>" in page
    assert "Not run in this configuration" in page and "never shown" not in page
    assert "±?&quot; marks a figure whose uncertainty is not estimated yet" in page


# --------------------------------------------------------------------------- rows of each stage


def test_calibration_rows_cover_chosen_unreachable_and_untested_contacts():
    rows = calibration_rows({
        "particle_particle": {"sliding_friction": 0.27, "lower": 0.25, "upper": 0.3},
        "particle_wall": {"aluminium": {"sliding_friction": 0.17}},
        "unreachable": {"perspex": "above the highest swept friction"},
        "not_tested": ["steel"],
    })
    assert [row["contact"] for row in rows] == ["particle-particle", "particle-aluminium", "perspex", "particle-steel"]
    assert rows[2]["note"] == "target not reached: above the highest swept friction"
    assert calibration_rows({"unreachable": {"internal": "no test"}})[0]["sliding_friction"] is None


def test_calibration_section_writes_targets_as_text_not_as_a_dict():
    (calibration, *_) = summary_sections(PARAMETERS, [], [], [], [])
    assert calibration.explanation == (
        "Contact parameters chosen from the Jenike shear sweep (particle model sphere2, rolling friction 0.1), "
        "with the band that reproduces the target bulk friction angles (internal 30.0°, aluminium 9.5°) within ±1.0°.")
    page = summary_html("siloflow", [calibration])
    assert "{" not in page.split("</style>")[1] and "'" not in page
    assert ('<tr><th scope="row">Band, lower end</th><td>0.2482</td><td>0.1500</td><td>n/a</td></tr>'
            '<tr><th scope="row">Band, upper end</th><td>0.2992</td><td>0.1832</td><td>n/a</td></tr>'
            '<tr><th scope="row">Band clipped at the swept range</th><td>no</td><td>yes</td><td>n/a</td></tr>'
            '<tr><th scope="row">Note</th><td class="text">n/a</td><td class="text">n/a</td>'
            '<td class="text">not tested; config value kept</td></tr>') in page
    assert summary_sections({}, [], [], [], [])[0].explanation == "Contact parameters chosen from the Jenike shear sweep."


def test_silo_flow_rows_take_the_flow_rate_error_and_carry_it_to_the_beverloo_ratio():
    flow = {"run_id": "r", "n_clumps": 6539, "filling_bulk_density_kg_m3": 535.92, "mass_flow_rate_kg_s": 0.116845,
            "mass_flow_rate_stderr_kg_s": 0.000123, "beverloo_mass_flow_rate_kg_s": 0.0765, "beverloo_ratio": 1.5274}
    (row,) = silo_flow_rows([flow])
    assert row["mass_flow_rate_kg_s_error"] == 0.000123
    assert row["beverloo_ratio_error"] == pytest.approx(0.000123 / 0.0765, rel=1e-15)
    (row,) = silo_flow_rows([{**flow, "mass_flow_rate_kg_s_error": 0.002, "beverloo_ratio_error": 0.03}])
    assert row["mass_flow_rate_kg_s_error"] == 0.002 and row["beverloo_ratio_error"] == 0.03
    page = summary_html("siloflow", [("Silo validation", "flow", silo_flow_rows([flow]))])
    assert ('<tr><th scope="row">Particles</th><td>6539</td></tr>'
            '<tr><th scope="row">Filling bulk density (kg/m³)</th><td>535.9 ±?</td></tr>'
            '<tr><th scope="row">Flow rate (kg/s)</th><td>0.11685 ± 0.00012</td></tr>'
            '<tr><th scope="row">Beverloo flow rate (kg/s)</th><td>0.07650</td></tr>'
            '<tr><th scope="row">Flow rate / Beverloo</th><td>1.5274 ± 0.0016</td></tr>') in page


def test_summary_sections_take_the_columns_each_stage_shows():
    flow = {"run_id": "r", "n_clumps": 10, "filling_bulk_density_kg_m3": 600.0, "mass_flow_rate_kg_s": 0.1,
            "beverloo_mass_flow_rate_kg_s": 0.2, "beverloo_ratio": 0.5, "not_shown": 1}
    sections = summary_sections({"shape": "sphere2", "particle_particle": {"sliding_friction": 0.3}}, [flow], [],
                                [{"flow_pattern": "internal_flow", "layout": "blue13", "vrr_nr1": 2.0,
                                  "vrr_nr1_error": 0.1, "extra": 1}],
                                [{"configuration": "straight", "vrr_at_0.5_tm": 3.0, "extra": 1}])
    assert [section.title for section in sections] == ["Calibration", "Silo validation", "Silo against measurements",
                                                       "Blending", "Blender", "Blender: differences",
                                                       "Settled fills"]
    assert sections[0].rows == [{"contact": "particle-particle", "sliding_friction": 0.3}]
    assert sections[1].rows == [{key: flow[key] for key in SILO_FLOW_COLUMNS}]
    assert sections[2].rows == []
    assert sections[3].rows == [{"flow_pattern": "internal_flow", "layout": "blue13", "residence_time_s": None,
                                 "t_s_over_t_d": None, "vrr_nr1": 2.0, "vrr_nr1_error": 0.1, "vrr_nr2": None,
                                 "vrr_nr3": None, "vrr_nr4": None, "prediction_rms_error": None}]
    assert sections[4].rows == [{**{key: None for key in BLENDER_COLUMNS}, "configuration": "straight",
                                 "vrr_at_0.5_tm": 3.0}]
    assert "sphere2" in sections[0].explanation
    assert all(section.legend for section in sections)
    summary_html("siloflow", sections)  # every column of every section has a header


def test_blending_rows_show_the_ceiling_flags_read_back_from_the_csv_and_are_headed_by_pattern_and_layout(tmp_path):
    row = {"flow_pattern": "internal_flow", "layout": "blue13", "run_id": "r", "residence_time_s": 0.83635,
           "t_s_over_t_d": 0.11902, "vrr_nr1": 2.1268, "vrr_nr2": 22.504, "vrr_nr3": 78.948, "vrr_nr4": 60.527,
           "prediction_rms_error": 0.044182, "vrr_ceiling": 80.5, "vrr_at_ceiling_nr1": False,
           "vrr_at_ceiling_nr2": False, "vrr_at_ceiling_nr3": True, "vrr_at_ceiling_nr4": True}
    path = write_flow_table(tmp_path / "blending.csv", [row, {**row, "layout": "blue25", "vrr_at_ceiling_nr3": False}])
    rows = recirculation_rows(read_table(path))
    assert rows[0]["vrr_at_ceiling_nr3"] == "True" and "run_id" not in rows[0]
    page = summary_html("siloflow", [("Blending", "VRR", rows)])
    assert ('<table class="transposed"><thead><tr><th scope="col">Flow pattern, Batch layout</th>'
            '<th scope="col">internal_flow, blue13</th><th scope="col">internal_flow, blue25</th></tr></thead>') in page
    assert ('<tr><th scope="row">VRR after recirculation 3</th><td>78.95 ±?</td><td>78.95 ±?</td></tr>' in page)
    assert ('<tr><th scope="row">VRR counting-noise ceiling</th><td>80.50</td><td>80.50</td></tr>'
            '<tr><th scope="row">VRR after recirculation 1 at the counting-noise ceiling</th><td>no</td><td>no</td>'
            '</tr>') in page
    assert ('<tr><th scope="row">VRR after recirculation 3 at the counting-noise ceiling</th><td>yes</td><td>no</td>'
            '</tr>') in page
    assert "vrr_ceiling" not in recirculation_rows([{"flow_pattern": "a", "layout": "b"}])[0]  # an older table


def test_tables_read_back_numbers_text_and_empty_cells(tmp_path):
    path = write_flow_table(tmp_path / "t.csv", [{"a": 1.5, "b": "x", "c": None}])
    assert read_table(path) == [{"a": 1.5, "b": "x", "c": None}]


def test_fill_balance_rows_give_the_shares_of_the_weight_and_the_planes_in_mm():
    balance = {"case": "silo_flat", "run_id": "sphere2-abc", "clumps": 6539, "support_ratio": 0.998,
               "floor_ratio": 0.63, "walls_ratio": 0.368, "silo_like": True,
               "planes": [{"height_m": 0.01, "contact_ratio": 0.65}, {"height_m": 0.06, "contact_ratio": 0.92}],
               "problems": []}
    (row,) = fill_balance_rows([balance])
    assert row == {"case": "silo_flat", "run_id": "sphere2-abc", "n_clumps": 6539, "support_ratio": 0.998,
                   "floor_ratio": 0.63, "walls_ratio": 0.368, "silo_like": True, "contacts_at_10_mm": 0.65,
                   "contacts_at_60_mm": 0.92, "balance_passed": True}
    page = summary_html("t", [Section("Settled fills", "x", [row])])
    assert "Contacts / weight above, plane at 60 mm" in page and "Walls / weight" in page


def test_blender_rows_keep_the_ceiling_its_flags_and_the_seed_count():
    row = {"configuration": "straight", "vrr_at_0.5_tm": 300.0, "vrr_at_0.5_tm_error": 40.0, "vrr_ceiling": 400.0,
           "vrr_at_0.5_tm_at_ceiling": "True", "replicates": 3.0, "vrr_at_0.5_tm_seed_std": 50.0}
    (picked,) = blender_rows([row])
    assert picked["vrr_ceiling"] == 400.0 and picked["vrr_at_0.5_tm_at_ceiling"] == "True"
    assert picked["replicates"] == 3.0 and "vrr_at_0.5_tm_seed_std" not in picked
    page = summary_html("siloflow", [("Blender", "x", [picked])])
    assert "VRR, sine period 0.5 t_m, at the counting-noise ceiling" in page and "Seeds" in page
    assert "300 ± 40" in page


def test_significance_rows_name_the_figure_in_words_and_print_the_difference_with_its_error():
    rows = significance_rows([{"figure": "mass_flow_rate_kg_s", "configuration_a": "straight",
                               "configuration_b": "converging", "value_a": 0.0099, "error_a": 0.0011,
                               "value_b": 0.0123, "error_b": 0.0010, "difference": -0.0024,
                               "difference_error": 0.0015, "significance": "not significant"}])
    assert rows == [{"figure": "Flow rate (kg/s)", "configuration_a": "straight", "configuration_b": "converging",
                     "difference": -0.0024, "difference_error": 0.0015, "significance": "not significant"}]
    page = summary_html("siloflow", [("Blender: differences", "x", rows)])
    assert "−0.0024 ± 0.0015" in page or "-0.0024 ± 0.0015" in page
    assert "not significant" in page


def test_recirculation_rows_add_the_transit_times_and_seed_count_when_the_table_has_them():
    row = {"flow_pattern": "internal_flow", "layout": "blue13", "residence_time_s": 0.836,
           "residence_time_s_error": 0.013, "transit_residence_time_s": 0.436, "transit_residence_time_s_error": 0.012,
           "rtd_mean_ids_transit_s": 0.416, "rtd_mean_ids_transit_s_error": 0.011, "replicates": 3}
    (picked,) = recirculation_rows([row])
    assert picked["transit_residence_time_s"] == 0.436 and picked["rtd_mean_ids_transit_s_error"] == 0.011
    assert picked["replicates"] == 3
    page = summary_html("siloflow", [("Blending", "x", [picked])])
    assert "Hold-up residence time (stagnant zones included) (s)" in page
    assert "0.436 ± 0.012" in page and "0.416 ± 0.011" in page


def test_summary_lists_the_validation_rows_judged_against_the_study():
    findings = [{"finding": "S2", "figure": "Filling bulk density", "case": "r", "agreement": "not reproduced",
                 "scale": "at scale", "note": "S2: 564 ± 1 lies outside 618 to 627.4"}]
    sections = summary_sections({"shape": "sphere2"}, [], [], [], [], findings=findings)
    assert sections[-1].title == "Against the study's findings" and sections[-1].rows == findings
    assert "make validate" in sections[-1].explanation and sections[-1].legend
    none = summary_sections({"shape": "sphere2"}, [], [], [], [], findings=[])[-1]
    assert none.rows[0]["note"].startswith("No row of this configuration")
    assert summary_sections({"shape": "sphere2"}, [], [], [], [])[-1].title == "Settled fills"
