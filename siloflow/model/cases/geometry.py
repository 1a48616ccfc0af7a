"""Parametric wall geometry as triangle meshes, written as STL for the engines."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import meshio
import numpy as np


@dataclass(frozen=True)
class TriangleMesh:
    """A triangulated surface.

    Attributes
    ----------
    vertices : numpy.ndarray
        (n, 3) vertex coordinates (m).
    faces : numpy.ndarray
        (m, 3) vertex indices per triangle, counter-clockwise seen from the side the normal points to.
    """

    vertices: np.ndarray
    faces: np.ndarray

    def normals(self) -> np.ndarray:
        """Unit normal of every triangle (right-hand rule on the vertex order)."""
        a, b, c = (self.vertices[self.faces[:, i]] for i in range(3))
        cross = np.cross(b - a, c - a)
        return cross / np.linalg.norm(cross, axis=1, keepdims=True)

    def area(self) -> float:
        """Total surface area (m^2)."""
        a, b, c = (self.vertices[self.faces[:, i]] for i in range(3))
        return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


def horizontal_rectangle(x_min: float, x_max: float, y_min: float, y_max: float, z: float) -> TriangleMesh:
    """Rectangle in the plane z = const, two triangles with normals pointing up (+z).

    Parameters
    ----------
    x_min, x_max, y_min, y_max : float
        Extent of the rectangle (m); max must exceed min.
    z : float
        Height of the plane (m).
    """
    if not (x_max > x_min and y_max > y_min):
        raise ValueError(f"empty rectangle: x [{x_min}, {x_max}], y [{y_min}, {y_max}]")
    vertices = np.array(
        [[x_min, y_min, z], [x_max, y_min, z], [x_max, y_max, z], [x_min, y_max, z]], dtype=float
    )
    faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    return TriangleMesh(vertices, faces)


def vertical_rectangle_x(x: float, y_min: float, y_max: float, z_min: float, z_max: float, normal: float) -> TriangleMesh:
    """Rectangle in the plane x = const, two triangles with normals along ``sign(normal)`` x.

    Parameters
    ----------
    x : float
        Position of the plane (m).
    y_min, y_max, z_min, z_max : float
        Extent of the rectangle (m); max must exceed min.
    normal : float
        +1 for normals pointing to +x, -1 for -x.
    """
    if not (y_max > y_min and z_max > z_min):
        raise ValueError(f"empty rectangle: y [{y_min}, {y_max}], z [{z_min}, {z_max}]")
    if normal not in (1, -1, 1.0, -1.0):
        raise ValueError(f"normal must be +1 or -1, got {normal!r}")
    vertices = np.array(
        [[x, y_min, z_min], [x, y_max, z_min], [x, y_max, z_max], [x, y_min, z_max]], dtype=float
    )
    # (y, z) counter-clockwise seen from +x gives a +x normal.
    faces = np.array([[0, 1, 2], [0, 2, 3]] if normal > 0 else [[0, 2, 1], [0, 3, 2]], dtype=np.int64)
    return TriangleMesh(vertices, faces)


def write_stl(mesh: TriangleMesh, path: str | Path) -> Path:
    """Write an ASCII STL file (LIGGGHTS reads ASCII STL), atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    meshio.write(
        partial,
        meshio.Mesh(mesh.vertices, [("triangle", mesh.faces)]),
        file_format="stl",
        binary=False,
    )
    os.replace(partial, path)
    return path


def read_stl(path: str | Path) -> TriangleMesh:
    """Read an STL file into a :class:`TriangleMesh` (duplicate vertices merged by meshio)."""
    loaded = meshio.read(path, file_format="stl")
    return TriangleMesh(np.asarray(loaded.points, dtype=float), np.asarray(loaded.cells_dict["triangle"]))
