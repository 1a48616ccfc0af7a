"""The report's summary page."""

from analysis.io.tables import read_table, write_flow_table
from analysis.report.summary import SILO_FLOW_COLUMNS, calibration_rows, format_cell, summary_html, summary_sections


def test_cells_are_formatted_and_escaped():
    assert format_cell(0.123456) == "0.1235"
    assert format_cell(float("nan")) == "n/a" and format_cell(None) == "n/a"
    assert format_cell(True) == "yes" and format_cell(3) == "3"
    assert format_cell("<b>") == "&lt;b&gt;"


def test_summary_page_has_one_table_per_section_with_the_union_of_columns():
    page = summary_html("siloflow", [
        ("Calibration", "chosen parameters", [{"parameter": "mu", "value": 0.27}]),
        ("Silo", "flow", [{"run": "a", "rate": 0.1}, {"run": "b", "error": 0.05}]),
        ("Blender", "figures of merit", []),
    ])
    assert page.startswith("<!DOCTYPE html>") and page.count("<table>") == 2
    assert "<th>run</th><th>rate</th><th>error</th>" in page
    assert "<td>b</td><td>n/a</td><td>0.05</td>" in page
    assert "Not run in this configuration" in page


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


def test_summary_sections_take_the_columns_each_stage_shows():
    flow = {"run_id": "r", "n_clumps": 10, "filling_bulk_density_kg_m3": 600.0, "mass_flow_rate_kg_s": 0.1,
            "beverloo_mass_flow_rate_kg_s": 0.2, "beverloo_ratio": 0.5, "not_shown": 1}
    sections = summary_sections({"shape": "sphere2", "particle_particle": {"sliding_friction": 0.3}}, [flow], [],
                                [{"flow_pattern": "internal_flow", "layout": "blue13", "vrr_nr1": 2.0, "extra": 1}],
                                [{"configuration": "straight"}])
    titles = [title for title, _, _ in sections]
    assert titles == ["Calibration", "Silo validation", "Silo against measurements", "Blending", "Blender"]
    assert sections[0][2] == [{"contact": "particle-particle", "sliding_friction": 0.3}]
    assert sections[1][2] == [{key: flow[key] for key in SILO_FLOW_COLUMNS}]
    assert sections[2][2] == []
    assert sections[3][2] == [{"flow_pattern": "internal_flow", "layout": "blue13", "residence_time_s": None,
                               "t_s_over_t_d": None, "vrr_nr1": 2.0, "vrr_nr2": None, "vrr_nr3": None, "vrr_nr4": None,
                               "prediction_rms_error": None}]
    assert sections[4][2] == [{"configuration": "straight"}]
    assert "sphere2" in sections[0][1]


def test_tables_read_back_numbers_text_and_empty_cells(tmp_path):
    path = write_flow_table(tmp_path / "t.csv", [{"a": 1.5, "b": "x", "c": None}])
    assert read_table(path) == [{"a": 1.5, "b": "x", "c": None}]
