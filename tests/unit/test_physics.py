"""Time step and seeds against hand-computed values."""

import math

import pytest

from siloflow.model.cases.particles import model_parameters, particle_template
from siloflow.model.cases.physics import (
    engine_seeds, free_fall_time, free_fall_velocity, hertz_contact_time, is_prime, rayleigh_time, stable_timestep, steps_for,
)


def test_rayleigh_time_of_a_3mm_hdpe_sphere_by_hand():
    # R = 1.5 mm, rho = 950 kg/m3, E = 1e8 Pa, nu = 0.4:
    # G = 1e8 / 2.8 = 3.5714285714e7 Pa; rho / G = 2.66e-5 s^2/m^2; sqrt = 5.1575187e-3 s/m;
    # pi R = 4.7123890e-3 m; denominator 0.1631 * 0.4 + 0.8766 = 0.94184;
    # t_R = 4.7123890e-3 * 5.1575187e-3 / 0.94184 = 2.5805e-5 s.
    assert rayleigh_time(1.5e-3, 950.0, 1e8, 0.4) == pytest.approx(2.58052e-5, rel=1e-5)


def test_rayleigh_time_scales_with_radius_and_inverse_sqrt_modulus():
    base = rayleigh_time(1e-3, 1000.0, 1e7, 0.3)
    assert rayleigh_time(2e-3, 1000.0, 1e7, 0.3) == pytest.approx(2 * base, rel=1e-12)
    assert rayleigh_time(1e-3, 1000.0, 4e7, 0.3) == pytest.approx(base / 2, rel=1e-12)


@pytest.mark.parametrize("args", [(0.0, 950, 1e8, 0.4), (1e-3, -1, 1e8, 0.4), (1e-3, 950, 1e8, 0.5), (1e-3, 950, math.nan, 0.3)])
def test_rayleigh_time_rejects_nonphysical_input(args):
    with pytest.raises(ValueError):
        rayleigh_time(*args)


def test_engine_seeds_are_distinct_primes_above_10000():
    seeds = engine_seeds(1, 3)
    assert seeds == [11003, 11027, 11047]
    assert all(is_prime(s) and s > 10000 for s in seeds)
    assert set(engine_seeds(2, 3)).isdisjoint(seeds)


def test_steps_for_rounds_up_and_tolerates_float_noise():
    assert steps_for(0.005, 1e-5) == 500
    assert steps_for(0.0050001, 1e-5) == 501
    assert steps_for(1e-9, 1e-5) == 1


def test_hertz_contact_time_of_two_3mm_hdpe_spheres_by_hand():
    # m = 950 * 4/3 pi (1.5e-3)^3 = 1.343030e-5 kg; m* = m/2, R* = 0.75 mm, E* = 5e6 / (2 (1 - 0.16)) Pa
    mass = 950.0 * 4.0 / 3.0 * math.pi * 1.5e-3**3
    expected = 2.87 * ((mass / 2) ** 2 / (0.75e-3 * (5e6 / 1.68) ** 2 * 1.0)) ** 0.2
    assert expected == pytest.approx(2.6560e-4, rel=1e-4)
    assert hertz_contact_time(1.5e-3, 950.0, 5e6, 0.4, 1.0) == pytest.approx(expected, rel=1e-12)


def test_hertz_contact_time_falls_as_the_fifth_root_of_the_impact_velocity():
    slow = hertz_contact_time(1.5e-3, 950.0, 5e6, 0.4, 0.1)
    assert hertz_contact_time(1.5e-3, 950.0, 5e6, 0.4, 3.2) == pytest.approx(slow / 2, rel=1e-12)


@pytest.mark.parametrize("velocity", [0.0, -1.0, math.nan, math.inf])
def test_hertz_contact_time_rejects_a_velocity_that_is_not_positive_and_finite(velocity):
    with pytest.raises(ValueError, match="impact_velocity"):
        hertz_contact_time(1.5e-3, 950.0, 5e6, 0.4, velocity)


def test_stable_timestep_takes_the_smaller_limit_and_names_it():
    t_r = rayleigh_time(1.5e-3, 950.0, 5e6, 0.4)
    t_h = hertz_contact_time(1.5e-3, 950.0, 5e6, 0.4, 1.0)
    by_rayleigh = stable_timestep(1.5e-3, 950.0, 5e6, 0.4, 1.0, 0.2, 0.2)
    assert (by_rayleigh.timestep, by_rayleigh.limited_by) == (0.2 * t_r, "rayleigh")
    assert (by_rayleigh.rayleigh_time, by_rayleigh.hertz_time, by_rayleigh.impact_velocity) == (t_r, t_h, 1.0)
    # a tenfold faster impact shortens the contact by 10^(1/5) = 1.585: now the Hertz limit binds
    fast = stable_timestep(1.5e-3, 950.0, 5e6, 0.4, 10.0, 0.2, 0.1)
    assert fast.limited_by == "hertz"
    assert fast.timestep == pytest.approx(0.1 * t_h / 10.0**0.2, rel=1e-12)


def test_stable_timestep_scales_the_smaller_limit_by_the_particle_models_factor():
    t_r = rayleigh_time(1.5e-3, 950.0, 5e6, 0.4)
    halved = stable_timestep(1.5e-3, 950.0, 5e6, 0.4, 1.0, 0.1, 0.1, scale=0.5)
    assert (halved.timestep, halved.limited_by, halved.scale) == (0.5 * 0.1 * t_r, "rayleigh", 0.5)
    with pytest.raises(ValueError, match=r"scale must lie in \(0, 1\], got 1.5"):
        stable_timestep(1.5e-3, 950.0, 5e6, 0.4, 1.0, 0.1, 0.1, scale=1.5)


def test_a_particle_models_time_step_scale_enters_its_defining_parameters_only_when_not_1():
    spheres = [{"position": [0.0, 0.0, 0.0], "radius": 0.0019}]
    assert model_parameters("sphere", {"spheres": spheres, "timestep_scale": 1.0}) == {"name": "sphere",
                                                                                     "spheres": spheres}
    assert model_parameters("sphere", {"spheres": spheres}) == {"name": "sphere", "spheres": spheres}
    assert model_parameters("sphere", {"spheres": spheres, "timestep_scale": 0.5}) == {
        "name": "sphere", "spheres": spheres, "timestep_scale": 0.5}
    assert particle_template("sphere", {"spheres": spheres, "timestep_scale": 0.5}, 950.0).timestep_scale == 0.5
    assert particle_template("sphere", {"spheres": spheres}, 950.0).timestep_scale == 1.0


@pytest.mark.parametrize("fractions", [(0.0, 0.1), (0.1, -0.1), (1.5, 0.1), (0.1, math.nan)])
def test_stable_timestep_rejects_fractions_outside_zero_to_one(fractions):
    with pytest.raises(ValueError, match="fraction"):
        stable_timestep(1.5e-3, 950.0, 5e6, 0.4, 1.0, *fractions)


def test_free_fall_velocity_adds_the_fall_to_the_start_speed():
    assert free_fall_velocity(3.0, 1.0, 8.0) == 5.0  # sqrt(9 + 2 * 8 * 1)
    assert free_fall_velocity(3.0, -1.0, 8.0) == 3.0  # a start below the landing point falls nowhere


def test_free_fall_time_is_the_root_of_the_fall():
    assert free_fall_time(3.0, 2.5, 8.0) == 0.5  # 3 * 0.5 + 8 * 0.25 / 2 = 2.5
    assert free_fall_time(0.0, 4.9, 9.8) == 1.0
    assert free_fall_time(2.0, 0.0, 9.8) == 0.0


@pytest.mark.parametrize("args", [(1.0, -0.1, 9.8), (1.0, 1.0, 0.0), (-1.0, 1.0, 9.8)])
def test_free_fall_time_refuses_a_negative_height_or_start_or_no_gravity(args):
    with pytest.raises(ValueError, match="need height >= 0"):
        free_fall_time(*args)
