"""The calibration table: one row per sweep point, a point run with several seeds combined, on synthetic summaries."""

import math

import pytest

from siloflow.calibration.table import POINT_COLUMNS, point_table


def _summary(mu, bulk, error, window="steady", lid="rigid", speed=0.03, run="r"):
    return {"run_id": run, "shape": "sphere2", "test": "internal", "wall_material": "", "lid": lid,
            "rolling_friction": 0.0, "restitution": 0.1, "rotation_blocked": False, "particle_friction": mu,
            "shear_velocity": speed, "pour": "configured", "bulk_friction": bulk, "bulk_friction_error": error,
            "window_method": window,
            "n_clumps": 100}


def test_a_point_run_with_three_seeds_is_one_row_with_their_spread():
    rows = point_table([_summary(0.5, 0.50, 0.01, run="a"), _summary(0.1, 0.30, 0.01, run="b"),
                        _summary(0.5, 0.52, 0.01, run="c", window="second half"), _summary(0.5, 0.54, 0.01, run="d"),
                        _summary(0.5, 0.60, 0.02, speed=0.015, run="e")])
    assert [(row["particle_friction"], row["shear_velocity"], row["replicates"]) for row in rows] == [
        (0.1, 0.03, 1), (0.5, 0.03, 3), (0.5, 0.015, 1)]
    seeds = rows[1]
    assert seeds["bulk_friction"] == pytest.approx(0.52)
    # the seeds' standard deviation 0.02 and its standard error 0.02 / sqrt(3) beat the within-run 0.01 / sqrt(3)
    assert seeds["bulk_friction_seed_std"] == pytest.approx(0.02)
    assert seeds["bulk_friction_error"] == pytest.approx(0.02 / math.sqrt(3.0))
    # steady only when every seed was; the run ids differ and are left out
    assert seeds["window_method"] == "second half" and "run_id" not in seeds
    assert rows[0]["window_method"] == "steady" and rows[0]["run_id"] == "b"
    assert list(rows[0])[:8] == list(POINT_COLUMNS[:8])


def test_a_summary_without_a_point_column_is_named():
    summary = _summary(0.5, 0.5, 0.01)
    del summary["shear_velocity"]
    with pytest.raises(KeyError, match="shear_velocity"):
        point_table([summary])
