"""LIGGGHTS: reading the wall forces a run wrote into a :class:`siloflow.model.forces.WallForceHistory`.

Silo-type runs (flat-bottom silo, recirculating silo, blender)
    The deck (``siloflow/templates/liggghts/macros.j2``, ``wall_force_output``) writes, from the fill on, one sample every
    dump interval to ``<run>/wall_forces.txt`` with ``fix ave/time``: a title line with the time step
    (``siloflow wall forces, time step <dt> s``), a header line naming the columns ``TimeStep`` and, per wall,
    ``v_<wall>_fx v_<wall>_fy v_<wall>_fz v_<wall>_tx v_<wall>_ty v_<wall>_tz``, then one row per sample (the
    step, forces in N and torques about the origin in N m, all exerted ON the particles). A sample's time is its
    step times the time step (exact; a resumed run restarts LIGGGHTS' own clock at zero). Primitive walls (side,
    front and back planes) sum the per-sphere force of ``store_force yes`` and take each at the sphere's contact
    point on the plane; meshes (floor plates, gate, channel and blender walls) negate their
    ``mesh/surface/stress`` sums. The gate keeps its columns after the outlet opened, as zeros. Values carry 6
    significant digits (``%g``); contact couples of rolling resistance are not in the torques.

    A resumed run (:mod:`siloflow.engines.liggghts.run`) writes ``<run>/resume_wall_forces_<R>.txt`` from its restart
    step R on, with the same columns. :func:`read_silo_wall_forces` joins the files by step: each resumed file
    replaces the rows after its restart step (the trajectory the run went on with) and the rows before it come
    from the earlier files; a file's sample at its own restart step is dropped. A killed attempt may have cut
    its last line: in a file that a later one supersedes, an unreadable last line is ignored; anything else
    that is not well formed is an error naming the file, the line (and column) and what was expected there, never
    what the file holds (:mod:`siloflow.model.file_messages`).

Jenike shear cell
    The deck writes ``<run>/forces.txt`` in the engines' one Jenike format (:mod:`siloflow.engines.jenike_checks`, read
    and turned into walls ``lid``, ``shear_ring``, ``base`` there).

The parser is hand-written (a few lines around ``str.split``; the files hold one row per dump interval, a few
hundred rows, so speed is no concern): ``numpy.loadtxt`` does not read the title's time step or the header's
column names that say which wall each column belongs to, and cannot ignore a cut last line only where a later
file supersedes it.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from siloflow.model.forces import WallForceHistory
from siloflow.model.file_messages import first_not_read
from siloflow.engines.jenike_checks import jenike_wall_forces, read_jenike_force_history
from siloflow.engines.liggghts.jenike import FORCES_NAME
from siloflow.engines.liggghts.run import WALL_FORCES_NAME
from siloflow.engines.liggghts.run import RESUME_STEM

__all__ = [
    "RESUMED_WALL_FORCES_PREFIX",
    "WALL_FORCES_NAME",
    "read_jenike_forces",
    "read_silo_wall_forces",
    "read_wall_forces",
    "read_wall_force_file",
]

#: Prefix of the files of resumed attempts; it starts with the resume stem, so that a fresh attempt sets the
#: files of an earlier one aside with its other resume files.
RESUMED_WALL_FORCES_PREFIX = f"{RESUME_STEM}_wall_forces"
_TITLE = re.compile(r"^siloflow wall forces, time step (\S+) s$")
QUANTITIES = ("fx", "fy", "fz", "tx", "ty", "tz")

_RESUMED = re.compile(rf"^{RESUMED_WALL_FORCES_PREFIX}_(\d+)\.txt$")
_WALL_COLUMN = re.compile(r"^v_([A-Za-z0-9_.-]+)_(fx|fy|fz|tx|ty|tz)$")


def _header_walls(path: Path, number: int, line: str) -> tuple[str, ...]:
    """Wall names of the column header ``# TimeStep v_<wall>_fx ... v_<wall>_tz ...``."""
    columns = line[1:].split()[1:]
    if not columns or len(columns) % len(QUANTITIES):
        raise ValueError(f"{path}: line {number} names {len(columns)} wall columns, expected six per wall "
                         f"({' '.join(QUANTITIES)})")
    walls = []
    for start in range(0, len(columns), len(QUANTITIES)):
        group = columns[start:start + len(QUANTITIES)]
        matches = [_WALL_COLUMN.match(column) for column in group]
        wall = matches[0].group(1) if matches[0] else None
        # columns are named by their place (TimeStep is column 1): their names are the file's text
        place = f"columns {start + 2} to {start + 1 + len(QUANTITIES)}"
        if any(m is None or m.group(1) != wall or m.group(2) != q for m, q in zip(matches, QUANTITIES)):
            raise ValueError(f"{path}: line {number}: {place} are not v_<wall>_"
                             f"{', v_<wall>_'.join(QUANTITIES)} of one wall")
        if wall in walls:
            earlier = 2 + len(QUANTITIES) * walls.index(wall)
            raise ValueError(f"{path}: line {number}: {place} name the wall of columns {earlier} to "
                             f"{earlier + len(QUANTITIES) - 1} again")
        walls.append(wall)
    return tuple(walls)


def read_wall_force_file(path: str | Path, cut_last_line_allowed: bool = False,
                         ) -> tuple[float, tuple[str, ...], np.ndarray, np.ndarray]:
    """Read one wall force file of a silo-type deck.

    Parameters
    ----------
    path : str or pathlib.Path
        The file (``wall_forces.txt`` or a resumed attempt's ``resume_wall_forces_<R>.txt``).
    cut_last_line_allowed : bool
        Ignore an unreadable last line (a killed attempt may have cut it).

    Returns
    -------
    timestep : float
        The run's time step [s], from the title line.
    walls : tuple of str
        Wall names in column order.
    steps : numpy.ndarray of int64, shape (n,)
        Time steps of the samples, strictly increasing.
    values : numpy.ndarray of float64, shape (n, 6 * len(walls))
        Per sample and wall: fx fy fz [N] and tx ty tz [N m] on the particles.

    Raises
    ------
    FileNotFoundError
        When the file is missing.
    ValueError
        Naming the file and line: a missing or malformed title or header, a row with the wrong number of columns,
        a value that is not a number or not finite, steps that do not increase.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no wall force file at {path}")
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    numbered = [(number, line.strip()) for number, line in enumerate(lines, start=1) if line.strip()]
    if len(numbered) < 2:
        raise ValueError(f"{path}: holds {len(numbered)} of its 2 header lines (title, columns); not a wall force file")
    (title_number, title), (header_number, header) = numbered[:2]
    match = _TITLE.match(title)
    try:
        timestep = float(match.group(1)) if match else math.nan
    except ValueError:
        timestep = math.nan
    if not (timestep > 0 and math.isfinite(timestep)):
        raise ValueError(f"{path}: line {title_number} is not the title 'siloflow wall forces, time step <dt> s' "
                         "with a positive time step")
    if not header.startswith("#") or header[1:].split()[:1] != ["TimeStep"]:
        raise ValueError(f"{path}: line {header_number} is not the column header '# TimeStep v_<wall>_fx ...'")
    walls = _header_walls(path, header_number, header)
    width = len(QUANTITIES) * len(walls)
    steps, rows = [], []
    last = numbered[-1][0]
    previous = header_number  # the line of the last sample read
    for number, text in numbered[2:]:
        try:
            step, values = _data_row(path, number, text, 1 + width)
        except ValueError:
            if cut_last_line_allowed and number == last:
                break
            raise
        if steps and step <= steps[-1]:
            raise ValueError(f"{path}: line {number}: the step does not follow the step of line {previous}")
        steps.append(step)
        rows.append(values)
        previous = number
    return timestep, walls, np.array(steps, dtype=np.int64), np.array(rows, dtype=float).reshape(-1, width)


def _data_row(path: Path, number: int, text: str, expected: int) -> tuple[int, list[float]]:
    fields = text.split()
    if len(fields) != expected:
        raise ValueError(f"{path}: line {number} has {len(fields)} columns, expected {expected}; "
                         "the file is malformed or was cut off")
    try:
        step = int(fields[0])
        values = [float(field) for field in fields[1:]]
    except ValueError:  # its message quotes the field: the message gives the field's place
        if first_not_read(fields[:1], int) is not None:
            raise ValueError(f"{path}: line {number}, column 1 is not a step (an integer)") from None
        raise ValueError(f"{path}: line {number}, column {first_not_read(fields[1:]) + 1} is not a number") from None
    if not all(np.isfinite(values)):
        raise ValueError(f"{path}: line {number}, column {int(np.argmin(np.isfinite(values))) + 2} is not finite")
    return step, values


def _resumed_files(run_dir: Path) -> list[tuple[int, Path]]:
    found = []
    for path in run_dir.glob(f"{RESUMED_WALL_FORCES_PREFIX}_*.txt"):
        match = _RESUMED.match(path.name)
        if match:
            found.append((int(match.group(1)), path))
    return sorted(found)


def read_silo_wall_forces(run_dir: str | Path) -> WallForceHistory:
    """The wall forces of a silo-type run (flat-bottom silo, recirculating silo, blender), resumed attempts joined.

    Parameters
    ----------
    run_dir : str or pathlib.Path
        The run directory (holds ``wall_forces.txt`` and any ``resume_wall_forces_<R>.txt``).

    Returns
    -------
    siloflow.model.forces.WallForceHistory
        Walls in the deck's order (primitive walls, then meshes); no signals. Forces [N] and torques about the
        origin [N m] on the particles; times [s] from the run's start.

    Raises
    ------
    FileNotFoundError
        When ``wall_forces.txt`` is missing.
    ValueError
        Naming the file and line of malformed content (see :func:`read_wall_force_file`), or the file whose
        walls differ from the first file's.
    """
    run_dir = Path(run_dir)
    files = [(None, run_dir / WALL_FORCES_NAME), *_resumed_files(run_dir)]
    first = None
    step_parts, value_parts = [], []
    for index, (start, path) in enumerate(files):
        superseded = index + 1 < len(files)
        timestep, walls, steps, values = read_wall_force_file(path, cut_last_line_allowed=superseded)
        if first is None:
            first = (timestep, walls)
        elif (timestep, walls) != first:
            raise ValueError(f"{path}: its time step or walls (title and column header) differ from those of "
                             f"{WALL_FORCES_NAME}")
        keep = np.ones(steps.shape, dtype=bool)
        if start is not None:
            keep &= steps > start
        if superseded:
            keep &= steps <= files[index + 1][0]
        step_parts.append(steps[keep])
        value_parts.append(values[keep])
    timestep, walls = first
    steps, table = np.concatenate(step_parts), np.concatenate(value_parts)
    width = len(QUANTITIES)
    force = {wall: table[:, width * i: width * i + 3] for i, wall in enumerate(walls)}
    torque = {wall: table[:, width * i + 3: width * (i + 1)] for i, wall in enumerate(walls)}
    try:
        return WallForceHistory(time=steps * timestep, walls=walls, force=force, torque=torque)
    except ValueError as error:
        raise ValueError(f"{run_dir}: wall forces of {', '.join(p.name for _, p in files)}: {error}") from None


def read_jenike_forces(run_dir: str | Path) -> WallForceHistory:
    """The wall forces of a Jenike run: ``<run_dir>/forces.txt`` read strictly, as :func:`jenike_wall_forces`.

    Raises
    ------
    FileNotFoundError, ValueError
        As :func:`siloflow.engines.jenike_checks.read_jenike_force_history`, naming the file.
    """
    return jenike_wall_forces(read_jenike_force_history(Path(run_dir) / FORCES_NAME))


def read_wall_forces(run_dir: str | Path) -> WallForceHistory:
    """The force and torque that each wall exerted on the particles during a run, over time.

    Reads what the run's deck wrote: ``wall_forces.txt`` of a silo-type run (:func:`read_silo_wall_forces`) or
    ``forces.txt`` of a Jenike run (:func:`read_jenike_forces`).

    Raises
    ------
    FileNotFoundError
        When the run directory holds neither file.
    ValueError
        Naming the file and line of malformed content.
    """
    run_dir = Path(run_dir)
    if (run_dir / WALL_FORCES_NAME).exists():
        return read_silo_wall_forces(run_dir)
    if (run_dir / FORCES_NAME).exists():
        return read_jenike_forces(run_dir)
    raise FileNotFoundError(f"{run_dir}: no wall forces: neither {WALL_FORCES_NAME} (silo-type runs) nor "
                            f"{FORCES_NAME} (Jenike runs); did the run finish?")
