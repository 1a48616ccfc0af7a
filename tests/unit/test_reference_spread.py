"""The spread between seeds in the validation rows, and the runs that measure it, on synthetic summaries."""

from __future__ import annotations

import math

import pytest

from siloflow.analysis.numerics.reference_spread import (SeedSpread, combine_seeds, floor_errors, floor_table, relative_spread, seed_note, table_spread,
                                               with_reference_spread)
from siloflow.calibration.friction import SECOND_HALF, STEADY
from siloflow.calibration.shear_record import combined_window_method
from siloflow.model.cases import cases_of, reference_runs
from siloflow.model.cases.jenike import jenike_cases
from siloflow.model.cases.jenike_sweep import reference_point, sweep_points
from siloflow.engines.config import validate_config


def _run(flow, index, vrr, problems=()):
    return {"case": {"run_id": f"r{flow}", "depth_m": 0.04}, "flow": flow, "flow_error": 0.01,
            "index": {"0.04": index}, "index_error": {"0.04": 0.05}, "vrr": vrr, "vrr_error": [0.1, 1.0],
            "at_ceiling": False, "n": 10, "problems": list(problems), "vrr_at_ceiling": [False, bool(problems)]}


def test_seeds_combine_into_their_mean_with_the_larger_of_spread_and_within_run_error():
    combined, spread = combine_seeds([_run(1.0, 0.8, [3.0, 9.0]), _run(1.2, 0.6, [3.0, 11.0], ["tilted"])])
    assert combined["flow"] == pytest.approx(1.1)
    # the seeds' standard error s / sqrt(2) = 0.1 beats the propagated within-run error sqrt(2) 0.01 / 2
    assert combined["flow_error"] == pytest.approx(0.1)
    assert combined["index"]["0.04"] == pytest.approx(0.7) and combined["index_error"]["0.04"] == pytest.approx(0.1)
    assert combined["vrr"] == pytest.approx([3.0, 10.0])
    # equal values: the within-run errors propagated, sqrt(0.1^2 + 0.1^2) / 2
    assert combined["vrr_error"][0] == pytest.approx(math.sqrt(0.02) / 2)
    assert combined["vrr_error"][1] == pytest.approx(1.0)
    # other leaves: the first seed's text, a mean of differing counts, the union of lists
    assert combined["case"]["run_id"] == "r1.0" and combined["problems"] == ["tilted"] and combined["n"] == 10
    # a flag per item: true where any seed's is
    assert combined["vrr_at_ceiling"] == [False, True]
    assert spread.seeds == 2
    assert spread[("flow",)] == pytest.approx(math.sqrt(0.02) / 1.1)
    assert spread[("vrr", 0)] == 0.0 and ("case", "depth_m") not in spread


def test_one_seed_passes_through_with_its_within_run_error():
    combined, spread = combine_seeds([_run(1.0, 0.8, [3.0, 9.0])])
    assert combined == _run(1.0, 0.8, [3.0, 9.0]) and spread == {} and spread.seeds == 1
    with pytest.raises(ValueError, match="at least one"):
        combine_seeds([])


def test_a_single_seed_takes_the_reference_s_relative_spread_where_it_is_larger():
    spread = relative_spread([_run(1.0, 0.8, [3.0, 9.0]), _run(1.2, 0.6, [3.0, 11.0])])
    other = _run(2.0, 0.5, [4.0, 20.0])
    other["vrr_error"][1] = math.nan
    floored = floor_errors(other, spread)
    assert floored["flow_error"] == pytest.approx(2.0 * math.sqrt(0.02) / 1.1)
    # the index: 0.5 x 0.2020 = 0.101 > 0.05
    assert floored["index_error"]["0.04"] == pytest.approx(0.5 * math.sqrt(0.02) / 0.7)
    # no spread at the first VRR: its within-run error stays; an unknown error becomes the spread's
    assert floored["vrr_error"][0] == 0.1
    assert floored["vrr_error"][1] == pytest.approx(20.0 * math.sqrt(2.0) / 10.0)
    assert other["flow_error"] == 0.01   # the input is not changed


def test_csv_rows_as_read_count_as_numbers_and_a_combined_table_gives_its_spread():
    rows = [{"shape": "sphere2", "bulk_friction": "0.5", "bulk_friction_error": "0.01", "bulk_friction_seed_std": "0.02",
             "replicates": "3"},
            {"shape": "sphere2", "bulk_friction": "0.6", "bulk_friction_error": "0.005", "replicates": "1"}]
    spread, replicated = table_spread(rows, ("bulk_friction", "bulk_friction_angle_deg"))
    assert replicated == [rows[0]] and spread.seeds == 3 and spread == {("bulk_friction",): pytest.approx(0.04)}
    assert floor_errors(rows[1], spread)["bulk_friction_error"] == pytest.approx(0.024)
    none, _ = table_spread(rows[1:], ("bulk_friction",))
    assert none == {} and none.seeds == 1
    # by default every figure with a seed spread in a replicated row
    assert table_spread(rows)[0] == {("bulk_friction",): pytest.approx(0.04)}


def test_the_seed_note_says_which_error_a_row_carries():
    spread = relative_spread([_run(1.0, 0.8, [3.0, 9.0]), _run(1.2, 0.6, [3.0, 11.0]), _run(1.1, 0.7, [3.0, 10.0])])
    assert seed_note("internal_flow", spread, True).startswith("mean of 3 seeds")
    assert "the 3 seeds of internal_flow" in seed_note("internal_flow", spread, False)
    assert seed_note("x", relative_spread([_run(1.0, 0.8, [3.0, 9.0])]), False) == "one seed: within-run error only"


def test_a_point_is_steady_only_when_every_seed_is():
    assert combined_window_method([STEADY, STEADY]) == STEADY
    assert combined_window_method([STEADY, SECOND_HALF, STEADY]) == SECOND_HALF
    with pytest.raises(ValueError, match="window methods"):
        combined_window_method(["plateau"])


@pytest.mark.parametrize("kind", ["silo_flat", "silo_recirculation", "blender"])
def test_reference_replicates_add_seeds_of_the_first_configuration_only(raw_default_config, kind):
    plain = validate_config(raw_default_config)
    raw_default_config["defaults"]["reference_replicates"] = 3
    config = validate_config(raw_default_config)
    runs, before = cases_of(config, kind), cases_of(plain, kind)
    reference = reference_runs(config, kind)
    # the runs already defined keep their ids; two more of the first configuration, with other seeds
    assert set(before) <= set(runs) and len(runs) == len(before) + 2
    assert reference[0] == next(iter(before)) and set(reference[1:]) == set(runs) - set(before)
    assert len({runs[run].seeds for run in reference}) == 3
    assert reference_runs(plain, kind) == [next(iter(before))]


@pytest.mark.parametrize("kind", ["silo_recirculation", "blender"])
def test_a_case_switched_off_has_no_runs_and_no_reference_whatever_its_seeds(raw_default_config, kind):
    raw_default_config["defaults"]["reference_replicates"] = 3
    raw_default_config[kind] = {"enabled": False}
    config = validate_config(raw_default_config)
    assert cases_of(config, kind) == {} and reference_runs(config, kind) == []


def test_the_jenike_reference_point_runs_with_more_seeds_and_at_a_slower_shear(raw_default_config):
    sweep = raw_default_config.setdefault("jenike", {}).setdefault("sweep", {})
    sweep.update(sliding_friction=[0.1, 0.3, 0.5], rolling_friction=[0.0, 0.1], reference_replicates=3,
                 shear_velocity_sensitivity=[0.01])
    config = validate_config(raw_default_config)
    point = reference_point(config["jenike"]["sweep"])
    assert point["sliding_friction"] == 0.3 and point["rolling_friction"] == 0.0 and point["test"] == "internal"
    extra = [p for p in sweep_points(config["jenike"]["sweep"]) if "replicate" in p or "shear_velocity" in p]
    assert extra == [{**point, "replicate": 1}, {**point, "replicate": 2}, {**point, "shear_velocity": 0.01}]
    cases = jenike_cases(config)
    same = [case for case in cases.values() if case.point == point and case.lid_kind == config["jenike"]["lid"]]
    assert len(same) == 4 and len({c.run_id for c in same}) == 4
    configured = config["jenike"]["shear"]["velocity"]
    seeded = [case for case in same if case.shear_velocity == configured]
    assert len(seeded) == 3 and len({case.seeds for case in seeded}) == 3
    (slow,) = [case for case in same if case.shear_velocity == 0.01]
    # the same travel at the slower speed: proportionally more steps
    fast = seeded[0]
    assert slow.shear_steps == pytest.approx(fast.shear_steps * configured / 0.01, rel=1e-3)
    assert slow.seeds == fast.seeds


def test_the_reference_s_seeds_are_combined_and_the_others_floored_in_order():
    runs = [_run(1.0, 0.8, [3.0, 9.0]), _run(2.0, 0.5, [4.0, 20.0]), _run(1.2, 0.6, [3.0, 11.0])]
    combined, others, spread = with_reference_spread(runs, ["a", "b", "c"], {"a", "c"})
    assert combined["flow"] == pytest.approx(1.1) and spread.seeds == 2
    ((run, floored),) = others
    assert run == "b" and floored["flow_error"] == pytest.approx(2.0 * math.sqrt(0.02) / 1.1)


def test_a_table_s_rows_run_once_are_floored_by_the_replicated_rows():
    rows = [{"flow": 2.0, "flow_error": 0.01, "replicates": 1},
            {"flow": 1.0, "flow_error": 0.05, "flow_seed_std": 0.1, "replicates": 3}]
    floored, spread, replicated = floor_table(rows)
    assert replicated == [rows[1]] and spread.seeds == 3
    assert floored == [{"flow": 2.0, "flow_error": pytest.approx(0.2), "replicates": 1}, rows[1]]


def test_the_seed_note_says_how_the_spread_enters_the_error():
    from_three = SeedSpread({("flow",): 0.02}, 3)
    assert seed_note("base", SeedSpread({}, 1), True) == "one seed: within-run error only"
    assert seed_note("base", from_three, True) == ("mean of 3 seeds; its error is the larger of the standard error of "
                                                    "their mean and the within-run errors; 2 degrees of freedom")
    assert seed_note("base", from_three, False) == (
        "one seed; its error is the larger of its within-run error and its value times the standard deviation between "
        "the 3 seeds of base relative to their mean; 2 degrees of freedom")
