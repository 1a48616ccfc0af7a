"""The validation table's rows and verdicts, on hand-built stage results with exact answers."""

import math

import pytest

from siloflow.analysis.report.summary import summary_html
from siloflow.analysis.studies.validation.blending import blender_rows, gravity_rows, recirculation_rows, rtd_peak
from siloflow.analysis.studies.validation.calibration import calibration_rows
from siloflow.analysis.studies.validation.rows import NO, UNKNOWN, YES, Criteria, precise, ratio, resolved, row, verdict
from siloflow.analysis.studies.validation.silo import SiloRun, front_wall_series_rows, silo_rows
from siloflow.analysis.studies.validation.table import page_sections, scale_limits
from siloflow.engines.config import validate_config

CRITERIA = Criteria()


def test_precise_judges_the_relative_error_against_its_limit_and_quotes_both():
    assert precise(0.409, 0.14, CRITERIA) == (False, "relative error 34 % (at most 25 %)")
    assert precise(-2.0, 0.5, CRITERIA) == (True, "relative error 25 % (at most 25 %)")
    assert precise(0.0, 0.1, CRITERIA) == (False, "relative error unbounded (at most 25 %)")
    assert precise(1.0, math.nan, CRITERIA) == (None, "relative error not known (at most 25 %)")
    assert precise(math.nan, 0.1, Criteria(max_relative_error=0.1)) == (None, "relative error not known (at most 10 %)")


def test_criteria_come_from_the_config_section_with_their_defaults():
    assert Criteria.from_config(validate_config({})["validation"]) == CRITERIA


def test_verdict_ratio_and_resolution():
    assert verdict(True, True) == YES and verdict(True, False, None) == NO and verdict(True, None) == UNKNOWN
    value, error = ratio(3.0, 0.3, 2.0, 0.4)
    assert value == 1.5 and error == pytest.approx(1.5 * math.hypot(0.1, 0.2), rel=1e-14)
    assert math.isnan(ratio(1.0, 0.1, 0.0, 0.1)[0])
    assert resolved(0.5, 0.2, 2.0) is True and resolved(0.4, 0.2, 2.0) is False and resolved(1.0, math.nan, 2.0) is None
    with pytest.raises(ValueError, match="shows must be"):
        row("g", "f", "c", 1.0, 0.1, "-", "", "maybe", "")


# --------------------------------------------------------------------------- calibration


def _bulk(shape, mu, bulk, error, lid="rigid", restitution=0.1, blocked=False, test="internal", rolling=0.0,
          window="steady", speed=0.03):
    return {"shape": shape, "test": test, "lid": lid, "rolling_friction": rolling, "restitution": restitution,
            "rotation_blocked": blocked, "particle_friction": mu, "bulk_friction": bulk, "bulk_friction_error": error,
            "window_method": window, "shear_velocity": speed}


PARAMETERS = {"shape": "sphere2", "rolling_friction": 0.0, "tolerance_deg": 1.0, "targets_deg": {"internal": 30.0},
              "particle_particle": {"sliding_friction": 0.3, "sliding_friction_error": 0.01, "lower": 0.25,
                                    "upper": 0.35, "band_clipped": False}}


def test_a_curve_that_rises_then_levels_off_in_a_wide_cell_shows_where_bulk_friction_stops_rising():
    rows = [_bulk("sphere2", 0.1, 0.40, 0.01), _bulk("sphere2", 0.3, 0.55, 0.01), _bulk("sphere2", 0.5, 0.56, 0.01),
            # a shape that still rises, and a lid comparison: servo - rigid = +0.05 and +0.03 (mean 0.04)
            _bulk("sphere", 0.1, 0.30, 0.01), _bulk("sphere", 0.3, 0.40, 0.01), _bulk("sphere", 0.5, 0.50, 0.01),
            _bulk("sphere2", 0.1, 0.45, 0.01, lid="servo"), _bulk("sphere2", 0.3, 0.58, 0.01, lid="servo"),
            # restitution 0.6 at 0.3: 0.55 -> 0.552 (not resolved, precise): insensitive
            _bulk("sphere2", 0.3, 0.552, 0.01, restitution=0.6),
            # half the shear speed at 0.3: 0.55 -> 0.58 (resolved at 2 standard errors: 0.03 > 2 x 0.01414)
            _bulk("sphere2", 0.3, 0.58, 0.01, speed=0.015)]
    diameters = {"sphere": 0.0038, "sphere2": 0.004}
    table = calibration_rows(rows, PARAMETERS, 0.095, diameters, 0.1, "rigid", 0.03, CRITERIA)
    curves = {r["case"]: r for r in table if r["figure"].startswith("Bulk friction at")}
    levelled = curves["sphere2, internal, rolling 0"]
    assert levelled["value"] == 0.56 and levelled["value_error"] == 0.01 and levelled["scale_shows"] == YES
    assert "23.8 particle diameters" in levelled["evidence"] and "stops rising" in levelled["evidence"]
    assert curves["sphere, internal, rolling 0"]["scale_shows"] == NO
    (lid,) = [r for r in table if "servo lid - rigid lid" in r["figure"]]
    assert lid["value"] == pytest.approx(0.04, abs=1e-12)
    assert lid["value_error"] == pytest.approx(math.sqrt(4 * 1e-4) / 2, rel=1e-12) and lid["scale_shows"] == YES
    (restitution,) = [r for r in table if "restitution 0.6 - 0.1" in r["figure"]]
    assert restitution["value"] == pytest.approx(0.002, abs=1e-12) and restitution["scale_shows"] == YES
    # sqrt(2) x 0.01 against the level 0.55: small enough to have seen a change
    assert restitution["evidence"].endswith(
        "not resolved at 2 standard errors; its error against the bulk friction 0.55: relative error 2.6 % (at most 25 %)")
    # the speed point stays off the chart's curve; its difference is resolved, so the speed independence is not shown
    (speed,) = [r for r in table if "shear velocity 0.015 - 0.03 m/s" in r["figure"]]
    assert speed["value"] == pytest.approx(0.03, abs=1e-12) and speed["scale_shows"] == NO
    assert speed["study_value"] == "independent of the shear speed (quasi-static)"
    (calibrated,) = [r for r in table if r["figure"].startswith("Calibrated")]
    assert calibrated["value"] == 0.3 and calibrated["study_value"] == "0.35" and calibrated["scale_shows"] == YES
    # the same curves in a 40 mm cell: 10 diameters, below 20
    small = calibration_rows(rows, PARAMETERS, 0.04, diameters, 0.1, "rigid", 0.03, CRITERIA)
    assert all(r["scale_shows"] == NO for r in small if r["figure"].startswith("Bulk friction at"))


def test_a_row_whose_shear_tests_did_not_all_reach_a_steady_window_does_not_show_its_physics():
    """A bulk friction averaged over the second half of a shear that never reached a plateau is a transient."""
    steady = [_bulk("sphere2", 0.1, 0.40, 0.01), _bulk("sphere2", 0.3, 0.55, 0.01), _bulk("sphere2", 0.5, 0.56, 0.01),
              _bulk("sphere2", 0.3, 0.60, 0.01, lid="servo")]
    transient = [*steady[:2], _bulk("sphere2", 0.5, 0.56, 0.01, window="second half"), steady[3]]
    unsaid = [*steady[:2], _bulk("sphere2", 0.5, 0.56, 0.01, window=""), steady[3]]
    judged = {}
    for name, rows in (("steady", steady), ("transient", transient), ("unsaid", unsaid)):
        table = calibration_rows(rows, PARAMETERS, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA)
        judged[name] = {r["figure"].split(" (")[0].split(",")[0]: r for r in table}
    curve, lid, chosen = "Bulk friction at particle friction 0.5", "Bulk friction", "Calibrated particle sliding friction"
    assert [judged["steady"][f]["scale_shows"] for f in (curve, lid, chosen)] == [YES, YES, YES]
    assert "steady shear window in 3 of 3 shear tests" in judged["steady"][curve]["evidence"]
    # the lid comparison's shear tests: both lids at 0.3, the one particle friction it pairs
    assert "steady shear window in 2 of 2 shear tests" in judged["steady"][lid]["evidence"]
    # the transient at 0.5 is the curve's and the calibration's, not the lid comparison's, which pairs 0.3 only
    assert [judged["transient"][f]["scale_shows"] for f in (curve, lid, chosen)] == [NO, YES, NO]
    assert "steady shear window in 2 of 2 shear tests" in judged["transient"][lid]["evidence"]
    transient_pair = [*steady[:3], _bulk("sphere2", 0.3, 0.60, 0.01, lid="servo", window="second half")]
    table = calibration_rows(transient_pair, PARAMETERS, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA)
    (paired,) = [r for r in table if r["figure"].startswith("Bulk friction, servo lid")]
    assert paired["scale_shows"] == NO
    assert "steady shear window in 1 of 2 shear tests (the others a transient)" in paired["evidence"]
    assert "steady shear window in 2 of 3 shear tests (the others a transient)" in judged["transient"][curve]["evidence"]
    assert [judged["unsaid"][f]["scale_shows"] for f in (curve, lid, chosen)] == [UNKNOWN, YES, UNKNOWN]
    assert "(the others do not say)" in judged["unsaid"][chosen]["evidence"]


def test_a_calibrated_coefficient_is_judged_on_the_points_its_band_lies_between_on_its_own_wall_curve():
    """The particle-particle coefficient read between 0.232 and 0.284 rests on the steady points at 0.1 and 0.3, not on
    the transients at 0.5 and 0.8; the particle-aluminium one is read from the wall test of aluminium."""
    internal = [_bulk("sphere2", 0.1, 0.44, 0.004, rolling=0.1), _bulk("sphere2", 0.3, 0.62, 0.006, rolling=0.1),
                _bulk("sphere2", 0.5, 0.73, 0.01, rolling=0.1, window="second half"),
                _bulk("sphere2", 0.8, 0.86, 0.02, rolling=0.1, window="second half")]
    wall = [{**_bulk("sphere2", mu, bulk, 0.002, test="wall", rolling=0.1), "wall_material": "aluminium"}
            for mu, bulk in ((0.1, 0.099), (0.3, 0.299), (0.5, 0.445))]
    parameters = {"shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0,
                  "targets_deg": {"internal": 30.0, "aluminium": 9.5},
                  "particle_particle": {"sliding_friction": 0.258, "sliding_friction_error": 0.014, "lower": 0.232,
                                        "upper": 0.284, "band_clipped": False},
                  "particle_wall": {"aluminium": {"sliding_friction": 0.170, "sliding_friction_error": 0.013,
                                                  "lower": 0.152, "upper": 0.188, "band_clipped": False}}}
    table = calibration_rows(internal + wall, parameters, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA,
                             sections=("calibrated",))
    chosen = {r["figure"]: r for r in table}
    particle = chosen["Calibrated particle sliding friction (particle-particle)"]
    aluminium = chosen["Calibrated particle sliding friction (particle-aluminium)"]
    assert particle["scale_shows"] == YES and "steady shear window in 2 of 2 shear tests" in particle["evidence"]
    assert aluminium["scale_shows"] == YES and "steady shear window in 2 of 2 shear tests" in aluminium["evidence"]
    # a band reaching past the steady points rests on the transient beyond them
    wide = {**parameters, "particle_particle": {**parameters["particle_particle"], "upper": 0.35}}
    (row_wide,) = [r for r in calibration_rows(internal + wall, wide, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03,
                                               CRITERIA, sections=("calibrated",)) if "particle-particle" in r["figure"]]
    assert row_wide["scale_shows"] == NO and "steady shear window in 2 of 3 shear tests" in row_wide["evidence"]


def test_an_unreachable_target_gives_the_chart_s_nearest_angle_and_whether_the_gap_exceeds_its_error():
    """A curve that levels off at 0.56 (29.25 deg) never reaches the 30 deg target; a wall curve that starts at 0.299
    (16.65 deg) lies above its 9.5 deg target. Each gives its nearest end in degrees against the target."""
    internal = [_bulk("sphere2", 0.1, 0.44, 0.004, rolling=0.1), _bulk("sphere2", 0.3, 0.52, 0.004, rolling=0.1),
                _bulk("sphere2", 0.5, 0.55, 0.005, rolling=0.1), _bulk("sphere2", 0.8, 0.56, 0.005, rolling=0.1)]
    wall = [{**_bulk("sphere2", mu, bulk, 0.002, test="wall", rolling=0.1, window=window), "wall_material": "aluminium"}
            for mu, bulk, window in ((0.3, 0.299, "steady"), (0.5, 0.44, "second half"))]
    parameters = {"shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0,
                  "targets_deg": {"internal": 30.0, "aluminium": 9.5}, "particle_wall": {},
                  "unreachable": {"internal": "internal 30.0 deg is unreachable", "aluminium": "aluminium unreachable"}}
    table = calibration_rows(internal + wall, parameters, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA,
                             sections=("calibrated",))
    rows = {r["figure"]: r for r in table}
    assert sorted(rows) == ["Bulk friction angle nearest the unreachable target (particle-aluminium)",
                            "Bulk friction angle nearest the unreachable target (particle-particle)"]
    top = rows["Bulk friction angle nearest the unreachable target (particle-particle)"]
    angle, error = math.degrees(math.atan(0.56)), math.degrees(0.005 / (1.0 + 0.56 ** 2))
    assert top["value"] == pytest.approx(angle, rel=1e-15) and top["value_error"] == pytest.approx(error, rel=1e-15)
    assert top["unit"] == "deg" and top["study_value"] == "30 deg measured; particle friction 0.35"
    # 30 - 29.249 = 0.751 deg against 2 x 0.218 deg: resolved, on steady points in a wide cell
    assert top["scale_shows"] == YES and "internal 30.0 deg is unreachable" in top["evidence"]
    assert "at particle friction 0.8, lies 0.751 ± 0.22 deg below the target: resolved" in top["evidence"]
    low = rows["Bulk friction angle nearest the unreachable target (particle-aluminium)"]
    assert low["value"] == pytest.approx(math.degrees(math.atan(0.299)), rel=1e-15)
    # judged on its two lowest points, one of them a transient
    assert low["scale_shows"] == NO and "lowest point, at particle friction 0.3" in low["evidence"]
    assert "steady shear window in 1 of 2 shear tests" in low["evidence"]
    assert f"lies {low['value'] - 9.5:.3g} ± " in low["evidence"] and "deg above the target" in low["evidence"]


def test_a_curve_that_falls_at_its_end_has_stopped_rising():
    """The wall test's bulk friction past its maximum (0.445 at 0.5, 0.325 at 0.8): the last step is a resolved fall,
    not a rise, so the curve shows where it stops rising."""
    rows = [{**_bulk("sphere2", mu, bulk, 0.002, test="wall", rolling=0.1), "wall_material": "aluminium"}
            for mu, bulk in ((0.1, 0.099), (0.3, 0.299), (0.5, 0.445), (0.8, 0.325))]
    (curve,) = calibration_rows(rows, None, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA,
                                sections=("curves",))
    assert curve["scale_shows"] == YES
    assert curve["evidence"].endswith("last step -0.12 ± 0.0028: bulk friction stops rising and falls at its end "
                                      "within the swept range")


def test_a_curve_of_two_points_cannot_show_where_it_stops_rising():
    rows = [_bulk("sphere2", 0.1, 0.40, 0.01), _bulk("sphere2", 0.3, 0.55, 0.01)]
    (curve, _) = calibration_rows(rows, PARAMETERS, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA)
    assert curve["scale_shows"] == NO and "fewer than three points" in curve["evidence"]


# --------------------------------------------------------------------------- flat-bottom silo


def _silo(depth=0.04, problems=(), index=(0.5, 0.02), run_id="base"):
    case = {"run_id": run_id, "depth_m": depth, "width_m": 0.15, "outlet_width_m": 0.04,
            "equivalent_diameter_m": 0.004}
    flow = {"filling_bulk_density_kg_m3": 650.0, "filling_bulk_density_kg_m3_error": 2.0,
            "mass_flow_rate_kg_s": 0.3, "mass_flow_rate_kg_s_error": 0.006, "beverloo_mass_flow_rate_kg_s": 0.25,
            "beverloo_ratio": 1.2, "beverloo_ratio_error": 0.03,
            "beverloo": {"discharge_coefficient": 0.58, "shape_coefficient": 1.5}}
    fields = {"flow_pattern_index": {"0.02": 0.1, "0.04": index[0]}, "flow_pattern_index_error": {"0.02": 0.01, "0.04": index[1]}}
    balance = {"support_ratio": 0.999, "problems": list(problems)}
    return SiloRun(case, flow, fields, balance,
                   janssen=[{"depth_below_surface_m": 0.05, "sigma_v_dem_Pa": 300.0, "sigma_v_dem_Pa_error": 6.0,
                             "sigma_v_janssen_Pa": 320.0, "hydrostatic_pa": 400.0, "hydrostatic_pa_error": 0.0},
                            {"depth_below_surface_m": 0.01, "sigma_v_dem_Pa": 90.0, "sigma_v_dem_Pa_error": 6.0,
                             "sigma_v_janssen_Pa": 90.0, "hydrostatic_pa": 90.0, "hydrostatic_pa_error": 0.0}],
                   kinematic=[{"z_m": 0.02, "B_m": 0.008, "B_m_error": 0.0004, "batches": 8}],
                   boundary=[{"z_m": 0.02, "fraction": 0.05, "x_left_m": -0.07, "x_right_m": 0.07,
                              "x_left_m_error": 0.001, "x_right_m_error": 0.001},
                             {"z_m": 0.02, "fraction": 0.1, "x_left_m": -0.03, "x_right_m": 0.05,
                              "x_left_m_error": 0.003, "x_right_m_error": 0.004}])


def test_silo_rows_give_the_figures_with_their_errors_and_judge_depth_and_balance():
    table = {r["figure"]: r for r in silo_rows(_silo(), CRITERIA)}
    assert table["Filling bulk density"]["value"] == 650.0 and table["Filling bulk density"]["scale_shows"] == YES
    coefficient = table["Beverloo discharge coefficient C (k = 1.5)"]
    assert coefficient["value"] == pytest.approx(0.58 * 1.2) and coefficient["value_error"] == pytest.approx(0.58 * 0.03)
    stress = table["Vertical stress / hydrostatic, 50 mm below the surface"]
    assert stress["value"] == 0.75 and stress["value_error"] == pytest.approx(0.015) and stress["scale_shows"] == YES
    assert table["Vertical stress / Janssen, 50 mm below the surface"]["value"] == pytest.approx(300.0 / 320.0)
    channel = table["Flow channel half-width (0.1 of centreline v_z) at z = 20 mm"]
    assert channel["value"] == pytest.approx(0.04) and channel["value_error"] == pytest.approx(0.0025)
    assert channel["scale_shows"] == YES
    assert table["Kinematic constant B at z = 20 mm"]["scale_shows"] == YES
    # 12 mm deep (3 diameters) and a fill that fails its balance: nothing shown
    shallow = silo_rows(_silo(depth=0.012, problems=["planes"]), CRITERIA)
    assert all(r["scale_shows"] == NO for r in shallow)
    assert "3.0 particle diameters" in shallow[0]["evidence"] and "planes" in shallow[0]["evidence"]


def test_front_wall_series_reports_the_index_and_its_change_across_the_walled_runs():
    series = [("mu_fw=0.2", _silo(index=(0.5, 0.02))), ("mu_fw=0", _silo(index=(0.8, 0.03))),
              ("mu_fw=1", _silo(index=(0.3, 0.04))), ("periodic", _silo(index=(0.9, 0.02)))]
    rows = front_wall_series_rows(series, 0.045, CRITERIA)
    assert [r["value"] for r in rows[:4]] == [0.5, 0.8, 0.3, 0.9]
    assert rows[0]["figure"] == "Flow-pattern index (wall / centreline v_z) at z = 40 mm"
    change = rows[-1]
    assert change["figure"] == "Flow-pattern index, front-wall friction 1 - 0"
    assert change["value"] == pytest.approx(-0.5) and change["value_error"] == pytest.approx(0.05)
    assert change["scale_shows"] == YES


# --------------------------------------------------------------------------- blending


def test_rtd_peak_is_the_largest_bin_over_the_mean_with_bin_and_mean_errors():
    theta, error = rtd_peak([0.5, 1.5, 2.5, 3.5], [0.1, 0.3, 0.2, 0.1], 2.0, 0.1)
    assert theta == 0.75
    assert error == pytest.approx(0.75 * math.hypot(1.0 / math.sqrt(12.0) / 1.5, 0.05), rel=1e-14)


def test_recirculation_rows_judge_the_vrr_against_the_window_ceiling_and_resolve_the_density_drop():
    case = {"depth_m": 0.04, "equivalent_diameter_m": 0.004}
    summary = {
        "flow_pattern": "internal_flow", "clumps_per_window": 100.0, "vrr_sampling_limit": 100.0,
        "layouts": {"blue13": {"blue_fraction": 0.13, "sublayers": 1, "vrr_by_recirculation": [2.0, 20.0, 120.0],
                               "vrr_by_recirculation_error": [0.5, 5.0, 30.0], "vrr_at_ceiling": [False, False, True]},
                    "blue50_5layers": {"blue_fraction": 0.5, "sublayers": 5, "vrr_by_recirculation": [30.0, 150.0],
                                       "vrr_by_recirculation_error": [8.0, 40.0], "vrr_at_ceiling": [False, True]}},
        "rtd_particle_ids": {"t_mean_s": 2.0, "t_mean_s_error": 0.1, "n_tracer": 200, "t_s_over_t_d": 0.25,
                             "t_s_over_t_d_error": 0.01},
        "bulk_density_drop": 0.06, "bulk_density_drop_error": 0.002, "bulk_density_slab_m": [0.012, 0.036],
        "settled_bulk_density_kg_m3": 600.0, "flowing_bulk_density_kg_m3": 564.0,
        "flowing_bulk_density_kg_m3_error": 1.2,
    }
    rtd = [{"method": "particle_ids", "time_s": t, "E_per_s": e} for t, e in ((0.5, 0.1), (1.5, 0.3), (2.5, 0.2))]
    table = recirculation_rows(case, summary, rtd, CRITERIA)
    vrr13, vrr5 = table[0], table[1]
    assert vrr13["value"] == 20.0 and vrr13["scale_shows"] == YES
    assert vrr5["value"] == 150.0 and vrr5["scale_shows"] == NO and "(ceiling)" in vrr5["evidence"]
    peak, ts_td, drop = table[2], table[3], table[4]
    assert peak["value"] == 0.75 and ts_td["value"] == 0.25
    # 0.01 / 0.25: the figure that decides its verdict is in its evidence
    assert ts_td["scale_shows"] == YES and ts_td["evidence"].endswith("200 tracer clumps; relative error 4 % (at most 25 %)")
    assert drop["value"] == 0.06 and drop["value_error"] == 0.002 and drop["scale_shows"] == YES
    assert len(table) == 5


def _blender(configuration, exterior, tube, factor=1.0, flow=0.01):
    metrics = {"exterior_v_z_m_s": exterior, "exterior_v_z_m_s_error": 0.0, "interior_v_z_m_s": -2.0,
               "interior_v_z_m_s_error": 0.0, "tube_v_z_m_s": tube, "tube_v_z_m_s_error": 0.0,
               "mass_flow_rate_kg_s": flow, "mass_flow_rate_kg_s_error": 0.0001, "rtd_mean_s": 5.0,
               "rtd_mean_s_error": 0.2, "recirculations_to_homogenise": 3.0, "recirculations_to_homogenise_error": 0.5}
    return {"configuration": configuration, "gravity_factor": factor, "metrics": metrics, "n_clumps": 1000,
            "geometry": {"clear_widths": {"exterior annulus": 0.05, "interior annulus": 0.02, "tube": 0.02}}}


def test_blender_rows_normalise_by_the_width_weighted_cross_section_and_judge_mass_flow_on_the_chosen_insert():
    case = {"depth_m": 0.0125, "equivalent_diameter_m": 0.0033}
    summaries = [_blender("converging", -1.0, -3.0), _blender("diverging", -0.5, -3.0)]
    rows = blender_rows(summaries, [case, case], CRITERIA)
    converging = {r["figure"]: r for r in rows if r["case"] == "converging"}
    # mean = (2 * 0.05 * -1 + 2 * 0.02 * -2 + 0.02 * -3) / 0.16 = -1.5
    assert converging["Exterior annulus v_z / cross-section mean"]["value"] == pytest.approx(2.0 / 3.0)
    assert converging["Tube v_z / cross-section mean"]["value"] == pytest.approx(2.0)
    mass_flow = converging["Exterior annulus / tube v_z (mass flow of the insert)"]
    assert mass_flow["value"] == pytest.approx(1.0 / 3.0) and mass_flow["scale_shows"] == NO
    assert all(r["scale_shows"] == NO for r in rows)  # the converging insert is not in mass flow
    in_mass_flow = blender_rows([_blender("converging", -2.0, -3.0)], [case], CRITERIA)
    assert {r["scale_shows"] for r in in_mass_flow} == {YES}


def test_gravity_rows_divide_the_ratio_to_1_g_by_sqrt_g():
    summaries = [_blender("converging", -1.0, -3.0), _blender("converging", -math.sqrt(5.0), -3.0 * math.sqrt(5.0),
                                                               factor=5.0, flow=0.01 * math.sqrt(5.0) * 1.1)]
    rows = {r["figure"].split(" at ")[0]: r for r in gravity_rows(summaries, CRITERIA)}
    assert rows["Tube velocity"]["value"] == pytest.approx(1.0) and rows["Exterior annulus velocity"]["value"] == pytest.approx(1.0)
    flow = rows["Mass flow rate"]
    assert flow["value"] == pytest.approx(1.1)
    assert flow["value_error"] == pytest.approx(1.1 * math.hypot(0.0001 / 0.01, 0.0001 / (0.011 * math.sqrt(5.0))))
    assert "does not scale" in flow["evidence"] and "scales with" in rows["Tube velocity"]["evidence"]
    assert gravity_rows([_blender("converging", -1.0, -3.0)], CRITERIA) == []


def test_the_page_groups_rows_and_the_summary_lists_what_the_scale_cannot_show():
    rows = [row("Silo", "A", "c1", 1.0, 0.1, "-", "", YES, "fine"), row("Silo", "B", "c1", 2.0, 0.1, "-", "", NO, "too shallow"),
            row("Blender", "C", "c2", 3.0, math.nan, "-", "", UNKNOWN, "error unknown")]
    sections = page_sections(rows)
    assert [s[0] for s in sections] == ["Silo", "Blender"] and sections[0][1] == "1 of 2 rows shown at this scale."
    assert scale_limits(rows) == [{"figure": "B", "case": "c1", "note": "too shallow"},
                                  {"figure": "C", "case": "c2", "note": "error unknown"}]
    page = summary_html("validation", sections, intro="How to read it.")
    assert "<p>How to read it.</p>" in page and "<td>2.00 ± 0.10</td>" in page and "too shallow" in page


def test_without_a_tube_the_interior_annulus_spans_both_plates_and_is_the_inner_passage():
    summary = _blender("plates", -1.0, float("nan"))
    summary["geometry"]["clear_widths"] = {"exterior annulus": 0.05, "interior annulus": 0.04}
    rows = {r["figure"]: r for r in blender_rows([summary], [{"depth_m": 0.01, "equivalent_diameter_m": 0.003}],
                                                   Criteria(mass_flow_configuration="plates"))}
    # mean = (2 * 0.05 * -1 + 1 * 0.04 * -2) / 0.14
    mean = (-0.1 - 0.08) / 0.14
    assert rows["Interior annulus v_z / cross-section mean"]["value"] == pytest.approx(-2.0 / mean)
    inner = rows["Exterior annulus / interior annulus v_z (mass flow of the insert)"]
    assert inner["value"] == pytest.approx(0.5) and inner["scale_shows"] == YES


def test_each_group_s_calibration_rows_are_its_sections():
    rows = [_bulk("sphere2", 0.1, 0.40, 0.01), _bulk("sphere2", 0.3, 0.55, 0.01), _bulk("sphere2", 0.5, 0.56, 0.01),
            _bulk("sphere2", 0.3, 0.60, 0.01, blocked=True)]
    curves = calibration_rows(rows, None, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA, sections=("curves",))
    assert [r["figure"] for r in curves] == ["Bulk friction at particle friction 0.5 (rigid lid)"]
    checks = calibration_rows(rows, None, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA,
                              sections=("comparisons",))
    assert [r["figure"] for r in checks] == ["Bulk friction, rotation blocked - free"]
    with pytest.raises(ValueError, match="need the calibration's parameters"):
        calibration_rows(rows, None, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA)
    with pytest.raises(ValueError, match="unknown calibration row sections chart"):
        calibration_rows(rows, None, 0.095, {"sphere2": 0.004}, 0.1, "rigid", 0.03, CRITERIA, sections=("chart",))
