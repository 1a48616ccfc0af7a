"""The verification problems' closed forms and measurements, against exact answers on synthetic trajectories."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from siloflow.model.frames import ParticleFrame
from siloflow.analysis.numerics.verification import (
    HERTZ_TIME_CONSTANT,
    axis_precession_angle,
    incline_acceleration,
    precession_rate,
    contact_interval,
    hertz_contact_time,
    linear_slope,
    moment_about_axis,
    rolling_deceleration_cdt,
    sliding_to_rolling,
    zero_crossings,
    hertz_normal_force,
    sphere_contacts,
    spin_deceleration,
)
from siloflow.analysis.studies.verification import Trajectories, measure_problem, trajectories_from_frames, verification_table
from siloflow.model.cases.verification import CLUMP_HALF_SPACING, PROBLEMS, verification_cases


def test_hertz_time_constant_is_the_integral_it_names():
    value, _ = integrate.quad(lambda x: (1.0 - x**2.5) ** -0.5, 0.0, 1.0)
    assert HERTZ_TIME_CONSTANT == pytest.approx(2.0 * value, rel=1e-9)
    assert HERTZ_TIME_CONSTANT == pytest.approx(2.9432, abs=1e-4)


def test_hertz_time_follows_the_undamped_impact_ode():
    """Integrate m x'' = -4/3 E sqrt(R) x^(3/2) from x = 0, x' = v until x returns to 0."""
    mass, radius, modulus, speed = 1.7e-5, 1.5e-3, 2.98e6, 1.0

    def motion(_, y):
        return [y[1], -4.0 / 3.0 * modulus * math.sqrt(radius) * max(y[0], 0.0) ** 1.5 / mass]

    leaves = lambda t, y: y[0] if t > 0 else 1.0  # noqa: E731
    leaves.terminal, leaves.direction = True, -1
    solution = integrate.solve_ivp(motion, (0.0, 1.0), [0.0, speed], events=leaves, rtol=1e-11, atol=1e-14)
    assert hertz_contact_time(mass, radius, modulus, speed) == pytest.approx(solution.t_events[0][0], rel=1e-6)


def test_sliding_to_rolling_and_rolling_deceleration_by_hand():
    assert sliding_to_rolling(0.7, 0.5, 10.0) == pytest.approx((0.04, 0.5), rel=1e-15)
    assert rolling_deceleration_cdt(0.14, 10.0) == pytest.approx(1.0, rel=1e-15)
    with pytest.raises(ValueError, match="friction"):
        sliding_to_rolling(1.0, 0.0, 9.81)


def test_precession_of_a_symmetric_top_by_hand():
    # I = (1, 2, 2), omega = (2, 1, 0): L = (2, 2, 0), |L| / I_perp = sqrt(8) / 2
    assert precession_rate([1.0, 2.0, 2.0], [2.0, 1.0, 0.0]) == pytest.approx(math.sqrt(2.0), rel=1e-15)


def test_axis_angle_about_the_momentum_unwraps_a_steady_precession():
    t = np.linspace(0.0, 3.0, 301)
    momentum = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
    first = np.array([0.0, 0.0, 1.0])
    second = np.cross(momentum, first)
    rate, tilt = 5.0, 0.4
    axis = (np.cos(tilt) * momentum + np.sin(tilt) * (np.cos(rate * t)[:, None] * first
                                                      + np.sin(rate * t)[:, None] * second))
    slope, _ = linear_slope(t, axis_precession_angle(axis, 3.0 * momentum))
    assert abs(slope) == pytest.approx(rate, rel=1e-12)


def test_incline_acceleration_by_hand_and_zero_below_the_friction_angle():
    assert incline_acceleration(30.0, 0.0, 10.0) == pytest.approx(5.0, rel=1e-15)
    assert incline_acceleration(45.0, 0.5, 10.0) == pytest.approx(10.0 * math.sqrt(0.5) * 0.5, rel=1e-12)
    assert incline_acceleration(15.0, 0.35, 9.81) == 0.0


@pytest.mark.parametrize("name", ["incline_slide", "incline_stick"])
def test_a_synthetic_block_moving_as_the_closed_form_says_passes(name):
    p = _params(name)
    g = np.linalg.norm(p["gravity"])
    angle = math.degrees(math.atan2(p["gravity"][0], -p["gravity"][2]))
    a = incline_acceleration(angle, p["sliding_friction"], g)
    t = np.linspace(0.0, 0.05, 401)
    velocity = np.zeros((t.size, 4, 3))
    velocity[:, :, 0] = (a * t)[:, None]
    velocity[:20, :, 2] = 0.01  # the settling at the start is left out
    (row,) = measure_problem(name, p, Trajectories(t, np.zeros_like(velocity), velocity, np.zeros_like(velocity)))
    assert row.closed_form == pytest.approx(a, rel=1e-15)
    assert row.measured == pytest.approx(a, rel=1e-9, abs=1e-12)
    assert row.passes and abs(row.error) < 1e-9


def test_zero_crossings_interpolate_linearly():
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    assert zero_crossings(t, [1.0, -1.0, -3.0, 1.0, 1.0]).tolist() == [0.5, 2.75]
    assert zero_crossings(t, [1.0, 0.0, -1.0, -1.0, -1.0]).tolist() == [1.0]


def test_contact_interval_and_its_refusals():
    t = np.linspace(0.0, 1.0, 11)
    assert contact_interval(t, (t - 0.25) * (t - 0.75)) == pytest.approx((0.25, 0.75), abs=0.01)
    with pytest.raises(ValueError, match="never touch"):
        contact_interval(t, t + 1.0)
    with pytest.raises(ValueError, match="not ended"):
        contact_interval(t, 0.5 - t)


def test_linear_slope_of_a_line_is_exact():
    slope, error = linear_slope([0.0, 1.0, 2.0, 3.0], [1.0, -1.0, -3.0, -5.0])
    assert slope == pytest.approx(-2.0, rel=1e-15) and error == pytest.approx(0.0, abs=1e-15)


def _params(name):
    case = verification_cases()[name]
    return {**case.summary(), "gravity": case.gravity, "radius": case.radius}


def test_a_synthetic_elastic_wall_impact_measures_its_own_rebound_and_contact():
    p = _params("wall_impact")
    r, closed = p["radius"], hertz_contact_time(p["mass_kg"], p["radius"], 5e6 / (2 * (1 - 0.16)), 1.0)
    t = np.linspace(0.0, 3 * closed, 3001)
    # a gap that dips below zero exactly for the Hertz time, the velocity reversed after it
    start = closed / 2
    gap = np.where((t > start) & (t < start + closed), -1e-6, 1e-6)
    gap[np.argmax(t > start) - 1] = 0.0
    z = r + gap
    v = np.where(t < start + closed / 2, -1.0, 1.0)
    position = np.zeros((t.size, 1, 3))
    position[:, 0, 2] = z
    velocity = np.zeros((t.size, 1, 3))
    velocity[:, 0, 2] = v
    rows = measure_problem("wall_impact", p, Trajectories(t, position, velocity, np.zeros_like(velocity)))
    assert [(row.quantity, row.measured) for row in rows][0] == ("restitution", 1.0)
    assert rows[1].measured == pytest.approx(closed, abs=2 * (t[1] - t[0]))
    assert all(row.passes for row in rows)


def test_a_sphere_that_slides_then_rolls_as_the_closed_form_says_passes():
    p = _params("slide_to_roll")
    r, mu, g = p["radius"], p["sliding_friction"], 9.81
    v0 = PROBLEMS["slide_to_roll"]["speed"]
    t_star, v_roll = sliding_to_rolling(v0, mu, g)
    t = np.linspace(0.0, 2 * t_star, 801)
    speed = np.where(t < t_star, v0 - mu * g * t, v_roll)
    spin = np.where(t < t_star, 2.5 * mu * g * t / r, v_roll / r)
    velocity, angular = np.zeros((t.size, 1, 3)), np.zeros((t.size, 1, 3))
    velocity[:, 0, 0], angular[:, 0, 1] = speed, spin
    rows = measure_problem("slide_to_roll", p, Trajectories(t, np.zeros_like(velocity), velocity, angular))
    assert rows[0].measured == pytest.approx(t_star, rel=1e-9)
    assert rows[1].measured == pytest.approx(v_roll, rel=1e-12)
    assert rows[0].error == pytest.approx(0.0, abs=1e-9)


def test_rolling_deceleration_is_measured_on_the_rolling_phase_only():
    p = _params("rolling")
    a = rolling_deceleration_cdt(p["rolling_friction"], 9.81)
    t = np.linspace(0.0, 0.06, 601)
    speed = np.maximum(0.05 - a * t, 0.0)
    speed[:10] += 0.003  # the settling bounce at the start is left out
    velocity = np.zeros((t.size, 1, 3))
    velocity[:, 0, 0] = speed
    (row,) = measure_problem("rolling", p, Trajectories(t, np.zeros_like(velocity), velocity, np.zeros_like(velocity)))
    assert row.measured == pytest.approx(a, rel=1e-9)


def test_the_table_reports_each_engines_rows_and_refuses_an_unknown_problem():
    p = _params("rolling")
    with pytest.raises(ValueError, match="unknown verification problem"):
        measure_problem("spin", p, Trajectories(np.zeros(3), *(np.zeros((3, 1, 3)),) * 3))
    rows = measure_problem("wall_impact_damped", _params("wall_impact_damped"), Trajectories(
        np.array([0.0, 1.0, 2.0, 3.0]), np.array([[[0, 0, 2e-3]], [[0, 0, 1e-3]], [[0, 0, 1.4e-3]], [[0, 0, 2e-3]]]),
        np.array([[[0, 0, -1.0]]] * 3 + [[[0, 0, 0.6]]]), np.zeros((4, 1, 3))))
    table = verification_table({"a": rows, "b": rows})
    assert table["engine"].tolist() == ["a", "b"]
    assert table["measured"].tolist() == pytest.approx([0.6, 0.6])
    assert table["error"].tolist() == pytest.approx([0.2, 0.2])
    assert not table["passes"].any()


def test_trajectories_order_spheres_by_id_and_refuse_missing_spin():
    def frame(step, ids, spin=True):
        n = len(ids)
        return ParticleFrame(time=step * 0.1, step=step, id=np.array(ids), type=np.ones(n, dtype=np.int32),
                             clump_id=np.array(ids), position=np.array(ids, dtype=float)[:, None] * np.ones((n, 3)),
                             velocity=np.zeros((n, 3)), angular_velocity=np.zeros((n, 3)) if spin else None,
                             radius=np.ones(n), mass=np.ones(n))
    run = trajectories_from_frames([frame(0, [2, 1]), frame(1, [1, 2])])
    assert run.position[:, :, 0].tolist() == [[1.0, 2.0], [1.0, 2.0]]
    assert run.time.tolist() == [0.0, 0.1]
    with pytest.raises(ValueError, match="no angular velocity"):
        trajectories_from_frames([frame(0, [1, 2], spin=False)])


def test_the_suite_resolves_each_contact_and_lasts_long_enough():
    cases = verification_cases()
    assert set(cases) == set(PROBLEMS)
    for name, case in cases.items():
        assert case.run_id.startswith(name)
        if "impact" in name:
            assert case.output_every == 1  # every step: the contact time is resolved to one time step


@pytest.mark.parametrize("name, reduced", [("pair_spin", 0.5), ("wall_spin", 1.0)])
def test_a_held_sphere_s_spin_decelerates_at_the_study_s_rolling_torque(name, reduced):
    """Synthetic spin at exactly mu_r |Fn| r / I, with |Fn| Hertz's at the held sphere's overlap: measured exactly."""
    p = _params(name)
    r, m, mu_r = p["radius"], p["mass_kg"], p["rolling_friction"]
    overlap = 0.002 * r
    force = 4.0 / 3.0 * 5e6 / (2 * (1 - 0.16)) * math.sqrt(reduced * r) * overlap**1.5
    alpha = mu_r * force * r / (0.4 * m * r * r)
    assert hertz_normal_force(5e6 / (2 * (1 - 0.16)), reduced * r, overlap) == pytest.approx(force, rel=1e-15)
    assert spin_deceleration(mu_r, force, r, 0.4 * m * r * r) == pytest.approx(alpha, rel=1e-15)
    t = np.linspace(0.0, 0.8 * 50.0 / alpha, 401)
    held = (0.0, 0.0, (2.0 * r if name == "pair_spin" else r) - overlap)
    position = np.array([[(0.0, 0.0, 0.0), held] if name == "pair_spin" else [held]] * t.size)
    angular = np.zeros_like(position)
    angular[:, -1, 0] = 50.0 - alpha * t
    (row,) = measure_problem(name, p, Trajectories(t, position, np.zeros_like(position), angular))
    assert row.quantity == "spin_deceleration" and row.closed_form == pytest.approx(alpha, rel=1e-9)
    assert row.measured == pytest.approx(alpha, rel=1e-9) and row.passes
    assert verification_cases()[name].spheres[-1].motion == "held"


def test_sphere_contacts_and_the_moment_about_an_axis_by_hand():
    overlaps, points = sphere_contacts([[0.0, 0.0, 1.9], [4.0, 0.0, 0.0]], [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]], 1.0)
    assert overlaps.tolist() == pytest.approx([0.1, 1.0], rel=1e-14)
    assert points.tolist() == [[0.0, 0.0, 0.95], [3.5, 0.0, 0.0]]
    overlaps, points = sphere_contacts([[0.0, 0.0, 3.0]], [[0.0, 0.0, 0.0]], 1.0)
    assert overlaps.shape == (0,) and points.shape == (0, 3)
    # I = (1, 2, 4) about (1, 1, 0): (1 + 2) / 2
    assert moment_about_axis([1.0, 2.0, 4.0], [3.0, 3.0, 0.0]) == pytest.approx(1.5, rel=1e-15)
    with pytest.raises(ValueError, match="non-zero axis"):
        moment_about_axis([1.0, 2.0, 4.0], [0.0, 0.0, 0.0])


def test_a_held_clump_s_spin_on_a_fixed_clump_against_the_study_s_torque_and_the_mapping_s():
    """Synthetic spin at the deceleration the engines' mapping gives (the torque at the clump's mean lever arm R):
    the closed form is the study's, 2 mu_r |Fn| R_i / I with R_i the distance from each contact point to the centre
    of mass and I the moment of the union of the two spheres about their line of centres, by hand; the spin row
    differs from it by R / R_i, and the torque ratio row finds R / R_i."""
    p = _params("clump_pair_spin")
    case = verification_cases()["clump_pair_spin"]
    r, mu_r, a, rho = p["radius"], p["rolling_friction"], CLUMP_HALF_SPACING, p["density"]
    overlap = 0.002 * r
    assert [s.motion for s in case.spheres] == ["fixed", "held"] and case.spheres[1].angular_velocity == (50.0, 0, 0)
    force = 4.0 / 3.0 * 5e6 / (2 * (1 - 0.16)) * math.sqrt(r / 2.0) * overlap**1.5
    arm = math.hypot(a, r - overlap / 2.0)
    # the union's disc of radius^2 r^2 - (|x| - a)^2 at each x along the axis: I = rho int pi R^4 / 2 dx
    value, _ = integrate.quad(lambda x: math.pi / 2.0 * (r * r - (x - a) ** 2) ** 2, 0.0, a + r, epsrel=1e-12)
    inertia = 2.0 * rho * value
    study = 2.0 * mu_r * force * arm / inertia
    lever = p["rolling_lever_arm_m"]
    assert lever == pytest.approx(1.6726e-3, rel=1e-4)
    # the engines are given the case's inertia, the quadrature of clump_inertia: 1e-5 of the exact union's
    assert p["clump_inertia"][0] == pytest.approx(inertia, rel=3e-5)
    mapped = 2.0 * mu_r * force * lever / p["clump_inertia"][0]
    t = np.linspace(0.0, 0.8 * 50.0 / mapped, 401)
    clump = np.array([[-a, 0.0, 0.0], [a, 0.0, 0.0]])
    position = np.array([np.concatenate([clump, clump + [0.0, 0.0, 2.0 * r - overlap]])] * t.size)
    angular = np.zeros_like(position)
    angular[:, 2:, 0] = (50.0 - mapped * t)[:, None]
    spin, ratio = measure_problem("clump_pair_spin", p, Trajectories(t, position, np.zeros_like(position), angular))
    assert spin.quantity == "spin_deceleration" and spin.closed_form == pytest.approx(study, rel=3e-5)
    assert spin.measured == pytest.approx(mapped, rel=1e-9)
    assert spin.error == pytest.approx(lever / arm - 1.0, rel=1e-8) and not spin.passes
    assert ratio.quantity == "torque_ratio" and ratio.closed_form == pytest.approx(lever / arm, rel=1e-12)
    assert ratio.measured == pytest.approx(lever / arm, rel=1e-9) and ratio.passes
    # a contact between the tip (the mapping gives it 0.892 of the study's torque) and the waist (1.152)
    assert 0.892 < lever / arm < 1.152
