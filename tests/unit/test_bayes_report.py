"""The Bayesian calibration's report on synthetic input whose answers are worked out by hand: credible intervals,
the posterior predictive check and its verdict, the chart inversion beside the posterior, the engines side by side;
and the figures are written as PNG (files under tmp_path only)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.colors import to_hex
from matplotlib.figure import Figure

from siloflow.calibration.bayes.joint import Calibration, calibration_of
from siloflow.engines.config import validate_config
from siloflow.calibration.bayes.plots import CHART_COLOR, plot_corner, plot_predictive
from siloflow.calibration.bayes.posterior import Prior
from scipy import stats

from siloflow.calibration.bayes.report import (CHART_COMPARISON_COLUMNS, chart_comparison_rows, engines_rows, interval_rows,
                                      predictive_columns, predictive_rows, predictive_verdict, TWIN_COLUMNS,
                                      twin_rows, twin_verdict)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
NAMES = ("sliding_friction", "rolling_friction", "wall_sliding_friction.aluminium")


def _calibration(walls=("aluminium",)) -> Calibration:
    names = ("sliding_friction", "rolling_friction", *(f"wall_sliding_friction.{wall}" for wall in walls))
    d = len(names)
    return Calibration(names=names, prior=Prior(np.full(d, 0.0), np.full(d, 1.0)), tests=("internal", *walls),
                       targets_deg=np.array([30.0, 9.5, 11.0][:1 + len(walls)]),
                       target_sd_deg=np.full(1 + len(walls), 1.0), shape="sphere2", restitution=0.1, settings={})


# --- intervals -------------------------------------------------------------------------------------------------------

def test_interval_rows_give_the_summary_and_the_equal_tailed_interval_of_each_parameter():
    # 11 evenly spaced samples 0, 0.01, ..., 0.1: the 5 % quantile sits half-way between the first two (0.005), the
    # 95 % one half-way between the last two (0.095); the second parameter is twice the first
    first = np.linspace(0.0, 0.1, 11)
    samples = np.column_stack([first, 2.0 * first])
    summary = {"parameters": {"a": {"mean": 0.05, "sd": 0.033, "median": 0.05, "q05": 0.005, "q95": 0.095},
                              "b": {"mean": 0.1, "sd": 0.066, "median": 0.1, "q05": 0.01, "q95": 0.19}},
               "seed_sd_deg": {"internal": 0.3}}
    rows = interval_rows(summary, samples, ["a", "b"])
    assert [row["parameter"] for row in rows] == ["a", "b"]
    assert rows[0] == {"parameter": "a", "mean": 0.05, "sd": 0.033, "median": 0.05,
                       "interval_lower": pytest.approx(0.005, abs=1e-15),
                       "interval_upper": pytest.approx(0.095, abs=1e-15), "level": 0.9, "units": "-"}
    assert (rows[1]["interval_lower"], rows[1]["interval_upper"]) == (pytest.approx(0.01), pytest.approx(0.19))
    # a 50 % interval: the quartiles, 0.025 and 0.075
    half = interval_rows(summary, samples, ["a", "b"], level=0.5)[0]
    assert (half["interval_lower"], half["interval_upper"], half["level"]) == (pytest.approx(0.025),
                                                                               pytest.approx(0.075), 0.5)


def test_interval_rows_refuse_samples_or_a_summary_that_do_not_match_the_names():
    summary = {"parameters": {"a": {"mean": 0.0, "sd": 1.0, "median": 0.0}}}
    with pytest.raises(ValueError, match="shape"):
        interval_rows(summary, np.zeros((5, 2)), ["a"])
    with pytest.raises(ValueError, match="no parameter b"):
        interval_rows(summary, np.zeros((5, 2)), ["a", "b"])


# --- predictive check ------------------------------------------------------------------------------------------------

def _predictive_input():
    sets = [{"theta": [0.3, 0.1, 0.4], "replicate": 5000, "points": {}, "runs": {"internal": "r1", "aluminium": "r2"},
             "predicted_deg": {"internal": [33.0, 1.5], "aluminium": [8.0, 0.5]}},
            {"theta": [0.35, 0.12, 0.45], "replicate": 5001, "points": {}, "runs": {"internal": "r3", "aluminium": "r4"},
             "predicted_deg": {"internal": [29.0, 1.5], "aluminium": [10.0, 1.0]}}]
    summaries = {
        # internal, against the target: allowed sqrt(1^2 + 2^2) = sqrt 5 deg (the run's own window error is part of
        # the seed noise, not added again); 36 - 30 = 6 deg = 2.683 sd: outside. Against its prediction: sqrt(1.5^2 +
        # 2^2) = 2.5 deg; (36 - 33) / 2.5 = 1.2
        "r1": {"bulk_friction_angle_deg": 36.0, "bulk_friction_angle_deg_error": 2.0, "window_method": "steady"},
        # aluminium: allowed sqrt(1^2 + 0^2) = 1 deg; 7 - 9.5 = -2.5 sd: outside; z = (7 - 8) / 0.5 = -2
        "r2": {"bulk_friction_angle_deg": 7.0, "bulk_friction_angle_deg_error": 0.0, "window_method": "second half"},
        # internal: 27 - 30 = -3 deg = -1.342 sd: within; z = (27 - 29) / 2.5 = -0.8
        "r3": {"bulk_friction_angle_deg": 27.0, "bulk_friction_angle_deg_error": 2.0, "window_method": "steady"},
        # aluminium: 10.5 - 9.5 = 1 sd: within; z = (10.5 - 10) / 1 = 0.5
        "r4": {"bulk_friction_angle_deg": 10.5, "bulk_friction_angle_deg_error": 1.0, "window_method": "steady"},
    }
    return sets, summaries, {"internal": 2.0, "aluminium": 0.0}


def test_predictive_rows_set_each_run_against_its_prediction_and_its_target():
    calibration = _calibration()
    sets, summaries, seed = _predictive_input()
    rows = predictive_rows(calibration, sets, summaries, seed)
    assert [(row["set"], row["test"], row["run_id"]) for row in rows] == [
        (0, "internal", "r1"), (0, "aluminium", "r2"), (1, "internal", "r3"), (1, "aluminium", "r4")]
    assert all(list(row) == predictive_columns(calibration) for row in rows)
    assert rows[0] == {"set": 0, "replicate": 5000, "sliding_friction": 0.3, "rolling_friction": 0.1,
                       "wall_sliding_friction.aluminium": 0.4, "test": "internal", "run_id": "r1", "target_deg": 30.0,
                       "target_sd_deg": 1.0, "seed_sd_deg": 2.0, "discrepancy_sd_deg": 0.0, "angle_deg": 36.0,
                       "angle_error_deg": 2.0, "predicted_deg": 33.0, "predicted_sd_deg": 1.5,
                       "predictive_sd_deg": 2.5, "z": pytest.approx(1.2), "pit": pytest.approx(stats.norm.cdf(1.2)),
                       "allowed_sd_deg": pytest.approx(math.sqrt(5.0)),
                       "difference_deg": 6.0, "difference_in_sd": pytest.approx(6.0 / math.sqrt(5.0)),
                       "within": False, "window_method": "steady"}
    assert [row["z"] for row in rows] == pytest.approx([1.2, -2.0, -0.8, 0.5])
    assert [row["allowed_sd_deg"] for row in rows] == pytest.approx([math.sqrt(5.0), 1.0, math.sqrt(5.0), 1.0])
    assert [row["difference_in_sd"] for row in rows] == pytest.approx([6.0 / math.sqrt(5.0), -2.5,
                                                                       -3.0 / math.sqrt(5.0), 1.0])
    assert [row["within"] for row in rows] == [False, False, True, True]
    # the seed noise may also come in the calibration's test order; a twin's target sd replaces the configured one
    assert predictive_rows(calibration, sets, summaries, [2.0, 0.0]) == rows
    twin = predictive_rows(calibration, sets, summaries, seed, {"internal": 0.0, "aluminium": 0.5})
    assert twin[0]["allowed_sd_deg"] == pytest.approx(2.0) and twin[1]["allowed_sd_deg"] == pytest.approx(0.5)
    # a model discrepancy widens what a run may miss its target by
    wide = predictive_rows(Calibration(**{**calibration.__dict__, "discrepancy_sd_deg": 2.0}), sets, summaries, seed)
    assert wide[1]["allowed_sd_deg"] == pytest.approx(math.sqrt(5.0))


def test_a_run_without_a_prediction_has_no_z_and_missing_runs_are_named():
    calibration = _calibration()
    sets, summaries, seed = _predictive_input()
    del sets[1]["predicted_deg"]
    row = predictive_rows(calibration, sets, summaries, seed)[3]
    assert math.isnan(row["z"]) and math.isnan(row["pit"]) and math.isnan(row["predicted_deg"])
    del summaries["r3"]
    with pytest.raises(ValueError, match="run r3"):
        predictive_rows(calibration, sets, summaries, seed)
    with pytest.raises(ValueError, match="seed noise"):
        predictive_rows(calibration, sets[:1], {"r1": {}, "r2": {}}, {"internal": 1.0})


def test_predictive_verdict_tests_the_chi_square_of_the_runs_in_both_tails():
    calibration = _calibration()
    sets, summaries, seed = _predictive_input()
    verdict = predictive_verdict(predictive_rows(calibration, sets, summaries, seed))
    chi2 = 1.2 ** 2 + 2.0 ** 2 + 0.8 ** 2 + 0.5 ** 2   # 6.33 over 4 runs
    assert verdict == {"rows": 4, "within": 2, "fraction": 0.5, "unknown": 0, "chi2": pytest.approx(chi2),
                       "degrees_of_freedom": 4, "p_upper": pytest.approx(stats.chi2.sf(chi2, 4)),
                       "p_lower": pytest.approx(stats.chi2.cdf(chi2, 4)), "verdict": "consistent",
                       "mean_pit": pytest.approx(np.mean(stats.norm.cdf([1.2, -2.0, -0.8, 0.5])))}
    # twelve runs each 3 predictive sd off: the runs scatter far more than the model says
    wide = [{"within": False, "allowed_sd_deg": 1.0, "z": 3.0}] * 12
    assert predictive_verdict(wide)["verdict"] == "runs scatter more than predicted"
    # twelve runs on their predictions to 0.05 sd: far less than the model says (the noise overestimated)
    narrow = [{"within": True, "allowed_sd_deg": 1.0, "z": 0.05}] * 12
    assert predictive_verdict(narrow)["verdict"] == "runs scatter less than predicted"
    assert predictive_verdict([])["verdict"] == "no runs with a prediction"


# --- chart beside the posterior --------------------------------------------------------------------------------------

def _comparison_samples() -> np.ndarray:
    """100 samples: 60 at rolling friction 0.1 (sliding 0.3 and 0.5, 30 each; aluminium 0.4) and 40 at 0.25 (sliding
    0.2, aluminium 0.6); perspex alternates 0.3 and 0.32."""
    sliding = np.array([0.3] * 30 + [0.5] * 30 + [0.2] * 40)
    rolling = np.array([0.1] * 60 + [0.25] * 40)
    aluminium = np.array([0.4] * 60 + [0.6] * 40)
    perspex = np.tile([0.3, 0.32], 50)
    return np.column_stack([sliding, rolling, aluminium, perspex])


def _chart(**changes) -> dict:
    return {"shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0,
            "particle_particle": {"sliding_friction": 0.35, "sliding_friction_error": 0.02, "lower": 0.3,
                                  "upper": 0.4, "band_clipped": False},
            # perspex was unreachable: the chart gives no wall friction for it
            "particle_wall": {"aluminium": {"sliding_friction": 0.7, "sliding_friction_error": None, "lower": 0.6,
                                            "upper": 0.8, "band_clipped": False}},
            "targets_deg": {"internal": 30.0, "aluminium": 9.5, "perspex": 11.0}, **changes}


def test_chart_comparison_rows_set_the_chart_beside_the_posterior_and_condition_on_its_rolling_friction():
    calibration = _calibration(walls=("aluminium", "perspex"))
    rows = chart_comparison_rows(calibration, _comparison_samples(), _chart())
    assert [row["parameter"] for row in rows] == ["sliding_friction", "rolling_friction",
                                                  "wall_sliding_friction.aluminium"]
    assert all(tuple(row) == CHART_COMPARISON_COLUMNS for row in rows)
    sliding, rolling, aluminium = rows
    # sliding: mean (30 0.3 + 30 0.5 + 40 0.2) / 100 = 0.32; squared deviations 40 0.12^2 + 30 0.02^2 + 30 0.18^2
    # = 1.56 over 99; 5 and 95 % quantiles at positions 4.95 and 94.05 of the sorted samples: 0.2 and 0.5. Near
    # rolling friction 0.1 (+- 0.02): the 60 samples of 0.3 and 0.5, mean 0.4, sd sqrt(60 0.1^2 / 59)
    assert sliding == {"parameter": "sliding_friction", "chart_value": 0.35, "chart_error": 0.02, "chart_fixed": False,
                       "posterior_mean": pytest.approx(0.32), "posterior_sd": pytest.approx(math.sqrt(1.56 / 99)),
                       "interval_lower": pytest.approx(0.2), "interval_upper": pytest.approx(0.5), "level": 0.9,
                       "chart_inside": True, "conditional_mean": pytest.approx(0.4),
                       "conditional_sd": pytest.approx(math.sqrt(0.6 / 59)), "conditional_samples": 60,
                       "conditional_window": 0.02, "chart_rolling_friction": 0.1,
                       "note": "conditioned on |rolling_friction - 0.1| <= 0.02: 60 samples"}
    # rolling friction: fixed by the chart at 0.1; the posterior's marginal (mean 0.16, interval 0.1 to 0.25) beside
    assert rolling["chart_fixed"] is True and rolling["chart_value"] == 0.1 and rolling["chart_error"] is None
    assert (rolling["posterior_mean"], rolling["interval_lower"], rolling["interval_upper"]) == (
        pytest.approx(0.16), 0.1, 0.25)
    assert rolling["chart_inside"] is True
    assert rolling["conditional_mean"] is None and rolling["conditional_sd"] is None
    assert rolling["note"].startswith("fixed in the chart inversion")
    # aluminium: mean (60 0.4 + 40 0.6) / 100 = 0.48, sd sqrt((60 0.08^2 + 40 0.12^2) / 99); interval 0.4 to 0.6 does
    # not hold the chart's 0.7; near the chart's rolling friction all are 0.4; the chart's error is unknown
    assert (aluminium["chart_value"], aluminium["chart_error"], aluminium["chart_inside"]) == (0.7, None, False)
    assert aluminium["posterior_mean"] == pytest.approx(0.48)
    assert aluminium["posterior_sd"] == pytest.approx(math.sqrt(0.96 / 99))
    assert (aluminium["interval_lower"], aluminium["interval_upper"]) == (pytest.approx(0.4), pytest.approx(0.6))
    assert aluminium["conditional_mean"] == pytest.approx(0.4)
    assert aluminium["conditional_sd"] == pytest.approx(0.0, abs=1e-12)


def test_too_few_samples_near_the_charts_rolling_friction_give_no_conditioned_mean():
    calibration = _calibration(walls=("aluminium", "perspex"))
    sliding = chart_comparison_rows(calibration, _comparison_samples(), _chart(), min_samples=61)[0]
    assert (sliding["conditional_mean"], sliding["conditional_sd"], sliding["conditional_samples"]) == (None, None, 60)
    assert sliding["note"] == ("only 60 samples with |rolling_friction - 0.1| <= 0.02 (fewer than 61): no conditioned "
                               "mean")
    # a wider window takes the 40 samples at 0.25 too: the conditioned mean is the marginal's
    wide = chart_comparison_rows(calibration, _comparison_samples(), _chart(), window=0.15)[0]
    assert (wide["conditional_samples"], wide["conditional_mean"]) == (100, pytest.approx(0.32))
    with pytest.raises(ValueError, match="sphere4"):
        chart_comparison_rows(calibration, _comparison_samples(), _chart(shape="sphere4"))


def test_a_chart_without_an_internal_inversion_gives_only_its_rolling_friction_and_walls():
    calibration = _calibration(walls=("aluminium", "perspex"))
    chart = _chart()
    del chart["particle_particle"]
    rows = chart_comparison_rows(calibration, _comparison_samples(), chart)
    assert [row["parameter"] for row in rows] == ["rolling_friction", "wall_sliding_friction.aluminium"]


# --- engines side by side --------------------------------------------------------------------------------------------

def _posterior(**parameters) -> dict:
    return {"parameters": {name: {"mean": mean, "sd": sd, "median": mean, "q05": mean - 2 * sd, "q95": mean + 2 * sd}
                           for name, (mean, sd) in parameters.items()},
            "correlation": {}, "seed_sd_deg": {"internal": 0.2}, "final_iteration": 2}


def test_engines_rows_set_two_engines_side_by_side_with_their_difference_in_combined_sd():
    rows = engines_rows({"liggghts": _posterior(sliding_friction=(0.3, 0.03), rolling_friction=(0.1, 0.02)),
                         "yade": _posterior(sliding_friction=(0.34, 0.04), rolling_friction=(0.07, 0.0))})
    # sliding: 0.34 - 0.3 = 0.04 over sqrt(0.03^2 + 0.04^2) = 0.05: 0.8; rolling: -0.03 over 0.02: -1.5
    assert rows[0] == {"parameter": "sliding_friction", "liggghts_mean": 0.3, "liggghts_sd": 0.03,
                       "liggghts_q05": 0.24, "liggghts_q95": 0.36, "yade_mean": 0.34, "yade_sd": 0.04,
                       "yade_q05": pytest.approx(0.26), "yade_q95": pytest.approx(0.42),
                       "yade_minus_liggghts": pytest.approx(0.04), "yade_minus_liggghts_in_sd": pytest.approx(0.8)}
    assert rows[1]["parameter"] == "rolling_friction"
    assert (rows[1]["yade_minus_liggghts"], rows[1]["yade_minus_liggghts_in_sd"]) == (pytest.approx(-0.03),
                                                                                      pytest.approx(-1.5))


def test_engines_rows_of_one_engine_or_a_missing_parameter():
    (only,) = engines_rows({"yade": _posterior(sliding_friction=(0.3, 0.03))})
    assert only == {"parameter": "sliding_friction", "yade_mean": 0.3, "yade_sd": 0.03, "yade_q05": 0.24,
                    "yade_q95": 0.36}
    rows = engines_rows({"liggghts": _posterior(sliding_friction=(0.3, 0.03)),
                         "yade": _posterior(sliding_friction=(0.3, 0.0), rolling_friction=(0.1, 0.01))})
    assert rows[0]["yade_minus_liggghts"] == 0.0 and rows[0]["yade_minus_liggghts_in_sd"] == 0.0
    assert rows[1]["parameter"] == "rolling_friction" and rows[1]["liggghts_mean"] is None
    assert rows[1]["yade_minus_liggghts"] is None and rows[1]["yade_minus_liggghts_in_sd"] is None
    # the parameters in the calibration's order, as the correlation keeps it, not the sorted keys of a JSON file
    ordered = _posterior(rolling_friction=(0.1, 0.01), sliding_friction=(0.3, 0.03))
    ordered["correlation"] = {"names": ["sliding_friction", "rolling_friction"], "matrix": [[1.0, 0.0], [0.0, 1.0]]}
    assert [row["parameter"] for row in engines_rows({"yade": ordered})] == ["sliding_friction", "rolling_friction"]
    # a zero combined sd gives no difference in sd
    (same,) = engines_rows({"a": _posterior(x=(0.1, 0.0)), "b": _posterior(x=(0.2, 0.0))})
    assert same["b_minus_a"] == pytest.approx(0.1) and same["b_minus_a_in_sd"] is None
    with pytest.raises(ValueError):
        engines_rows({})


# --- figures ---------------------------------------------------------------------------------------------------------

def _only_file(folder, name):
    assert sorted(p.name for p in folder.iterdir()) == [name], "temporary files left behind"


def test_plot_corner_writes_a_png_with_the_charts_values_marked(tmp_path):
    rng = np.random.default_rng(1)
    samples = rng.normal([0.3, 0.1, 0.4], [0.03, 0.02, 0.05], size=(500, 3))
    path = tmp_path / "corner.png"
    figure = plot_corner(samples, NAMES, path, truths=[0.3, 0.1, 0.4],
                         chart={"sliding_friction": 0.33, "rolling_friction": 0.1})
    assert isinstance(figure, Figure) and len(figure.axes) == 9
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(tmp_path, "corner.png")
    # the chart's sliding friction is a vertical line on the first marginal; the aluminium has none
    diagonal = [figure.axes[4 * i] for i in range(3)]
    marked = [sorted({round(float(line.get_xdata()[0]), 6) for line in axes.get_lines()
                      if to_hex(line.get_color()) == to_hex(CHART_COLOR)}) for axes in diagonal]
    assert marked == [[0.33], [0.1], []]
    with pytest.raises(ValueError, match="unknown parameters"):
        plot_corner(samples, NAMES, tmp_path / "other.png", chart={"perspex": 0.2})


def test_plot_predictive_writes_a_png_with_a_panel_per_test(tmp_path):
    sets, summaries, seed = _predictive_input()
    rows = predictive_rows(_calibration(), sets, summaries, seed)
    path = tmp_path / "predictive.png"
    figure = plot_predictive(rows, path)
    assert path.read_bytes().startswith(PNG_SIGNATURE)
    _only_file(tmp_path, "predictive.png")
    assert [axes.get_title() for axes in figure.axes] == ["internal: 1 of 2 within 2 sd",
                                                          "aluminium: 1 of 2 within 2 sd"]
    empty = tmp_path / "empty" / "predictive.png"
    plot_predictive([], empty)
    assert empty.read_bytes().startswith(PNG_SIGNATURE)


def test_the_twin_verdict_tests_the_truths_highest_density_level_and_says_what_was_learnt():
    # a Gaussian posterior of two parameters with a uniform prior on [0, 1]^2 (prior sd 1 / sqrt 12): the HPD level of
    # a point is the chi-square(2) probability of its squared Mahalanobis distance, 1 - exp(-r^2 / 2)
    rng = np.random.default_rng(3)
    mean, sd = np.array([0.3, 0.1]), np.array([0.02, 0.01])
    samples = rng.normal(mean, sd, size=(40000, 2))
    log_p = -0.5 * np.sum(((samples - mean) / sd) ** 2, axis=1)
    calibration = Calibration(names=("sliding_friction", "rolling_friction"), prior=Prior([0.0, 0.0], [1.0, 1.0]),
                              tests=("internal",), targets_deg=np.array([30.0]), target_sd_deg=np.array([1.0]),
                              shape="sphere2", restitution=0.1, settings={})

    def verdict(truth):
        return twin_verdict(calibration, samples, log_p, truth, -0.5 * np.sum(((np.array(truth) - mean) / sd) ** 2))

    inside = verdict([0.32, 0.1])   # r = 1
    assert inside["hpd_level"] == pytest.approx(1.0 - math.exp(-0.5), abs=0.01)
    assert inside["inside_credible_region"] and inside["truth"] == {"sliding_friction": 0.32, "rolling_friction": 0.1}
    sliding = inside["parameters"]["sliding_friction"]
    assert sliding["z"] == pytest.approx(1.0, abs=0.02) and sliding["inside"]
    assert sliding["prior_sd"] == pytest.approx(1.0 / math.sqrt(12.0))
    assert sliding["sd_over_prior_sd"] == pytest.approx(0.02 * math.sqrt(12.0), rel=0.02)
    # the principal axes in prior-sd units: the sliding friction's (the wider) first
    first, second = inside["axes"]
    assert abs(first["loadings"]["sliding_friction"]) == pytest.approx(1.0, abs=1e-2)
    assert first["sd_over_prior_sd"] == pytest.approx(0.02 * math.sqrt(12.0), rel=0.02)
    assert second["sd_over_prior_sd"] == pytest.approx(0.01 * math.sqrt(12.0), rel=0.02)
    assert abs(first["truth_z"]) == pytest.approx(1.0, abs=0.02) and abs(second["truth_z"]) < 0.05
    outside = verdict([0.3, 0.125])   # r = 2.5: level 1 - exp(-3.125) = 0.956
    assert outside["hpd_level"] == pytest.approx(1.0 - math.exp(-3.125), abs=0.01)
    assert not outside["inside_credible_region"]
    # every marginal may hold the truth while the joint region does not: the ridge's test is the joint one
    corner = verdict([0.3 + 1.5 * 0.02, 0.1 + 1.5 * 0.01])   # r^2 = 4.5: level 0.895, each marginal inside
    assert corner["parameters"]["sliding_friction"]["inside"] and corner["parameters"]["rolling_friction"]["inside"]
    assert corner["hpd_level"] == pytest.approx(1.0 - math.exp(-2.25), abs=0.01)


def test_the_chart_comparison_of_a_calibration_with_its_rolling_friction_held_fixed():
    config = validate_config({"calibration": {"targets_deg": {"internal": 30.0}, "rolling_friction": 0.1,
                                              "bayesian": {"fixed": {"rolling_friction": 0.1}}},
                              "jenike": {"sweep": {"tests": ["internal"]}}})
    calibration = calibration_of(config)
    samples = np.linspace(0.2, 0.4, 101)[:, np.newaxis]
    chart = {"shape": "sphere2", "rolling_friction": 0.1,
             "particle_particle": {"sliding_friction": 0.3, "sliding_friction_error": 0.01}}
    (row,) = chart_comparison_rows(calibration, samples, chart)
    assert row["parameter"] == "sliding_friction" and row["chart_inside"]
    assert row["conditional_samples"] == 101 and row["conditional_mean"] == pytest.approx(0.3)


def test_the_twin_table_has_a_row_per_parameter_per_axis_and_the_verdict_last():
    verdict = {"level": 0.9, "hpd_level": 0.64, "inside_credible_region": True,
               "parameters": {"a": {"truth": 0.3, "mean": 0.31, "sd": 0.07, "sd_over_prior_sd": 0.45, "z": -0.12,
                                    "inside": True},
                              "b": {"truth": 0.1, "mean": 0.09, "sd": 0.06, "sd_over_prior_sd": 1.02, "z": 0.12,
                                    "inside": False}},
               "axes": [{"loadings": {"a": 0.96, "b": -0.28}, "sd_over_prior_sd": 1.05, "truth_z": 0.124}]}
    rows = twin_rows(verdict)
    assert all(tuple(row) == TWIN_COLUMNS for row in rows)
    assert rows[0] == {"quantity": "a", "truth": 0.3, "posterior_mean": 0.31, "posterior_sd": 0.07,
                       "sd_over_prior_sd": 0.45, "truth_z": -0.12, "hpd_level": "", "level": 0.9, "inside": True}
    assert rows[1]["inside"] is False
    assert rows[2] == {**dict.fromkeys(TWIN_COLUMNS, ""), "quantity": "axis 1: 0.960*a + -0.280*b",
                       "sd_over_prior_sd": 1.05, "truth_z": 0.124}
    assert rows[3] == {**dict.fromkeys(TWIN_COLUMNS, ""), "quantity": "truth (all parameters)", "hpd_level": 0.64,
                       "level": 0.9, "inside": True}
