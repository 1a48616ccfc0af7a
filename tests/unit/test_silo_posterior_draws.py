"""The silo at the posterior's draws: exact answers on synthetic runs."""

import math

import pytest
from scipy import stats

from siloflow.analysis.studies.silo_flat.posterior_draws import (
    POSTERIOR_MEAN, base_vertical_stress, calibration_spread, posterior_draw_rows,
)


def _parameters(mu, mu_r, mu_wall):
    return {"rolling_friction": mu_r, "particle_particle": {"sliding_friction": mu},
            "particle_wall": {"aluminium": {"sliding_friction": mu_wall}}}


def _rows(flows, flow_errors, stresses, stress_errors):
    labels = [POSTERIOR_MEAN, *(f"draw {k}" for k in range(len(flows) - 1))]
    return posterior_draw_rows(
        labels, [f"sphere2-{k}" for k in range(len(flows))],
        [_parameters(0.3 + 0.01 * k, 0.1, 0.2) for k in range(len(flows))],
        [{"mass_flow_rate_kg_s": v, "mass_flow_rate_kg_s_error": e} for v, e in zip(flows, flow_errors)],
        list(zip(stresses, stress_errors)))


def test_the_base_stress_is_the_deepest_row_of_the_janssen_profile():
    rows = [{"depth_below_surface_m": 0.05, "sigma_v_dem_Pa": 200.0, "sigma_v_dem_Pa_error": 3.0},
            {"depth_below_surface_m": 0.07, "sigma_v_dem_Pa": 247.0, "sigma_v_dem_Pa_error": 5.5},
            {"depth_below_surface_m": 0.01, "sigma_v_dem_Pa": 40.0, "sigma_v_dem_Pa_error": 1.0}]
    assert base_vertical_stress(rows) == (247.0, 5.5)
    # the deepest bin has no neighbour to pair with for its error: the deepest with one stands for the base
    unpaired = [*rows, {"depth_below_surface_m": 0.08, "sigma_v_dem_Pa": 260.0, "sigma_v_dem_Pa_error": None}]
    assert base_vertical_stress(unpaired) == (247.0, 5.5)
    value, error = base_vertical_stress([{"depth_below_surface_m": 0.08, "sigma_v_dem_Pa": 260.0,
                                          "sigma_v_dem_Pa_error": ""}])
    assert value == 260.0 and math.isnan(error)
    with pytest.raises(ValueError, match="no rows"):
        base_vertical_stress([])


def test_each_run_keeps_its_parameters_and_figures_with_their_errors():
    rows = _rows([1.1, 1.0], [0.05, 0.1], [250.0, 240.0], [4.0, 3.0])
    assert rows[1] == {"label": "draw 0", "run_id": "sphere2-1", "sliding_friction": 0.31, "rolling_friction": 0.1,
                       "wall_sliding_friction.aluminium": 0.2, "mass_flow_rate_kg_s": 1.0,
                       "mass_flow_rate_kg_s_error": 0.1, "base_vertical_stress_Pa": 240.0,
                       "base_vertical_stress_Pa_error": 3.0}
    with pytest.raises(ValueError, match="one label"):
        posterior_draw_rows(["a"], ["r1", "r2"], [], [], [])


def test_the_calibration_error_bar_is_the_spread_between_draws_less_the_runs_own_error():
    # draws: flow 1.0, 1.2, 1.4 (sd 0.2) with errors 0.1 (rms 0.1); stress 100, 101, 102 (sd 1) with errors 2
    spread = calibration_spread(_rows([1.15, 1.0, 1.2, 1.4], [0.02, 0.1, 0.1, 0.1],
                                      [99.0, 100.0, 101.0, 102.0], [1.5, 2.0, 2.0, 2.0]))
    flow, stress = spread
    critical = stats.chi2.ppf(0.95, 2) / 2
    assert flow["figure"] == "mass_flow_rate_kg_s" and flow["unit"] == "kg/s" and flow["draws"] == 3
    assert (flow["posterior_mean"], flow["posterior_mean_error"]) == (1.15, 0.02)
    assert flow["draws_mean"] == pytest.approx(1.2) and flow["draws_sd"] == pytest.approx(0.2)
    assert flow["run_error"] == pytest.approx(0.1) and flow["calibration_sd"] == pytest.approx(math.sqrt(0.03))
    assert flow["spread_ratio"] == pytest.approx(4.0) and flow["critical_ratio"] == pytest.approx(critical)
    assert flow["spread_exceeds_run_error"] is True
    assert stress["unit"] == "Pa" and stress["draws_sd"] == pytest.approx(1.0) and stress["run_error"] == pytest.approx(2.0)
    assert stress["calibration_sd"] == 0.0 and stress["spread_ratio"] == pytest.approx(0.25)
    assert stress["spread_exceeds_run_error"] is False


def test_one_draw_has_no_spread_and_no_verdict():
    flow, _ = calibration_spread(_rows([1.15, 1.0], [0.02, 0.1], [99.0, 100.0], [1.5, 2.0]))
    assert flow["draws"] == 1 and flow["draws_mean"] == 1.0 and flow["run_error"] == pytest.approx(0.1)
    assert math.isnan(flow["draws_sd"]) and math.isnan(flow["calibration_sd"]) and math.isnan(flow["critical_ratio"])
    assert flow["spread_exceeds_run_error"] is None


def test_runs_without_error_leave_every_spread_to_the_parameters():
    flow, stress = calibration_spread(_rows([1.0, 1.0, 2.0], [0.0, 0.0, 0.0], [5.0, 5.0, 5.0], [0.0, 0.0, 0.0]))
    assert flow["spread_ratio"] == math.inf and flow["spread_exceeds_run_error"] is True
    assert flow["calibration_sd"] == pytest.approx(math.sqrt(0.5))
    assert math.isnan(stress["spread_ratio"]) and stress["spread_exceeds_run_error"] is None


def test_the_runs_own_error_leaves_out_the_unknown_ones():
    flow, stress = calibration_spread(_rows([1.0, 1.0, 2.0], [0.0, 0.3, float("nan")], [5.0, 5.0, 6.0],
                                            [0.0, float("nan"), float("nan")]))
    assert flow["run_error"] == pytest.approx(0.3)
    assert math.isnan(stress["run_error"]) and stress["spread_exceeds_run_error"] is None
