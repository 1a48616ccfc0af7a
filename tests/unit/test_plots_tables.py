"""Unit tests for the discharge plot (siloflow.analysis.studies.silo_flat.plots: the PNG and the plotted data) and
siloflow.analysis.io.tables (files under tmp_path only)."""

from __future__ import annotations

import csv
import json
import math

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from siloflow.analysis.numerics.flow import DischargeHistory, discharged_mass_history, steady_flow_rate
from siloflow.analysis.studies.silo_flat.plots import plot_discharge
from siloflow.analysis.io.tables import markdown_table, write_discharge_history_csv, write_flow_table, write_json, write_text

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _history():
    time = np.linspace(0.0, 1.0, 101)
    mass_in_silo = 5.0 - 2.5 * np.clip(time - 0.1, 0.0, 0.7)
    history = discharged_mass_history(time + 3.0, mass_in_silo)
    fit = steady_flow_rate(history.time, history.discharged_mass)
    return history, fit


def _only_file(folder, name):
    assert sorted(p.name for p in folder.iterdir()) == [name], "temporary files left behind"


@pytest.mark.parametrize("beverloo_rate", [2.7, None])
def test_plot_discharge_draws_the_history_the_fit_and_the_beverloo_slope(tmp_path, beverloo_rate):
    history, fit = _history()
    target = tmp_path / "plots" / "discharge.png"
    figure = plot_discharge(history, fit, beverloo_rate, target, "flat-bottom silo")
    assert target.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(target.parent, "discharge.png")
    assert not plt.fignum_exists(figure.number), "the writer closes its figure"
    (axes,) = figure.axes
    assert (axes.get_title(), axes.get_xlabel(), axes.get_ylabel()) == (
        "flat-bottom silo", "time since opening [s]", "discharged mass [kg]")
    lines = {line.get_label(): line for line in axes.get_lines()}
    # The dots are the synthetic history: nothing until 0.1 s, then 2.5 kg/s for 0.7 s.
    time = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(lines["DEM discharged mass"].get_xydata(),
                               np.column_stack([time, 2.5 * np.clip(time - 0.1, 0.0, 0.7)]), rtol=0, atol=1e-12)
    assert fit.mass_flow_rate == pytest.approx(2.5, rel=1e-12)
    fit_line = lines[f"fit: {fit.mass_flow_rate:.4g} ± {fit.standard_error:.2g} kg/s"]
    window = [fit.t_start, fit.t_end]
    np.testing.assert_allclose(fit_line.get_xydata(), np.column_stack([window, 2.5 * (np.array(window) - 0.1)]),
                               rtol=1e-12)
    (span,) = [patch for patch in axes.patches if patch.get_label() == "steady window"]
    assert (span.get_x(), span.get_x() + span.get_width()) == pytest.approx(window, rel=1e-15)
    if beverloo_rate is None:
        assert len(lines) == 2
    else:
        beverloo = lines["Beverloo: 2.7 kg/s"]
        middle = 0.5 * (fit.t_start + fit.t_end)
        np.testing.assert_allclose(beverloo.get_xydata(), np.column_stack(
            [window, 2.5 * (middle - 0.1) + 2.7 * (np.array(window) - middle)]), rtol=1e-12)
    plt.close(figure)


def test_write_flow_table_round_trip(tmp_path):
    rows = [
        {"case": "sphere2", "mass_flow_rate_kg_s": 0.123456789012345, "n_points": 40, "bulk_density": 667.1},
        {"case": "sphere", "mass_flow_rate_kg_s": 1e-7, "n_points": 3, "bulk_density": np.float64(650.25)},
    ]
    target = tmp_path / "metrics" / "flow.csv"
    write_flow_table(target, rows)
    table = pd.read_csv(target)
    assert list(table.columns) == ["case", "mass_flow_rate_kg_s", "n_points", "bulk_density"]
    expected = pd.DataFrame(rows).astype({"bulk_density": float})
    pd.testing.assert_frame_equal(table, expected)
    _only_file(target.parent, "flow.csv")


def test_write_flow_table_column_order_from_first_row(tmp_path):
    rows = [{"b": 1, "a": 2}, {"a": 3, "b": 4, "c": 5}]
    target = tmp_path / "t.csv"
    write_flow_table(target, rows)
    with open(target, newline="") as stream:
        records = list(csv.DictReader(stream))
    assert list(records[0].keys()) == ["b", "a", "c"]
    assert records == [{"b": "1", "a": "2", "c": ""}, {"b": "4", "a": "3", "c": "5"}]


def test_write_flow_table_rejects_no_rows(tmp_path):
    with pytest.raises(ValueError, match="rows"):
        write_flow_table(tmp_path / "t.csv", [])
    assert list(tmp_path.iterdir()) == []


def test_write_json_sorted_plain_numbers(tmp_path):
    target = tmp_path / "flow.json"
    write_json(target, {"zeta": np.float64(1.25), "alpha": np.int64(3), "rates": np.array([0.5, 1.5]), "nan": math.nan})
    text = target.read_text()
    assert json.loads(text) == {"alpha": 3, "nan": None, "rates": [0.5, 1.5], "zeta": 1.25}
    assert text.index('"alpha"') < text.index('"nan"') < text.index('"rates"') < text.index('"zeta"')
    assert "np.float64" not in text
    _only_file(tmp_path, "flow.json")


def test_write_json_dataclass(tmp_path):
    _, fit = _history()
    target = tmp_path / "fit.json"
    write_json(target, fit)
    loaded = json.loads(target.read_text())
    assert loaded["mass_flow_rate"] == fit.mass_flow_rate
    assert loaded["n_points"] == fit.n_points


def test_failed_write_keeps_old_file_and_leaves_no_temp(tmp_path):
    target = tmp_path / "flow.json"
    write_json(target, {"a": 1})
    with pytest.raises(TypeError):
        write_json(target, {"a": object()})
    assert json.loads(target.read_text()) == {"a": 1}
    _only_file(tmp_path, "flow.json")


def test_write_discharge_history_csv_round_trip(tmp_path):
    history = DischargeHistory(time=np.array([0.0, 0.005, 0.01]), discharged_mass=np.array([0.0, 1 / 3, 0.7]))
    target = tmp_path / "history.csv"
    write_discharge_history_csv(target, history)
    table = pd.read_csv(target)
    assert list(table.columns) == ["time_s", "discharged_mass_kg"]
    np.testing.assert_array_equal(table["time_s"].to_numpy(), history.time)
    np.testing.assert_array_equal(table["discharged_mass_kg"].to_numpy(), history.discharged_mass)
    _only_file(tmp_path, "history.csv")


def test_markdown_table_writes_columns_of_the_first_row_with_significant_digits(tmp_path):
    text = markdown_table([{"name": "a", "rate": 0.0123456, "n": 3}, {"name": "b", "rate": float("nan")}], digits=3)
    assert text == "| name | rate | n |\n|---|---|---|\n| a | 0.0123 | 3 |\n| b | nan |  |\n"
    path = write_text(tmp_path / "table.md", text)
    assert path.read_text() == text
    with pytest.raises(ValueError, match="at least one row"):
        markdown_table([])
