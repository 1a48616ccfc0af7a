"""The study's rolling law: the clump's lever arm and each engine's mapping of it."""

import math

import numpy as np
import pytest

from siloflow.engines.liggghts.rolling import cdt_matrix
from siloflow.model.rolling import RollingGeometry, rolling_geometry, study_torque

SPHERE2 = ([[-0.375e-3, 0.0, 0.0], [0.375e-3, 0.0, 0.0]], [1.5e-3, 1.5e-3])


def test_a_sphere_s_lever_arm_is_its_radius_and_an_inner_sphere_has_no_surface():
    for geometry in (rolling_geometry([[0.0, 0.0, 0.0]], [2e-3]),
                     rolling_geometry([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], [2e-3, 1e-3])):
        assert geometry.lever_arm == pytest.approx(2e-3, rel=1e-14) and geometry.contact_radius == 2e-3
        assert geometry.ratio == 1.0
    with pytest.raises(ValueError, match="one centre and one radius"):
        rolling_geometry([[0.0, 0.0, 0.0]], [2e-3, 1e-3])


def test_two_spheres_far_apart_have_the_mean_distance_of_each_surface_from_the_midpoint():
    # two spheres of radius a whose centres are d from the centre: over a sphere's surface the mean distance from a
    # point d from its centre is d + a^2 / (3 d) for d >= a (the shell theorem's mean of |x - c|)
    a, d = 1.0, 3.0
    geometry = rolling_geometry([[-d, 0.0, 0.0], [d, 0.0, 0.0]], [a, a], points=200000)
    assert geometry.lever_arm == pytest.approx(d + a * a / (3.0 * d), rel=1e-5)
    assert geometry.contact_radius == a


def test_the_study_s_two_sphere_clump_reaches_from_its_waist_to_its_tips():
    geometry = rolling_geometry(*SPHERE2)
    waist = math.sqrt(1.5e-3**2 - 0.375e-3**2)
    assert waist < geometry.lever_arm < 1.875e-3 and geometry.contact_radius == 1.5e-3
    assert geometry.lever_arm == pytest.approx(rolling_geometry(*SPHERE2, points=80000).lever_arm, rel=1e-5)
    assert geometry.ratio == pytest.approx(1.11510, abs=1e-5)
    assert study_torque(-0.1, 2.0, 1.5e-3) == pytest.approx(3e-4, rel=1e-15)


def test_liggghts_coefficients_give_pairs_twice_the_lever_ratio_and_walls_the_ratio():
    geometry = RollingGeometry(lever_arm=3.0, contact_radius=2.0)
    mapped = cdt_matrix([[0.1, 0.2, 0.0], [0.2, 0.0, 0.0], [0.0, 0.0, 0.5]], geometry)
    # pair: 0.1 x 2 x 1.5; particle-wall: 0.2 x 1.5; wall-wall pairs as given
    assert np.allclose(mapped, [[0.3, 0.3, 0.0], [0.3, 0.0, 0.0], [0.0, 0.0, 0.5]], rtol=1e-15, atol=0.0)
