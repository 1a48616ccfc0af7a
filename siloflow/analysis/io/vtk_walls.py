"""Writer of a case's wall meshes for ParaView: every wall in one VTK XML PolyData file (.vtp).

The meshes are the case model's (:class:`siloflow.model.cases.geometry.TriangleMesh`, the same the engines turn into their
walls: LIGGGHTS' STL files, YADE's facets), so a run of either engine shows its walls. The walls the engines make of
planes (a silo's side, front and back walls) are not meshes and are not drawn; the particles show where they are.

Layout: one triangle cell per mesh face, in the order of the meshes; cell data ``wall`` (Int32), the index of each
face's wall in the field-data string array ``wall_names``, so that ParaView can pick a wall out (Threshold on
``wall``) or hide the gate, which is open from the discharge on.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pyvista

from siloflow.analysis.io.vtk_xml import write_vtk_xml
from siloflow.model.cases.geometry import TriangleMesh

__all__ = ["walls_polydata", "write_walls_vtp"]


def walls_polydata(meshes: Mapping[str, TriangleMesh]) -> pyvista.PolyData:
    """The :class:`pyvista.PolyData` that :func:`write_walls_vtp` writes (same arguments, see there)."""
    meshes = dict(meshes)
    if not meshes:
        raise ValueError("meshes must hold at least one wall")
    vertices, faces, wall = [], [], []
    start = 0
    for index, (name, mesh) in enumerate(meshes.items()):
        if not isinstance(mesh, TriangleMesh):
            raise ValueError(f"meshes[{name!r}] must be a TriangleMesh, got {type(mesh).__name__}")
        vertices.append(np.asarray(mesh.vertices, dtype=float))
        faces.append(np.asarray(mesh.faces, dtype=np.int64) + start)
        wall.append(np.full(len(mesh.faces), index, dtype=np.int32))
        start += len(mesh.vertices)
    triangles = np.vstack(faces)
    # VTK's cell array: 3, then the three corner indices, per face
    cells = np.column_stack([np.full(len(triangles), 3, dtype=np.int64), triangles]).reshape(-1)
    data = pyvista.PolyData(np.vstack(vertices), faces=cells)
    data.cell_data["wall"] = np.concatenate(wall)
    data.field_data["wall_names"] = np.array(list(meshes), dtype=str)
    return data


def write_walls_vtp(path: str | os.PathLike, meshes: Mapping[str, TriangleMesh]) -> Path:
    """Write a case's wall meshes as one VTK XML PolyData file (.vtp), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination, normally ending in ``.vtp``.
    meshes : mapping of str to TriangleMesh
        The walls by name, vertices in m (e.g. :func:`siloflow.model.cases.silo_flat.silo_meshes` of a case).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    return write_vtk_xml(path, walls_polydata(meshes))
