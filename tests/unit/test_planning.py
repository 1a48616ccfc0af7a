"""Planning a configuration: every run estimated, runs still to do, and the disk check before starting."""

import json

import pytest

from engines.config import load_config
from engines.estimates import InsufficientDiskSpace
from engines.planning import (
    check_run_disk_space,
    config_estimates,
    ensure_disk_space,
    estimate_table,
    main,
    measured_cost_model,
    pending,
    preflight,
    run_directory,
)
from tests.conftest import DEFAULT_CONFIG


@pytest.fixture(scope="module")
def estimates():
    return config_estimates(load_config(DEFAULT_CONFIG))


def test_every_run_of_the_default_config_is_estimated(estimates):
    kinds = [e.kind for e in estimates]
    assert kinds.count("jenike") == 15 and kinds.count("silo_flat") == 1
    assert kinds.count("silo_recirculation") == 3 and kinds.count("blender") == 3
    assert all(e.dump_bytes > 0 and e.wall_time_s > 0 for e in estimates)


def test_finished_runs_are_not_pending(estimates, tmp_path):
    done = estimates[0]
    run_dir = run_directory(tmp_path, done)
    assert run_dir == tmp_path / "calibration" / "runs" / done.run_id
    run_dir.mkdir(parents=True)
    (run_dir / "run.json").write_text(json.dumps({}))
    assert pending(estimates, tmp_path) == estimates[1:]


def test_the_disk_check_refuses_runs_that_exceed_the_free_space_given_to_it(estimates, tmp_path):
    needed = sum(e.dump_bytes for e in estimates)
    assert ensure_disk_space(estimates, tmp_path, free=needed + 1000) == pytest.approx(1000)
    with pytest.raises(InsufficientDiskSpace, match=r"need about .* but only .* are free"):
        ensure_disk_space(estimates, tmp_path, free=needed // 2)


def test_one_run_is_checked_where_it_writes_unless_disabled(estimates, tmp_path):
    config = load_config(DEFAULT_CONFIG)
    assert check_run_disk_space(config, estimates[0], tmp_path) > 0
    config["estimates"]["disk_check"] = False
    assert check_run_disk_space(config, estimates[0], tmp_path) is None
    assert estimates[0].run_id in preflight(config, estimates[0], tmp_path)


def test_the_estimate_table_and_command(estimates, capsys):
    table = estimate_table(estimates).splitlines()
    assert table[0].split()[:3] == ["run", "kind", "mpi_ranks"]
    assert table[-1].startswith("total (22 runs)")
    assert main([str(DEFAULT_CONFIG)]) == 0
    assert "runs still to do" in capsys.readouterr().out
    assert main([]) == 2


def test_a_finished_run_without_engine_timing_leaves_the_config_cost_model(estimates, tmp_path):
    run_dir = run_directory(tmp_path, estimates[0])
    run_dir.mkdir(parents=True)
    (run_dir / "run.json").write_text(json.dumps({}))
    assert measured_cost_model(load_config(DEFAULT_CONFIG), estimates, tmp_path) is None
    assert measured_cost_model(load_config(DEFAULT_CONFIG), estimates, tmp_path / "nothing here") is None
