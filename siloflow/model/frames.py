"""Particle and clump frames: the engine-neutral state of the particles at one saved instant.

Every engine reader returns :class:`ParticleFrame` objects (one per saved step, per-sphere arrays); analysis
turns them into :class:`ClumpFrame` objects (one row per clump) with :func:`clumps_from_frame`. Nothing here reads
or writes files.

All quantities are SI: metres, seconds, kilograms, newtons, radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.arrays import frozen_array

__all__ = ["ParticleFrame", "ClumpFrame", "clumps_from_frame"]

#: Per-sphere vectors a frame may carry or leave out (dumps of the silo-type decks omit them).
OPTIONAL_VECTORS = ("angular_velocity", "force")



@dataclass(frozen=True, eq=False)
class ParticleFrame:
    """The spheres of one dump step.

    Arrays are copied on construction and read-only; row i of every array is sphere i.

    Attributes
    ----------
    time : float
        Simulated time [s] (step times the time step).
    step : int
        Time step number of the dump [-].
    id : numpy.ndarray of int64, shape (n,)
        Sphere id (unique in a frame) [-].
    type : numpy.ndarray of int32, shape (n,)
        Material (atom) type [-].
    clump_id : numpy.ndarray of int64, shape (n,)
        Id of the rigid clump the sphere belongs to (the engine's clump id); a free
        sphere carries its own sphere id [-].
    position : numpy.ndarray of float64, shape (n, 3)
        Sphere centre [m].
    velocity : numpy.ndarray of float64, shape (n, 3)
        Velocity of the sphere centre [m/s].
    angular_velocity : numpy.ndarray of float64, shape (n, 3), or None
        Angular velocity [rad/s] (for a clump sphere, that of its clump); None when the dump has no omega
        columns (the silo-type decks leave them out: their analyses do not use them).
    radius : numpy.ndarray of float64, shape (n,)
        Sphere radius [m].
    mass : numpy.ndarray of float64, shape (n,)
        Mass [kg]. LIGGGHTS writes the CLUMP mass on every sphere of a multisphere clump,
        so do not sum it over spheres; use :func:`clumps_from_frame`.
    force : numpy.ndarray of float64, shape (n, 3), or None
        Total force on the sphere [N], None when the dump has no force columns.
    """

    time: float
    step: int
    id: np.ndarray
    type: np.ndarray
    clump_id: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray | None
    radius: np.ndarray
    mass: np.ndarray
    force: np.ndarray | None = None

    def __post_init__(self) -> None:
        ids = frozen_array(self.id, np.int64, (), "id", None)
        n = ids.shape[0]
        set_field = object.__setattr__
        set_field(self, "time", float(self.time))
        set_field(self, "step", int(self.step))
        set_field(self, "id", ids)
        set_field(self, "type", frozen_array(self.type, np.int32, (), "type", n))
        set_field(self, "clump_id", frozen_array(self.clump_id, np.int64, (), "clump_id", n))
        for name in ("position", "velocity"):
            set_field(self, name, frozen_array(getattr(self, name), np.float64, (3,), name, n))
        for name in ("radius", "mass"):
            set_field(self, name, frozen_array(getattr(self, name), np.float64, (), name, n))
        for name in OPTIONAL_VECTORS:
            if getattr(self, name) is not None:
                set_field(self, name, frozen_array(getattr(self, name), np.float64, (3,), name, n))
        # engines write spheres in ascending id order: checking that first spares the sort (a third of a read)
        sorted_ids = ids if np.all(ids[1:] > ids[:-1]) else np.sort(ids)
        if np.any(sorted_ids[1:] == sorted_ids[:-1]):
            raise ValueError("sphere ids in a frame must be unique")

    def __len__(self) -> int:
        return int(self.id.shape[0])


@dataclass(frozen=True, eq=False)
class ClumpFrame:
    """The rigid clumps of one dump step (one row per clump, sorted by clump id).

    Attributes
    ----------
    time : float
        Simulated time [s].
    step : int
        Time step number [-].
    clump_id : numpy.ndarray of int64, shape (m,)
        Clump id, ascending [-].
    position : numpy.ndarray of float64, shape (m, 3)
        Mean of the clump's sphere centres [m]; the centre of mass for the symmetric
        templates used (see :func:`clumps_from_frame`).
    velocity : numpy.ndarray of float64, shape (m, 3)
        Mean of the sphere velocities [m/s]; the centre-of-mass velocity for those templates.
    mass : numpy.ndarray of float64, shape (m,)
        Clump mass [kg].
    n_spheres : numpy.ndarray of int64, shape (m,)
        Number of spheres in the clump [-].
    """

    time: float
    step: int
    clump_id: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    mass: np.ndarray
    n_spheres: np.ndarray

    def __post_init__(self) -> None:
        ids = frozen_array(self.clump_id, np.int64, (), "clump_id", None)
        m = ids.shape[0]
        set_field = object.__setattr__
        set_field(self, "time", float(self.time))
        set_field(self, "step", int(self.step))
        set_field(self, "clump_id", ids)
        set_field(self, "position", frozen_array(self.position, np.float64, (3,), "position", m))
        set_field(self, "velocity", frozen_array(self.velocity, np.float64, (3,), "velocity", m))
        set_field(self, "mass", frozen_array(self.mass, np.float64, (), "mass", m))
        set_field(self, "n_spheres", frozen_array(self.n_spheres, np.int64, (), "n_spheres", m))

    def __len__(self) -> int:
        return int(self.clump_id.shape[0])


def clumps_from_frame(frame: ParticleFrame, periodic_bounds=None) -> ClumpFrame:
    """Group the spheres of a frame into rigid clumps.

    The clump position is the mean of its sphere centres and the clump velocity the mean
    of its sphere velocities. For the symmetric templates used here (a single sphere, two
    equal spheres, a regular tetrahedron of four equal spheres) the mean of the sphere
    centres is the centre of mass, so these are the centre-of-mass position and velocity
    (the mean sphere velocity is v_cm + omega x (mean centre - centre of mass) = v_cm). For
    an asymmetric template the mean would be a geometric centre, not the centre of mass.

    Parameters
    ----------
    frame : ParticleFrame
        Spheres of one step; ``mass`` holds the clump mass on every sphere of a clump.
    periodic_bounds : sequence of 3 (lower, upper) or None, optional
        Box bounds [m] of the periodic axes (None for the others, and None for no periodic axis, the
        default). The engine wraps every sphere into the box on its own, so a clump that straddles a
        periodic boundary has spheres on both sides; they are taken to the minimum image of the
        clump's first sphere before averaging, and the clump position is wrapped back into
        ``[lower, upper)``.

    Returns
    -------
    ClumpFrame
        One row per clump, sorted by clump id: position [m], velocity [m/s], mass [kg],
        number of spheres.

    Raises
    ------
    ValueError
        When spheres of one clump carry different masses.
    """
    clump_ids, first_index, inverse, n_spheres = np.unique(
        frame.clump_id, return_index=True, return_inverse=True, return_counts=True
    )
    inverse = inverse.reshape(-1)  # numpy 2.0 returned it in the input's shape
    m = clump_ids.size

    def clump_mean(values: np.ndarray) -> np.ndarray:
        sums = np.stack(
            [np.bincount(inverse, weights=values[:, axis], minlength=m) for axis in range(3)], axis=1
        )
        return sums / n_spheres[:, None]

    position = frame.position
    if m and periodic_bounds is not None:
        position, bounds = position.copy(), list(periodic_bounds)
        if len(bounds) != 3:
            raise ValueError(f"periodic_bounds must give 3 axes (None for non-periodic), got {len(bounds)}")
        for axis, axis_bounds in enumerate(bounds):
            if axis_bounds is None:
                continue
            lower, upper = (float(v) for v in axis_bounds)
            if not upper > lower:
                raise ValueError(f"periodic_bounds[{axis}] must have upper > lower, got {axis_bounds!r}")
            length = upper - lower
            anchor = position[first_index[inverse], axis]
            position[:, axis] -= length * np.round((position[:, axis] - anchor) / length)
    if m:
        # Spheres sorted by clump, then min == max per clump <=> one mass per clump.
        order = np.argsort(inverse, kind="stable")
        starts = np.concatenate(([0], np.cumsum(n_spheres)[:-1]))
        sorted_mass = frame.mass[order]
        inconsistent = np.maximum.reduceat(sorted_mass, starts) != np.minimum.reduceat(sorted_mass, starts)
        if inconsistent.any():
            raise ValueError(
                f"spheres of clump(s) {clump_ids[inconsistent][:5].tolist()} carry different masses; "
                "expected the clump mass on every sphere"
            )
    return ClumpFrame(
        time=frame.time,
        step=frame.step,
        clump_id=clump_ids,
        position=_wrapped(clump_mean(position), periodic_bounds) if m else np.empty((0, 3)),
        velocity=clump_mean(frame.velocity) if m else np.empty((0, 3)),
        mass=frame.mass[first_index],
        n_spheres=n_spheres,
    )


def _wrapped(position: np.ndarray, periodic_bounds) -> np.ndarray:
    if periodic_bounds is None:
        return position
    for axis, axis_bounds in enumerate(periodic_bounds):
        if axis_bounds is not None:
            lower, upper = (float(v) for v in axis_bounds)
            position[:, axis] = lower + np.mod(position[:, axis] - lower, upper - lower)
    return position


