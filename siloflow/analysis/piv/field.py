"""The neutral planar velocity field of PIV and of DEM front-wall fields: nodes on a regular x-z grid, the two
in-plane velocity components and a validity mask; and :class:`PivRows`, one PIV file's vectors as its program wrote
them, each with the kind of node its program says it is.

Conventions (those of :mod:`siloflow.analysis.numerics.grid`): SI units, x across the silo (x = 0 on the axis), z up (z = 0
at the outlet plane); ``u`` is the x velocity, ``w`` the z velocity (negative downwards). Arrays are indexed
``[k, i]``: row k along z, column i along x.

Node kinds
----------
Every PIV program says in its own words what each vector is; the readers translate them into one set of kinds
(:data:`NODE_KINDS`, stored as their index in an ``int8`` array):

``measured``
    The highest correlation peak, kept by the program's validation.
``second_peak``
    A lower correlation peak that the program's validation took instead of a rejected highest one.
``interpolated``
    A vector the program filled in, interpolated or smoothed instead of taking it from a correlation peak.
``unflagged``
    A finite vector in a file that does not say which of the three above it is.
``masked``
    Outside the image mask: no vector was measured.
``invalid``
    Rejected by the program's validation and not replaced, or without a finite velocity.

Which kinds count as valid is the measured sequence's policy (``silo_flat.piv.measured.valid``, default
:data:`DEFAULT_VALID_KINDS`); ``masked`` and ``invalid`` never do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["DEFAULT_VALID_KINDS", "INTERPOLATED", "INVALID", "MASKED", "MEASURED", "NODE_KINDS", "SECOND_PEAK",
           "SELECTABLE_KINDS", "UNFLAGGED", "PivRows", "PlanarField", "field_from_rows", "kind_codes", "time_average"]

#: The kinds of PIV node, in the order of their codes (module docstring).
NODE_KINDS = ("measured", "second_peak", "interpolated", "unflagged", "masked", "invalid")
#: The code of each kind.
MEASURED, SECOND_PEAK, INTERPOLATED, UNFLAGGED, MASKED, INVALID = range(len(NODE_KINDS))
#: The kinds a validity policy may count as valid.
SELECTABLE_KINDS = NODE_KINDS[:4]
#: The kinds counted as valid unless the configuration says otherwise.
DEFAULT_VALID_KINDS = ("measured", "second_peak")


def kind_codes(kinds) -> np.ndarray:
    """The codes (int8) of the node kinds named in ``kinds``.

    Raises
    ------
    ValueError
        Naming a kind that is not one of :data:`NODE_KINDS`.
    """
    unknown = [k for k in kinds if k not in NODE_KINDS]
    if unknown:
        raise ValueError(f"unknown PIV node kind(s) {', '.join(map(repr, unknown))}; the kinds are "
                         f"{', '.join(NODE_KINDS)}")
    return np.array([NODE_KINDS.index(k) for k in kinds], dtype=np.int8)


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
        Where the velocity counts: for PIV, a node of a kind the validity policy counts that no filter removed.
    time : float
        Time of the field [s].
    kind : numpy.ndarray of int8, shape (nz, nx), or None
        What the PIV program says each node is (codes of :data:`NODE_KINDS`); None for fields that are not PIV
        (the DEM's).
    """

    x: np.ndarray
    z: np.ndarray
    u: np.ndarray
    w: np.ndarray
    valid: np.ndarray
    time: float = 0.0
    kind: np.ndarray | None = None

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
        if self.kind is not None:
            kind = np.asarray(self.kind)
            if kind.shape != shape:
                raise ValueError(f"kind has shape {kind.shape}, expected (nz, nx) = {shape}")
            if kind.dtype.kind not in "iu" or kind.size and not 0 <= kind.min() <= kind.max() < len(NODE_KINDS):
                raise ValueError(f"kind holds codes other than 0 to {len(NODE_KINDS) - 1} ({', '.join(NODE_KINDS)})")
            object.__setattr__(self, "kind", kind.astype(np.int8))
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "u", np.where(valid, u, np.nan))
        object.__setattr__(self, "w", np.where(valid, w, np.nan))
        object.__setattr__(self, "valid", valid)


def field_from_rows(x, z, u, w, valid, time: float = 0.0, decimals: int = 9, kind=None) -> PlanarField:
    """A :class:`PlanarField` from one row per node (any order), as PIV programs write them; ``kind`` (codes of
    :data:`NODE_KINDS`, one per row) goes onto the grid with them when given.

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
    kinds = None
    if kind is not None:
        kinds = np.full(shape, INVALID, dtype=np.int8)
        kinds[k, i] = kind
    return PlanarField(xs, zs, grids[0], grids[1], grids[2], time, kinds)


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
    """One row per vector as a PIV program wrote it.

    Attributes
    ----------
    x, y : numpy.ndarray, shape (n,)
        Positions in the file's units: pixels [px] or metres [m].
    u, v : numpy.ndarray, shape (n,)
        Displacements [px/frame] or velocities [m/s] along x and y, in the file's units.
    kind : numpy.ndarray of int8, shape (n,)
        What the program says each vector is (codes of :data:`NODE_KINDS`). A boolean array is taken as measured
        (True) or invalid (False), for rows made by hand.
    y_down : bool
        True when y and v point down the image (image rows), False when they point up.
    pixels : bool or None
        True for pixels and displacements per frame, False for metres and m/s, None when the file does not say.
    out_of_plane : numpy.ndarray, shape (n,), or None
        The third velocity component of a stereo file, in the unit of u and v, when the reader was told to keep it.
    """

    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    v: np.ndarray
    kind: np.ndarray
    y_down: bool
    pixels: bool | None = None
    out_of_plane: np.ndarray | None = None

    def __post_init__(self) -> None:
        arrays = {name: np.asarray(getattr(self, name), dtype=float).ravel() for name in ("x", "y", "u", "v")}
        kind = np.asarray(self.kind).ravel()
        if kind.dtype == bool:
            kind = np.where(kind, MEASURED, INVALID)
        if kind.dtype.kind not in "iu" or kind.size and not 0 <= kind.min() <= kind.max() < len(NODE_KINDS):
            raise ValueError(f"kind holds codes other than 0 to {len(NODE_KINDS) - 1} ({', '.join(NODE_KINDS)})")
        arrays["kind"] = kind.astype(np.int8)
        if self.out_of_plane is not None:
            arrays["out_of_plane"] = np.asarray(self.out_of_plane, dtype=float).ravel()
        sizes = {name: array.size for name, array in arrays.items()}
        if len(set(sizes.values())) > 1:
            raise ValueError(f"PIV rows of different lengths: {sizes}")
        for name, array in arrays.items():
            object.__setattr__(self, name, array)

    def counted(self, kinds=DEFAULT_VALID_KINDS) -> np.ndarray:
        """Where the vector is of one of ``kinds`` (names of :data:`NODE_KINDS`) and has a finite velocity."""
        return np.isin(self.kind, kind_codes(kinds)) & np.isfinite(self.u) & np.isfinite(self.v)

    @property
    def valid(self) -> np.ndarray:
        """Where the vector counts under the default policy (:data:`DEFAULT_VALID_KINDS`)."""
        return self.counted()
