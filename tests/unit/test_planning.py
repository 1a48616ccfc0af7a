"""Planning a configuration: every run estimated, runs still to do, the disk check before starting, and the
estimates of finished runs against what they took."""

import json
import math

import pytest

import siloflow.engines.planning as planning
from siloflow.cli.main import main
from siloflow.model.record import RunRecord
from siloflow.engines.config import load_config
from siloflow.model.cost import CostModel, MeasuredWork, RunEstimate
from siloflow.engines.estimates import InsufficientDiskSpace
from siloflow.engines.planning import (
    COMPARISON_COLUMNS,
    calibrated_model,
    check_run_disk_space,
    comparison_rows,
    comparison_total,
    config_estimates,
    cost_model,
    ensure_disk_space,
    estimate_table,
    estimate_report,
    measured_cost_model,
    measured_runs,
    pending,
    preflight,
    run_directory,
    run_priorities,
    run_steps,
)
from tests.conftest import DEFAULT_CONFIG


@pytest.fixture(scope="module")
def estimates():
    return config_estimates(load_config(DEFAULT_CONFIG))


def test_every_run_of_the_default_config_is_estimated(estimates):
    kinds = [e.kind for e in estimates]
    # the demo tier: 2 Jenike tests (internal, aluminium) x 3 sliding x 2 rolling frictions, the two blending silos (the thin one
    # is make verify's) and two blenders (diverging and converging)
    assert kinds.count("jenike") == 12 and kinds.count("silo_flat") == 1
    assert kinds.count("silo_recirculation") == 2 and kinds.count("blender") == 2
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


def test_the_estimate_table_and_command(estimates, tmp_path, capsys):
    table = estimate_table(estimates).splitlines()
    assert table[0].split()[:3] == ["run", "kind", "mpi_ranks"]
    assert len(table) == len(estimates) + 2 and table[-1].startswith(f"total ({len(estimates)} runs)")
    command = ["estimate", "--config", str(DEFAULT_CONFIG), "--directory", str(tmp_path)]
    assert main(command) == 0
    out = capsys.readouterr().out
    assert "runs still to do" in out and "Validation groups (make validate GROUP=<name>) on 2 core(s)" in out
    assert f"free for {tmp_path / 'results'}/" in out
    assert main([*command, "--cores", "8"]) == 0
    assert "on 8 core(s)" in capsys.readouterr().out
    assert main([*command, "--cores", "0"]) == 2
    assert "argument --cores: takes a whole number of cores >= 1, got '0'" in capsys.readouterr().err
    assert main([]) == 2


def test_the_estimate_command_refuses_a_config_it_cannot_read_without_a_traceback(tmp_path, capsys):
    """`make estimate` on a file that asks Snakemake to evaluate it (YTE) evaluates nothing and says why."""
    config = tmp_path / "yte.yaml"
    marker = tmp_path / "evaluated"
    config.write_text(f"__use_yte__: true\ndefaults:\n  seed: ?__import__('pathlib').Path('{marker}').touch() or 1\n")
    assert main(["estimate", "--config", str(config)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"siloflow estimate: invalid configuration: {config.resolve()}: sets __use_yte__")
    assert "Traceback" not in err and len(err.splitlines()) == 1
    assert not marker.exists()


def test_a_finished_run_without_engine_timing_leaves_the_config_cost_model(estimates, tmp_path):
    run_dir = run_directory(tmp_path, estimates[0])
    run_dir.mkdir(parents=True)
    (run_dir / "run.json").write_text(json.dumps({}))
    assert measured_cost_model(load_config(DEFAULT_CONFIG), estimates, tmp_path) is None
    assert measured_cost_model(load_config(DEFAULT_CONFIG), estimates, tmp_path / "nothing here") is None


def _estimate(run_id: str, sphere_steps: float, wall_time_s: float, mpi_ranks: int = 1, steps: int = 1000) -> RunEstimate:
    return RunEstimate(run_id=run_id, kind="silo_flat", clumps=10, spheres=20, steps=steps, sphere_steps=sphere_steps,
                       simulated_time_s=0.01, wall_time_s=wall_time_s, dump_frames=1, dump_bytes=1000,
                       mpi_ranks=mpi_ranks)


def test_comparison_rows_set_each_estimate_against_its_measurement():
    measured = [(_estimate("a", 2.0e6, 1.0), MeasuredWork(1.25, 1.6e6)),
                (_estimate("b", 1.0e6, 3.0, mpi_ranks=2), MeasuredWork(8.0, 1.0e6))]
    rows = comparison_rows(measured, [800, None])
    assert [list(row) for row in rows] == [list(COMPARISON_COLUMNS)] * 2
    assert rows[0] == {"run": "a", "kind": "silo_flat", "estimated_cpu_s": 1.0, "measured_cpu_s": 1.25, "ratio": 0.8,
                       "estimated_sphere_steps": 2.0e6, "measured_sphere_steps": 1.6e6, "work_ratio": 1.25,
                       "steps_ratio": 1.25, "measured_rate": 1.28e6}
    # two ranks: the estimate's core time is twice its wall time; an unknown step count leaves the steps ratio out
    assert rows[1]["estimated_cpu_s"] == 6.0 and rows[1]["ratio"] == 0.75 and math.isnan(rows[1]["steps_ratio"])
    # total: (1 + 6) s estimated against (1.25 + 8) s measured, in core-hours
    assert comparison_total(measured) == pytest.approx((7.0 / 3600, 9.25 / 3600, 7.0 / 9.25), rel=1e-12)
    with pytest.raises(ValueError, match="steps has 1 entries for 2 runs"):
        comparison_rows(measured, [1])


def test_run_steps_is_the_last_step_of_the_run_record(estimates, tmp_path):
    run_dir = run_directory(tmp_path, estimates[0])
    run_dir.mkdir(parents=True)
    assert run_steps(tmp_path, estimates[0]) is None
    (run_dir / "run.json").write_text(json.dumps({}))
    assert run_steps(tmp_path, estimates[0]) is None  # not a valid record
    record = RunRecord(engine="liggghts", case="jenike", run_id=estimates[0].run_id, timestep_s=1e-5, n_clumps=10,
                       n_frames=0, mpi_ranks=1, stages={"fill": {"step": 400.0}, "shear": {"step": 1200.0}})
    (run_dir / "run.json").write_text(record.to_json())
    assert run_steps(tmp_path, estimates[0]) == 1200


class _TimedEngine:
    """An engine whose finished runs each took 90 CPU s for 3e8 sphere-steps."""

    def measured_work(self, run_dir):
        return MeasuredWork(90.0, 3.0e8)


def test_finished_runs_are_compared_with_their_estimates(estimates, tmp_path, monkeypatch, capsys):
    config = load_config(DEFAULT_CONFIG)
    monkeypatch.setattr(planning, "engine_for", lambda config, kind: _TimedEngine())
    done = estimates[:2]
    for estimate in done:
        run_dir = run_directory(tmp_path, estimate)
        run_dir.mkdir(parents=True)
        (run_dir / "run.json").write_text(json.dumps({}))
    assert measured_runs(config, estimates, tmp_path) == [(e, MeasuredWork(90.0, 3.0e8)) for e in done]
    model, count = measured_cost_model(config, estimates, tmp_path)
    assert (model.seconds_per_sphere_step, count) == (3.0e-7, 2)
    out = estimate_report(config, str(DEFAULT_CONFIG), tmp_path, cores=2)
    assert "3e-07 s per sphere-step on one core, measured on this machine, the median of 2 finished run(s)" in out
    lines = out.splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("run ") and "measured_cpu" in line)
    assert lines[header].split() == ["run", "kind", "estimated_cpu", "measured_cpu", "ratio", "estimated_sphere_steps",
                                     "measured_sphere_steps", "work_ratio", "steps_ratio", "measured_rate"]
    assert [line.split()[0] for line in lines[header + 1:header + 3]] == [e.run_id for e in done]
    # estimated with the config's rate, as before the runs
    apriori = cost_model(config).seconds_per_sphere_step
    estimated = sum(e.sphere_steps for e in done) * apriori / 3600
    assert lines[header + 3] == (f"total: estimated {estimated:.3g} core-h, measured {180 / 3600:.3g} core-h, "
                                 f"ratio {estimated * 3600 / 180:.3g}")
    assert lines[header + 4] == (f"total with the measured median 3e-07 s per sphere-step: estimated "
                                 f"{estimated * 3e-7 / apriori:.3g} core-h, ratio {estimated * 3600 / 180 * 3e-7 / apriori:.3g}")


def test_without_finished_runs_only_the_estimates_are_printed(tmp_path):
    out = estimate_report(load_config(DEFAULT_CONFIG), str(DEFAULT_CONFIG), tmp_path, cores=2)
    assert "no run of it has finished here yet" in out and "measured_cpu" not in out and "total: estimated" not in out


def _timed(kind: str, wall_time_s: float, mpi_ranks: int = 1) -> RunEstimate:
    return RunEstimate(run_id=f"{kind}-{wall_time_s}", kind=kind, clumps=1, spheres=1, steps=1, sphere_steps=1.0,
                       simulated_time_s=1.0, wall_time_s=wall_time_s, dump_frames=0, dump_bytes=0, mpi_ranks=mpi_ranks)


def test_the_kind_with_the_longest_run_gets_the_highest_priority():
    estimates = [_timed("jenike", 30.0), _timed("jenike", 40.0), _timed("blender", 300.0), _timed("blender", 500.0),
                 _timed("silo_flat", 200.0, mpi_ranks=4), _timed("silo_recirculation", 450.0)]
    # silo_flat: 800 CPU s on 4 ranks outranks the blender's 500
    assert run_priorities(estimates) == {"jenike": 1, "silo_recirculation": 2, "blender": 3, "silo_flat": 4}
    assert run_priorities([]) == {}


def test_each_measured_kind_takes_its_own_cost_and_an_unmeasured_one_keeps_the_config_s():
    def timed(run_id, kind, seconds_per_sphere_step):
        estimate = RunEstimate(run_id=run_id, kind=kind, clumps=10, spheres=20, steps=100, sphere_steps=1.0e6,
                               simulated_time_s=0.01, wall_time_s=1.0, dump_frames=1, dump_bytes=1000, mpi_ranks=1)
        return estimate, MeasuredWork(seconds_per_sphere_step * 1.0e6, 1.0e6)

    model = CostModel(seconds_per_sphere_step=4.0e-7, kind_seconds_per_sphere_step={"jenike": 8.0e-7, "blender": 6.0e-7})
    measured = [timed("s1", "silo_flat", 5.0e-7), timed("s2", "silo_flat", 7.0e-7), timed("r1", "silo_recirculation", 9.0e-7),
                timed("j1", "jenike", 1.2e-6)]
    calibrated = calibrated_model(model, measured)
    # the overall median of 5, 7, 9 and 12 (x 1e-7)
    assert calibrated.seconds_per_sphere_step == pytest.approx(8.0e-7, rel=1e-12)
    assert calibrated.seconds_for("silo_flat") == pytest.approx(6.0e-7, rel=1e-12)
    assert calibrated.seconds_for("jenike") == pytest.approx(1.2e-6, rel=1e-12)
    # the blender has not run: the cost the config gives it; the recirculating silo its own measured one
    assert calibrated.seconds_for("blender") == 6.0e-7
    assert calibrated.seconds_for("silo_recirculation") == pytest.approx(9.0e-7, rel=1e-12)
    with pytest.raises(ValueError, match="keys are case kinds' names, got ''"):
        CostModel(kind_seconds_per_sphere_step={"": 1.0e-6})


def test_a_kind_s_own_cost_sets_its_estimates(estimates):
    config = load_config(DEFAULT_CONFIG)
    config["estimates"]["seconds_per_sphere_step_by_case"] = {"jenike": 2.0 * config["estimates"]["seconds_per_sphere_step"]}
    doubled = {e.run_id: e for e in config_estimates(config)}
    for estimate in estimates:
        factor = 2.0 if estimate.kind == "jenike" else 1.0
        assert doubled[estimate.run_id].wall_time_s == pytest.approx(factor * estimate.wall_time_s, rel=1e-12)
