"""Replicate runs combined: exact means, seed spreads and the larger-of error rule."""

import math

import pytest

from siloflow.analysis.numerics.replicates import combine_replicates, replicate_error


def test_one_seed_keeps_its_within_run_error():
    mean, error, seed_std = replicate_error([2.0], [0.3])
    assert (mean, error) == (2.0, 0.3)
    assert math.isnan(seed_std)


def test_seed_spread_wins_when_larger_than_the_within_run_errors():
    # values 1, 2, 3: s = 1, s/sqrt(3) = 0.57735; within-run sqrt(3 * 0.1^2)/3 = 0.057735
    mean, error, seed_std = replicate_error([1.0, 2.0, 3.0], [0.1, 0.1, 0.1])
    assert mean == pytest.approx(2.0)
    assert seed_std == pytest.approx(1.0)
    assert error == pytest.approx(1.0 / math.sqrt(3.0))


def test_within_run_errors_win_when_the_seeds_agree_by_chance():
    # values 2, 2: s = 0; within-run sqrt(0.3^2 + 0.4^2)/2 = 0.25
    mean, error, seed_std = replicate_error([2.0, 2.0], [0.3, 0.4])
    assert (mean, seed_std) == (2.0, 0.0)
    assert error == pytest.approx(0.25)


def test_unknown_within_run_error_falls_back_to_the_seed_spread():
    mean, error, _ = replicate_error([1.0, 3.0], [math.nan, 0.1])
    assert mean == 2.0
    assert error == pytest.approx(math.sqrt(2.0) / math.sqrt(2.0))


def test_lengths_must_match():
    with pytest.raises(ValueError, match="one error per replicate"):
        replicate_error([1.0, 2.0], [0.1])


def test_rows_of_one_configuration_combine_and_others_pass_through():
    rows = [
        {"configuration": "straight", "run_id": "a", "flow": 1.0, "flow_error": 0.01, "at_ceiling": False},
        {"configuration": "converging", "run_id": "b", "flow": 5.0, "flow_error": 0.2, "at_ceiling": False},
        {"configuration": "straight", "run_id": "c", "flow": 3.0, "flow_error": 0.01, "at_ceiling": True},
    ]
    combined = combine_replicates(rows, ["configuration"])
    assert [row["configuration"] for row in combined] == ["straight", "converging"]
    straight, converging = combined
    assert straight["replicates"] == 2
    assert straight["flow"] == pytest.approx(2.0)
    assert straight["flow_seed_std"] == pytest.approx(math.sqrt(2.0))
    assert straight["flow_error"] == pytest.approx(1.0)  # s/sqrt(2) = sqrt(2)/sqrt(2)
    assert straight["at_ceiling"] is True
    assert "run_id" not in straight  # differs between the replicates
    assert converging == {**rows[1], "replicates": 1}


def test_a_replicate_without_the_figure_is_left_out_of_its_mean():
    rows = [{"k": 1, "vrr": 10.0}, {"k": 1, "vrr": math.nan}, {"k": 1, "vrr": 20.0}]
    combined, = combine_replicates(rows, ["k"])
    assert combined["vrr"] == pytest.approx(15.0)
    assert combined["replicates"] == 3


def test_missing_key_column_is_named():
    with pytest.raises(KeyError, match="configuration"):
        combine_replicates([{"flow": 1.0}], ["configuration"])
