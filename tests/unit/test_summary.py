"""The report's summary page."""

from analysis.report.summary import calibration_rows, format_cell, summary_html


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
