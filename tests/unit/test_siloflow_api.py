"""The notebook API (siloflow/) on synthetic run folders of known answer.

The run folders are written to tmp_path in the formats the engines write (YADE's numpy archives and tables,
LIGGGHTS' legacy VTK dumps through the test helpers of tests/dump_fixtures.py): synthetic inputs whose every answer
is known, not engine output. Each test checks that the API reads them through the engine that made the run and that
its numbers are the closed-form ones, or those the study's own functions give for the same input.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import siloflow
from siloflow.analysis.numerics.clump_tracks import clump_tracks, tracks_from_frames
from siloflow.analysis.numerics.exit_times import outlet_exits
from siloflow.analysis.numerics.lti import vrr_versus_period
from siloflow.analysis.numerics.rtd import rtd_from_exit_times
from siloflow.analysis.studies.silo_flat.field_study import SiloDimensions, SiloFieldOptions, analyse_silo_fields
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events
from tests.repo import REPO_ROOT
from siloflow.engines.jenike_checks import FORCE_COLUMNS
from siloflow.model.constants import GRAVITY
from siloflow.model.frames import ParticleFrame
from siloflow.model.record import RunRecord
from tests.dump_fixtures import write_liggghts_dump

DT = 1e-5  # time step of every synthetic run [s]


# --------------------------------------------------------------------------- synthetic run folders

def _record(kind: str, engine: str = "yade", **values) -> RunRecord:
    fields = {"engine": engine, "case": kind, "run_id": f"synthetic-{kind}", "timestep_s": DT, "n_clumps": 0,
              "n_frames": 0, "mpi_ranks": 1, "stages": {"end": {"step": 1, "time": DT}}}
    return RunRecord(**{**fields, **values})


def _run_folder(tmp_path, record: RunRecord, case: dict):
    folder = tmp_path / record.run_id
    (folder / "deck").mkdir(parents=True)
    (folder / "dumps").mkdir()
    (folder / "run.json").write_text(record.to_json())
    (folder / "deck" / "case.json").write_text(json.dumps({"case": record.case, **case}))
    return folder


def _frame_arrays(frame: ParticleFrame) -> dict:
    return {"step": frame.step, "time": frame.time, "id": frame.id, "type": frame.type, "clump_id": frame.clump_id,
            "position": frame.position, "velocity": frame.velocity, "radius": frame.radius, "mass": frame.mass}


def _write_yade_frames(folder, frames) -> None:
    for frame in frames:
        np.savez(folder / "dumps" / f"particles_{frame.step}.npz", **_frame_arrays(frame))


def _spheres(step: int, clump_id, position, velocity, mass, radius=0.002) -> ParticleFrame:
    n = len(clump_id)
    return ParticleFrame(time=step * DT, step=step, id=np.arange(1, n + 1), type=np.ones(n), clump_id=clump_id,
                         position=position, velocity=velocity, angular_velocity=None, radius=np.full(n, radius),
                         mass=mass)


# --------------------------------------------------------------------------- opening runs of every kind

KINDS = {
    "silo_flat": {"open_step": 200, "open_time_s": 200 * DT, "outlet_z": 0.0},
    "silo_recirculation": {"open_step": 200, "open_time_s": 200 * DT, "outlet_z": 0.0, "domain_z": [-0.1, 0.2]},
    "blender": {"open_step": 200, "open_time_s": 200 * DT, "outlet_z": 0.0, "domain_z": [-0.1, 0.2]},
    "jenike": {"labels": {"shear_start_s": 0.0, "shear_end_s": 1.0}},
}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_run_of_every_kind_opens_with_its_record_case_paths_and_frames(tmp_path, kind):
    folder = _run_folder(tmp_path, _record(kind, **KINDS[kind]), {"n_clumps": 2, "width_m": 0.05})
    frames = [_spheres(step, [4, 9], [[0.01, 0.005, 0.05 - step * 1e-5], [-0.01, 0.005, 0.02]],
                       [[0.0, 0.0, -1.0], [0.5, 0.0, 0.0]], [2e-5, 3e-5]) for step in (100, 200, 300)]
    _write_yade_frames(folder, frames)
    run = siloflow.open_run(str(folder))
    assert (run.kind, run.run_id, run.engine.name) == (kind, f"synthetic-{kind}", "yade")
    assert run.case == {"case": kind, "n_clumps": 2, "width_m": 0.05}
    assert (run.path, run.record_path, run.case_path, run.deck) == (
        folder, folder / "run.json", folder / "deck" / "case.json", folder / "deck")
    read = run.frames()
    assert [frame.step for frame in read] == [100, 200, 300]
    assert [frame.time for frame in read] == pytest.approx([1e-3, 2e-3, 3e-3], rel=1e-12)
    np.testing.assert_array_equal(read[2].position, frames[2].position)
    np.testing.assert_array_equal(read[0].velocity, frames[0].velocity)
    clumps = run.clumps()
    np.testing.assert_array_equal(clumps[1].clump_id, [4, 9])
    np.testing.assert_array_equal(clumps[1].mass, [2e-5, 3e-5])
    if kind == "jenike":
        with pytest.raises(ValueError, match="has no outlet opening"):
            run.frames(since_opening=True)
    else:
        assert [frame.step for frame in run.frames(since_opening=True)] == [200, 300]


def test_a_liggghts_run_opens_and_reads_through_its_own_engine(tmp_path):
    folder = _run_folder(tmp_path, _record("silo_flat", engine="liggghts", open_step=10, outlet_z=0.0), {})
    # values exact in float32, the type of the positions in a LIGGGHTS dump
    points = np.array([[0.0, 0.0, 0.5], [0.25, 0.0, 0.5], [0.0, 0.125, 0.75]], dtype=np.float32)
    fields = {"id": np.array([1, 2, 3], dtype=np.int32), "id_multisphere": np.array([1, 1, 2], dtype=np.int32),
              "type": np.ones(3, dtype=np.int32), "mass": np.array([2e-5, 2e-5, 1e-5]),
              "v": np.array([[0.0, 0.0, -1.0]] * 3), "radius": np.full(3, 0.002)}
    for step in (10, 20):
        write_liggghts_dump(folder / "dumps" / f"particles_{step}.vtk", points, fields)
    run = siloflow.open_run(folder)
    assert run.engine.name == "liggghts"
    frames = run.frames(since_opening=True)
    assert [(frame.step, frame.time) for frame in frames] == [(10, pytest.approx(1e-4)), (20, pytest.approx(2e-4))]
    (clumps, _) = run.clumps()
    np.testing.assert_array_equal(clumps.clump_id, [1, 2])
    np.testing.assert_allclose(clumps.position, [[0.125, 0.0, 0.5], [0.0, 0.125, 0.75]], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(clumps.mass, [2e-5, 1e-5])


def test_open_run_says_why_a_folder_is_no_finished_run(tmp_path):
    with pytest.raises(FileNotFoundError, match="no run folder at"):
        siloflow.open_run(tmp_path / "absent")
    (tmp_path / "running" / "deck").mkdir(parents=True)
    with pytest.raises(FileNotFoundError, match=r"holds no run\.json: the run has not finished or failed a check"):
        siloflow.open_run(tmp_path / "running")
    (tmp_path / "running" / "run.json").write_text(_record("silo_flat").to_json())
    with pytest.raises(FileNotFoundError, match=r"holds no case summary deck/case\.json"):
        siloflow.open_run(tmp_path / "running")


def test_clumps_of_a_periodic_run_join_the_spheres_either_side_of_the_boundary(tmp_path):
    folder = _run_folder(tmp_path, _record("silo_recirculation", **KINDS["silo_recirculation"]), {})
    # clump 3 straddles the periodic boundary of [-0.1, 0.2): spheres at 0.19 and -0.09, i.e. 0.21 unwrapped
    frame = _spheres(200, [3, 3], [[0.0, 0.0, 0.19], [0.0, 0.0, -0.09]], [[0.0, 0.0, -1.0]] * 2, [2e-5, 2e-5])
    _write_yade_frames(folder, [frame])
    (clump,) = siloflow.open_run(folder).clumps()
    np.testing.assert_allclose(clump.position[0], [0.0, 0.0, -0.1], rtol=0, atol=1e-12)  # 0.2 wrapped to -0.1


def test_wall_forces_and_contacts_come_through_the_engine(tmp_path):
    folder = _run_folder(tmp_path, _record("silo_flat", **KINDS["silo_flat"]), {})
    walls = ("floor_left", "floor_right", "outlet_gate")
    title = "# step time " + " ".join(f"{wall}_{q}" for wall in walls for q in ("fx", "fy", "fz", "tx", "ty", "tz"))
    rows = [f"{step} {step * DT!r} " + " ".join(str(float(step + k)) for k in range(18)) for step in (100, 200)]
    (folder / "wall_force_history.txt").write_text("\n".join([title, *rows]) + "\n")
    frame = _spheres(150, [1, 2], [[0.0, 0.0, 0.002], [0.0, 0.0, 0.006]], np.zeros((2, 3)), [2e-5, 2e-5])
    contacts = np.array([[0.0, 0.0, 0.002, 0.0, 0.0, 0.006, 1, 2, 0.0, 0.0, -0.5]])
    np.savez(folder / "dumps" / "settled_fill_150.npz", **_frame_arrays(frame), wall_force=np.zeros((2, 3)),
             contacts=contacts, walls=np.array(walls), wall_forces=np.zeros((3, 6)))
    run = siloflow.open_run(folder)
    history = run.wall_forces()
    assert history.walls == walls
    np.testing.assert_allclose(history.time, [1e-3, 2e-3], rtol=1e-12)
    np.testing.assert_array_equal(history.force["outlet_gate"][:, 2], [114.0, 214.0])
    (pairs,) = run.contacts()
    assert pairs.step == 150 and pairs.id_j.tolist() == [2]
    np.testing.assert_array_equal(pairs.force, [[0.0, 0.0, -0.5]])


# --------------------------------------------------------------------------- a flat-bottom silo, from frames to Janssen

WIDTH, DEPTH, OUTLET, RADIUS, MASS = 0.048, 0.008, 0.016, 0.002, 2e-5
SPEED = 0.05  # every clump above the outlet falls at this speed [m/s]
PER_FRAME = 4  # clumps leaving through the outlet between frames
FRAME_STEPS = 1000  # 10 ms between frames


def _lattice() -> np.ndarray:
    """12 x 2 x 10 clump centres 4 mm apart filling the silo from the floor, the lowest first."""
    x, y, z = np.meshgrid(-0.022 + 0.004 * np.arange(12), [0.002, 0.006], 0.002 + 0.004 * np.arange(10),
                          indexing="ij")
    lattice = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    return lattice[np.argsort(lattice[:, 2], kind="stable")]


def _draining_frames(n_frames: int = 21) -> list[ParticleFrame]:
    lattice = _lattice()
    n = len(lattice)
    frames = []
    for k in range(n_frames):
        position = lattice.copy()
        position[: PER_FRAME * k, 2] = -0.05  # out through the outlet, in the channel below it
        velocity = np.zeros((n, 3))
        velocity[:, 2] = -SPEED
        frames.append(_spheres(FRAME_STEPS * (k + 1), np.arange(n), position, velocity, np.full(n, MASS), RADIUS))
    return frames


def _column_contacts(frame: ParticleFrame) -> np.ndarray:
    """Each clump of the settled fill pressed on by the one above it with the weight of the column above (N)."""
    rows = []
    for i, below in enumerate(frame.position):
        above = np.flatnonzero(np.all(np.isclose(frame.position[:, :2], below[:2]), axis=1)
                               & np.isclose(frame.position[:, 2], below[2] + 0.004))
        for j in above:
            weight = MASS * GRAVITY * np.count_nonzero(np.all(np.isclose(frame.position[:, :2], below[:2]), axis=1)
                                                       & (frame.position[:, 2] > below[2]))
            rows.append([*below, *frame.position[j], frame.id[i], frame.id[j], 0.0, 0.0, -weight])
    return np.array(rows)


@pytest.fixture
def silo_run(tmp_path):
    frames = _draining_frames()
    record = _record("silo_flat", open_step=frames[0].step, open_time_s=frames[0].time, outlet_z=0.0,
                     n_clumps=len(frames[0]), n_frames=len(frames))
    case = {"width_m": WIDTH, "depth_m": DEPTH, "outlet_width_m": OUTLET, "equivalent_diameter_m": 2 * RADIUS,
            "clump_mass_kg": MASS, "fill_height_m": 0.04}
    folder = _run_folder(tmp_path, record, case)
    _write_yade_frames(folder, frames)
    settled = frames[0]
    np.savez(folder / "dumps" / f"settled_fill_{settled.step}.npz", **_frame_arrays(settled),
             wall_force=np.zeros((len(settled), 3)), contacts=_column_contacts(settled),
             walls=np.array(["floor_left", "floor_right", "outlet_gate"]), wall_forces=np.zeros((3, 6)))
    return siloflow.open_run(folder)


def test_the_silo_dimensions_are_the_case_summarys():
    summary = {"width_m": WIDTH, "depth_m": DEPTH, "outlet_width_m": OUTLET, "equivalent_diameter_m": 2 * RADIUS,
               "clump_mass_kg": MASS}
    run = type("Run", (), {"case": summary})()
    assert siloflow.silo_dimensions(run) == SiloDimensions(WIDTH, DEPTH, OUTLET, RADIUS, MASS)
    run.case = {"case": "jenike"}
    with pytest.raises(KeyError, match="it is no silo's"):
        siloflow.silo_dimensions(run)


def test_the_discharge_of_a_synthetic_silo_is_its_steady_rate(silo_run):
    clumps = silo_run.clumps(since_opening=True)
    flow = siloflow.discharge(clumps, siloflow.silo_dimensions(silo_run))
    # four clumps of 20 mg leave every 10 ms
    assert flow.fit.mass_flow_rate == pytest.approx(PER_FRAME * MASS / (FRAME_STEPS * DT), rel=1e-9)
    np.testing.assert_allclose(flow.history.discharged_mass, PER_FRAME * MASS * np.arange(len(clumps)), atol=1e-15)
    np.testing.assert_allclose(flow.history.time, FRAME_STEPS * DT * np.arange(len(clumps)), rtol=1e-12)


def test_the_velocity_field_and_profiles_of_a_uniform_fall_are_the_fall(silo_run):
    clumps = silo_run.clumps(since_opening=True)
    silo = siloflow.silo_dimensions(silo_run)
    surface = siloflow.fill_surface(clumps[0], silo)
    np.testing.assert_allclose(surface, 0.038 + RADIUS, rtol=1e-12)  # the top layer's tops
    grid = siloflow.silo_grid(silo, top=float(np.nanmax(surface)))
    assert grid.shape == (8, 2, 7) and grid.spacing == pytest.approx((0.006, 0.004, 0.006))
    fields = siloflow.coarse_grain(clumps, grid, siloflow.default_width(RADIUS))
    assert len(fields) == len(clumps)
    # mass on the grid: the clumps above the outlet plane, exactly
    for k, field in enumerate(fields):
        assert field.total_mass == pytest.approx((240 - PER_FRAME * k) * MASS, rel=1e-12)
    times = np.array([frame.time for frame in clumps]) - clumps[0].time
    steady = siloflow.time_average(fields, times, window=(0.0, 0.055))
    profiles = siloflow.velocity_profiles(steady, [0.012, 0.021])
    assert [profile.z for profile in profiles] == [0.012, 0.021]
    for profile in profiles:
        np.testing.assert_allclose(profile.x, grid.x)
        np.testing.assert_allclose(profile.v_z, -SPEED, rtol=1e-12)
        np.testing.assert_allclose(profile.v_x, 0.0, atol=1e-15)
    # over the window: the fields of its six frames, mass-weighted
    expected = sum(fields[k].density for k in range(6)) / 6
    np.testing.assert_allclose(steady.density, expected, rtol=1e-12)
    with pytest.raises(ValueError, match="needs the fields' times"):
        siloflow.time_average(fields, window=(0.0, 0.055))


# the study's kinematic fit of a flat profile has no covariance; the comparison here is of Janssen and the profiles
@pytest.mark.filterwarnings("ignore:Covariance of the parameters could not be estimated")
def test_janssen_and_profiles_are_those_of_the_studys_own_analysis(silo_run):
    clumps = silo_run.clumps(since_opening=True)
    silo = siloflow.silo_dimensions(silo_run)
    surface = siloflow.fill_surface(clumps[0], silo)
    grid = siloflow.silo_grid(silo, top=float(np.nanmax(surface)))
    width = 0.002  # narrower than the study's 3 radii, so that the 40 mm fill keeps rows beyond the kernel's reach
    (contacts,) = silo_run.contacts()
    comparison = siloflow.janssen_comparison(contacts, grid, silo, float(np.nanmin(surface)), 600.0, width,
                                             internal_friction_angle_deg=30.0, side_wall_friction_angle_deg=9.5,
                                             front_wall_friction_angle_deg=11.0)
    options = SiloFieldOptions(spacing=(0.006, 0.004, 0.006), kernel="gaussian", width_radii=width / RADIUS, cutoff=3.0,
                               profile_heights=(0.012,), fcb_fractions=(0.1,), subtract_wall_velocity=False,
                               average_window=None, vtk_every=1, internal_friction_angle_deg=30.0,
                               side_wall_friction_angle_deg=9.5, front_wall_friction_angle_deg=11.0,
                               force_chain_slice=0.004)
    study = analyse_silo_fields(clumps, contacts, silo, options, steady_window=(0.0, 0.2), bulk_density=600.0)
    for name in ("depth_below_surface", "height", "simulated", "simulated_error", "janssen", "hydrostatic"):
        np.testing.assert_array_equal(getattr(comparison, name), getattr(study.janssen, name))
    assert comparison.height.size == 5
    # the column weights make a compression that grows with depth
    assert np.all(comparison.simulated > 0.0) and np.all(np.diff(comparison.simulated) < 0.0)
    times = np.array([frame.time for frame in clumps]) - clumps[0].time
    steady = siloflow.time_average(siloflow.coarse_grain(clumps, grid, width), times, window=(0.0, 0.2))
    (profile,) = siloflow.velocity_profiles(steady, [0.012])
    np.testing.assert_allclose(profile.v_z, study.profiles.v_z[0], rtol=1e-12)


# --------------------------------------------------------------------------- exit times, RTD and VRR

BOTTOM, TOP, OUTLET_Z = -0.25, 0.75, 0.0  # periodic domain of 1 m; the outlet 0.25 m above its bottom
N_CONVEYOR, FALL = 20, 0.1  # clumps evenly spaced along the domain, falling at 0.1 m/s: a pass takes 7.5 s


def _conveyor_frames(duration: float = 30.0, every: float = 0.05) -> list[ParticleFrame]:
    """Two-sphere clumps (the two spheres side by side in x) circulating through the periodic domain."""
    z0 = BOTTOM + (np.arange(N_CONVEYOR) + 0.5) / N_CONVEYOR
    frames = []
    for k in range(int(round(duration / every)) + 1):
        t = k * every
        z = BOTTOM + np.mod(z0 - FALL * t - BOTTOM, TOP - BOTTOM)
        position = np.column_stack([np.tile([-0.001, 0.001], N_CONVEYOR), np.zeros(2 * N_CONVEYOR), np.repeat(z, 2)])
        frames.append(ParticleFrame(
            time=t, step=k, id=np.arange(2 * N_CONVEYOR), type=np.ones(2 * N_CONVEYOR),
            clump_id=np.repeat(np.arange(N_CONVEYOR), 2), position=position,
            velocity=np.tile([0.0, 0.0, -FALL], (2 * N_CONVEYOR, 1)), angular_velocity=None,
            radius=np.full(2 * N_CONVEYOR, 0.001), mass=np.full(2 * N_CONVEYOR, 1e-5)))
    return frames


@pytest.fixture(scope="module")
def conveyor_exits():
    return siloflow.exit_times(_conveyor_frames(), OUTLET_Z, (BOTTOM, TOP))


def test_exit_times_of_a_conveyor_are_the_closed_form(conveyor_exits):
    exits = conveyor_exits
    z0 = BOTTOM + (np.arange(N_CONVEYOR) + 0.5) / N_CONVEYOR
    # first crossing: (z0 - outlet) / speed, or after one loop of 10 s for the clumps below the outlet at t = 0
    first = np.where(z0 > OUTLET_Z, (z0 - OUTLET_Z) / FALL, (z0 - OUTLET_Z) / FALL + 10.0)
    np.testing.assert_allclose(exits.first_exit_time, first, rtol=0, atol=1e-9)
    residence = exits.residence_time[np.isfinite(exits.residence_time)]
    np.testing.assert_allclose(residence, 7.5, rtol=0, atol=1e-9)
    assert exits.n_clumps == N_CONVEYOR and exits.domain_z == (BOTTOM, TOP)
    assert np.all(np.diff(exits.crossing_time) >= 0.0) and exits.crossing_is_pass_exit.all()


def test_the_study_reads_its_events_from_the_same_exit_times(conveyor_exits):
    tracked = tracks_from_frames(_conveyor_frames(), (BOTTOM, TOP))
    events = recirculation_events(tracked.tracks, OUTLET_Z, BOTTOM, TOP)
    np.testing.assert_array_equal(events.exit_times_all, conveyor_exits.crossing_time)
    np.testing.assert_array_equal(events.entry_time, conveyor_exits.entry_time)
    np.testing.assert_array_equal(events.exit_time, conveyor_exits.exit_time)
    np.testing.assert_array_equal(events.first_exit_time, conveyor_exits.first_exit_time)


def test_exit_times_without_a_periodic_boundary_are_first_crossings():
    frames = [_spheres(step, [1, 2], [[0.0, 0.0, 0.03 - 0.02 * step], [0.01, 0.0, 0.05]], np.zeros((2, 3)),
                       [1e-5, 1e-5]) for step in (0, 1, 2)]
    exits = siloflow.exit_times(frames, 0.0)
    np.testing.assert_allclose(exits.first_exit_time, [1.5 * DT, np.nan])  # 0.01 m above the plane at step 1
    assert exits.n_passes == 2 and exits.domain_z is None
    with pytest.raises(ValueError, match="a run without a periodic boundary has none"):
        siloflow.residence_time_distribution(exits)


def test_the_rtd_of_a_conveyor_is_one_pulse_at_its_pass_time(conveyor_exits):
    rtd = siloflow.residence_time_distribution(conveyor_exits, bins=10, entered_until=20.0)
    entries = conveyor_exits.entry_time
    assert rtd.n_total == np.count_nonzero(np.isfinite(entries) & (entries <= 20.0)) == 40
    assert (rtd.n_exited, rtd.t_mean, rtd.variance) == (40, pytest.approx(7.5, abs=1e-9), pytest.approx(0.0, abs=1e-12))
    assert np.sum(rtd.E * rtd.widths) == pytest.approx(1.0, rel=1e-12)
    assert np.count_nonzero(rtd.E) == 1
    # entries after 22.5 s cannot leave by the last frame (30 s): they count, not left
    late = siloflow.residence_time_distribution(conveyor_exits, bins=10, entered_from=20.0)
    assert late.n_exited == np.count_nonzero((entries >= 20.0) & (entries <= 22.5))
    assert late.fraction_exited < 1.0
    assert np.sum(late.E * late.widths) == pytest.approx(late.fraction_exited, rel=1e-12)
    with pytest.raises(ValueError, match="widen the window"):
        siloflow.residence_time_distribution(conveyor_exits, entered_from=29.9)


def test_vrr_is_the_convolution_of_the_rtd_and_has_the_closed_form_of_a_uniform_rtd():
    # residence times spread evenly over [0, 1] s: a sine of period P = 2 s is damped by sin(pi/2) / (pi/2) in
    # amplitude, so VRR = pi^2 / 4; the rectangle rule of the convolution is first order in the bin width
    rtd = rtd_from_exit_times((np.arange(4000) + 0.5) / 4000, bins=400)
    table = siloflow.vrr(rtd, [4.0, 2.0])
    assert table.t_mean == pytest.approx(0.5)
    np.testing.assert_allclose(table.period, [2.0, 1.0])
    assert table.vrr[0] == pytest.approx(math.pi**2 / 4, rel=5e-3)
    direct = vrr_versus_period(rtd.E, rtd.edges[:-1], [4.0, 2.0], t_mean=rtd.t_mean)
    np.testing.assert_array_equal(table.vrr, direct.vrr)
    square = siloflow.vrr(rtd, [4.0], waveform="square")
    assert square.waveform == "square" and square.vrr[0] > 1.0
    uneven = rtd_from_exit_times([0.2, 0.5, 0.9], bins=[0.0, 0.3, 1.0])
    with pytest.raises(ValueError, match="equal bins from 0"):
        siloflow.vrr(uneven, [1.0])


def test_an_outlet_outside_the_periodic_domain_is_refused():
    tracks = clump_tracks([0.0, 1.0], [[1], [1]], [[[0, 0, 0.1]], [[0, 0, 0.05]]])
    with pytest.raises(ValueError, match="outlet_z must lie strictly between domain_bottom and domain_top"):
        outlet_exits(tracks, 0.3, (0.0, 0.2))


# --------------------------------------------------------------------------- a Jenike shear test

def test_the_bulk_friction_of_a_jenike_run_is_its_shear_over_its_load(tmp_path):
    folder = _run_folder(tmp_path, _record("jenike", labels={"shear_start_s": 0.1, "shear_end_s": 0.5}), {})
    # the particles push the lid and the ring back with 0.2 N and 0.1 N, hold the lid up with 1 N, carry 10 g above
    # the shear plane, and push the bottom ring on with the 0.3 N of the shear: mu = 0.3 / (1 + 0.01 g)
    values = {"lid_fx": -0.2, "lid_fy": 0.0, "lid_fz": 1.0, "ring_fx": -0.1, "ring_fy": 0.0, "ring_fz": 0.0,
              "bottom_fx": 0.3, "bottom_fy": 0.0, "bottom_fz": 0.0, "lid_z": 0.03, "mass_above": 0.01}
    rows = [f"{k} {k * 1e-2!r} " + " ".join(str(values[name]) for name in FORCE_COLUMNS[1:]) for k in range(1, 61)]
    (folder / "jenike_force_history.txt").write_text("# step " + " ".join(FORCE_COLUMNS) + "\n" + "\n".join(rows))
    friction, window = siloflow.bulk_friction(siloflow.open_run(folder))
    expected = 0.3 / (1.0 + 0.01 * GRAVITY)
    assert friction.coefficient == pytest.approx(expected, rel=1e-12)
    assert friction.bottom_coefficient == pytest.approx(expected, rel=1e-12)
    assert friction.angle_deg == pytest.approx(math.degrees(math.atan(expected)))
    assert window in ("steady", "second half")
    assert 0.1 < friction.window.t_start and friction.window.t_end <= 0.5


def test_bulk_friction_refuses_a_run_that_is_no_shear_test(silo_run):
    with pytest.raises(ValueError, match="is a silo_flat run, not a Jenike shear test"):
        siloflow.bulk_friction(silo_run)


# --------------------------------------------------------------------------- the package itself

def test_the_public_names_are_exported_and_importing_leaves_matplotlibs_backend_alone():
    assert sorted(siloflow.__all__) == sorted(name for name in siloflow.__all__ if hasattr(siloflow, name))
    for name in ("open_run", "coarse_grain", "velocity_profiles", "janssen_comparison", "exit_times",
                 "residence_time_distribution", "vrr", "bulk_friction"):
        assert name in siloflow.__all__
    probe = ("import matplotlib, sys; import siloflow; "
             "assert 'matplotlib.pyplot' not in sys.modules, 'siloflow imports pyplot'; "
             "print(matplotlib.get_backend())")
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=REPO_ROOT,
                            env={**os.environ, "MPLBACKEND": "svg", "PYTHONPATH": str(REPO_ROOT)}, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "svg"
