"""The steady field of the multi-flow blender (thesis ch. 7): velocities and solid fraction on (x, z) bins.

Pure computation on numpy arrays; no file I/O. SI units: lengths in m, velocities in m/s.

Input
-----
The caller builds from the engine's frames a time-averaged, depth-averaged steady field on a regular
(x, z) grid (:mod:`siloflow.analysis.studies.blender.window_fields`), a :class:`BlenderField`: bin centres ``x``
(nx,) and ``z`` (nz,), velocities ``v_x``, ``v_z`` (nx, nz) and the solid fraction (nx, nz) (only its
ratios are used, as tracer weights). A bin is *occupied* where the solid fraction is finite and > 0;
elsewhere (inside walls, above the fill) the velocity is not used. x runs across the width with x = 0
on the axis of the mirror-symmetric silo (a field may cover both halves or only x >= 0), z is up with
the outlet plane at z = 0, and the flow is downward (``v_z < 0``).

Interpolation in height
-----------------------
A profile at a height ``z`` between two bin rows is linear in z between the rows (exact at a row;
:func:`siloflow.analysis.numerics.profiles.velocity_profile`); where only one of the two bins is occupied its
value is taken, where neither is the profile is NaN (:func:`at_height`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, positive_number, uniform_step
from siloflow.analysis.numerics.grid import Fields
from siloflow.analysis.numerics.profiles import velocity_profile

__all__ = ["BlenderField", "checked_field", "at_height"]


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


def _increasing(name: str, values) -> np.ndarray:
    array = finite_array(name, values, ndim=1)
    if array.size == 0 or np.any(np.diff(array) <= 0.0):
        raise ValueError(f"{name} must be a non-empty, strictly increasing array")
    return array


@dataclass(frozen=True, eq=False)
class BlenderField:
    """A steady (time-averaged), depth-averaged field on a regular (x, z) grid of bins.

    Arrays are copied and read-only. Velocities are NaN and the solid fraction 0 in unoccupied bins.

    Attributes
    ----------
    x : numpy.ndarray, shape (nx,)
        Bin centres across the width, strictly increasing [m] (x = 0 on the silo axis).
    z : numpy.ndarray, shape (nz,)
        Bin centres in height, strictly increasing [m] (z = 0 at the outlet plane).
    v_x, v_z : numpy.ndarray, shape (nx, nz)
        Velocity components [m/s] (``v_z < 0`` downward); they must be finite in occupied bins.
    solid_fraction : numpy.ndarray, shape (nx, nz)
        Solid volume fraction [-]; 0 or NaN where there are no particles, never negative or infinite.
        Only its ratios are used (as tracer weights), so any quantity proportional to it will do.
    """

    x: np.ndarray
    z: np.ndarray
    v_x: np.ndarray
    v_z: np.ndarray
    solid_fraction: np.ndarray

    def __post_init__(self) -> None:
        x = _increasing("x", self.x)
        z = _increasing("z", self.z)
        shape = (x.size, z.size)
        fraction = np.array(self.solid_fraction, dtype=float)
        if fraction.shape != shape:
            raise ValueError(f"solid_fraction must have shape {shape} = (len(x), len(z)), got {fraction.shape}")
        if np.any(np.isinf(fraction)) or np.any(fraction < 0.0):
            raise ValueError("solid_fraction must be >= 0 or NaN (no particles), never negative or infinite")
        occupied = np.isfinite(fraction) & (fraction > 0.0)
        set_field = object.__setattr__
        for name in ("v_x", "v_z"):
            velocity = np.array(getattr(self, name), dtype=float)
            if velocity.shape != shape:
                raise ValueError(f"{name} must have shape {shape} = (len(x), len(z)), got {velocity.shape}")
            if not np.all(np.isfinite(velocity[occupied])):
                raise ValueError(f"{name} must be finite in every occupied bin (solid_fraction > 0)")
            set_field(self, name, _read_only(np.where(occupied, velocity, np.nan)))
        set_field(self, "x", _read_only(x.copy()))
        set_field(self, "z", _read_only(z.copy()))
        set_field(self, "solid_fraction", _read_only(np.where(occupied, fraction, 0.0)))

    @classmethod
    def from_fields(cls, fields: Fields, particle_density: float) -> "BlenderField":
        """The field of a depth-averaged :class:`~siloflow.analysis.numerics.grid.Fields` (one node layer in y).

        The solid fraction is the bulk density over ``particle_density`` [kg/m^3] where the fields' mask
        is set, 0 elsewhere.
        """
        if not isinstance(fields, Fields):
            raise ValueError(f"fields must be a Fields, got {type(fields).__name__}")
        if fields.grid.shape[1] != 1:
            raise ValueError(
                f"fields must have one node layer in y (use depth_average), got {fields.grid.shape[1]} layers"
            )
        particle_density = positive_number("particle_density", particle_density)
        return cls(
            x=fields.grid.x,
            z=fields.grid.z,
            v_x=fields.velocity[:, 0, :, 0],
            v_z=fields.velocity[:, 0, :, 2],
            solid_fraction=np.where(fields.mask[:, 0, :], fields.density[:, 0, :] / particle_density, 0.0),
        )

    @classmethod
    def from_planar(cls, planar) -> "BlenderField":
        """The field of an object with attributes ``x, z, v_x, v_z, solid_fraction`` (e.g.
        :class:`siloflow.analysis.studies.blender.window_fields.PlanarField`, whose velocities are NaN in bins no clump entered)."""
        try:
            arrays = {name: getattr(planar, name) for name in ("x", "z", "v_x", "v_z", "solid_fraction")}
        except AttributeError as error:
            raise ValueError(f"planar must have x, z, v_x, v_z and solid_fraction ({error})") from None
        return cls(**arrays)

    @property
    def occupied(self) -> np.ndarray:
        """Bins with particles (solid fraction > 0), shape (nx, nz)."""
        return self.solid_fraction > 0.0

    def bin_size(self) -> tuple[float, float]:
        """Uniform bin edges ``(dx, dz)`` [m]; a ValueError unless both axes are uniform with >= 2 bins."""
        return uniform_step("field.x", self.x), uniform_step("field.z", self.z)


def checked_field(field) -> BlenderField:
    """``field`` when it is a :class:`BlenderField`, else a ValueError."""
    if not isinstance(field, BlenderField):
        raise ValueError(f"field must be a BlenderField, got {type(field).__name__}")
    return field


def at_height(field: BlenderField, values: np.ndarray, z_value: float) -> np.ndarray:
    """``values`` (nx, nz) at height ``z_value``: linear in z between the occupied bins of the two rows.

    :func:`siloflow.analysis.numerics.profiles.velocity_profile` interpolates the occupancy-weighted values and the
    occupancy together; their ratio renormalises the weights to the occupied bins (NaN where none).
    """
    occupancy = field.occupied.astype(float)
    weighted = velocity_profile((field.x, field.z, np.where(field.occupied, values, 0.0), occupancy), z_value)
    weight = weighted.v_z
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(weight > 0.0, weighted.v_x / np.where(weight > 0.0, weight, 1.0), np.nan)
