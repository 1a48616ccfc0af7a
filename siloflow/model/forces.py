"""Wall forces over time: the engine-neutral form every engine reader returns.

A :class:`WallForceHistory` holds, for each named wall (side walls, floor plates, gate, lid, ...), the force and
the torque that the wall exerts ON the particles at each sample time, plus optional per-sample signals of the
case (the Jenike cell's lid height, the mass above its shear plane). Nothing here reads or writes files.

Sign convention: the force on the particles, so at rest the walls and floor of a silo carry its weight as a
positive (upward) vertical sum, and a side wall pushes the particles away from itself (a wall at x = -W/2 has a
positive x force). Torques are about the origin of the case's coordinates. SI units: s, N, N m.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from collections.abc import Iterable

import numpy as np

from siloflow.model.arrays import frozen_array

__all__ = ["WallForceHistory"]


def _first_bad(mask: np.ndarray) -> int:
    """Index of the first sample (row) where ``mask`` holds."""
    rows = mask.reshape(mask.shape[0], -1).any(axis=1)
    return int(np.argmax(rows))


@dataclass(frozen=True, eq=False)
class WallForceHistory:
    """The force and torque each wall exerts on the particles, sampled over time.

    Arrays are copied on construction and read-only; row i of every array is sample i.

    Attributes
    ----------
    time : numpy.ndarray of float64, shape (n,)
        Sample times [s], strictly increasing, finite; n >= 1.
    walls : tuple of str
        Wall names, unique and non-empty, in the engine's order.
    force : dict of str to numpy.ndarray of float64, shape (n, 3)
        Per wall, the force the wall exerts on the particles [N]; finite. A wall that is no longer there (a
        gate after the outlet opened) exerts zero force.
    torque : dict of str to numpy.ndarray of float64, shape (n, 3)
        Per wall, the torque of that force about the origin [N m]: the sum of contact point x contact force.
        NaN, for the whole wall, where the engine cannot give it (documented by its reader); infinities are
        refused. Pure contact couples (rolling resistance) are not included.
    signals : dict of str to numpy.ndarray of float64, shape (n,)
        Extra per-sample quantities of the case, in SI units named by the reader (e.g. ``lid_z`` [m],
        ``mass_above`` [kg] of the Jenike cell); finite. Empty by default.

    Raises
    ------
    ValueError
        On construction, naming the offending wall or signal, when a shape is wrong, a wall lacks a force or a
        torque or has one for an unknown name, a value is not finite (or NaN in a force), or the times do not
        increase.
    """

    time: np.ndarray
    walls: tuple[str, ...]
    force: dict[str, np.ndarray]
    torque: dict[str, np.ndarray]
    signals: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        time = frozen_array(self.time, float, (), "time", None)
        n = time.shape[0]
        if n == 0:
            raise ValueError("a wall force history needs at least one sample; time is empty")
        if not np.all(np.isfinite(time)):
            raise ValueError(f"time holds a non-finite value at sample {_first_bad(~np.isfinite(time))}")
        steps = np.diff(time)
        if np.any(steps <= 0):
            index = int(np.argmax(steps <= 0)) + 1
            raise ValueError(f"times must increase: sample {index} at {time[index]!r} s follows {time[index - 1]!r} s")
        walls = tuple(self.walls) if not isinstance(self.walls, str) else (self.walls,)
        if any(not isinstance(name, str) or not name for name in walls):
            raise ValueError(f"wall names must be non-empty strings, got {walls!r}")
        if len(set(walls)) != len(walls):
            raise ValueError(f"wall names must be unique, got {walls!r}")
        force = self._per_wall(self.force, "force", walls, n, allow_nan=False)
        torque = self._per_wall(self.torque, "torque", walls, n, allow_nan=True)
        signals = {}
        for name, value in dict(self.signals).items():
            if not isinstance(name, str) or not name:
                raise ValueError(f"signal names must be non-empty strings, got {name!r}")
            array = frozen_array(value, float, (), f"signal {name!r}", n)
            if not np.all(np.isfinite(array)):
                bad = _first_bad(~np.isfinite(array))
                raise ValueError(f"signal {name!r} holds a non-finite value at sample {bad}")
            signals[name] = array
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "walls", walls)
        object.__setattr__(self, "force", force)
        object.__setattr__(self, "torque", torque)
        object.__setattr__(self, "signals", signals)

    @staticmethod
    def _per_wall(values, what: str, walls: tuple[str, ...], n: int, allow_nan: bool) -> dict[str, np.ndarray]:
        values = dict(values)
        missing = [name for name in walls if name not in values]
        unknown = sorted(set(values) - set(walls))
        if missing or unknown:
            raise ValueError(f"{what}: missing for walls {missing}, given for unknown walls {unknown}; "
                             f"walls are {list(walls)}")
        checked = {}
        for name in walls:
            array = frozen_array(values[name], float, (3,), f"{what} of wall {name!r}", n)
            bad = np.isinf(array) if allow_nan else ~np.isfinite(array)
            if bad.any():
                kind = "an infinite" if allow_nan else "a non-finite"
                raise ValueError(f"{what} of wall {name!r} holds {kind} value at sample {_first_bad(bad)}")
            checked[name] = array
        return checked

    def __len__(self) -> int:
        """Number of samples."""
        return int(self.time.shape[0])

    def _selected(self, walls: Iterable[str] | None) -> tuple[str, ...]:
        if walls is None:
            return self.walls
        selected = (walls,) if isinstance(walls, str) else tuple(walls)
        unknown = [name for name in selected if name not in self.walls]
        if unknown:
            raise KeyError(f"unknown walls {unknown}; the history has {list(self.walls)}")
        return selected

    def total_force(self, walls: Iterable[str] | None = None) -> np.ndarray:
        """Summed force of a set of walls on the particles.

        Parameters
        ----------
        walls : iterable of str or str, optional
            Wall names (default: every wall). An empty set gives zeros.

        Returns
        -------
        numpy.ndarray of float64, shape (n, 3)
            Force on the particles per sample [N].

        Raises
        ------
        KeyError
            Naming walls the history does not have.
        """
        total = np.zeros((len(self), 3))
        for name in self._selected(walls):
            total += self.force[name]
        return total

    def total_torque(self, walls: Iterable[str] | None = None) -> np.ndarray:
        """Summed torque about the origin of a set of walls on the particles, shape (n, 3) [N m]; NaN if any
        selected wall's torque is unknown. Parameters and errors as :meth:`total_force`."""
        total = np.zeros((len(self), 3))
        for name in self._selected(walls):
            total += self.torque[name]
        return total

    def between(self, start: float, end: float | None = None) -> WallForceHistory:
        """The samples with ``start < time <= end`` (``end`` None: to the last sample) [s].

        Raises
        ------
        ValueError
            When no sample lies in the interval.
        """
        keep = self.time > start
        if end is not None:
            keep &= self.time <= end
        if not keep.any():
            raise ValueError(f"no sample lies in ({start}, {end}] s; "
                             f"the history spans {self.time[0]}..{self.time[-1]} s")
        return WallForceHistory(
            time=self.time[keep],
            walls=self.walls,
            force={name: value[keep] for name, value in self.force.items()},
            torque={name: value[keep] for name, value in self.torque.items()},
            signals={name: value[keep] for name, value in self.signals.items()},
        )
