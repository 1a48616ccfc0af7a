"""Reading what a YADE script wrote back into the neutral objects of :mod:`model`.

The scripts write particle frames and the settled fill as numpy archives (``numpy.savez``: one array per quantity,
read with ``numpy.load``) and the wall forces as a whitespace table with a ``# step time <wall>_fx ...`` title
(read with ``numpy.loadtxt``), so no reader here parses bytes itself. A message names the file, the place and what
was expected there, never what the file holds: numpy's own messages quote it (the bytes of a damaged ``.npy`` header,
the text of a row it could not convert), so they are not passed on (:mod:`siloflow.model.file_messages`).
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from siloflow.model.contacts import ContactFrame
from siloflow.model.forces import WallForceHistory
from siloflow.model.frames import ParticleFrame
from siloflow.model.settled import SettledFill
from siloflow.model.file_messages import first_not_read, unreadable
from siloflow.engines.yade.run import RESUME_STEM, WALL_FORCES_NAME, frame_files

__all__ = ["DamagedOutput", "read_archive", "read_frame", "read_frames", "read_settled_fill", "read_wall_forces"]

_QUANTITIES = ("fx", "fy", "fz", "tx", "ty", "tz")


class DamagedOutput(ValueError):
    """An output file of a YADE run is truncated or lacks a quantity; the message names it."""


def _archive(path: Path) -> dict:
    try:
        with np.load(path, allow_pickle=False) as archive:
            return {key: archive[key] for key in archive.files}
    except OSError as error:
        raise DamagedOutput(f"{path}: {unreadable(error)}") from None
    except (ValueError, EOFError, zipfile.BadZipFile):
        raise DamagedOutput(f"{path}: not a readable numpy archive") from None


def read_archive(path: str | Path, required: tuple[str, ...]) -> dict:
    """Every array of a numpy archive a script wrote, by name.

    Raises
    ------
    DamagedOutput
        Naming the file, when it is truncated or lacks one of ``required``.
    """
    path = Path(path)
    data = _archive(path)
    missing = [key for key in required if key not in data]
    if missing:
        raise DamagedOutput(f"{path}: the archive has no {', '.join(map(repr, missing))}")
    return data


def _frame(data: dict, path: Path) -> ParticleFrame:
    try:
        return ParticleFrame(
            time=float(data["time"]), step=int(data["step"]), id=data["id"].astype(np.int64),
            type=data["type"].astype(np.int32), clump_id=data["clump_id"].astype(np.int64),
            position=data["position"].reshape(-1, 3), velocity=data["velocity"].reshape(-1, 3),
            angular_velocity=data["angular_velocity"].reshape(-1, 3) if "angular_velocity" in data else None,
            radius=data["radius"], mass=data["mass"])
    except KeyError as error:
        raise DamagedOutput(f"{path}: the archive has no {error.args[0]!r}") from None


def read_frame(path: str | Path) -> ParticleFrame:
    """One particle frame (``dumps/particles_<step>.npz``).

    Raises
    ------
    DamagedOutput
        Naming the file, when it is truncated or lacks a quantity.
    """
    path = Path(path)
    return _frame(_archive(path), path)


def read_frames(run_dir: str | Path, prefix: str, on_damaged: str = "error") -> list[ParticleFrame]:
    """Every frame ``dumps/<prefix>_<step>.npz`` of a run, oldest first (``on_damaged``: ``error`` or ``skip``)."""
    if on_damaged not in ("error", "skip"):
        raise ValueError(f"on_damaged must be 'error' or 'skip', got {on_damaged!r}")
    frames = []
    for path in frame_files(run_dir, prefix):
        try:
            frames.append(read_frame(path))
        except DamagedOutput:
            if on_damaged == "error":
                raise
    return frames


def _table_fault(lines: list[str], width: int) -> str:
    """Where the first row that ``numpy.loadtxt`` refused is (lines from line 2, after the title), and why: its
    message quotes the text it could not convert."""
    for number, line in enumerate(lines, start=2):
        words = line.split("#", 1)[0].split()  # loadtxt's comments and blank lines
        if not words:
            continue
        if len(words) != width:
            return f"line {number} holds {len(words)} values, expected {width}"
        place = first_not_read(words)
        if place is not None:
            return f"line {number}, column {place} is not a number"
    return "a value is not a number"


def _wall_force_table(path: Path, tolerate_cut_line: bool) -> tuple[list[str], np.ndarray]:
    with open(path, encoding="utf-8", errors="replace") as handle:  # a codec's message quotes the byte
        title = handle.readline()
        lines = handle.read().splitlines()
    if not title.startswith("# step time "):
        raise DamagedOutput(f"{path}: the title line is not '# step time <wall>_fx ...'")
    columns = title.split()[3:]
    width = 2 + len(columns)
    if tolerate_cut_line and lines and len(lines[-1].split()) != width:
        lines = lines[:-1]  # the kill cut the last row of a superseded attempt
    try:
        table = np.loadtxt(lines, ndmin=2) if lines else np.empty((0, width))
    except ValueError:
        raise DamagedOutput(f"{path}: {_table_fault(lines, width)}") from None
    if table.shape[1] != width:
        raise DamagedOutput(f"{path}: rows of {table.shape[1]} columns under a title of {width}")
    if len(columns) % 6 or any(not c.endswith(tuple(f"_{q}" for q in _QUANTITIES)) for c in columns):
        raise DamagedOutput(f"{path}: the title's columns are not six per wall (<wall>_fx ... <wall>_tz)")
    walls = [columns[i].rsplit("_", 1)[0] for i in range(0, len(columns), 6)]
    return walls, table


def read_wall_forces(run_dir: str | Path, timestep: float) -> WallForceHistory:
    """The force and torque each wall exerted on the particles, resumed attempts joined (a later attempt's rows
    replace an earlier one's of the same step).

    Raises
    ------
    FileNotFoundError
        When ``wall_force_history.txt`` is missing.
    DamagedOutput
        Naming the file of malformed content or of walls that differ from the first attempt's.
    """
    run_dir = Path(run_dir)
    first = run_dir / WALL_FORCES_NAME
    if not first.exists():
        raise FileNotFoundError(f"{run_dir}: no {WALL_FORCES_NAME}; did the run start?")
    resumed = sorted(run_dir.glob(f"{RESUME_STEM}_*_{WALL_FORCES_NAME}"), key=lambda p: p.stat().st_mtime)
    files = [first, *resumed]
    rows: dict[int, np.ndarray] = {}
    walls = None
    for index, path in enumerate(files):
        names, table = _wall_force_table(path, tolerate_cut_line=index + 1 < len(files))
        if walls is None:
            walls = names
        elif names != walls:
            raise DamagedOutput(f"{path}: its walls (the title's columns) differ from those of {first.name}")
        for row in table:
            rows[int(row[0])] = row
    steps = sorted(rows)
    table = np.array([rows[s] for s in steps]).reshape(-1, 2 + 6 * len(walls))
    force = {w: table[:, 2 + 6 * i: 5 + 6 * i] for i, w in enumerate(walls)}
    torque = {w: table[:, 5 + 6 * i: 8 + 6 * i] for i, w in enumerate(walls)}
    return WallForceHistory(time=np.array(steps, dtype=float) * timestep, walls=tuple(walls), force=force,
                            torque=torque)


def read_settled_fill(run_dir: str | Path, prefix: str, floor_walls: tuple[str, ...]) -> tuple[SettledFill, ...]:
    """The settled fill at each step of its snapshot (``dumps/<prefix>_<step>.npz``), oldest first.

    Raises
    ------
    FileNotFoundError
        When the run saved no snapshot.
    DamagedOutput
        Naming a truncated archive.
    """
    paths = frame_files(run_dir, prefix)
    if not paths:
        raise FileNotFoundError(f"{run_dir}: no settled fill snapshot dumps/{prefix}_<step>.npz")
    fills = []
    for path in paths:
        data = _archive(path)
        contacts = data["contacts"].reshape(-1, 11)
        step = int(data["step"])
        forces = data["wall_forces"].reshape(-1, 6)
        fills.append(SettledFill(
            frame=_frame(data, path),
            wall_force=data["wall_force"].reshape(-1, 3),
            contacts=ContactFrame(step=step, position_i=contacts[:, 0:3], position_j=contacts[:, 3:6],
                                  id_i=contacts[:, 6].astype(np.int64), id_j=contacts[:, 7].astype(np.int64),
                                  force=contacts[:, 8:11]),
            wall_forces={str(w): forces[i, :3].copy() for i, w in enumerate(data["walls"])},
            floor_walls=tuple(floor_walls),
        ))
    return tuple(fills)
