"""The neutral planar velocity field of PIV and of DEM front-wall fields: nodes on a regular x-z grid, the two
in-plane velocity components and a validity mask.

Conventions (those of :mod:`analysis.numerics.grid`): SI units, x across the silo (x = 0 on the axis), z up (z = 0
at the outlet plane); ``u`` is the x velocity, ``w`` the z velocity (negative downwards). Arrays are indexed
``[k, i]``: row k along z, column i along x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PivRows", "PlanarField", "field_from_rows", "time_average"]


@dataclass(frozen=True)
class PlanarField:
    """A velocity field on a regular x-z grid.

    Attributes
    ----------
    x : numpy.ndarray, shape (nx,)
        Node x coordinates, increasing [m].
    z : numpy.ndarray, shape (nz,)
        Node z coordinates, increasing [m].
    u, w : numpy.ndarray, shape (nz, nx)
        Horizontal and vertical velocity [m/s]; NaN where not valid.
    valid : numpy.ndarray of bool, shape (nz, nx)
        Where the velocity is a measurement (not masked, not an outlier, not interpolated).
    time : float
        Time of the field [s].
    """

    x: np.ndarray
    z: np.ndarray
    u: np.ndarray
    w: np.ndarray
    valid: np.ndarray
    time: float = 0.0

    def __post_init__(self) -> None:
        x, z = np.asarray(self.x, dtype=float), np.asarray(self.z, dtype=float)
        for name, axis in (("x", x), ("z", z)):
            if axis.ndim != 1 or axis.size < 1 or not np.all(np.isfinite(axis)):
                raise ValueError(f"{name} must be a finite 1-D array of node coordinates")
            if np.any(np.diff(axis) <= 0):
                raise ValueError(f"{name} must increase from node to node")
        shape = (z.size, x.size)
        u, w = np.asarray(self.u, dtype=float), np.asarray(self.w, dtype=float)
        valid = np.asarray(self.valid, dtype=bool)
        for name, array in (("u", u), ("w", w), ("valid", valid)):
            if array.shape != shape:
                raise ValueError(f"{name} has shape {array.shape}, expected (nz, nx) = {shape}")
        if np.any(valid & ~(np.isfinite(u) & np.isfinite(w))):
            raise ValueError("a valid node has a non-finite velocity")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "u", np.where(valid, u, np.nan))
        object.__setattr__(self, "w", np.where(valid, w, np.nan))
        object.__setattr__(self, "valid", valid)


def field_from_rows(x, z, u, w, valid, time: float = 0.0, decimals: int = 9) -> PlanarField:
    """A :class:`PlanarField` from one row per node (any order), as PIV programs write them.

    Coordinates are rounded to ``decimals`` before they are matched to grid lines (text files carry a few digits).

    Raises
    ------
    ValueError
        When the nodes do not fill a regular grid (a node missing or given twice).
    """
    x, z = np.round(np.asarray(x, dtype=float), decimals), np.round(np.asarray(z, dtype=float), decimals)
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(z))):
        raise ValueError("node coordinates must be finite")
    xs, i = np.unique(x, return_inverse=True)
    zs, k = np.unique(z, return_inverse=True)
    if xs.size * zs.size != x.size or np.unique(k * xs.size + i).size != x.size:
        raise ValueError(f"{x.size} nodes do not fill a regular grid of {xs.size} x {zs.size} nodes")
    shape = (zs.size, xs.size)
    grids = [np.full(shape, np.nan), np.full(shape, np.nan), np.zeros(shape, dtype=bool)]
    for grid, values in zip(grids, (u, w, valid)):
        grid[k, i] = values
    return PlanarField(xs, zs, grids[0], grids[1], grids[2], time)


def time_average(fields, start: float, end: float, min_fraction: float = 0.5) -> PlanarField:
    """The mean of the fields with ``start <= time <= end`` [s], node by node over the fields where the node is valid;
    a node valid in fewer than ``min_fraction`` of them is not valid. Its time is the mean time of the fields.

    Raises
    ------
    ValueError
        When no field lies in the window, or the fields are not on one grid.
    """
    chosen = [f for f in fields if start <= f.time <= end]
    if not chosen:
        raise ValueError(f"no PIV field between {start} and {end} s")
    first = chosen[0]
    if any(f.u.shape != first.u.shape or not (np.array_equal(f.x, first.x) and np.array_equal(f.z, first.z))
           for f in chosen):
        raise ValueError("the PIV fields to average are not on one grid")
    valid = np.array([f.valid for f in chosen])
    count = valid.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        u, w = (np.where(valid, component, 0.0).sum(axis=0) / count
                for component in (np.array([f.u for f in chosen]), np.array([f.w for f in chosen])))
    keep = count >= max(1.0, min_fraction * len(chosen))
    return PlanarField(first.x, first.z, u, w, keep, float(np.mean([f.time for f in chosen])))


@dataclass(frozen=True)
class PivRows:
    """One row per vector as a PIV program wrote it: positions (x, y) and displacements or velocities (u, v) in the
    file's units, ``y_down`` when y and v point down the image, and which vectors are measurements. ``pixels`` is
    True for pixels and displacements per frame, False for metres and m/s, None when the file does not say."""

    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    v: np.ndarray
    valid: np.ndarray
    y_down: bool
    pixels: bool | None = None
