"""Exact answers for the blender's PIV figures on one plane: the vertical section's uniformity away from the tube, the
passages with their errors, and the wall layer's summary."""

import math

import numpy as np
import pytest

from siloflow.analysis.studies.blender.sections import (
    WALL_LAYER_WALLS,
    exclusion_of,
    passage_figures,
    section_heights,
    section_uniformity,
    tube_distance,
    uniformity_summary,
    vertical_uniformity,
    wall_layer_summary,
)
from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.study import top_internal

#: Eight bins 50 mm wide across a 400 mm section, two rows.
X = np.arange(-0.175, 0.176, 0.05)
Z = np.array([0.1, 0.2])


def _field(values) -> BlenderField:
    """A field whose v_z across the width is ``values`` (nx,) at both rows, every bin occupied."""
    v = np.repeat(np.asarray(values, dtype=float)[:, None], Z.size, axis=1)
    return BlenderField(x=X, z=Z, v_x=np.zeros_like(v), v_z=v, solid_fraction=np.full_like(v, 0.6))


LINEAR = -1.0 - 0.5 * X  # mean -1 across the width, deviations 0.5 x


def test_section_heights_are_the_key_heights_above_the_internals_in_the_vertical_section():
    heights = {"insert outlet": 0.05, "insert inlet": 0.2, "tube inlet": 0.31, "100 mm above": 0.41}
    assert section_heights(heights, z_transition=0.25, top_internal=0.3) == {"tube inlet": 0.31, "100 mm above": 0.41}
    # a hopper transition above the internals: only the heights above it
    assert section_heights(heights, z_transition=0.35, top_internal=0.3) == {"100 mm above": 0.41}
    insert = {"z_insert_outlet": 0.05, "inlet": [0.1, 0.21], "z_tube_inlet": 0.3}
    assert top_internal(insert) == 0.3 and top_internal({**insert, "z_tube_inlet": None}) == 0.21
    assert top_internal({"z_insert_outlet": 0.05, "inlet": None, "z_tube_inlet": None}) == 0.05


def test_tube_distance_is_to_the_tube_outline_below_its_inlet():
    x = np.array([-0.2, -0.06, 0.0, 0.03, 0.1])
    np.testing.assert_allclose(tube_distance(x, 0.13, 0.02, 0.1),
                               np.hypot([0.18, 0.04, 0.0, 0.01, 0.08], 0.03), rtol=1e-14)
    # beside the tube, below its inlet: the distance across only; inside its outline: 0
    np.testing.assert_allclose(tube_distance(x, 0.05, 0.02, 0.1), [0.18, 0.04, 0.0, 0.01, 0.08], rtol=1e-14)
    with pytest.raises(ValueError, match="tube_x"):
        tube_distance(x, 0.1, -0.01, 0.1)
    assert exclusion_of(0.04) == 0.04 and exclusion_of(None) == 0.0 and exclusion_of(0.0) == 0.0


def test_a_linear_profile_deviates_most_at_the_walls_by_its_slope_times_the_half_width():
    frames = [_field(LINEAR)] * 4
    result = vertical_uniformity(_field(LINEAR), frames, 0.15, None, 0.0)
    # v / mean - 1 = 0.5 x: largest at x = -0.175 (the first of the two ends), |deviation| 0.0875
    assert result.mean_v_z == pytest.approx(-1.0, rel=1e-14)
    assert result.largest_deviation == pytest.approx(0.0875, rel=1e-12) and result.deviation_x == pytest.approx(-0.175)
    assert (result.n_bins, result.excluded_bins, result.batches) == (8, 0, 4)
    assert result.mean_v_z_error == pytest.approx(0.0, abs=1e-15)
    assert result.largest_deviation_error == pytest.approx(0.0, abs=1e-15)
    # without frames the errors are not known
    alone = vertical_uniformity(_field(LINEAR), [], 0.15, None, 0.0)
    assert math.isnan(alone.mean_v_z_error) and math.isnan(alone.largest_deviation_error) and alone.batches == 0


def test_the_errors_are_the_batch_means_of_the_mean_and_of_the_chosen_bin_s_deviation():
    # a flow twice as fast in the second half of the window: the mean's batch means -1 and -2, the deviation unchanged
    scaled = [_field(s * LINEAR) for s in (1.0, 1.0, 2.0, 2.0)]
    result = vertical_uniformity(_field(LINEAR), scaled, 0.15, None, 0.0, n_batches=2)
    assert result.mean_v_z_error == pytest.approx(0.5, rel=1e-12)  # |(-1) - (-2)| / 2
    assert result.largest_deviation_error == pytest.approx(0.0, abs=1e-14)
    # the chosen bin (x = -0.175, v = -0.9125) 0.8 m/s slower in the second half: its frame mean is -7.2 / 8 = -0.9
    # and its deviation -0.1125 / -0.9 - 1 = -0.875 against -0.0875, taken with the steady deviation's sign
    bumped = []
    for delta in (0.0, 0.0, 0.8, 0.8):
        values = LINEAR.copy()
        values[0] += delta
        bumped.append(_field(values))
    result = vertical_uniformity(_field(LINEAR), bumped, 0.15, None, 0.0, n_batches=2)
    assert result.largest_deviation_error == pytest.approx((0.875 - 0.0875) / 2, rel=1e-12)
    assert result.mean_v_z_error == pytest.approx(0.1 / 2, rel=1e-12)  # frame means -1 and -0.9


def test_bins_within_the_exclusion_of_the_tube_are_left_out():
    # the tube (outline 20 mm from the axis, inlet at 100 mm) drags the bins next to it to -3 m/s
    values = LINEAR.copy()
    values[np.abs(X) < 0.05] = -3.0
    # at z = 120 mm the bins at |x| = 25 mm are hypot(5, 20) mm from the tube: within one tube width (40 mm)
    result = vertical_uniformity(_field(values), [], 0.12, (0.02, 0.1), 0.04)
    assert (result.n_bins, result.excluded_bins, result.exclusion) == (6, 2, 0.04)
    assert result.mean_v_z == pytest.approx(-1.0, rel=1e-14) and result.largest_deviation == pytest.approx(0.0875)
    # with no exclusion the dragged bins dominate: mean (-8 + 2 (-3) - (-1 - 0.0125) - (-1 + 0.0125)) / 8 = -1.5
    kept = vertical_uniformity(_field(values), [], 0.12, (0.02, 0.1), 0.0)
    assert kept.mean_v_z == pytest.approx(-1.5) and kept.largest_deviation == pytest.approx(1.0)
    # fewer than two bins kept: no figure
    assert vertical_uniformity(_field(values), [], 0.12, (0.02, 0.1), 1.0) is None
    with pytest.raises(ValueError, match="exclusion"):
        vertical_uniformity(_field(values), [], 0.12, None, -0.01)


def test_uniformity_is_laid_out_per_height_for_the_summary():
    section = {"tube inlet": 0.12, "100 mm above": 0.15}
    summary = section_uniformity(_field(LINEAR), [_field(LINEAR)] * 2, section, (0.02, 0.1), 0.04)
    assert list(summary) == ["0.12", "0.15"]
    entry = summary["0.15"]
    assert entry["name"] == "100 mm above" and entry["height_m"] == 0.15 and entry["n_bins"] == 8
    assert entry["largest_deviation"] == pytest.approx(0.0875) and entry["deviation_x_m"] == pytest.approx(-0.175)
    assert entry["exclusion_m"] == 0.04 and entry["batches"] == 2 and entry["largest_deviation_error"] == 0.0
    assert summary["0.12"]["excluded_bins"] == 2
    assert uniformity_summary({"a": None}, {"a": 0.1}) == {}


def test_passage_figures_are_the_steady_means_with_the_frames_batch_errors():
    # tube bins |x| < 0.1 (four), exterior 0.1 <= |x| <= 0.2 (four)
    passages = {"tube": (0.0, 0.1), "exterior": (0.1, 0.2)}
    steady = _field(np.where(np.abs(X) < 0.1, -2.0, -1.0))
    frames = [_field(np.where(np.abs(X) < 0.1, tube, -1.0)) for tube in (-2.0, -2.0, -3.0, -3.0)]
    figures = passage_figures(steady, frames, 0.15, passages)
    assert figures["mean_v_z_m_s"] == {"tube": -2.0, "exterior": -1.0}
    assert figures["n_bins"] == {"tube": 4, "exterior": 4}
    # four batches of one frame: std(-2, -2, -3, -3) / sqrt(4)
    assert figures["mean_v_z_m_s_error"]["tube"] == pytest.approx(math.sqrt(1.0 / 3.0) / 2.0, rel=1e-12)
    assert figures["mean_v_z_m_s_error"]["exterior"] == 0.0
    assert all(math.isnan(e) for e in passage_figures(steady, [], 0.15, passages)["mean_v_z_m_s_error"].values())


def test_the_wall_layer_summary_holds_its_depth_passages_and_section():
    passages = {"tube": (0.0, 0.1), "exterior": (0.1, 0.2)}
    steady = _field(LINEAR)
    summary = wall_layer_summary(steady, [steady] * 2, 0.0033, {"insert outlet": (0.15, passages)},
                                 {"100 mm above": 0.15}, None, 0.0)
    assert summary["depth_m"] == 0.0033 and summary["walls"] == WALL_LAYER_WALLS
    assert summary["passages_at_insert_inlet"] is None
    assert summary["passages_at_insert_outlet"] == passage_figures(steady, [steady] * 2, 0.15, passages)
    assert summary["vertical_section"] == section_uniformity(steady, [steady] * 2, {"100 mm above": 0.15}, None, 0.0)
    with pytest.raises(ValueError, match="depth"):
        wall_layer_summary(steady, [], 0.0, {"insert outlet": (0.15, passages)}, {}, None, 0.0)
