"""Unit tests for siloflow.analysis.studies.silo_recirculation.shortcut on the plug-flow conveyor of
``test_silo_recirculation_study.py`` (100 clumps moving down at 0.1 m/s through a periodic domain; t_res = 7.5 s,
every pass exactly 7.5 s, 30 s of frames = 4 recirculations).

In plug flow every tracer that enters after ``Nr = 0.4`` has left 7.5 s later, so a run cut at ``Nr = 2`` (15 s)
already holds the whole RTD: the shortcut's analysis must equal the full one exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.analysis.studies.silo_recirculation.configured import analyse_configured, configured_layouts
from siloflow.analysis.studies.silo_recirculation.shortcut import shortcut_rows, tracks_until
from siloflow.analysis.studies.silo_recirculation.study import Layout, analyse_blending
from tests.unit.test_silo_recirculation_study import (
    BOTTOM, LAYOUTS, OUTLET, PASS_TIME, PASSES, PERIOD_FRACTIONS, RTD_BINS, TIMES, TOLERANCE, TOP, TRACER_FRACTION,
    TRACER_START, WINDOW_FRACTION, conveyor_tracks,
)


def _analyse(tracks, layouts=LAYOUTS, with_transit=False):
    return analyse_blending(tracks, layouts, BOTTOM, TOP, WINDOW_FRACTION, TRACER_FRACTION, TRACER_START, RTD_BINS,
                            PERIOD_FRACTIONS, PASSES, TOLERANCE, outlet_z=OUTLET, with_transit=with_transit)


@pytest.fixture(scope="module")
def tracks():
    return conveyor_tracks()


def test_tracks_until_keeps_the_frames_up_to_the_cut(tracks):
    cut = tracks_until(tracks, 15.0)
    assert cut.n_times == 751 and cut.times[-1] == pytest.approx(15.0)
    np.testing.assert_array_equal(cut.position, tracks.position[:751])
    np.testing.assert_array_equal(cut.clump_id, tracks.clump_id)


@pytest.mark.parametrize("t_end, message", [(0.01, "leaves 1 frame"), (TIMES[-1], "not after the cut"),
                                            (100.0, "not after the cut")])
def test_tracks_until_refuses_a_cut_that_leaves_too_little_or_nothing(tracks, t_end, message):
    with pytest.raises(ValueError, match=message):
        tracks_until(tracks, t_end)


def test_in_plug_flow_the_shortcut_equals_the_full_analysis(tracks):
    full = _analyse(tracks, with_transit=True)
    short = _analyse(tracks_until(tracks, 2.0 * PASS_TIME))
    assert full.transit is not None and short.transit is None and short.tracer_transit_mean is None
    rows = shortcut_rows(full, short)
    assert [row["layout"] for row in rows] == [layout.name for layout in LAYOUTS] + ["continuous (sine)"]
    for row in rows:
        assert row["recirculations_full"] == pytest.approx(4.0)
        assert row["recirculations_shortcut"] == pytest.approx(2.0)
        assert row["t_mean_full_s"] == pytest.approx(PASS_TIME) and row["t_mean_shortcut_s"] == pytest.approx(PASS_TIME)
        assert row["t_mean_full_error_s"] == pytest.approx(0.0, abs=1e-9)
        assert row["t_mean_difference_over_error"] == pytest.approx(0.0, abs=1e-6)
        assert row["tracer_exited_shortcut"] == 1.0
    for row in rows[:-1]:
        assert row["model_rms_difference"] == pytest.approx(0.0, abs=1e-12)
        assert row["homogenised_model_shortcut"] == row["homogenised_model_full"] or (
            math.isnan(row["homogenised_model_shortcut"]) and math.isnan(row["homogenised_model_full"]))
        assert math.isnan(row["vrr_largest_relative_difference"])
    assert rows[-1]["vrr_largest_relative_difference"] == pytest.approx(0.0, abs=1e-9)
    assert math.isnan(rows[-1]["model_rms_difference"])


def test_a_shortcut_too_short_for_the_loop_rtd_says_what_to_change(tracks):
    # every loop (outlet to outlet) takes 10 s: cut at 12 s, none of the tracer's loops entering after 3 s has ended
    with pytest.raises(ValueError, match="run more recirculations"):
        _analyse(tracks_until(tracks, 12.0))


def test_the_layouts_must_match(tracks):
    full = _analyse(tracks)
    short = _analyse(tracks_until(tracks, 2.0 * PASS_TIME), layouts=[Layout("other", 0.5)])
    with pytest.raises(ValueError, match="same batch layouts"):
        shortcut_rows(full, short)


def test_the_configured_analysis_is_analyse_blending_with_the_sections_keys(tracks):
    settings = {"layouts": [{"name": layout.name, "blue_fraction": layout.blue_fraction,
                             "sublayers": layout.sublayers, "blue_at": layout.blue_at} for layout in LAYOUTS],
                "concentration_window": WINDOW_FRACTION, "concentration_window_target_vrr": None,
                "tracer": {"volume_fraction": TRACER_FRACTION, "start_recirculations": TRACER_START, "bins": RTD_BINS},
                "lti": {"period_fractions": PERIOD_FRACTIONS, "passes": PASSES, "tolerance": TOLERANCE}}
    configured = analyse_configured(tracks, BOTTOM, TOP, settings, with_transit=False)
    direct = _analyse(tracks)
    assert configured_layouts(settings) == LAYOUTS
    assert configured.window == direct.window and configured.timing.residence_time == direct.timing.residence_time
    for mine, theirs in zip(configured.layouts, direct.layouts):
        np.testing.assert_array_equal(mine.model_concentration, theirs.model_concentration)
    np.testing.assert_array_equal(configured.vrr_sine.vrr, direct.vrr_sine.vrr)
