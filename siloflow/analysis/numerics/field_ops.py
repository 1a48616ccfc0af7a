"""Operations on coarse-grained fields: time average, depth average and the layer at the front wall.

Pure functions on :class:`siloflow.analysis.numerics.grid.Fields`; velocities are always re-derived from the
averaged momentum and density (mass-weighted), never averaged themselves.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from siloflow.analysis.numerics.grid import Fields, Grid

__all__ = ["average_fields", "depth_average", "front_wall_slice"]


def average_fields(fields: Sequence[Fields], density_threshold: float | None = None) -> Fields:
    """Time average of fields on the same grid.

    Density, momentum density and kinetic stress are arithmetic means over the frames; the
    velocity is the mass-weighted mean ``mean(p) / mean(rho)`` (not the mean of the frame
    velocities), masked as in :meth:`Fields.from_moments`. The kinetic stress is the mean of the
    instantaneous kinetic stresses (fluctuations about each frame's own node velocity);
    velocity fluctuations between frames are not added to it.

    Parameters
    ----------
    fields : sequence of Fields
        At least one frame, all on the same grid.
    density_threshold : float, optional
        Mask threshold of the result; default: that of the first frame.

    Returns
    -------
    Fields
    """
    fields = list(fields)
    if not fields:
        raise ValueError("fields must contain at least one Fields")
    if not all(isinstance(item, Fields) for item in fields):
        raise ValueError("fields must contain only Fields")
    grid = fields[0].grid
    for index, item in enumerate(fields):
        if item.grid != grid:
            raise ValueError(f"fields: frame {index} is on a different grid ({item.grid}) than frame 0 ({grid})")
    threshold = fields[0].density_threshold if density_threshold is None else density_threshold
    count = len(fields)
    density = sum(item.density for item in fields) / count
    momentum = sum(item.momentum_density for item in fields) / count
    kinetic = sum(item.kinetic_stress for item in fields) / count
    return Fields.from_moments(grid, density, momentum, kinetic, threshold)


def depth_average(fields: Fields) -> Fields:
    """Average over the depth (y): one layer of nodes, shape (nx, 1, nz).

    Density, momentum density and kinetic stress are means over the y nodes; the velocity is
    density-weighted, ``sum_y p / sum_y rho``, masked as in :meth:`Fields.from_moments`. The
    returned grid spans the same box with one cell in y (``spacing_y = T``), so its single node
    lies at mid-depth.
    """
    if not isinstance(fields, Fields):
        raise ValueError(f"fields must be a Fields, got {type(fields).__name__}")
    grid = fields.grid
    ny = grid.shape[1]
    flat = Grid(
        origin=grid.origin,
        spacing=(grid.spacing[0], grid.spacing[1] * ny, grid.spacing[2]),
        shape=(grid.shape[0], 1, grid.shape[2]),
    )
    density = fields.density.mean(axis=1, keepdims=True)
    momentum = fields.momentum_density.mean(axis=1, keepdims=True)
    kinetic = fields.kinetic_stress.mean(axis=1, keepdims=True)
    return Fields.from_moments(flat, density, momentum, kinetic, fields.density_threshold)


def front_wall_slice(fields: Fields, wall_y: float = 0.0) -> Fields:
    """The layer of nodes nearest the front wall (y = 0, the camera side), shape (nx, 1, nz).

    Parameters
    ----------
    fields : Fields
        Fields on a grid with any number of y layers.
    wall_y : float, optional
        y of the front wall [m] (default 0).

    Returns
    -------
    Fields
        The node layer nearest ``wall_y`` (the first layer when the grid starts at the wall,
        i.e. the nodes at ``y = dy / 2``), values unchanged; its grid is that single cell
        layer, so the node keeps its y coordinate.
    """
    if not isinstance(fields, Fields):
        raise ValueError(f"fields must be a Fields, got {type(fields).__name__}")
    wall_y = float(wall_y)
    if not math.isfinite(wall_y):
        raise ValueError(f"wall_y must be finite, got {wall_y!r}")
    grid = fields.grid
    layer = int(np.argmin(np.abs(grid.y - wall_y)))
    sliced = Grid(
        origin=(grid.origin[0], grid.origin[1] + layer * grid.spacing[1], grid.origin[2]),
        spacing=grid.spacing,
        shape=(grid.shape[0], 1, grid.shape[2]),
    )
    pick = slice(layer, layer + 1)
    return Fields(
        grid=sliced,
        density=fields.density[:, pick],
        momentum_density=fields.momentum_density[:, pick],
        velocity=fields.velocity[:, pick],
        kinetic_stress=fields.kinetic_stress[:, pick],
        mask=fields.mask[:, pick],
        density_threshold=fields.density_threshold,
    )
