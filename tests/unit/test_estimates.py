"""Run estimates before a run starts: steps, sphere-steps stage by stage, times, dump frames, disk space,
calibration from engine logs, formatting."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import pytest

from siloflow.model.cases.blender import blender_cases, build_blender_case
from siloflow.model.cases.silo_recirculation import recirculation_cases
from siloflow.engines.config import load_config
from tests.repo import REPO_ROOT
from siloflow.analysis.numerics.flow import beverloo_mass_flow_rate
from siloflow.model.cost import (
    CostModel,
    MeasuredWork,
    RunEstimate,
    StageWork,
    beverloo_clump_rate,
    drain_sphere_steps,
    dump_frames,
    estimate_run,
    on_ranks,
    parallel_speedup,
    pour_sphere_steps,
    wall_time,
)
from siloflow.model.cases.silo_cost import (
    estimate_blender_case,
    estimate_recirculation_case,
    estimate_silo_case,
    silo_run_steps,
    sink_fall_time,
)
from siloflow.model.cases.jenike_cost import estimate_jenike_case, jenike_levelled_clumps, jenike_run_steps
from siloflow.engines.estimates import (
    ESTIMATE_COLUMNS,
    InsufficientDiskSpace,
    check_disk_space,
    estimate_rows,
    format_bytes,
    format_duration,
    total_dump_bytes,
)
from siloflow.model.cases.kinds import CASE_KINDS, configured_kinds
from siloflow.model.cases.jenike import FILL_SOLID_FRACTION, build_jenike_case
from siloflow.engines.liggghts.cost import (StageCost, TimedRun, calibrate_cost_model, elapsed_seconds, measured_work, stage_costs,
                                   timed_runs)
from siloflow.engines.interface import engine_named
from siloflow.engines.liggghts.run import LOG_NAME, RESUME_STEM
from siloflow.engines.run_files import FAILED_ATTEMPTS
from siloflow.model.cases.silo_flat import build_silo_case

JENIKE_POINT = {
    "shape": "sphere2",
    "test": "internal",
    "sliding_friction": 0.5,
    "rolling_friction": 0.1,
    "restitution": 0.1,
    "rotation_blocked": False,
}

#: Settling counted at its longest time, the closed form the tests compare with.
WORST_CASE = CostModel(settle_fraction=1.0)


@pytest.fixture(scope="module")
def config() -> dict:
    return load_config(REPO_ROOT / "config" / "config.yaml")


def _silo_like(**overrides) -> SimpleNamespace:
    """A hand-made silo case: 100 two-sphere clumps poured in 4 batches of 25, 200 steps apart, over a fill of 1000
    steps; 4 x 50 settle steps, 2000 discharge steps of 1 ms through a 20 mm slot in a silo 0.1 m wide, 10 mm deep,
    filled 0.1 m high (10^6 clumps per m^3), clumps 4 mm across, leaving 20 mm below the outlet."""
    values = dict(
        run_id="silo-test",
        fill=SimpleNamespace(n_clumps=100, fill_steps=1000, clumps_per_insertion=25, insert_every=200),
        spheres_per_clump=2, settle_check_steps=50, settle_max_checks=4, discharge_steps=2000, dump_every=300,
        timestep=1.0e-3, width=0.1, depth=0.01, fill_height=0.1, outlet_width=0.02,
        particle=SimpleNamespace(equivalent_diameter=0.004), sink_depth=0.02, gravity=9.81,
    )
    values.update(overrides)
    return SimpleNamespace(**values)


#: The hand-made silo's discharge: Beverloo's clumps per second, 10^6 / m^3 * 0.58 sqrt(g) L (B0 - 1.5 d)^1.5, as
#: spheres per step; the first clumps leave after falling 20 mm from rest.
SILO_LIKE_RATE = 2 * 1.0e6 * 0.58 * math.sqrt(9.81) * 0.01 * (0.02 - 1.5 * 0.004) ** 1.5 * 1.0e-3
SILO_LIKE_DELAY = math.sqrt(2 * 0.02 / 9.81) / 1.0e-3
SILO_LIKE_DISCHARGE = 200 * 2000 - 0.5 * SILO_LIKE_RATE * (2000 - SILO_LIKE_DELAY) ** 2
#: Its pour: 25, 50, 75, 100 clumps for 200 steps each, then 100 for the last 200 steps (two spheres per clump).
SILO_LIKE_FILL = 2 * ((25 + 50 + 75 + 100) * 200 + 100 * 200)


# ---------------------------------------------------------------------------------------------- model


def test_cost_model_defaults_are_the_measured_values():
    model = CostModel()
    assert model.seconds_per_sphere_step == 5.0e-7
    assert model.bytes_per_sphere_per_dump == 128
    assert model.dump_header_bytes == 1024
    assert model.parallel_efficiency == 0.8


@pytest.mark.parametrize(
    "field, value",
    [("seconds_per_sphere_step", 0.0), ("bytes_per_sphere_per_dump", -1.0), ("contact_bytes_per_sphere_per_dump", float("nan")),
     ("parallel_efficiency", 0.0), ("parallel_efficiency", 1.5), ("dump_header_bytes", float("inf"))],
)
def test_cost_model_refuses_impossible_values_and_names_them(field, value):
    with pytest.raises(ValueError, match=field):
        CostModel(**{field: value})


@pytest.mark.parametrize("ranks, speedup", [(1, 1.0), (2, 1.6), (4, 2.56), (8, 4.096)])
def test_parallel_speedup_loses_the_efficiency_per_doubling(ranks, speedup):
    assert parallel_speedup(ranks, 0.8) == pytest.approx(speedup, rel=1e-12)
    # wall = serial / (ranks * efficiency^log2(ranks))
    assert wall_time(100.0, ranks, CostModel()) == pytest.approx(100.0 / speedup, rel=1e-12)


def test_perfect_efficiency_divides_by_the_ranks():
    assert wall_time(90.0, 3, CostModel(parallel_efficiency=1.0)) == pytest.approx(30.0, rel=1e-12)


def test_a_run_on_more_ranks_does_the_same_work_faster():
    one = RunEstimate(run_id="r", kind="silo_flat", clumps=10, spheres=20, steps=100, sphere_steps=2000.0,
                      simulated_time_s=0.1, wall_time_s=3600.0, dump_frames=3, dump_bytes=7, mpi_ranks=1)
    model = CostModel(parallel_efficiency=0.9)
    two = on_ranks(one, 2, model)
    # 2 * 0.9: 1.8 times as fast; 4 ranks: 4 * 0.81 = 3.24
    assert (two.mpi_ranks, two.wall_time_s) == (2, pytest.approx(2000.0, rel=1e-12))
    assert two.core_seconds == pytest.approx(4000.0, rel=1e-12)
    assert on_ranks(two, 4, model).wall_time_s == pytest.approx(3600.0 / 3.24, rel=1e-12)
    assert on_ranks(two, 1, model).wall_time_s == pytest.approx(3600.0, rel=1e-12)
    assert (two.sphere_steps, two.dump_bytes, two.run_id) == (2000.0, 7, "r")


@pytest.mark.parametrize("ranks", [0, -2, 1.5, True])
def test_parallel_speedup_refuses_bad_rank_counts(ranks):
    with pytest.raises(ValueError, match="mpi_ranks"):
        parallel_speedup(ranks, 0.8)


# ---------------------------------------------------------------------------------------------- calibration


SYNTHETIC_LOG = """\
LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)
Loop time of 4 on 1 procs for 1000 steps with 2000 atoms, finish time Sat Nov 21 12:23:30 2026
Loop time of 6.21e-07 on 1 procs for 0 steps with 13078 atoms, finish time Sat Nov 21 15:27:18 2026
Pair  time (%) = 1.54284 (31.0069)
Loop time of 3 on 2 procs for 500 steps with 4000 atoms
Loop time of 1.5 on 1 procs for 100 steps with 0 atoms
"""


def test_calibration_without_thermo_rows_counts_each_run_at_its_final_atoms():
    # (4 * 1 + 6.21e-7 + 3 * 2 + 1.5) / (1000 * 2000 + 500 * 4000): every run's CPU time counts, that of the run
    # with 0 atoms too (the estimate has to cover it); without rows a run's steps count at its line's atoms
    base = CostModel(bytes_per_sphere_per_dump=100.0, parallel_efficiency=0.9)
    model = calibrate_cost_model(SYNTHETIC_LOG, base)
    assert model.seconds_per_sphere_step == pytest.approx((4.0 + 6.21e-7 + 6.0 + 1.5) / 4.0e6, rel=1e-12)
    assert dataclasses.replace(model, seconds_per_sphere_step=base.seconds_per_sphere_step) == base


def _thermo(rows) -> str:
    """A thermo block of (step, atoms) rows, two spheres per clump."""
    lines = ["    Step    Atoms           Time       n_clumps       ke_per_c            CPU"]
    lines += [f"{step:8d} {atoms:8d} {step * 1e-5:14.8g} {atoms // 2:14d} {1e-9:14.8g} {0.0:14.8g}" for step, atoms in rows]
    return "\n".join(lines) + "\n"


#: A pour from 0 to 1000 atoms over 1000 steps, one row every 100 steps, then a drain from 1000 to 200 atoms over
#: 400 steps after which the count stays for 200 steps.
POUR_AND_DRAIN_LOG = (
    _thermo([(step, step) for step in range(0, 1001, 100)])
    + "Loop time of 2 on 1 procs for 1000 steps with 1000 atoms, finish time Thu Nov 26 16:28:43 2026\n"
    + "SILOFLOW opened step=1000 time=0.01 clumps=500 ke_per_clump=1e-13\n"
    + _thermo([(1000, 1000), (1200, 600), (1400, 200), (1600, 200)])
    + "Loop time of 3 on 2 procs for 600 steps with 200 atoms\n"
)


def test_a_linear_pour_integrates_to_half_its_final_count_times_its_steps():
    runs = list(timed_runs(POUR_AND_DRAIN_LOG))
    assert runs[0] == TimedRun((), 2.0, 1000, 1000 * 1000 / 2)
    # drain: (1000 + 600) / 2 * 200 + (600 + 200) / 2 * 200 + 200 * 200, not 200 atoms * 600 steps
    assert runs[1] == TimedRun(("opened",), 6.0, 600, 160_000.0 + 80_000.0 + 40_000.0)


def test_calibration_counts_the_atoms_over_time_not_at_the_end():
    model = calibrate_cost_model(POUR_AND_DRAIN_LOG)
    assert model.seconds_per_sphere_step == pytest.approx((2.0 + 6.0) / (500_000 + 280_000), rel=1e-12)
    # what dividing by the final counts gave: 8 / (1000 * 1000 + 200 * 600)
    assert model.seconds_per_sphere_step != pytest.approx(8.0 / 1_120_000, rel=1e-3)


def test_steps_the_rows_do_not_span_count_at_the_final_atoms():
    text = _thermo([(0, 100), (100, 300)]) + "Loop time of 1 on 1 procs for 150 steps with 300 atoms\n"
    assert list(timed_runs(text)) == [TimedRun((), 1.0, 150, 20_000.0 + 50 * 300)]


def test_a_run_cut_off_before_its_loop_time_counts_for_nothing():
    cut = POUR_AND_DRAIN_LOG + _thermo([(1600, 200), (1700, 200)]) + "ERROR: Lost atoms\n"
    assert list(timed_runs(cut)) == list(timed_runs(POUR_AND_DRAIN_LOG))


def test_measured_work_adds_the_attempts():
    resumed = _thermo([(1500, 200), (1600, 200)]) + "Loop time of 0.5 on 1 procs for 100 steps with 200 atoms\n"
    work = measured_work([POUR_AND_DRAIN_LOG, resumed])
    assert work == MeasuredWork(8.5, 780_000.0 + 20_000.0)
    assert work.seconds_per_sphere_step == pytest.approx(8.5 / 800_000, rel=1e-12)
    assert measured_work(["no timing\n"]) is None
    # both attempts in one text, the first cut off after step 1700: the resumed run's first row goes back, and the
    # rows of the run that never finished count for nothing
    cut = POUR_AND_DRAIN_LOG + _thermo([(1600, 200), (1700, 200)])
    assert measured_work([cut + resumed]) == work


def _timed_thermo(cpus) -> str:
    """A thermo block whose rows carry the given ``cpu`` column (s since its ``run`` began), 100 steps apart."""
    lines = ["    Step    Atoms           Time       n_clumps       ke_per_c            CPU"]
    lines += [f"{100 * i:8d} {200:8d} {i * 1e-3:14.8g} {100:14d} {1e-9:14.8g} {cpu:14.8g}" for i, cpu in enumerate(cpus)]
    return "\n".join(lines) + "\n"


def test_the_elapsed_time_of_a_cut_off_attempt_counts_its_last_row():
    finished = _timed_thermo([0.0, 1.5, 3.9]) + "Loop time of 4 on 2 procs for 200 steps with 200 atoms\n"
    # a finished run counts its Loop time (wall time, not times the ranks); the run cut off its last row's cpu
    assert elapsed_seconds(finished) == 4.0
    assert elapsed_seconds(finished + _timed_thermo([0.0, 2.25]) + "ERROR: killed\n") == 6.25
    # a garbled Loop time falls back on the run's last row
    assert elapsed_seconds(_timed_thermo([0.0, 0.75]) + "Loop time of 1.2.3 on 1 procs for 100 steps with 200 atoms\n") == 0.75
    assert elapsed_seconds("no thermo\n") == 0.0


def test_a_run_s_attempts_before_its_last_add_up(tmp_path):
    engine = engine_named("liggghts")
    (tmp_path / LOG_NAME).write_text(_timed_thermo([0.0, 99.0]) + "Loop time of 99.5 on 1 procs for 100 steps with 200 atoms\n")
    assert engine.earlier_attempts_seconds(tmp_path) == 0.0  # made in one go: the benchmark timed it all
    # two attempts set aside to start afresh, the second with a resumption of its own
    first, second = tmp_path / FAILED_ATTEMPTS / "20261129T073502Z", tmp_path / FAILED_ATTEMPTS / "20261129T080427Z"
    first.mkdir(parents=True)
    second.mkdir()
    (first / LOG_NAME).write_text(_timed_thermo([0.0, 10.0]))
    (second / LOG_NAME).write_text(_timed_thermo([0.0, 3.0]) + "Loop time of 3.5 on 1 procs for 100 steps with 200 atoms\n")
    (second / f"{RESUME_STEM}1.{LOG_NAME}").write_text(_timed_thermo([0.0, 1.25]))
    assert engine.earlier_attempts_seconds(tmp_path) == 10.0 + 3.5 + 1.25
    # the run then resumed in place: its first attempt counts, its last (the benchmark's) does not
    (tmp_path / LOG_NAME).write_text(_timed_thermo([0.0, 99.0]))
    (tmp_path / f"{RESUME_STEM}1.{LOG_NAME}").write_text(_timed_thermo([0.0, 7.0]))
    assert engine.earlier_attempts_seconds(tmp_path) == 10.0 + 3.5 + 1.25 + 99.0
    assert engine.earlier_attempt_seconds(tmp_path) == [10.0, 3.5, 1.25, 99.0]  # each, oldest first


def test_measured_work_refuses_impossible_values():
    with pytest.raises(ValueError, match="cpu_seconds"):
        MeasuredWork(-1.0, 10.0)
    assert math.isnan(MeasuredWork(1.0, 0.0).seconds_per_sphere_step)


def test_calibration_of_a_real_log_line_with_mpi():
    # no thermo rows: the run's steps count at the line's atoms
    line = "Loop time of 296.734 on 4 procs for 103983 steps with 2134 atoms, finish time Sat Nov 21 15:32:15 2026\n"
    model = calibrate_cost_model(line)
    assert model.seconds_per_sphere_step == pytest.approx(296.734 * 4 / (103983 * 2134), rel=1e-12)


@pytest.mark.parametrize(
    "text", ["", "no timing here\n", "Loop time of 6.2e-07 on 1 procs for 0 steps with 13078 atoms\n"]
)
def test_calibration_without_usable_loop_lines_is_refused(text):
    with pytest.raises(ValueError, match="Loop time of"):
        calibrate_cost_model(text)


# ---------------------------------------------------------------------------------------------- core estimate


def test_estimate_run_exact_numbers():
    estimate = estimate_run("r", "silo_flat", clumps=1000, spheres_per_clump=2, steps=10_000, timestep=1.0e-5,
                            dump_frames=11)
    assert estimate.spheres == 2000
    assert estimate.simulated_time_s == pytest.approx(0.1, rel=1e-12)
    # 2000 spheres x 10,000 steps x 0.5 microseconds: without stages the count holds over the run
    assert estimate.sphere_steps == 2.0e7
    assert estimate.stages == (StageWork("run", 10_000, 2.0e7),)
    assert estimate.wall_time_s == pytest.approx(10.0, rel=1e-12)
    # 11 dumps of 1024 + 2000 x 128 bytes (no frame cache: it did not pay, make bench)
    assert estimate.dump_bytes == 11 * (1024 + 2000 * 128) == 2_827_264
    assert (estimate.run_id, estimate.kind, estimate.clumps, estimate.steps, estimate.dump_frames,
            estimate.mpi_ranks) == ("r", "silo_flat", 1000, 10_000, 11, 1)


def test_estimate_run_with_ranks_lid_spheres_and_contacts():
    estimate = estimate_run("r", "jenike", clumps=100, spheres_per_clump=3, steps=1000, timestep=2.0e-6,
                            dump_frames=5, mpi_ranks=2, extra_spheres=20, contact_frames=4)
    assert estimate.spheres == 320
    assert estimate.wall_time_s == pytest.approx(320 * 1000 * 5.0e-7 / 1.6, rel=1e-12)
    assert estimate.core_seconds == pytest.approx(2 * estimate.wall_time_s, rel=1e-15)
    assert estimate.dump_bytes == 5 * (1024 + 320 * 128) + 4 * (1024 + 320 * 200)


def test_estimate_run_costs_the_work_of_its_stages():
    stages = (StageWork("fill", 600, 60_000.0), StageWork("shear", 400, 128_000.0))
    estimate = estimate_run("r", "jenike", clumps=100, spheres_per_clump=3, steps=1000, timestep=2.0e-6,
                            dump_frames=5, extra_spheres=20, stages=stages)
    assert estimate.sphere_steps == 188_000.0 and estimate.stages == stages
    assert estimate.wall_time_s == pytest.approx(188_000 * 5.0e-7, rel=1e-12)
    # the disk still counts every dump at the most spheres the run holds
    assert estimate.spheres == 320 and estimate.dump_bytes == 5 * (1024 + 320 * 128)
    with pytest.raises(ValueError, match="add up to 1000, not to steps = 999"):
        estimate_run("r", "jenike", clumps=100, spheres_per_clump=3, steps=999, timestep=2.0e-6, dump_frames=5,
                     stages=stages)


@pytest.mark.parametrize("steps, sphere_steps, message", [(-1, 0.0, "steps"), (1.5, 0.0, "steps"),
                                                          (10, -1.0, "sphere_steps"), (10, math.inf, "sphere_steps")])
def test_stage_work_refuses_impossible_values(steps, sphere_steps, message):
    with pytest.raises(ValueError, match=message):
        StageWork("fill", steps, sphere_steps)


def test_stage_work_mean_spheres():
    assert StageWork("settle", 400, 1_000_000.0).mean_spheres == 2500.0
    assert StageWork("open", 0, 0.0).mean_spheres == 0.0


@pytest.mark.parametrize(
    "changes, message",
    [({"kind": ""}, "kind must name a case kind"), ({"mpi_ranks": 0}, "mpi_ranks"),
     ({"timestep": 0.0}, "timestep"), ({"clumps": -1}, "clumps"), ({"spheres_per_clump": 0}, "spheres_per_clump"),
     ({"dump_frames": 2.5}, "dump_frames")],
)
def test_estimate_run_refuses_bad_input_and_names_it(changes, message):
    arguments = dict(run_id="r", kind="silo_flat", clumps=10, spheres_per_clump=2, steps=100, timestep=1e-5,
                     dump_frames=2)
    arguments.update(changes)
    with pytest.raises(ValueError, match=message):
        estimate_run(**arguments)


@pytest.mark.parametrize("steps, every, frames", [(0, 10, 1), (100, 10, 11), (101, 10, 12), (9, 10, 2),
                                                  (103983, 434, 241), (21664, 1733, 14)])
def test_dump_frames_is_the_first_dump_plus_the_multiples_a_stage_can_hold(steps, every, frames):
    # 241: the recorded silo_flat run (1.2 s discharge at 434 steps per dump); 14: a recorded Jenike run
    assert dump_frames(steps, every) == frames


def test_dump_frames_refuses_a_zero_interval():
    with pytest.raises(ValueError, match="dump_every"):
        dump_frames(100, 0)


# ---------------------------------------------------------------------------------------------- work over time


@pytest.mark.parametrize(
    "n, per_insertion, every, steps, held",
    [
        (100, 10, 50, 500, 10 * 50 * (1 + 2 + 3 + 4 + 5 + 6 + 7 + 8 + 9 + 10)),  # 27,500: the last batch ends the stage
        (100, 10, 50, 600, 27_500 + 100 * 100),  # then the full silo for 100 steps more
        (95, 10, 50, 600, (10 * (1 + 2 + 3 + 4 + 5 + 6 + 7 + 8 + 9) + 95) * 50 + 95 * 100),  # a last batch of 5
        (100, 10, 50, 275, 10 * 50 * (1 + 2 + 3 + 4 + 5) + 60 * 25),  # cut off in the sixth batch
        (100, 100, 50, 400, 100 * 400),  # one batch: the count at once
        (1000, 1, 1, 1000, 1000 * 1001 // 2),  # a clump a step: a linear ramp, N (N + 1) / 2
        (0, 5, 10, 100, 0),
    ],
)
def test_a_pour_holds_each_batch_from_its_insertion_on(n, per_insertion, every, steps, held):
    assert pour_sphere_steps(n, per_insertion, every, steps) == held


def test_a_pour_refuses_impossible_batches():
    with pytest.raises(ValueError, match="clumps_per_insertion"):
        pour_sphere_steps(100, 0, 50, 500)


@pytest.mark.parametrize(
    "spheres, rate, delay, steps, held",
    [
        (1000.0, 0.0, 0.0, 500, 500_000.0),  # nothing leaves: the count holds
        (1000.0, 1.0, 100.0, 500, 1000 * 500 - 0.5 * 400**2),  # draining, not empty by the end
        (100.0, 1.0, 0.0, 500, 0.5 * 100 * 100),  # empty after 100 steps: N^2 / (2 rate)
        (100.0, 1.0, 50.0, 500, 100 * 50 + 0.5 * 100 * 100),  # the same, 50 steps later
        (100.0, 2.0, 600.0, 500, 100 * 500),  # the first clumps have not left by the end
    ],
)
def test_a_drain_loses_its_rate_per_step_after_the_delay(spheres, rate, delay, steps, held):
    assert drain_sphere_steps(spheres, rate, delay, steps) == pytest.approx(held, rel=1e-15)


def test_beverloo_rate_is_the_mass_flow_rate_over_the_clump_mass():
    n, mass = 1.2e6, 1.3e-5  # clumps per m^3 and kg per clump: bulk density 15.6 kg/m^3
    rate = beverloo_clump_rate(n, 0.04, 0.012, 0.0033, 9.81)
    assert rate == pytest.approx(n * 0.58 * math.sqrt(9.81) * 0.012 * (0.04 - 1.5 * 0.0033) ** 1.5, rel=1e-15)
    assert rate * mass == pytest.approx(beverloo_mass_flow_rate(n * mass, 0.04, 0.012, 0.0033, gravity=9.81), rel=1e-12)
    # an outlet no wider than k d: Beverloo predicts no flow, and the count holds
    assert beverloo_clump_rate(n, 0.0045, 0.012, 0.003, 9.81) == 0.0
    with pytest.raises(ValueError, match="gravity"):
        beverloo_clump_rate(n, 0.04, 0.012, 0.0033, 0.0)


def test_sink_fall_time_is_a_free_fall_from_rest():
    assert sink_fall_time(0.02, 9.81) == pytest.approx(math.sqrt(0.04 / 9.81), rel=1e-15)
    assert sink_fall_time(0.0, 9.81) == 0.0


# ---------------------------------------------------------------------------------------------- case kinds


def test_hand_made_silo_case_exact_numbers():
    estimate = estimate_silo_case(_silo_like(), model=WORST_CASE)
    assert estimate.steps == 1000 + 4 * 50 + 2000 == 3200
    assert estimate.spheres == 200
    assert estimate.dump_frames == 1 + math.ceil(2000 / 300) == 8
    assert estimate.simulated_time_s == pytest.approx(3.2, rel=1e-12)
    assert [(stage.stage, stage.steps) for stage in estimate.stages] == [("fill", 1000), ("settle", 200),
                                                                         ("discharge", 2000)]
    fill, settle, discharge = (stage.sphere_steps for stage in estimate.stages)
    assert fill == SILO_LIKE_FILL == 140_000
    assert settle == 200 * 200
    assert discharge == pytest.approx(SILO_LIKE_DISCHARGE, rel=1e-12)
    assert 0.5 < discharge / (200 * 2000) < 0.8  # it drains: 30 clumps/s for about 1.94 s out of the 100
    assert estimate.wall_time_s == pytest.approx((SILO_LIKE_FILL + 40_000 + SILO_LIKE_DISCHARGE) * 5.0e-7, rel=1e-12)
    # 8 dumps and their ParaView copies, plus the one contact snapshot of the settled fill
    assert estimate.dump_bytes == 8 * (1024 + 200 * 128) + 8 * (1024 + 200 * 50) + (1024 + 200 * 200) == 342_208
    assert (estimate.run_id, estimate.kind) == ("silo-test", "silo_flat")


def test_silo_case_from_config_counts_the_settle_stage_at_its_longest(config):
    case = build_silo_case(config)
    estimate = estimate_silo_case(case, mpi_ranks=2, model=WORST_CASE)
    expected_steps = case.fill.fill_steps + case.settle_max_checks * case.settle_check_steps + case.discharge_steps
    assert estimate.steps == silo_run_steps(case) == expected_steps
    assert estimate.clumps == case.fill.n_clumps
    assert estimate.spheres == case.fill.n_clumps * case.particle.n_spheres
    assert estimate.simulated_time_s == pytest.approx(expected_steps * case.timestep, rel=1e-12)
    assert estimate.wall_time_s == pytest.approx(estimate.sphere_steps * 5.0e-7 / 1.6, rel=1e-12)
    assert estimate.dump_frames == 1 + math.ceil(case.discharge_steps / case.dump_every)
    frames_bytes = estimate.dump_frames * (1024 + estimate.spheres * 128 + 1024 + estimate.spheres * 50)
    assert estimate.dump_bytes == frames_bytes + 1024 + estimate.spheres * 200
    assert estimate.run_id == case.run_id and estimate.mpi_ranks == 2


def test_silo_case_from_config_counts_its_spheres_stage_by_stage(config):
    case = build_silo_case(config)
    spheres = case.fill.n_clumps * case.particle.n_spheres
    fill, settle, discharge = estimate_silo_case(case, model=WORST_CASE).stages
    # the pour ramps the count up: about half the fill on average while it pours, all of it once poured
    assert 0.5 * spheres < fill.mean_spheres < spheres
    assert settle.sphere_steps == spheres * settle.steps
    # the discharge drains at Beverloo's rate for the bulk density the fill was sized with (n_clumps rounds it:
    # the same to 1e-3), once the first clumps have fallen out of the domain
    clumps_per_s = beverloo_mass_flow_rate(config["defaults"]["fill"]["bulk_density_estimate"], case.outlet_width,
                                           case.depth, case.particle.equivalent_diameter) / case.particle.mass
    delay = sink_fall_time(case.sink_depth, case.gravity) / case.timestep
    drained = drain_sphere_steps(float(spheres), clumps_per_s * case.particle.n_spheres * case.timestep, delay,
                                 discharge.steps)
    assert discharge.sphere_steps == pytest.approx(drained, rel=1e-3)
    assert discharge.sphere_steps < 0.9 * spheres * discharge.steps


def test_changing_a_silo_case_changes_its_estimate_exactly(config):
    case = build_silo_case(config)
    changed = dataclasses.replace(
        case, fill=dataclasses.replace(case.fill, n_clumps=500, fill_steps=7000), settle_check_steps=100,
        settle_max_checks=3, discharge_steps=9000, dump_every=1000,
        timestep_choice=dataclasses.replace(case.timestep_choice, timestep=2.0e-5),
    )
    estimate = estimate_silo_case(changed, model=WORST_CASE)
    assert estimate.steps == 7000 + 300 + 9000
    assert estimate.dump_frames == 10
    assert estimate.simulated_time_s == pytest.approx(16300 * 2.0e-5, rel=1e-12)
    spheres = 500 * case.particle.n_spheres
    assert estimate.dump_bytes == 10 * (1024 + spheres * 128) + 10 * (1024 + spheres * 50) + 1024 + spheres * 200


def test_recirculation_cases_use_their_silo_and_their_own_run_id(config):
    cases = recirculation_cases(config)
    assert cases, "the default config defines recirculating-silo runs"
    for run_id, case in cases.items():
        estimate = estimate_recirculation_case(case, model=WORST_CASE)
        silo = case.silo
        assert estimate.run_id == run_id != silo.run_id
        assert estimate.kind == "silo_recirculation"
        assert estimate.steps == silo.fill.fill_steps + silo.settle_max_checks * silo.settle_check_steps + silo.discharge_steps
        assert estimate.dump_frames == 1 + math.ceil(silo.discharge_steps / silo.dump_every)
        assert estimate.spheres == silo.fill.n_clumps * silo.particle.n_spheres
        # the recirculation stage is the silo's discharge stage; its clumps re-enter at the top, so all stay
        assert silo.discharge_steps * silo.timestep == pytest.approx(case.recirculation_time, rel=1e-12)
        assert estimate.stages[-1] == StageWork("recirculate", silo.discharge_steps,
                                                float(estimate.spheres * silo.discharge_steps))


def test_blender_cases_use_their_gravity_scaled_silo(config):
    cases = blender_cases(config)
    assert cases, "the default config defines blender runs"
    for run_id, case in cases.items():
        estimate = estimate_blender_case(case, model=WORST_CASE)
        silo = case.silo
        assert (estimate.run_id, estimate.kind) == (run_id, "blender")
        assert estimate.steps == silo_run_steps(silo)
        assert estimate.dump_frames == dump_frames(silo.discharge_steps, silo.dump_every)
    configuration = config["blender"]["configurations"][0]
    normal, heavy = (estimate_blender_case(build_blender_case(config, configuration, f), model=WORST_CASE) for f in (1.0, 4.0))
    # at 4 g the flow times halve, the dump interval with them, and so does the time step (the moduli are 4 times
    # stiffer): the discharge makes about as many steps, and as many frames
    discharge = {estimate: next(stage for stage in estimate.stages if stage.stage == "discharge") for estimate in (normal, heavy)}
    assert discharge[heavy].steps == pytest.approx(discharge[normal].steps, rel=0.1)
    assert heavy.dump_frames == normal.dump_frames


def test_a_continuous_blender_keeps_its_clumps_and_a_batch_blender_drains(config):
    configuration = config["blender"]["configurations"][0]
    assert config["blender"]["discharge"]["mode"] == "continuous"
    case = build_blender_case(config, configuration)
    continuous = estimate_blender_case(case, model=WORST_CASE).stages[-1]
    assert continuous == StageWork("discharge", case.silo.discharge_steps,
                                   float(case.silo.fill.n_clumps * case.silo.spheres_per_clump * case.silo.discharge_steps))
    batch = dataclasses.replace(case, mode="batch")
    silo = case.silo
    drained = estimate_blender_case(batch, model=WORST_CASE).stages[-1]
    clumps_per_s = beverloo_clump_rate(silo.fill.n_clumps / (case.fill_area * silo.depth), silo.outlet_width,
                                       silo.depth, silo.particle.equivalent_diameter, case.gravity)
    assert drained.sphere_steps == pytest.approx(drain_sphere_steps(
        continuous.sphere_steps / continuous.steps, clumps_per_s * silo.spheres_per_clump * silo.timestep,
        sink_fall_time(silo.sink_depth, case.gravity) / silo.timestep, silo.discharge_steps), rel=1e-12)
    assert drained.sphere_steps < continuous.sphere_steps


def test_hand_made_jenike_case_exact_numbers():
    case = SimpleNamespace(
        run_id="jenike-test", particle=SimpleNamespace(n_spheres=2, volume=1.45e-8), timestep=1.0e-5,
        fill=SimpleNamespace(n_clumps=453, steps=16900, relax_steps=1734),
        ramp_steps=1083, hold_steps=3250, shear_steps=17331, dump_every=1733,
        rigid_lid=SimpleNamespace(n_spheres=280), servo_lid=None,
        geometry=SimpleNamespace(area=1.0e-3, sample_height=0.01),
    )
    estimate = estimate_jenike_case(case)
    # levelling keeps 0.58 * 1e-3 m^2 * 0.01 m / 1.45e-8 m^3 = 400 clumps; the lid comes after it
    assert jenike_levelled_clumps(case) == 400
    assert estimate.stages == (
        StageWork("fill", 16900, 906.0 * 16900),
        StageWork("settle", 1 + 1734, 906.0 * 1 + 800.0 * 1734),  # the deletion step still holds all 906
        StageWork("consolidate", 1083 + 3250, 1080.0 * (1083 + 3250)),
        StageWork("shear", 17331, 1080.0 * 17331),
    )
    assert estimate.sphere_steps == 906 * 16901 + 800 * 1734 + 1080 * (1083 + 3250 + 17331)
    # 40299: the last step of the recorded calibration run with these numbers
    assert estimate.steps == jenike_run_steps(case) == 16900 + 1 + 1734 + 1083 + 3250 + 17331 == 40299
    assert estimate.clumps == 453 and estimate.spheres == 906 + 280
    # as the recorded run: 14 particle dumps over consolidation and shear
    assert estimate.dump_frames == 14
    # particle dumps and contact dumps
    assert estimate.dump_bytes == 14 * (1024 + 1186 * 128) + 14 * (1024 + 1186 * 200)
    assert estimate.simulated_time_s == pytest.approx(0.40299, rel=1e-12)
    assert estimate.kind == "jenike"


def test_jenike_cases_from_config_count_all_stages_and_the_lid(config):
    for lid in ("rigid", "servo"):
        case = build_jenike_case(config, {**JENIKE_POINT, "lid": lid})
        estimate = estimate_jenike_case(case)
        assert estimate.steps == (case.fill.steps + 1 + case.fill.relax_steps + case.ramp_steps + case.hold_steps
                                  + case.shear_steps)
        lid_atoms = case.rigid_lid.n_spheres if lid == "rigid" else 2
        assert estimate.spheres == case.fill.n_clumps * case.particle.n_spheres + lid_atoms
        # the pour was sized for 1 + overfill times the sample: levelling keeps about 1 / (1 + overfill) of it
        overfill = config["jenike"]["fill"]["overfill"]
        assert jenike_levelled_clumps(case) == pytest.approx(case.fill.n_clumps / (1 + overfill), abs=1)
        assert jenike_levelled_clumps(case) == round(FILL_SOLID_FRACTION * case.geometry.area
                                                     * case.geometry.sample_height / case.particle.volume)
        shear = estimate.stages[-1]
        assert shear.sphere_steps == (jenike_levelled_clumps(case) * case.particle.n_spheres + lid_atoms) * shear.steps
        dumped = case.ramp_steps + case.hold_steps + case.shear_steps
        assert estimate.dump_frames == 1 + math.ceil(dumped / case.dump_every)
        assert estimate.run_id == case.run_id


def test_every_configured_kind_names_its_cost_model():
    assert configured_kinds() == ("jenike", "silo_flat", "silo_recirculation", "blender")
    assert [CASE_KINDS[kind].estimate for kind in configured_kinds()] == [
        estimate_jenike_case, estimate_silo_case, estimate_recirculation_case, estimate_blender_case]


# ---------------------------------------------------------------------------------------------- disk


def test_disk_check_refuses_when_the_estimate_exceeds_the_free_space():
    with pytest.raises(InsufficientDiskSpace) as caught:
        check_disk_space(12.3e9, 4.5e9, "/data", "of the blender study")
    assert str(caught.value) == (
        "the runs of the blender study need about 12.3 GB for dumps but only 4.5 GB are free on "
        "/data; free space, move results/ to a larger disk, or raise dump intervals"
    )
    assert isinstance(caught.value, RuntimeError)


def test_disk_check_of_estimated_runs_names_both_sizes():
    estimates = [estimate_silo_case(_silo_like(), model=WORST_CASE), estimate_silo_case(_silo_like(run_id="silo-2"), model=WORST_CASE)]
    required = total_dump_bytes(estimates)
    assert required == 2 * 342_208
    with pytest.raises(InsufficientDiskSpace, match=r"need about 684 kB .* only 500 kB are free on results/"):
        check_disk_space(required, 500_000, "results/", "of silo_flat")


def test_disk_check_returns_the_margin():
    assert check_disk_space(1.0e9, 4.5e9, "/data", "x") == 3.5e9
    assert check_disk_space(4.5e9, 4.5e9, "/data", "x") == 0.0


@pytest.mark.parametrize("required, free", [(-1.0, 10.0), (1.0, float("nan"))])
def test_disk_check_refuses_impossible_sizes(required, free):
    with pytest.raises(ValueError, match="bytes"):
        check_disk_space(required, free, "/data", "x")


# ---------------------------------------------------------------------------------------------- formatting


@pytest.mark.parametrize(
    "size, text",
    [(0, "0 B"), (999, "999 B"), (1000, "1 kB"), (1536, "1.54 kB"), (999_999, "1 MB"), (12.3e9, "12.3 GB"),
     (4.5e9, "4.5 GB"), (2.0e12, "2 TB"), (1.234e15, "1230 TB")],
)
def test_format_bytes_uses_powers_of_1000(size, text):
    assert format_bytes(size) == text


@pytest.mark.parametrize(
    "seconds, text",
    [(0, "0 s"), (0.5, "0.5 s"), (42, "42 s"), (59.97, "1 min"), (180, "3 min"), (336, "5.6 min"),
     (5400, "1.5 h"), (86400, "1 d"), (150 * 86400, "150 d")],
)
def test_format_duration_uses_s_min_h_d(seconds, text):
    assert format_duration(seconds) == text


@pytest.mark.parametrize("function", [format_bytes, format_duration])
def test_formatting_refuses_negative_values(function):
    with pytest.raises(ValueError, match=">= 0"):
        function(-1)


# ---------------------------------------------------------------------------------------------- table


def test_estimate_rows_have_stable_columns_and_a_totals_row():
    first = estimate_silo_case(_silo_like(), model=WORST_CASE)
    second = RunEstimate(run_id="b", kind="blender", clumps=10, spheres=20, steps=100, sphere_steps=1500.0,
                         simulated_time_s=0.5, wall_time_s=3600.0, dump_frames=7, dump_bytes=2_000_000_000, mpi_ranks=2)
    rows = estimate_rows([first, second])
    assert [list(row) for row in rows] == [list(ESTIMATE_COLUMNS)] * 3
    assert rows[1] == {"run": "b", "kind": "blender", "mpi_ranks": 2, "clumps": 10, "spheres": 20, "steps": 100,
                       "sphere_steps": 1500.0, "simulated_s": 0.5, "wall_time": "1 h", "core_time": "2 h",
                       "dump_frames": 7, "disk": "2 GB"}
    assert rows[0]["disk"] == "342 kB" and rows[0]["sphere_steps"] == first.sphere_steps
    assert rows[0]["wall_time"] == rows[0]["core_time"] == format_duration(first.sphere_steps * 5.0e-7) == "0.23 s"
    assert rows[2] == {"run": "total (2 runs)", "kind": "", "mpi_ranks": "", "clumps": "", "spheres": "",
                       "steps": "", "sphere_steps": first.sphere_steps + 1500.0, "simulated_s": "",
                       "wall_time": "1 h", "core_time": "2 h", "dump_frames": 15, "disk": "2 GB"}


def test_estimate_rows_of_no_runs_is_a_zero_totals_row():
    assert estimate_rows([]) == [{**dict.fromkeys(ESTIMATE_COLUMNS, ""), "run": "total (0 runs)", "sphere_steps": 0.0,
                                  "wall_time": "0 s", "core_time": "0 s", "dump_frames": 0, "disk": "0 B"}]


def test_settling_is_counted_as_a_share_of_its_longest_time_in_whole_checks():
    silo = _silo_like()  # fill 1000, 4 checks of 50 steps, discharge 2000
    assert silo_run_steps(silo) == 1000 + 4 * 50 + 2000
    assert silo_run_steps(silo, 0.25) == 1000 + 1 * 50 + 2000
    assert silo_run_steps(silo, 0.3) == 1000 + 2 * 50 + 2000
    assert estimate_silo_case(silo).steps == 1000 + 50 + 2000  # the default model: a quarter
    with pytest.raises(ValueError, match="settle_fraction"):
        CostModel(settle_fraction=0.0)


STAGED_LOG = """\
    Step    Atoms           Time       n_clumps            CPU
       0        0              0              0              0
     100      200          0.001            100            1.0
Loop time of 2.0 on 1 procs for 100 steps with 200 atoms, finish time Thu Nov 26 16:28:43 2026
print "SILOFLOW filled step=$(step)"
SILOFLOW filled step=100
    Step    Atoms           Time       n_clumps            CPU
     100      200          0.001            100              0
     300      200          0.003            100            2.0
Loop time of 4.0 on 2 procs for 200 steps with 200 atoms
SILOFLOW settle step=300
    Step    Atoms           Time       n_clumps            CPU
     300      200          0.003            100              0
     400      100          0.004             50            1.0
Loop time of 1.0 on 1 procs for 100 steps with 100 atoms
SILOFLOW opened step=400
"""


def test_stage_costs_split_cpu_time_and_integrate_sphere_steps_by_stage():
    costs = stage_costs(STAGED_LOG, {None: "fill", "filled": "settle", "opened": "discharge"})
    # fill: one row pair, (0 + 200) / 2 * 100; settle: 200 * 200 + (200 + 100) / 2 * 100, the "settle" marker
    # is not in the mapping and keeps the stage; the echoed print command is no marker
    assert costs == {"fill": StageCost(2.0, 100, 10_000.0), "settle": StageCost(9.0, 300, 55_000.0)}
    assert costs["settle"].sphere_steps_per_second == pytest.approx(55_000.0 / 9.0, rel=1e-12)
    assert math.isnan(StageCost(0.0, 0, 0.0).sphere_steps_per_second)
