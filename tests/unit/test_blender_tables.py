"""Unit tests for siloflow.analysis.studies.blender.tables: rows and summaries of a hand-built blender study, the
comparison page, and gravity scaling of hand-written run summaries.

The study is built by hand from its dataclasses with round numbers; only the parts the tables and
:func:`siloflow.analysis.studies.blender.study.study_summary` read are filled (the profile behind the passage means, the
flow channel boundary and the pathline integration result are None).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from siloflow.analysis.io.tables import write_json
from siloflow.analysis.numerics.lti import VRRTable
from siloflow.analysis.numerics.rtd import RTD
from siloflow.analysis.studies.blender.comparison import BlenderMetrics
from siloflow.analysis.studies.blender.modes import ContinuousMode, DiscontinuousMode
from siloflow.analysis.studies.blender.profiles import PassageVelocities, ProfilesOverTime
from siloflow.analysis.studies.blender.study import BlenderStudy, metrics_from_summary, rtd_from_summary
from siloflow.analysis.studies.blender.tables import (
    blender_summary,
    comparison_markdown,
    gravity_rows,
    lowest_gravity_runs,
    rtd_label,
    profile_rows,
    residence_rows,
    rtd_rows,
    vrr_period_rows,
)
from siloflow.analysis.studies.blender.tracers import TracerPathlines, VirtualTracerRTD

NAN = math.nan
# RTD of 4 virtual tracers out at 0.5, 1.5, 2.5 and 3.5 s, t_m = 2 s.
RTD_CURVE = RTD(time=np.array([1.0, 3.0]), edges=np.array([0.0, 2.0, 4.0]), E=np.array([0.25, 0.25]), t_mean=2.0,
                variance=1.25, t_first=0.5, t_last=3.5, n_exited=4, n_total=4)
PROFILES = ProfilesOverTime(
    window_time=np.array([0.1, 0.3]), heights=np.array([0.05, 0.1]), x=np.array([-0.01, 0.01]),
    v_z=np.array([[[-1.0, -3.0], [-2.0, -2.0]], [[-4.0, NAN], [-5.0, -7.0]]]),
    normalised=np.array([[[0.5, 1.5], [1.0, 1.0]], [[1.0, NAN], [0.8125, 1.1875]]]),
    cross_section_mean=np.array([[-2.0, -2.0], [-4.0, -6.0]]),
)
PATHLINES = TracerPathlines(release_x=np.array([-0.02, 0.0, 0.02]), release_z=0.15,
                            residence_time=np.array([3.0, 2.5, NAN]), paths=(), pathlines=None)
CONTINUOUS = ContinuousMode(
    vrr_table=VRRTable(period_over_tm=np.array([0.5, 1.0]), period=np.array([1.0, 2.0]), vrr=np.array([16.0, 4.0]),
                       t_mean=2.0, waveform="sine", n_periods=10),
    cov_in=0.5, cov_out=np.array([0.125, 0.25]), weakest_damping_period_over_tm=1.0,
    resonant_periods_over_tm=np.array([]),
)
STUDY = BlenderStudy(
    heights={"insert outlet": 0.05},
    profiles=PROFILES,
    inlet=None,
    outlet=PassageVelocities(profile=None, passages={"interior": (0.0, 0.05), "exterior": (0.05, 0.1)},
                             mean_v_z={"interior": -0.05, "exterior": -0.04}, n_bins={"interior": 4, "exterior": 2}),
    boundary=None,
    pathlines=PATHLINES,
    rtd=VirtualTracerRTD(rtd=RTD_CURVE, release_x=np.zeros(4), release_z=np.full(4, 0.19), weights=np.ones(4),
                         residence_time=np.array([0.5, 1.5, 2.5, 3.5]), layer_bottom=0.18, layer_top=0.2),
    discontinuous=DiscontinuousMode(
        window=0.5, window_start=np.array([0.0, 0.5]), time_in_passes=np.array([0.0, 0.25]),
        first_pass=np.array([0.0, 1.0]), concentration=np.array([0.0, 1.0]), pass_mean=np.array([0.5, 0.25]),
        tracer_fraction=0.2, tracer_bottom=0.18, mean_residence_time=2.0, entry_time=np.array([0.0, 0.5]),
        entry_E=np.array([0.0, 2.0]), homogenised_after=3.0, homogenised_after_error=0.25, tolerance=0.1,
        n_not_exited=1, n_entry_not_exited=0,
    ),
    continuous=CONTINUOUS,
)
METRICS = BlenderMetrics(name="straight", mass_flow_rate=0.01, exterior_v_z=-0.04, interior_v_z=-0.05, tube_v_z=NAN,
                         rtd_mean=2.0, rtd_spread=math.sqrt(1.25) / 2.0, ts_over_td=0.5 / 3.5,
                         recirculations_to_homogenise=3.0, vrr_by_period={1.0: 4.0})
#: What of the run's case the summary holds, as the adapter passes it (the steady window a tuple, as in the case).
RUN = {"run_id": "blender_cd34", "configuration": "straight", "gravity_factor": 1.0,
       "geometry": {"z_insert_outlet": 0.04, "inlet": [0.05, 0.11], "z_tube_inlet": None}, "mode": "continuous",
       "n_clumps": 1234, "steady_window": (1.0, 2.0)}
FLOW = {"mass_flow_rate_kg_s": 0.01, "mass_flow_rate_standard_error_kg_s": 1e-4, "time_since_open_s": [0.0, 1.0],
        "discharged_mass_kg": [0.0, 0.01], "mean_v_z_m_s": [0.0, -0.05], "beverloo_ratio": 1.1}


def assert_rows(rows, columns, expected):
    """Same columns in the same order in every row, and the same values (NaN equal to NaN)."""
    assert [list(row) for row in rows] == [columns] * len(expected)
    np.testing.assert_equal(rows, [dict(zip(columns, row)) for row in expected])


# --------------------------------------------------------------------------- one run


def test_blender_summary_adds_the_case_flow_rtd_curve_and_history_to_the_study_summary():
    summary = blender_summary(FLOW, STUDY, METRICS, **RUN)
    assert list(summary)[:8] == ["run_id", "configuration", "gravity_factor", "geometry", "mode", "n_clumps",
                                 "steady_window_s", "mass_flow_rate_standard_error_kg_s"]
    assert list(summary)[-2:] == ["rtd_curve", "flow_history"]
    assert {key: summary[key] for key in list(summary)[:8]} == {
        "run_id": "blender_cd34", "configuration": "straight", "gravity_factor": 1.0,
        "geometry": RUN["geometry"], "mode": "continuous", "n_clumps": 1234, "steady_window_s": [1.0, 2.0],
        "mass_flow_rate_standard_error_kg_s": 1e-4,
    }
    assert summary["flow_history"] == {"time_since_open_s": [0.0, 1.0], "discharged_mass_kg": [0.0, 0.01],
                                       "mean_v_z_m_s": [0.0, -0.05]}
    assert summary["rtd_curve"] == {"time": [1.0, 3.0], "E": [0.25, 0.25], "edges": [0.0, 2.0, 4.0], "t_mean": 2.0,
                                    "variance": 1.25, "t_first": 0.5, "t_last": 3.5, "n_exited": 4, "n_total": 4}
    # the study summary's keys, unchanged
    assert summary["pathlines"] == {"n_released": 3, "n_not_exited": 1}
    assert summary["passages_at_insert_inlet"] is None
    assert summary["discontinuous"] == {"homogenised_after": 3.0, "pass_mean": [0.5, 0.25], "tracer_fraction": 0.2,
                                        "n_not_exited": 1}
    assert summary["metrics"]["vrr_by_period"] == {"1": 4.0}
    # the PIV figures of the vertical section and the wall layer: null unless given, else as given
    assert summary["vertical_section"] is None and summary["wall_layer"] is None
    given = blender_summary(FLOW, STUDY, METRICS, **RUN, vertical_section={"0.5": {"largest_deviation": 0.1}},
                            wall_layer={"depth_m": 0.0033})
    assert given["vertical_section"] == {"0.5": {"largest_deviation": 0.1}}
    assert given["wall_layer"] == {"depth_m": 0.0033}


def test_blender_summary_round_trips_through_json_to_the_comparison_inputs(tmp_path):
    loaded = json.loads(write_json(tmp_path / "blender.json", blender_summary(FLOW, STUDY, METRICS, **RUN)).read_text())
    back = metrics_from_summary(loaded)
    assert back.name == "straight" and back.mass_flow_rate == 0.01 and math.isnan(back.tube_v_z)
    assert back.vrr_by_period == {1.0: 4.0}
    np.testing.assert_array_equal(rtd_from_summary(loaded["rtd_curve"]).E, [0.25, 0.25])


def test_profile_rows_run_over_windows_then_heights_then_x():
    assert_rows(profile_rows(PROFILES), ["window_time_s", "height_m", "x_m", "v_z_m_s", "normalised"], [
        [0.1, 0.05, -0.01, -1.0, 0.5], [0.1, 0.05, 0.01, -3.0, 1.5],
        [0.1, 0.1, -0.01, -2.0, 1.0], [0.1, 0.1, 0.01, -2.0, 1.0],
        [0.3, 0.05, -0.01, -4.0, 1.0], [0.3, 0.05, 0.01, NAN, NAN],
        [0.3, 0.1, -0.01, -5.0, 0.8125], [0.3, 0.1, 0.01, -7.0, 1.1875],
    ])
    assert all(type(value) is float for row in profile_rows(PROFILES) for value in row.values())


def test_residence_rows_keep_the_tracers_that_did_not_exit_as_nan():
    assert_rows(residence_rows(PATHLINES), ["release_x_m", "residence_time_s"],
                [[-0.02, 3.0], [0.0, 2.5], [0.02, NAN]])


def test_rtd_rows_give_the_dimensional_and_dimensionless_curve():
    # theta = t / 2 s, E_theta = 2 s x E
    assert_rows(rtd_rows(RTD_CURVE), ["time_s", "E_per_s", "theta", "E_theta"],
                [[1.0, 0.25, 0.5, 0.5], [3.0, 0.25, 1.5, 0.5]])


def test_vrr_period_rows_give_vrr_and_outlet_cov_per_period():
    assert_rows(vrr_period_rows(CONTINUOUS), ["period_over_tm", "vrr", "cov_out"],
                [[0.5, 16.0, 0.125], [1.0, 4.0, 0.25]])


# --------------------------------------------------------------------------- comparison


def test_lowest_gravity_runs_keeps_the_order_of_the_runs_at_the_lowest_factor():
    summaries = [{"configuration": "a", "gravity_factor": 5.0}, {"configuration": "b", "gravity_factor": 1.0},
                 {"configuration": "c", "gravity_factor": 50.0}, {"configuration": "d", "gravity_factor": 1.0}]
    lowest, chosen = lowest_gravity_runs(summaries)
    assert lowest == 1.0
    assert chosen == [summaries[1], summaries[3]]
    assert lowest_gravity_runs(summaries[2:3]) == (50.0, [summaries[2]])


def test_rtd_label_names_the_run_of_a_replicated_configuration_only():
    summaries = [{"configuration": "converging", "run_id": "converging-g1-aa"},
                 {"configuration": "straight", "run_id": "straight-g1-bb"},
                 {"configuration": "converging", "run_id": "converging-g1-cc"}]
    assert [rtd_label(s, summaries) for s in summaries] == [
        "converging (converging-g1-aa)", "straight", "converging (converging-g1-cc)"]


def test_comparison_markdown_is_heading_table_and_verdict():
    rows = [{"configuration": "straight", "vrr_at_1_tm": 2.5}, {"configuration": "diverging", "vrr_at_1_tm": 0.125}]
    assert comparison_markdown(0.5, rows, "straight", 0.1) == (
        "# Insert configurations at 0.5 g\n\n"
        "| configuration | vrr_at_1_tm |\n|---|---|\n| straight | 2.5 |\n| diverging | 0.125 |\n\n"
        "Best blender: **straight** (fewest recirculations to homogenise within +-10%, ties broken by the highest "
        "VRR at the shortest period).\n"
    )


def test_comparison_markdown_prints_value_and_error_and_marks_vrrs_at_the_ceiling():
    rows = [{"configuration": "straight", "flow": 0.11682, "flow_error": 0.00213, "recirculations_to_homogenise": 4.61,
             "vrr_at_1_tm": 300.0, "vrr_at_1_tm_error": 250.0, "vrr_ceiling": 400.0, "vrr_at_1_tm_at_ceiling": True},
            {"configuration": "diverging", "flow": NAN, "flow_error": 0.1, "recirculations_to_homogenise": 5.0,
             "vrr_at_1_tm": 12.5, "vrr_at_1_tm_error": NAN, "vrr_ceiling": 400.0, "vrr_at_1_tm_at_ceiling": False}]
    assert comparison_markdown(1.0, rows, "straight", 0.1) == (
        "# Insert configurations at 1 g\n\n"
        "| configuration | flow | recirculations_to_homogenise | vrr_at_1_tm | vrr_ceiling |\n|---|---|---|---|---|\n"
        "| straight | 0.1168 ± 0.0021 | 4.61 | 300 ± 250 (at ceiling) | 400 |\n"
        "| diverging | n/a | 5 | 12.5 ± unknown | 400 |\n\n"
        "Best blender: **straight** (fewest recirculations to homogenise within +-10%, ties broken by the highest "
        "VRR at the shortest period).\n\n"
        "Figures are value ± standard error. A VRR marked (at ceiling) lies within a factor 2 of its counting-noise "
        "ceiling, so it is only a lower bound. Whether the differences between configurations exceed their "
        "uncertainty: significance.csv.\n"
    )


# --------------------------------------------------------------------------- gravity scaling


def run_summary(configuration, gravity_factor, mass_flow_rate, exterior, interior):
    """A run summary as read from JSON (NaN written as null)."""
    return {"configuration": configuration, "gravity_factor": gravity_factor,
            "metrics": {"mass_flow_rate_kg_s": mass_flow_rate, "exterior_v_z_m_s": exterior,
                        "interior_v_z_m_s": interior, "tube_v_z_m_s": None},
            "flow_history": {"time_since_open_s": [0.0, gravity_factor], "mean_v_z_m_s": [0.0, -interior]}}


SUMMARIES = [
    run_summary("C", 2.0, 1.0, -0.1, 0.5), run_summary("C", 8.0, 2.0, -0.2, 1.0),  # no 1 g run
    run_summary("A", 4.0, 2.0, None, 1.5),  # listed before its 1 g run; its exterior velocity is null
    run_summary("B", 1.0, 1.0, -0.1, 0.5),  # 1 g only
    run_summary("A", 1.0, 1.0, -0.1, 0.5),
]


def test_gravity_rows_scale_configurations_with_a_1g_run_and_skip_the_others():
    rows, curves, skipped = gravity_rows(SUMMARIES)
    # A at 4 g: mass flow rate 2 / 1 = sqrt(4) scales; interior 1.5 / 0.5 = 3 deviates by 3 / 2 - 1 = 0.5; the
    # exterior velocity (null at 4 g) is left out.
    assert_rows(rows, ["configuration", "quantity", "gravity_factor", "value", "ratio_to_1g", "expected_ratio",
                       "relative_deviation", "scales"], [
        ["A", "mass_flow_rate_kg_s", 1.0, 1.0, 1.0, 1.0, 0.0, True],
        ["A", "mass_flow_rate_kg_s", 4.0, 2.0, 2.0, 2.0, 0.0, True],
        ["A", "interior_v_z_m_s", 1.0, 0.5, 1.0, 1.0, 0.0, True],
        ["A", "interior_v_z_m_s", 4.0, 1.5, 3.0, 2.0, 0.5, False],
    ])
    assert curves == [("A", 1.0, [0.0, 1.0], [0.0, -0.5]), ("A", 4.0, [0.0, 4.0], [0.0, -1.5])]
    assert skipped == [("B", [1.0]), ("C", [2.0, 8.0])]


def test_gravity_rows_take_the_mean_of_a_replicated_factor():
    """The reference at 1 g runs with seeds: their mean is the 1 g value, the first seed draws the curve."""
    replicated = [run_summary("A", 1.0, 0.9, -0.1, 0.4), run_summary("A", 4.0, 2.0, -0.2, 1.0),
                  run_summary("A", 1.0, 1.1, -0.1, 0.6)]
    rows, curves, skipped = gravity_rows(replicated)
    assert [(row["quantity"], row["gravity_factor"], row["value"]) for row in rows] == [
        ("mass_flow_rate_kg_s", 1.0, pytest.approx(1.0)), ("mass_flow_rate_kg_s", 4.0, 2.0),
        ("exterior_v_z_m_s", 1.0, pytest.approx(-0.1)), ("exterior_v_z_m_s", 4.0, -0.2),
        ("interior_v_z_m_s", 1.0, pytest.approx(0.5)), ("interior_v_z_m_s", 4.0, 1.0)]
    assert all(row["scales"] for row in rows)
    assert curves == [("A", 1.0, [0.0, 1.0], [0.0, -0.4]), ("A", 4.0, [0.0, 4.0], [0.0, -1.0])] and skipped == []


def test_gravity_rows_pass_the_tolerance_on():
    rows, _, _ = gravity_rows(SUMMARIES, tolerance=0.6)
    assert [row["scales"] for row in rows] == [True, True, True, True]


def test_gravity_rows_without_a_scalable_configuration_are_empty():
    assert gravity_rows(SUMMARIES[:2] + SUMMARIES[3:4]) == ([], [], [("B", [1.0]), ("C", [2.0, 8.0])])

