"""What a user says about a silo run siloflow did not make: where its particle dumps are and what the silo is.

A run made by the user's own engine input (not rendered by siloflow) leaves particle dumps and nothing siloflow
writes: no run record, no case summary, no wall force or contact files. :class:`ExistingSiloRun` holds what the
analysis then needs from the user instead: the silo's dimensions, where siloflow's origin lies in the dumps'
coordinates, when the outlet opened, the engine's time step (dumps carry steps, not times) and the particle
density for dumps without a mass. It is the neutral hand-over between the engine that reads the dumps
(:mod:`siloflow.engines.existing_runs`) and the study that analyses them (:mod:`siloflow.analysis.studies.silo_flat.existing_run`);
nothing here reads files.

Coordinates as everywhere in siloflow: x across the width (0 on the silo axis), y front to back (0 at the front
wall), z up (0 at the outlet plane). SI units: metres, seconds, kilograms.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import PurePosixPath

__all__ = ["EXISTING_RUN_NAME", "ExistingRunError", "ExistingSiloRun"]

#: What a run's name may hold: it names the folder of its results.
EXISTING_RUN_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")

#: Keys a user must give (the configuration schema gives them a null default).
_REQUIRED = {
    "folder": "the run's folder",
    "dumps": "the dump file pattern inside the folder",
    "width": "the silo's inner width W (m)",
    "depth": "the silo's inner depth T (m)",
    "outlet_width": "the slot outlet's width B0 (m)",
    "timestep": "the engine's time step (s): the dumps carry steps, not times",
}


class ExistingRunError(ValueError):
    """A description of an existing run is incomplete or contradicts itself.

    Attributes
    ----------
    key : str
        The description's key at fault (e.g. ``width``).
    reason : str
        What is wrong with it.
    """

    def __init__(self, key: str, reason: str):
        super().__init__(f"{key}: {reason}")
        self.key = key
        self.reason = reason


def _positive(key: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ExistingRunError(key, f"must be a number, got {value!r}")
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ExistingRunError(key, f"must be a finite positive number, got {value!r}")
    return value


@dataclass(frozen=True)
class ExistingSiloRun:
    """A flat-bottom silo run siloflow did not make, as its user describes it.

    Attributes
    ----------
    name : str
        The run's name: letters, digits, ``_ . -`` (it names the folder of its results).
    engine : str
        Registry name of the engine that wrote the dumps (``liggghts``).
    folder : str
        The run's folder (absolute, or relative to the working directory).
    dumps : str
        The particle dump files inside ``folder``, as the engine's dump command names them (the engine reads the
        pattern: for LIGGGHTS a ``*`` stands for the step).
    width, depth, outlet_width : float
        Silo inner width W (x), inner depth T (y) and the width B0 of the slot outlet centred in the floor, across
        the full depth (m).
    timestep : float
        The engine's time step (s): a dump's time is its step times this (the step must not change during the run).
    open_step : int
        Step at which the outlet opened (-).
    origin : tuple of float
        Where siloflow's origin lies in the dumps' coordinates (m): the x of the silo axis, the y of the front wall,
        the z of the outlet plane. Gravity must point along -z.
    density : float or None
        Particle density (kg/m^3), for dumps without a mass field (each sphere's mass is density x 4/3 pi r^3); not
        used where the dumps carry a mass.
    particle_diameter : float or None
        Volume-equivalent particle diameter (m); None: from the dumps' sphere radii (dumps of spheres only).
    profile_heights : tuple of float or None
        Heights of the velocity profiles above the outlet (m); None: the flat-bottom silo's configured ones.
    """

    name: str
    engine: str
    folder: str
    dumps: str
    width: float
    depth: float
    outlet_width: float
    timestep: float
    open_step: int
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    density: float | None = None
    particle_diameter: float | None = None
    profile_heights: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if not EXISTING_RUN_NAME.fullmatch(self.name):
            raise ExistingRunError("name", f"{self.name!r} must be letters, digits, '_', '.' or '-', starting with a "
                                           "letter or digit (it names the folder of its results)")
        for key in ("folder", "dumps"):
            value = getattr(self, key)
            if not isinstance(value, str) or not value:
                raise ExistingRunError(key, f"must be a non-empty string, got {value!r}")
        pattern = PurePosixPath(self.dumps)
        if pattern.is_absolute() or ".." in pattern.parts or "\\" in self.dumps:
            raise ExistingRunError("dumps", f"{self.dumps!r} must be a relative path inside the folder, without '..'")
        for key in ("width", "depth", "outlet_width", "timestep"):
            object.__setattr__(self, key, _positive(key, getattr(self, key)))
        if not self.outlet_width < self.width:
            raise ExistingRunError("outlet_width", f"{self.outlet_width} m must be smaller than the width "
                                                   f"({self.width} m)")
        if isinstance(self.open_step, bool) or not isinstance(self.open_step, int) or self.open_step < 0:
            raise ExistingRunError("open_step", f"must be a step number >= 0, got {self.open_step!r}")
        origin = tuple(self.origin)
        if len(origin) != 3 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                                       for v in origin):
            raise ExistingRunError("origin", f"must be three finite numbers [x, y, z] (m), got {self.origin!r}")
        object.__setattr__(self, "origin", tuple(float(v) for v in origin))
        for key in ("density", "particle_diameter"):
            if getattr(self, key) is not None:
                object.__setattr__(self, key, _positive(key, getattr(self, key)))
        if self.profile_heights is not None:
            heights = tuple(_positive("profile_heights", z) for z in self.profile_heights)
            if not heights:
                raise ExistingRunError("profile_heights", "must hold at least one height, or be null")
            object.__setattr__(self, "profile_heights", heights)

    @property
    def open_time(self) -> float:
        """Time at which the outlet opened (s): the opening step times the time step."""
        return self.open_step * self.timestep

    @classmethod
    def from_config(cls, name: str, section: Mapping) -> "ExistingSiloRun":
        """From one entry of the ``silo_flat.existing_runs`` configuration (defaults filled by the schema).

        The opening is given as ``open_step`` or as ``open_time`` (s), which becomes the nearest step of
        ``timestep``.

        Raises
        ------
        ExistingRunError
            Naming the key: a required key left null, both or neither of ``open_time`` and ``open_step``, an
            opening time that is no whole number of steps, or a value out of range.
        """
        for key, meaning in _REQUIRED.items():
            if section.get(key) is None:
                raise ExistingRunError(key, f"required: {meaning}")
        timestep = _positive("timestep", section["timestep"])
        open_time, open_step = section.get("open_time"), section.get("open_step")
        if (open_time is None) == (open_step is None):
            raise ExistingRunError("open_time", "give the outlet's opening as open_time (s) or as open_step, once")
        if open_time is not None:
            if isinstance(open_time, bool) or not isinstance(open_time, (int, float)) or not open_time >= 0:
                raise ExistingRunError("open_time", f"must be a time >= 0 (s), got {open_time!r}")
            open_step = round(open_time / timestep)
            # a time that falls between two steps names no step the engine ran: the time step is likely wrong
            if abs(open_step * timestep - open_time) > 1e-6 * timestep + 1e-9 * open_time:
                raise ExistingRunError("open_time", f"{open_time} s is not a whole number of time steps of "
                                                    f"{timestep} s; give open_step, or check timestep")
        heights = section.get("profile_heights")
        return cls(
            name=name, engine=section.get("engine", "liggghts"), folder=section["folder"], dumps=section["dumps"],
            width=section["width"], depth=section["depth"], outlet_width=section["outlet_width"], timestep=timestep,
            open_step=open_step, origin=tuple(section.get("origin", (0.0, 0.0, 0.0))),
            density=section.get("density"), particle_diameter=section.get("particle_diameter"),
            profile_heights=None if heights is None else tuple(heights),
        )
