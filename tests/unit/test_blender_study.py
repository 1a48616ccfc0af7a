"""The blender study composed on a uniform downward field: exact residence times, RTD, key heights, JSON round trips."""

import json
import math

import numpy as np
import pytest

from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.study import (
    BlenderSettings,
    analyse_blender,
    key_heights,
    metrics_from_summary,
    rtd_from_summary,
    rtd_summary,
    study_metrics,
    study_summary,
)
from siloflow.analysis.io.tables import write_json
from siloflow.analysis.studies.blender.errors import sine_vrr_error

V = 0.05          # downward speed [m/s]
FILL = 0.2        # fill height [m]


def uniform_field(speed=V):
    x = np.arange(-0.095, 0.1, 0.01)
    z = np.arange(0.005, FILL, 0.01)
    shape = (x.size, z.size)
    return BlenderField(x=x, z=z, v_x=np.zeros(shape), v_z=np.full(shape, -speed), solid_fraction=np.full(shape, 0.6))


SETTINGS = BlenderSettings(
    fill_height=FILL, release_height=0.15, release_spacing=0.02, integration_step=0.01, max_time=20.0,
    rtd_tracer_fraction=0.1, rtd_bins=10, discontinuous_tracer_fraction=0.2, passes=4, tolerance=0.1,
    period_fractions=(0.5, 1.0, 2.0), comparison_fractions=(1.0,),
)


def passages(z):
    return {"interior": (0.0, 0.05), "exterior": (0.05, 0.1)}


@pytest.fixture(scope="module")
def study():
    field = uniform_field()
    heights = {"insert outlet": 0.05, "insert inlet": 0.1}
    return analyse_blender(field, [field, uniform_field(2 * V)], [0.1, 0.3], heights, passages,
                           lambda z: np.full(np.shape(z), 0.1), SETTINGS)


def test_uniform_field_gives_exact_pathline_residence_times_and_plug_profiles(study):
    np.testing.assert_allclose(study.pathlines.residence_time, 0.15 / V, rtol=1e-9)
    np.testing.assert_allclose(study.profiles.normalised[np.isfinite(study.profiles.normalised)], 1.0)
    np.testing.assert_allclose(study.profiles.cross_section_mean[:, 0], [-V, -2 * V])
    assert study.outlet.mean_v_z == pytest.approx({"interior": -V, "exterior": -V})


def test_rtd_of_the_top_layer_is_uniform_between_its_bottom_and_top_transit_times(study):
    rtd = study.rtd.rtd
    bottom, top = study.rtd.layer_bottom, study.rtd.layer_top
    assert top == pytest.approx(FILL) and bottom == pytest.approx(0.9 * FILL)
    assert rtd.t_mean == pytest.approx(0.5 * (bottom + top) / V, rel=0.02)
    assert study.rtd.n_not_exited == 0


def test_plug_flow_never_homogenises_a_layered_fill(study):
    assert math.isnan(study.discontinuous.homogenised_after)
    np.testing.assert_allclose(study.discontinuous.pass_mean, 0.2, atol=0.02)


def test_metrics_and_rtd_survive_a_json_round_trip(study, tmp_path):
    metrics = study_metrics("plug", study, 0.01, SETTINGS.comparison_fractions)
    assert math.isnan(metrics.tube_v_z) and metrics.interior_v_z == pytest.approx(-V)
    summary = {**study_summary(study, metrics), "rtd_curve": rtd_summary(study.rtd.rtd)}
    loaded = json.loads(write_json(tmp_path / "blender.json", summary).read_text())
    back = metrics_from_summary(loaded)
    assert back.name == "plug" and math.isnan(back.tube_v_z) and math.isnan(back.recirculations_to_homogenise)
    assert back.rtd_mean == metrics.rtd_mean and back.vrr_by_period == pytest.approx(metrics.vrr_by_period)
    rtd = rtd_from_summary(loaded["rtd_curve"])
    np.testing.assert_array_equal(rtd.E, study.rtd.rtd.E)
    assert rtd.n_total == study.rtd.rtd.n_total


def test_metrics_carry_the_errors_of_the_frames_and_tracers_through_json(study, tmp_path):
    # four frames moving at 1, 2, 3, 4 V: batch means of 4 batches, the error of a mean of 1, 2, 3, 4 (times V)
    frames = [uniform_field(k * V) for k in (1.0, 2.0, 3.0, 4.0)]
    metrics = study_metrics("plug", study, 0.01, SETTINGS.comparison_fractions, mass_flow_rate_error=2e-4,
                            frames=frames, resolution=SETTINGS.integration_step)
    assert metrics.mass_flow_rate_error == 2e-4
    assert metrics.interior_v_z_error == pytest.approx(V * math.sqrt(5.0 / 3.0) / 2.0, rel=1e-12)
    assert metrics.exterior_v_z_error == pytest.approx(metrics.interior_v_z_error, rel=1e-12)
    assert math.isnan(metrics.tube_v_z_error)  # no tube
    # equal solid fractions: equal tracer weights, so n_eff = n and the tracers' part of t_m's error is
    # std(ddof=1) / sqrt(n); the field's part is t_m times the flow rate's relative error, 2e-4 / 0.01
    tau = study.rtd.residence_time[np.isfinite(study.rtd.residence_time)]
    assert metrics.vrr_ceiling == pytest.approx(tau.size, rel=1e-12)
    assert metrics.rtd_mean_error == pytest.approx(
        math.hypot(np.std(tau, ddof=1) / math.sqrt(tau.size), 0.02 * metrics.rtd_mean), rel=1e-9)
    assert metrics.vrr_errors == pytest.approx(
        {1.0: sine_vrr_error(metrics.vrr_by_period[1.0], tau.size)}, rel=1e-12)
    assert math.isfinite(metrics.ts_over_td_error) and math.isfinite(metrics.rtd_spread_error)
    summary = study_summary(study, metrics)["metrics"]
    assert list(summary)[:4] == ["configuration", "mass_flow_rate_kg_s", "mass_flow_rate_kg_s_error",
                                 "exterior_v_z_m_s"]
    # the plug never homogenises within its windows: the figure and its error are unknown
    assert summary["vrr_ceiling"] == metrics.vrr_ceiling and math.isnan(summary["recirculations_to_homogenise_error"])
    loaded = json.loads(write_json(tmp_path / "blender.json", {"metrics": summary}).read_text())
    back = metrics_from_summary(loaded)
    assert back.interior_v_z_error == metrics.interior_v_z_error and math.isnan(back.tube_v_z_error)
    assert back.vrr_errors == metrics.vrr_errors and back.vrr_ceiling == metrics.vrr_ceiling
    # without frames or a resolution those errors are unknown; a summary without errors reads back as unknown
    bare = study_metrics("plug", study, 0.01, SETTINGS.comparison_fractions)
    assert math.isnan(bare.interior_v_z_error) and math.isnan(bare.ts_over_td_error)
    assert math.isnan(bare.mass_flow_rate_error) and math.isnan(bare.rtd_mean_error)
    old = {key: value for key, value in summary.items() if not key.endswith("_error") and key != "vrr_ceiling"}
    assert math.isnan(metrics_from_summary({"metrics": old}).rtd_mean_error)


def test_key_heights_sit_one_bin_inside_the_insert_and_above_the_tube_and_stay_below_the_fill():
    insert = {"z_insert_outlet": 0.10, "inlet": [0.03, 0.20], "z_tube_inlet": 0.21}
    heights = key_heights(insert, 0.005, 0.25, [0.01, 0.1])
    assert heights == pytest.approx({"insert outlet": 0.105, "insert inlet": 0.195, "tube inlet": 0.215,
                                     "10 mm above": 0.225})
    none = key_heights({"z_insert_outlet": 0.10, "inlet": None, "z_tube_inlet": None}, 0.005, 0.25, [0.01])
    assert none == pytest.approx({"insert outlet": 0.105, "10 mm above": 0.115})
    with pytest.raises(ValueError, match="insert outlet"):
        analyse_blender(uniform_field(), [uniform_field()], [0.1], {"tube inlet": 0.1}, passages,
                        lambda z: np.full(np.shape(z), 0.1), SETTINGS)
