"""Blender wall meshes: closed outward solids of the right volume, subdivided outlines, mirror, STL round trip."""

from __future__ import annotations

import math

import numpy as np
import pytest

from siloflow.model.cases.blender_geometry import blender_geometry
from siloflow.model.cases.blender_meshes import blender_meshes, is_watertight, mirror_x, signed_volume
from siloflow.model.cases.geometry import horizontal_rectangle, read_stl, write_stl

# The study's full scale (thesis ch. 7) and a half scale with thinner walls.
FULL = dict(width=0.45, depth=0.04, vertical_height=1.5, hopper_half_angle=30.0, outlet_width=0.04,
            wall_thickness=0.005, tube_width=0.04, tube_inlet_above_transition=0.15 * 0.45)
HALF = dict(width=0.225, depth=0.02, vertical_height=0.75, hopper_half_angle=30.0, outlet_width=0.02,
            wall_thickness=0.002, tube_width=0.02, tube_inlet_above_transition=0.15 * 0.225)
INSERTS = ("diverging", "straight", "converging")


def full(insert="diverging", **changes):
    return blender_geometry(**{**FULL, **changes}, insert=insert)


def outline_edge_lengths(mesh):
    """Lengths of the outline edges at y = 0: edges of the side faces (those reaching both caps) lying in y = 0."""
    y = mesh.vertices[:, 1]
    lengths = []
    for face in mesh.faces:
        on_front = [v for v in face if y[v] == 0.0]
        if len(on_front) == 2 and len(face) - len(on_front) == 1:
            a, b = mesh.vertices[on_front]
            lengths.append(np.linalg.norm(a - b))
    return np.array(lengths)


# ------------------------------------------------------------------------------------------------ meshes
@pytest.mark.parametrize("scale", [FULL, HALF], ids=["full", "half"])
@pytest.mark.parametrize("preset", [*INSERTS, "none"])
@pytest.mark.parametrize("max_edge", [None, 0.05])
def test_every_mesh_is_a_closed_outward_solid(scale, preset, max_edge):
    meshes = blender_meshes(blender_geometry(**scale, insert=preset), max_edge=max_edge)
    expected = ["hopper_left", "hopper_right"] + ([] if preset == "none" else
                                                  ["insert_left", "insert_right", "tube_left", "tube_right"])
    assert list(meshes) == expected
    for name, mesh in meshes.items():
        assert is_watertight(mesh), name
        assert signed_volume(mesh) > 0, name
        assert len(np.unique(mesh.vertices, axis=0)) == len(mesh.vertices), name
        a, b, c = (mesh.vertices[mesh.faces[:, i]] for i in range(3))
        doubled_area = np.linalg.norm(np.cross(b - a, c - a), axis=1)
        longest = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1)], axis=0)
        assert np.all(doubled_area > 1e-6 * longest**2), name
        assert np.all(mesh.vertices[:, 1] >= 0) and np.all(mesh.vertices[:, 1] <= scale["depth"])


def test_box_volumes_are_thickness_times_length_times_depth():
    g = full("diverging")
    meshes = blender_meshes(g, max_edge=0.02)
    (x_i, z_i), (x_o, z_o) = g.insert_inlet, g.insert_outlet
    insert = 0.005 * math.hypot(x_i - x_o, z_i - z_o) * 0.04
    tube = 0.005 * (g.z_tube_inlet - g.z_tube_outlet) * 0.04
    for side in ("left", "right"):
        assert signed_volume(meshes[f"insert_{side}"]) == pytest.approx(insert, rel=1e-12)
        assert signed_volume(meshes[f"tube_{side}"]) == pytest.approx(tube, rel=1e-12)


@pytest.mark.parametrize("max_edge", [None, 0.05, 0.004])
def test_hopper_volume_is_its_wall_cross_section_times_depth(max_edge):
    t, alpha, hv = 0.005, math.radians(30.0), 1.5
    z_t = 0.205 * math.sqrt(3.0)
    # Outer surface: x = b + t / cos(alpha) + z tan(alpha) up to its bend at z_c = z_t - t tan(alpha/2), then
    # x = W/2 + t. Integrate (outer - inner) dz: slanted strip, the bend between z_c and z_t, the vertical strip.
    bend = t * math.tan(alpha / 2.0)
    area = (z_t - bend) * t / math.cos(alpha) + t * bend + math.tan(alpha) * bend**2 / 2.0 + t * hv
    meshes = blender_meshes(full("diverging"), max_edge=max_edge)
    for side in ("left", "right"):
        assert signed_volume(meshes[f"hopper_{side}"]) == pytest.approx(area * 0.04, rel=1e-12)


def test_box_normals_point_outward():
    g = full("diverging")
    tube = blender_meshes(g)["tube_right"]
    normals, centroids = tube.normals(), tube.vertices[tube.faces].mean(axis=1)
    outer = np.isclose(centroids[:, 0], 0.0225, rtol=0, atol=1e-12)
    inner = np.isclose(centroids[:, 0], 0.0175, rtol=0, atol=1e-12)
    front = centroids[:, 1] == 0.0
    assert outer.sum() == 2 and inner.sum() == 2 and front.sum() == 2
    np.testing.assert_allclose(normals[outer], [[1.0, 0.0, 0.0]] * 2, atol=1e-12)
    np.testing.assert_allclose(normals[inner], [[-1.0, 0.0, 0.0]] * 2, atol=1e-12)
    np.testing.assert_allclose(normals[front], [[0.0, -1.0, 0.0]] * 2, atol=1e-12)
    # the left tube is the mirror: its face at x min (-0.0225) points to -x
    left = blender_meshes(g)["tube_left"]
    at_min = np.isclose(left.vertices[left.faces].mean(axis=1)[:, 0], -0.0225, rtol=0, atol=1e-12)
    np.testing.assert_allclose(left.normals()[at_min], [[-1.0, 0.0, 0.0]] * 2, atol=1e-12)


def test_max_edge_bounds_every_outline_edge():
    # 0.0015 m is below the wall thickness, so the wall ends are split too
    meshes = blender_meshes(blender_geometry(**HALF, insert="converging"), max_edge=0.0015)
    for name, mesh in meshes.items():
        lengths = outline_edge_lengths(mesh)
        assert lengths.max() <= 0.0015 * (1 + 1e-12), name
        assert is_watertight(mesh) and signed_volume(mesh) > 0, name
    unsplit = outline_edge_lengths(blender_meshes(blender_geometry(**HALF, insert="converging"))["hopper_right"])
    assert len(unsplit) == 6  # two surfaces of two segments each, and the two ends


def test_mirror_keeps_the_solid_outward():
    right = blender_meshes(full("converging"))["insert_right"]
    left = mirror_x(right)
    np.testing.assert_array_equal(left.vertices[:, 0], -right.vertices[:, 0])
    assert is_watertight(left)
    assert signed_volume(left) == pytest.approx(signed_volume(right), rel=1e-12)


def test_watertight_rejects_open_and_inconsistent_meshes():
    assert not is_watertight(horizontal_rectangle(0.0, 1.0, 0.0, 1.0, 0.0))
    tube = blender_meshes(full("diverging"))["tube_right"]
    flipped = tube.faces.copy()
    flipped[0] = flipped[0, [0, 2, 1]]
    assert not is_watertight(type(tube)(tube.vertices, flipped))


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # meshio probing an ASCII STL
def test_stl_round_trip_keeps_vertices_and_faces(tmp_path):
    for name, mesh in blender_meshes(full("diverging"), max_edge=0.05).items():
        loaded = read_stl(write_stl(mesh, tmp_path / f"{name}.stl"))
        # meshio's ASCII writer formats each float64 with Python's shortest round-trip repr, so coordinates come
        # back exactly; the tolerance only allows for a writer that prints fewer digits than that.
        expected = mesh.vertices[np.lexsort(mesh.vertices.T[::-1])]
        got = loaded.vertices[np.lexsort(loaded.vertices.T[::-1])]
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
        assert len(loaded.faces) == len(mesh.faces)
        assert is_watertight(loaded)
        assert signed_volume(loaded) == pytest.approx(signed_volume(mesh), rel=1e-12)


def test_a_non_positive_max_edge_is_rejected():
    g = full("diverging")
    with pytest.raises(ValueError, match="max_edge"):
        blender_meshes(g, max_edge=0.0)
