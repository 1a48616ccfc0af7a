"""The Cartesian grid of the coarse-grained fields and the fields on its nodes.

Conventions
-----------
* SI units; coordinates x across the width (x = 0 on the axis), y front-to-back depth
  (y = 0 the front wall, the camera side), z up (z = 0 at the outlet plane).
* Nodes are cell centres: the cells of a :class:`Grid` tile a box (normally the silo
  interior) and node (i, j, k) sits at ``origin + (i + 0.5, j + 0.5, k + 0.5) * spacing``.
* Stress is **compression positive** (soil-mechanics sign).
* Tensors are stored as full 3 x 3 arrays in the last two axes, index order (x, y, z).

:mod:`siloflow.analysis.numerics.coarse_graining` fills the fields from particles,
:mod:`siloflow.analysis.numerics.field_ops` averages and slices them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import points3, vector3

__all__ = ["DEFAULT_SPACING", "DEFAULT_DENSITY_THRESHOLD", "Grid", "Fields", "checked_density_threshold"]

DEFAULT_SPACING: tuple[float, float, float] = (0.006, 0.004, 0.006)
"""Grid spacing of the study (dx, dy, dz) [m]: 6 mm across, 4 mm in depth, 6 mm vertically."""

DEFAULT_DENSITY_THRESHOLD = 1.0e-6
"""Nodes with density at or below this fraction of the maximum density are masked out [-]."""

_REL_TILE_TOLERANCE = 1.0e-9


def _triple(name: str, values, positive: bool) -> tuple[float, float, float]:
    return tuple(float(v) for v in vector3(name, values, positive))


def checked_density_threshold(value: float) -> float:
    """``value`` as the relative mask threshold of :class:`Fields`: a number in [0, 1) [-]."""
    value = float(value)
    if not math.isfinite(value) or not 0.0 <= value < 1.0:
        raise ValueError(f"density_threshold must be a number in [0, 1), got {value!r}")
    return value


# --------------------------------------------------------------------------- grid


@dataclass(frozen=True, kw_only=True)
class Grid:
    """A Cartesian grid of cells tiling a box; the field nodes are the cell centres.

    Attributes
    ----------
    origin : tuple of 3 float
        Lower corner of the box (of cell (0, 0, 0)) [m].
    spacing : tuple of 3 float
        Cell size (dx, dy, dz) [m]; default (6, 4, 6) mm, the grid of the study.
    shape : tuple of 3 int
        Number of cells (nx, ny, nz), each >= 1.

    Notes
    -----
    Node (i, j, k) sits at ``origin + (i + 0.5, j + 0.5, k + 0.5) * spacing``. Arrays of a
    field on the grid have shape ``(nx, ny, nz, ...)`` (x index first). All arguments are
    keyword-only: ``Grid(origin=..., spacing=..., shape=...)``.
    """

    origin: tuple[float, float, float]
    spacing: tuple[float, float, float] = DEFAULT_SPACING
    shape: tuple[int, int, int]

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", _triple("origin", self.origin, positive=False))
        object.__setattr__(self, "spacing", _triple("spacing", self.spacing, positive=True))
        shape = tuple(self.shape) if isinstance(self.shape, (tuple, list, np.ndarray)) else None
        if (
            shape is None
            or len(shape) != 3
            or any(isinstance(n, (bool, np.bool_)) or int(n) != n or int(n) < 1 for n in shape)
        ):
            raise ValueError(f"shape must be 3 integers >= 1 (nx, ny, nz), got {self.shape!r}")
        object.__setattr__(self, "shape", (int(shape[0]), int(shape[1]), int(shape[2])))

    @classmethod
    def covering(
        cls,
        lower,
        upper,
        spacing=DEFAULT_SPACING,
        adjust_spacing: bool = False,
    ) -> "Grid":
        """The grid whose cells exactly tile the box ``[lower, upper]``.

        Parameters
        ----------
        lower, upper : array_like, shape (3,)
            Opposite corners of the box, e.g. the silo interior
            ``(-W/2, 0, 0)`` and ``(W/2, T, H)`` [m]; ``upper > lower`` in every component.
        spacing : array_like, shape (3,), optional
            Wanted cell size (dx, dy, dz) [m]; default (6, 4, 6) mm.
        adjust_spacing : bool, optional
            What to do when a side of the box is not a whole number of cells (within a
            relative 1e-9). False (default): raise ``ValueError``. True: use the nearest whole
            number of cells ``n = max(1, round(L / d))`` and stretch the spacing to ``L / n``,
            so the cells still tile the box exactly (the returned ``spacing`` may then
            differ from the one asked for; compare it).

        Returns
        -------
        Grid
            ``origin = lower``, ``shape = (L / d)`` per axis, ``spacing = L / shape``.
        """
        lower = _triple("lower", lower, positive=False)
        upper = _triple("upper", upper, positive=False)
        spacing = _triple("spacing", spacing, positive=True)
        shape = []
        exact_spacing = []
        for axis, (lo, hi, d) in enumerate(zip(lower, upper, spacing)):
            length = hi - lo
            if length <= 0.0:
                raise ValueError(
                    f"upper must exceed lower in every component; axis {'xyz'[axis]}: "
                    f"lower {lo!r}, upper {hi!r}"
                )
            cells = length / d
            n = max(1, int(round(cells)))
            if abs(cells - n) > _REL_TILE_TOLERANCE * max(cells, 1.0) and not adjust_spacing:
                raise ValueError(
                    f"spacing: the box side along {'xyz'[axis]} ({length!r} m) is {cells:.9g} cells of "
                    f"{d!r} m, not a whole number; choose another spacing or pass adjust_spacing=True "
                    f"(it would use {n} cells of {length / n!r} m)"
                )
            shape.append(n)
            exact_spacing.append(length / n)
        return cls(origin=lower, spacing=tuple(exact_spacing), shape=tuple(shape))

    @property
    def lower(self) -> np.ndarray:
        """Lower corner of the box [m]."""
        return np.array(self.origin)

    @property
    def upper(self) -> np.ndarray:
        """Upper corner of the box, ``origin + shape * spacing`` [m]."""
        return np.array(self.origin) + np.array(self.shape) * np.array(self.spacing)

    @property
    def cell_volume(self) -> float:
        """Volume of one cell ``dx dy dz`` [m3]."""
        return float(self.spacing[0] * self.spacing[1] * self.spacing[2])

    @property
    def n_nodes(self) -> int:
        """Number of nodes (cells) ``nx ny nz``."""
        return int(self.shape[0] * self.shape[1] * self.shape[2])

    def axis(self, index: int) -> np.ndarray:
        """Node coordinates along one axis (0 = x, 1 = y, 2 = z) [m]."""
        if index not in (0, 1, 2):
            raise ValueError(f"index must be 0, 1 or 2, got {index!r}")
        return self.origin[index] + (np.arange(self.shape[index]) + 0.5) * self.spacing[index]

    @property
    def x(self) -> np.ndarray:
        """Node x coordinates, shape (nx,) [m]."""
        return self.axis(0)

    @property
    def y(self) -> np.ndarray:
        """Node y coordinates, shape (ny,) [m]."""
        return self.axis(1)

    @property
    def z(self) -> np.ndarray:
        """Node z coordinates, shape (nz,) [m]."""
        return self.axis(2)

    def node_positions(self) -> np.ndarray:
        """All node positions, shape (nx, ny, nz, 3) [m]."""
        xs, ys, zs = np.meshgrid(self.x, self.y, self.z, indexing="ij")
        return np.stack([xs, ys, zs], axis=-1)

    def contains(self, points) -> np.ndarray:
        """Whether each point lies in the closed box ``[lower, upper]``; shape (n,) bool."""
        points = points3("points", points)
        return np.all((points >= self.lower) & (points <= self.upper), axis=1)


# --------------------------------------------------------------------------- fields


def _frozen(name: str, values, shape: tuple[int, ...], dtype) -> np.ndarray:
    array = np.array(values, dtype=dtype, copy=True)
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Fields:
    """Coarse-grained continuum fields on the nodes of a grid.

    Arrays are copied on construction and read-only. No entry is ever NaN.

    Attributes
    ----------
    grid : Grid
        The grid; arrays have shape ``grid.shape + (...)``.
    density : numpy.ndarray, shape (nx, ny, nz)
        Mass density [kg/m3].
    momentum_density : numpy.ndarray, shape (nx, ny, nz, 3)
        Momentum density [kg/(m2 s)].
    velocity : numpy.ndarray, shape (nx, ny, nz, 3)
        ``momentum_density / density`` where :attr:`mask` is set, 0 elsewhere [m/s].
    kinetic_stress : numpy.ndarray, shape (nx, ny, nz, 3, 3)
        Kinetic (streaming) stress, compression positive, symmetric [Pa].
    mask : numpy.ndarray of bool, shape (nx, ny, nz)
        Nodes with particles: density above ``density_threshold`` times the maximum density.
    density_threshold : float
        Relative threshold used for :attr:`mask` [-].
    """

    grid: Grid
    density: np.ndarray
    momentum_density: np.ndarray
    velocity: np.ndarray
    kinetic_stress: np.ndarray
    mask: np.ndarray
    density_threshold: float = DEFAULT_DENSITY_THRESHOLD

    def __post_init__(self) -> None:
        if not isinstance(self.grid, Grid):
            raise ValueError(f"grid must be a Grid, got {type(self.grid).__name__}")
        shape = self.grid.shape
        set_field = object.__setattr__
        set_field(self, "density", _frozen("density", self.density, shape, np.float64))
        set_field(self, "momentum_density", _frozen("momentum_density", self.momentum_density, shape + (3,), np.float64))
        set_field(self, "velocity", _frozen("velocity", self.velocity, shape + (3,), np.float64))
        set_field(self, "kinetic_stress", _frozen("kinetic_stress", self.kinetic_stress, shape + (3, 3), np.float64))
        set_field(self, "mask", _frozen("mask", self.mask, shape, bool))
        set_field(self, "density_threshold", checked_density_threshold(self.density_threshold))

    @property
    def total_mass(self) -> float:
        """Integral of density over the grid, ``sum(density) * cell volume`` [kg]."""
        return float(self.density.sum() * self.grid.cell_volume)

    @property
    def total_momentum(self) -> np.ndarray:
        """Integral of momentum density over the grid [kg m/s]."""
        return self.momentum_density.sum(axis=(0, 1, 2)) * self.grid.cell_volume

    @classmethod
    def from_moments(cls, grid: Grid, density, momentum_density, kinetic_stress,
                     density_threshold: float = DEFAULT_DENSITY_THRESHOLD) -> "Fields":
        """Fields from density, momentum density and kinetic stress; the mask and velocity are derived.

        The mask holds the nodes with ``density > density_threshold * max(density)`` (none when the
        maximum is 0); the velocity is ``momentum_density / density`` there and 0 elsewhere.
        """
        threshold = checked_density_threshold(density_threshold)
        density = np.asarray(density, dtype=float)
        momentum = np.asarray(momentum_density, dtype=float)
        peak = float(density.max()) if density.size else 0.0
        mask = density > threshold * peak if peak > 0.0 else np.zeros(density.shape, dtype=bool)
        velocity = np.zeros(momentum.shape)
        velocity[mask] = momentum[mask] / density[mask][:, None]
        return cls(grid=grid, density=density, momentum_density=momentum, velocity=velocity,
                   kinetic_stress=kinetic_stress, mask=mask, density_threshold=threshold)
