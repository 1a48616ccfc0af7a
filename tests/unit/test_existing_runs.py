"""The silo study of a run siloflow did not make, on synthetic particle frames with exact answers: which frames stand
for the discharge, the move into siloflow's coordinates, the discharged mass counted from the frames (particles that
fall below the outlet, vanish below it, or vanish as they cross it), escapes, the particle size, and the fields
without contacts."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.optimize import OptimizeWarning

from siloflow.model.existing_run import ExistingSiloRun
from siloflow.model.frames import ClumpFrame, ParticleFrame
from siloflow.model.constants import GRAVITY
from siloflow.analysis.studies.silo_flat.existing_run import (
    SKIPPED_ANALYSES,
    analyses_summary,
    existing_field_study,
    existing_flow,
    existing_flow_row,
    opening_frames,
    particle_size,
    silo_dimensions,
    to_silo_coordinates,
)
from siloflow.analysis.studies.silo_flat.field_study import SiloFieldOptions, field_summary
from siloflow.analysis.studies.silo_flat.metrics import EscapedParticles, could_reach_outlet, escaped_clumps

ORIGIN = (0.1, 0.2, 0.3)  # the dumps' coordinates of the silo axis (x), front wall (y) and outlet plane (z) (m)
TIMESTEP = 1e-4  # s
OPEN_STEP = 1000
RADIUS = 0.001  # m
DENSITY = 1000.0  # kg/m3
SPHERE_MASS = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3
PER_FRAME = 4  # spheres that fall below the outlet between two frames
N_SPHERES = 40
FRAMES_AFTER = 6


def _run(**changes) -> ExistingSiloRun:
    values = dict(name="mine", engine="liggghts", folder="runs/mine", dumps="post/silo*.vtk", width=0.04,
                  depth=0.01, outlet_width=0.012, timestep=TIMESTEP, open_step=OPEN_STEP, origin=ORIGIN,
                  density=DENSITY)
    return ExistingSiloRun(**{**values, **changes})


def _frame(step: int, ids, silo_position, velocity=None, radius=RADIUS, time=None) -> ParticleFrame:
    """A frame of spheres in the dumps' coordinates, given their silo coordinates."""
    silo_position = np.asarray(silo_position, dtype=float).reshape(-1, 3)
    n = len(silo_position)
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (n,))
    return ParticleFrame(
        time=step * TIMESTEP if time is None else time, step=step, id=np.asarray(ids), type=np.ones(n, dtype=int),
        clump_id=np.asarray(ids), position=silo_position + np.asarray(ORIGIN),
        velocity=np.zeros((n, 3)) if velocity is None else velocity, angular_velocity=None, radius=radius,
        mass=DENSITY * 4.0 / 3.0 * math.pi * radius**3)


def _settled_positions() -> np.ndarray:
    # a row of 10 spheres across the slot in each of 4 layers: x = -13.5 ... 13.5 mm, z = 1, 3, 5, 7 mm
    x = -0.0135 + 0.003 * np.arange(10)
    z = 0.001 + 0.002 * np.arange(4)
    return np.array([[xi, 0.005, zi] for zi in z for xi in x])


def _discharge() -> list[ParticleFrame]:
    """The fill at step 900, then a frame every 100 steps from 1100 on: after frame k the first 4k spheres are below
    the outlet; those below it for two frames have left the domain. Step 1100 is dumped twice, the earlier copy with
    every sphere still at rest (the later copy is the frame)."""
    settled = _settled_positions()
    ids = np.arange(1, N_SPHERES + 1)
    frames = [_frame(900, ids, settled), _frame(1100, ids, settled)]
    for k in range(1, FRAMES_AFTER + 1):
        position = settled.copy()
        position[: PER_FRAME * k, 2] = -0.005
        kept = ids > PER_FRAME * (k - 2)  # gone: below the outlet since the frame before last
        frames.append(_frame(OPEN_STEP + 100 * k, ids[kept], position[kept]))
    return frames


def test_the_fill_at_the_opening_is_the_last_frame_before_it_at_the_opening_time_in_silo_coordinates():
    run = _run()
    chosen = opening_frames(_discharge(), run)
    assert [frame.step for frame in chosen] == [900, 1100, 1200, 1300, 1400, 1500, 1600]
    assert chosen[0].time == run.open_time == OPEN_STEP * TIMESTEP
    assert chosen[1].time == 1100 * TIMESTEP
    np.testing.assert_allclose(chosen[0].position, _settled_positions(), rtol=0, atol=1e-15)
    # of step 1100 dumped twice, the later copy: four spheres below the outlet
    assert np.count_nonzero(chosen[1].position[:, 2] < 0) == PER_FRAME
    moved = to_silo_coordinates(chosen[1], (1.0, 2.0, 3.0), time=7.0)
    np.testing.assert_array_equal(moved.position, chosen[1].position - [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(moved.velocity, chosen[1].velocity)
    assert moved.time == 7.0 and moved.step == 1100


def test_opening_frames_refuse_a_discharge_without_its_fill_or_without_frames_after_it():
    frames = _discharge()
    with pytest.raises(ValueError, match="no frame at or before the opening"):
        opening_frames(frames[1:], _run(open_step=1000))
    with pytest.raises(ValueError, match="no frame after the opening"):
        opening_frames(frames, _run(open_step=1600))
    empty = _frame(1000, np.empty(0, dtype=int), np.empty((0, 3)))
    with pytest.raises(ValueError, match="holds no particle"):
        opening_frames([frames[0], empty, *frames[2:]], _run())


def test_discharged_mass_is_the_mass_that_has_left_the_silo_counted_from_the_frames():
    flow = existing_flow(_discharge(), _run())
    history = flow.metrics.history
    np.testing.assert_allclose(history.time, 0.01 * np.arange(FRAMES_AFTER + 1), rtol=0, atol=1e-15)
    expected = SPHERE_MASS * PER_FRAME * np.arange(FRAMES_AFTER + 1)
    np.testing.assert_allclose(history.discharged_mass, expected, rtol=1e-14, atol=0)
    assert np.all(np.diff(history.discharged_mass) >= 0.0)
    assert flow.metrics.initial_mass == pytest.approx(N_SPHERES * SPHERE_MASS, rel=1e-14)
    # the discharged mass at the end is the mass missing from the silo in the last frame
    last = _discharge()[-1]
    in_silo = SPHERE_MASS * np.count_nonzero(last.position[:, 2] - ORIGIN[2] >= 0)
    assert history.discharged_mass[-1] == pytest.approx(N_SPHERES * SPHERE_MASS - in_silo, rel=1e-14)
    # 4 spheres every 10 ms, exactly linear: the steady rate is 400 sphere masses per second
    assert flow.metrics.fit.mass_flow_rate == pytest.approx(400.0 * SPHERE_MASS, rel=1e-10)
    assert flow.settled_step == 900 and flow.n_particles == N_SPHERES and flow.particle_model == "spheres"
    assert flow.silo.particle_radius == pytest.approx(RADIUS, rel=1e-15)
    assert flow.silo.clump_mass == pytest.approx(SPHERE_MASS, rel=1e-15)
    row = existing_flow_row(_run(), flow)
    assert row["run_id"] == "mine" and row["n_clumps"] == N_SPHERES and row["particle_model"] == "spheres"
    assert row["discharged_mass_kg"] == history.discharged_mass[-1]
    assert row["particle_diameter_m"] == pytest.approx(2 * RADIUS, rel=1e-15)


def _without(frame: ParticleFrame, gone: int) -> ParticleFrame:
    keep = frame.id != gone
    return _frame(frame.step, frame.id[keep], frame.position[keep] - np.asarray(ORIGIN), frame.velocity[keep])


def test_a_sphere_deleted_as_it_crosses_the_outlet_is_discharged_and_one_lost_elsewhere_escaped():
    frames = _discharge()
    ids = np.arange(1, N_SPHERES + 1)
    # sphere 5 (x = -1.5 mm, over the slot) falls at 0.5 m/s 0.5 mm above the outlet at step 1100; the deck deletes it
    # as it crosses the plane, so it is gone from step 1200 on, where it would otherwise be below the outlet
    position = frames[2].position - np.asarray(ORIGIN)
    position[4] = [-0.0015, 0.005, 0.0005]
    velocity = np.zeros((N_SPHERES, 3))
    velocity[4, 2] = -0.5
    crossing = [*frames[:2], _frame(1100, ids, position, velocity), *(_without(f, 5) for f in frames[3:])]
    flow = existing_flow(crossing, _run())
    expected = SPHERE_MASS * PER_FRAME * np.arange(FRAMES_AFTER + 1)
    np.testing.assert_allclose(flow.metrics.history.discharged_mass, expected, rtol=1e-14, atol=0)
    # sphere 40 (x = 13.5 mm, beside the slot, at rest in the top layer) vanishes at step 1300: it escaped
    lost = [*frames[:4], *(_without(f, 40) for f in frames[4:])]
    with pytest.raises(EscapedParticles, match=r"1 clumps vanished above the outlet plane .* \(ids \[40\]"):
        existing_flow(lost, _run())


def test_could_reach_outlet_within_its_fall_and_sideways_travel():
    dt, half = 0.01, 0.006
    fall = 0.5 * GRAVITY * dt**2  # from rest
    position = np.array([[0.0, 0.0, fall], [0.0, 0.0, fall * 1.0001], [half, 0.0, 0.0], [half + 1e-4, 0.0, 0.0],
                         [half + 1e-4, 0.0, 0.0], [0.0, 0.0, 0.002]])
    velocity = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-0.01, 0.0, 0.0],
                         [0.0, 0.0, -0.2]])
    reached = could_reach_outlet(position, velocity, dt, 2 * half)
    # from rest: at most the fall under gravity; beside the slot: no farther than the sideways travel (1 mm in 10 ms);
    # 2 mm above it at 0.2 m/s down: the interval's travel alone
    assert reached.tolist() == [True, False, True, False, True, True]
    with pytest.raises(ValueError, match="interval"):
        could_reach_outlet(position, velocity, 0.0, 2 * half)


def test_escaped_clumps_without_removal_at_the_outlet_are_every_clump_that_vanished_above_it():
    def clumps(time, ids, z, vz=0.0):
        n = len(ids)
        position = np.column_stack([np.zeros(n), np.zeros(n), z])
        return ClumpFrame(time=time, step=0, clump_id=ids, position=position,
                          velocity=np.tile([0.0, 0.0, vz], (n, 1)), mass=np.ones(n), n_spheres=np.ones(n, dtype=int))

    previous = clumps(0.0, np.array([1, 2, 3]), np.array([0.0001, 0.05, -0.01]), vz=-1.0)
    current = clumps(0.01, np.array([]), np.empty(0))
    assert escaped_clumps(previous, current, 0.01).tolist() == [1, 2]
    assert escaped_clumps(previous, current, 0.01, removed_at_outlet=True).tolist() == [2]


def test_particle_size_is_that_of_the_mean_sphere_volume_or_the_given_diameter():
    mixed = _frame(900, [1, 2], [[0, 0.005, 0.01], [0.01, 0.005, 0.01]], radius=[0.001, 0.002])
    diameter, mass = particle_size(mixed, _run())
    assert diameter == pytest.approx(2.0 * (4.5e-9) ** (1.0 / 3.0), rel=1e-14)
    assert mass == pytest.approx(0.5 * DENSITY * 4.0 / 3.0 * math.pi * 9e-9, rel=1e-14)
    assert particle_size(mixed, _run(particle_diameter=0.005))[0] == 0.005
    silo = silo_dimensions(mixed, _run(particle_diameter=0.005))
    assert (silo.width, silo.depth, silo.outlet_width, silo.particle_radius) == (0.04, 0.01, 0.012, 0.0025)
    clump = ParticleFrame(time=0.0, step=0, id=[1, 2], type=[1, 1], clump_id=[7, 7], position=np.zeros((2, 3)),
                          velocity=np.zeros((2, 3)), angular_velocity=None, radius=[0.001, 0.001], mass=[1e-5, 1e-5])
    with pytest.raises(ValueError, match="particle_diameter"):
        particle_size(clump, _run())


FIELD_OPTIONS = SiloFieldOptions(
    spacing=(0.004, 0.005, 0.004), kernel="gaussian", width_radii=3.0, cutoff=3.0, profile_heights=(0.1,),
    fcb_fractions=(0.05,), subtract_wall_velocity=False, average_window=None, vtk_every=1,
    internal_friction_angle_deg=30.0, side_wall_friction_angle_deg=10.0, front_wall_friction_angle_deg=10.0,
    force_chain_slice=0.004)


def test_fields_of_a_run_without_contacts_leave_the_contact_analyses_out():
    # a lattice of spheres 2 mm apart filling the silo 30 mm high, sinking at 0.1 m/s in every frame
    x = -0.019 + 0.002 * np.arange(20)
    y = 0.001 + 0.002 * np.arange(5)
    z = 0.001 + 0.002 * np.arange(15)
    lattice = np.stack(np.meshgrid(x, y, z, indexing="ij"), axis=-1).reshape(-1, 3)
    ids = np.arange(1, len(lattice) + 1)
    velocity = np.tile([0.0, 0.0, -0.1], (len(lattice), 1))
    frames = [_frame(OPEN_STEP + 100 * k, ids, lattice, velocity) for k in range(4)]
    run = _run(profile_heights=(0.01, 0.015))
    with warnings.catch_warnings():
        # a flat profile gives the kinematic fit no curvature to fit (scipy warns; B is not asserted here)
        warnings.simplefilter("ignore", OptimizeWarning)
        study = existing_field_study(frames, run, FIELD_OPTIONS, steady_window=(0.0, 0.03), bulk_density=600.0)
    assert study.stress is None and study.janssen is None and study.segments is None and study.n_contacts is None
    assert study.heights == [0.01, 0.015]  # the run's heights, not the options' 0.1 m
    np.testing.assert_allclose(study.profiles.v_z, -0.1, rtol=1e-12)
    assert study.averaged.total_mass == pytest.approx(len(lattice) * SPHERE_MASS, rel=1e-12)
    summary = field_summary(study, outflow_rate=1.0)
    assert summary["contacts"] is None and summary["janssen_error_bin_pairs"] is None


def test_the_summary_says_what_was_read_made_and_skipped_and_why():
    summary = analyses_summary(_run(), [900, 1100, 1200], 900, ["metrics/flow.csv"])
    assert summary["run"] == "mine" and summary["open_step"] == OPEN_STEP and summary["settled_step"] == 900
    assert (summary["frames"], summary["first_step"], summary["last_step"]) == (3, 900, 1200)
    assert summary["origin_m"] == list(ORIGIN) and summary["density_kg_m3"] == DENSITY
    assert summary["made"] == ["metrics/flow.csv"]
    skipped = {entry["analysis"]: entry for entry in summary["skipped"]}
    assert set(skipped) == {s.analysis for s in SKIPPED_ANALYSES} == {
        "settled contact stress", "Janssen comparison", "force chains", "fill force balance"}
    assert skipped["Janssen comparison"]["products"] == ["metrics/janssen.csv", "plots/janssen.png"]
    assert "contact forces" in skipped["force chains"]["reason"]
    assert "wall" in skipped["fill force balance"]["reason"]
