"""Mesh primitives of the Jenike cell: polygon counts from the chord error, walls, annuli, fans, circle overlap."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.model.cases.jenike import CHORD_TOLERANCE
from siloflow.model.cases.jenike_cell import annulus, circle_intersection_area, cylinder_wall, disk, segments_for_chord


def _sagitta(radius: float, n: int) -> float:
    return radius * (1.0 - math.cos(math.pi / n))


# ---------------------------------------------------------------------------------------------- primitives


@pytest.mark.parametrize("radius", [0.02, 0.0475])
def test_segment_count_is_the_fewest_that_keeps_the_chord_error(radius):
    tolerance = CHORD_TOLERANCE * 0.0015
    n = segments_for_chord(radius, tolerance)
    assert _sagitta(radius, n) <= tolerance
    assert _sagitta(radius, n - 1) > tolerance


def test_cylinder_wall_vertices_lie_on_the_circle_and_normals_face_the_axis():
    radius, n, centre = 0.0475, 126, (-0.003, 0.001)
    mesh = cylinder_wall(radius, 0.013, 0.029, n, centre)
    r = np.hypot(mesh.vertices[:, 0] - centre[0], mesh.vertices[:, 1] - centre[1])
    np.testing.assert_allclose(r, radius, rtol=1e-14)
    normals = mesh.normals()
    # each face spans one segment: its normal is minus the radial direction of the segment's middle
    for face, normal in zip(mesh.faces, normals):
        corners = np.unique(np.round(mesh.vertices[face, :2] - np.array(centre), 15), axis=0)
        assert len(corners) == 2
        middle = corners.mean(axis=0)
        np.testing.assert_allclose(normal, [*(-middle / np.linalg.norm(middle)), 0.0], atol=1e-12)


def test_cylinder_wall_area_is_the_prism_side_and_within_the_chord_error_of_the_cylinder():
    radius, height, n = 0.0475, 0.016, 126
    mesh = cylinder_wall(radius, 0.0, height, n)
    assert mesh.area() == pytest.approx(n * 2 * radius * math.sin(math.pi / n) * height, rel=1e-12)
    exact = 2 * math.pi * radius * height
    assert 0 < (exact - mesh.area()) / exact <= 2 * _sagitta(radius, n) / radius


def test_annulus_area_radii_and_normals():
    inner, outer, n = 0.0475, 0.0505, 126
    up = annulus(inner, outer, 0.013, n)
    down = annulus(inner, outer, 0.013, n, normal_up=False)
    polygon = 0.5 * n * math.sin(2 * math.pi / n) * (outer**2 - inner**2)
    assert up.area() == pytest.approx(polygon, rel=1e-12)
    exact = math.pi * (outer**2 - inner**2)
    assert 0 < (exact - up.area()) / exact <= 2 * _sagitta(outer, n) / outer
    np.testing.assert_allclose(up.normals(), np.tile([0.0, 0.0, 1.0], (2 * n, 1)), atol=1e-12)
    np.testing.assert_allclose(down.normals(), np.tile([0.0, 0.0, -1.0], (2 * n, 1)), atol=1e-12)
    r = np.hypot(up.vertices[:, 0], up.vertices[:, 1])
    assert set(np.round(r / inner, 12)) == {1.0, round(outer / inner, 12)}
    np.testing.assert_allclose(up.vertices[:, 2], 0.013)


def test_disk_fan_area_normals_and_smallest_angle():
    radius, n = 0.0472, 126
    mesh = disk(radius, 0.02, n, (0.001, 0.0), normal_up=False)
    assert mesh.area() == pytest.approx(0.5 * n * radius**2 * math.sin(2 * math.pi / n), rel=1e-12)
    np.testing.assert_allclose(mesh.normals()[:, 2], -1.0)
    corners = [mesh.vertices[mesh.faces[:, i]] for i in range(3)]
    angles = []
    for i in range(3):
        a, b, c = corners[i], corners[(i + 1) % 3], corners[(i + 2) % 3]
        cosine = np.sum((b - a) * (c - a), axis=1) / np.linalg.norm(b - a, axis=1) / np.linalg.norm(c - a, axis=1)
        angles.append(np.degrees(np.arccos(cosine)))
    np.testing.assert_allclose(np.min(angles, axis=0), 360.0 / n, rtol=1e-9)
    assert 360.0 / n > 0.5  # LIGGGHTS warns below 0.5 degrees


def test_circle_intersection_area_exact_values():
    a = 0.02
    assert circle_intersection_area(a, 0.0) == pytest.approx(math.pi * a**2, rel=1e-15)
    assert circle_intersection_area(a, a) == pytest.approx((2 * math.pi / 3 - math.sqrt(3) / 2) * a**2, rel=1e-12)
    assert circle_intersection_area(a, 2 * a) == 0.0
