"""A user's own LIGGGHTS particle dumps: the files a ``dump`` command's file name made, and the frames they hold.

A LIGGGHTS input written by hand dumps the particles with e.g.::

    dump dmp all custom/vtk 500 post/silo*.vtk id type x y z vx vy vz radius
    dump dmp all custom 500 post/dump*.liggghts id type x y z vx vy vz radius
    dump dmp all custom 500 post/dump.txt id type x y z vx vy vz radius

LIGGGHTS replaces the ``*`` of the file name by the step, with no separator (``post/silo12500.vtk``), and without
a ``*`` appends every snapshot to the one file. siloflow takes the same pattern the user wrote (relative to the
run's folder) and reads what it made: the files ``<head><step><tail>`` in step order (the bounding-box files
LIGGGHTS writes beside VTK dumps, ``siloboundingBox_<step>.vtk`` for ``silo*.vtk``, never match, as their names hold
more than digits where the ``*`` is), or the one file. Each file is read by :func:`siloflow.engines.liggghts.dumps.read_file_frames` (legacy VTK 4.2 or 5.1, ASCII or
binary, or text ``dump custom``, told apart by its first line); a VTK file's step is the number its name gives.
A pattern with ``%`` (one file per processor) is refused: siloflow reads whole frames. So is a pattern that names or
matches anything but a regular file (a folder, or a link to a device or a pipe: ``/dev/zero`` never ends), when the
files are listed, before any is opened.

All quantities are SI: metres, seconds, kilograms.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path, PurePosixPath

from siloflow.model.existing_run import ExistingRunError
from siloflow.model.frames import ParticleFrame
from siloflow.model.file_messages import not_regular
from siloflow.engines.interface import DumpFile
from siloflow.engines.liggghts.dumps import PerType, dump_format, readable_frames

__all__ = ["DumpFile", "check_dump_pattern", "match_dump_files", "read_dump_files"]

#: Characters a pattern may not hold: shell-style wildcards LIGGGHTS does not expand, and its per-processor ``%``.
_REFUSED = {"%": "one file per processor ('%') is not read: dump every particle into one file per step",
            "?": "'?' is no LIGGGHTS wildcard: '*' stands for the step",
            "[": "'[' is no LIGGGHTS wildcard: '*' stands for the step",
            "]": "']' is no LIGGGHTS wildcard: '*' stands for the step"}


def check_dump_pattern(pattern: str) -> None:
    """Refuse a dump file pattern siloflow cannot read (every error names the ``dumps`` key).

    Parameters
    ----------
    pattern : str
        A path relative to the run's folder, ``/``-separated, with at most one ``*`` (the step), in the file name.

    Raises
    ------
    ExistingRunError
        For an absolute path, ``..``, a ``*`` in a folder name or more than one, ``%``, ``?``, ``[`` or ``]``.
    """
    path = PurePosixPath(pattern)
    if not pattern or path.is_absolute() or ".." in path.parts:
        raise ExistingRunError("dumps", f"{pattern!r} must be a relative path inside the run's folder, without '..'")
    for character, reason in _REFUSED.items():
        if character in pattern:
            raise ExistingRunError("dumps", f"{pattern!r}: {reason}")
    if pattern.count("*") > 1:
        raise ExistingRunError("dumps", f"{pattern!r} has more than one '*'; LIGGGHTS puts the step in place of one")
    if "*" in "/".join(path.parts[:-1]):
        raise ExistingRunError("dumps", f"{pattern!r}: the '*' (the step) belongs in the file name, not a folder")


def _regular(pattern: str, folder: Path, entry: Path, relative: PurePosixPath) -> None:
    """Refuse an ``entry`` of the pattern that is no regular file (:func:`siloflow.model.file_messages.not_regular`), naming
    it by ``relative``, its path in ``folder``."""
    refused = not_regular(entry)
    if refused is not None:
        matches = f"{pattern!r} matches " if "*" in pattern else ""
        raise ExistingRunError("dumps", f"{matches}{str(relative)!r} in {str(folder)!r}: {refused}")


def match_dump_files(folder: str | os.PathLike, pattern: str) -> list[DumpFile]:
    """The dump files a LIGGGHTS dump file name made in a run's folder, in step order.

    Parameters
    ----------
    folder : str or path-like
        The run's folder.
    pattern : str
        The dump command's file name, relative to ``folder`` (:func:`check_dump_pattern`); ``*`` stands for the
        step.

    Returns
    -------
    list of DumpFile
        With ``*``: every file ``<head><digits><tail>``, ascending step (numerically); without: the one file.

    Raises
    ------
    ExistingRunError
        Key ``folder`` when the folder does not exist or is no folder; key ``dumps`` when the pattern is refused,
        matches no file, or names or matches something that is no regular file (a folder, a device, a pipe).
    """
    check_dump_pattern(pattern)
    folder = Path(folder)
    if not folder.is_dir():
        raise ExistingRunError("folder", f"{str(folder)!r} is not a folder" if folder.exists()
                               else f"{str(folder)!r} does not exist")
    relative = PurePosixPath(pattern)
    where = folder.joinpath(*relative.parts[:-1])
    name = relative.name
    if "*" not in name:
        path = where / name
        if not os.path.lexists(path):
            raise ExistingRunError("dumps", f"no file {pattern!r} in {str(folder)!r}")
        _regular(pattern, folder, path, relative)
        return [DumpFile(path, None)]
    head, _, tail = name.partition("*")
    step_name = re.compile(re.escape(head) + r"([0-9]+)" + re.escape(tail))
    found = []
    if where.is_dir():
        found = [(int(match.group(1)), entry) for entry in where.iterdir()
                 if (match := step_name.fullmatch(entry.name))]
    for _, entry in sorted(found):  # in step order, so that the first refused is the same on every system
        _regular(pattern, folder, entry, relative.parent / entry.name)
    if not found:
        raise ExistingRunError("dumps", f"no file matches {pattern!r} in {str(folder)!r} ('*' stands for the step, "
                                        "as in the dump command)")
    steps = [step for step, _ in found]
    if len(set(steps)) != len(steps):
        # silo01000.vtk and silo1000.vtk name one step twice: which is the frame is not known
        twice = sorted({step for step in steps if steps.count(step) > 1})
        raise ExistingRunError("dumps", f"{pattern!r} matches two files of one step ({twice[:3]}) in {str(folder)!r}")
    return [DumpFile(entry, step) for step, entry in sorted(found)]


def read_dump_files(
    files: Sequence[DumpFile], timestep: float, *, density: PerType | None = None, on_damaged: str = "error",
) -> list[ParticleFrame]:
    """Read the frames of dump files, in the files' order, through :func:`siloflow.engines.liggghts.dumps.readable_frames`.

    Parameters
    ----------
    files : sequence of DumpFile
        From :func:`match_dump_files`.
    timestep : float
        The run's time step [s]; a frame's time is its step times it.
    density : float or mapping of int to float, optional
        Particle density [kg/m^3] (or per atom type), used only for dumps without a mass field
        (:func:`siloflow.engines.liggghts.dumps.frame_from_arrays`).
    on_damaged : {"error", "skip"}
        A damaged dump raises :class:`~siloflow.engines.liggghts.vtk_legacy.DumpFormatError` naming the file, or is left out
        with a warning (``warnings`` and the ``siloflow`` logger), by :func:`siloflow.engines.liggghts.dumps.readable_frames`.

    Returns
    -------
    list of ParticleFrame
        Every frame of every readable file (a text dump may hold several).

    Raises
    ------
    DumpFormatError
        A damaged file under ``on_damaged="error"``, or a file that is no LIGGGHTS particle dump.
    ValueError
        An unknown ``on_damaged``, or from the reader: a dump without a mass field and no ``density``, or a VTK dump
        without a step in its name.
    """
    # a legacy VTK file holds no step: its name's; a text dump holds its own, and refuses another (told apart lazily,
    # each just before it is read)
    steps = (dump.step if dump_format(dump.path) == "vtk" else None for dump in files)
    return list(readable_frames([dump.path for dump in files], timestep, on_damaged=on_damaged, density=density,
                                steps=steps))
