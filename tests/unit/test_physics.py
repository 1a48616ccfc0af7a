"""Time step and seeds against hand-computed values."""

import math

import pytest

from engines.cases.physics import engine_seeds, is_prime, rayleigh_time, steps_for


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
