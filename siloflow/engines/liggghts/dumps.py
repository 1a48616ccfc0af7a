"""Particle dumps: reading LIGGGHTS' particle dumps, in every form users have them, into particle frames.

What is read
------------
- Legacy VTK (``dump custom/vtk`` to ``.vtk``): BINARY (``dump_modify ... binary yes``, what siloflow's decks
  write) and ASCII (LIGGGHTS' default), versions 5.1 (LIGGGHTS built against VTK 9) and 4.2 (VTK 8.2 and older
  4.x writers); parsed by :mod:`siloflow.engines.liggghts.vtk_legacy`, which says why it is hand-written (``pyvista.read``
  returns damaged files without an error) and what it costs. The file carries no step: it is the number after the
  last underscore of the name (or passed).
- Text ``dump custom`` (``ITEM: TIMESTEP`` ...), one or several snapshots a file, any file name; parsed by
  :mod:`siloflow.engines.liggghts.dump_text`. The step is the file's ``ITEM: TIMESTEP``.

The reader tells them apart by their first line, not by the file name.

Every siloflow deck (``siloflow/templates/liggghts/macros.j2``) dumps the spheres with::

    dump ID all custom/vtk N dumps/particles_*.vtk id type id_multisphere x y z vx vy vz radius mass
    dump_modify ID binary yes first yes

(the Jenike deck adds ``fx fy fz omegax omegay omegaz`` before ``radius``); a user's dumps may lack some of these:

- no ``mass`` (LIGGGHTS' tutorials dump none): the caller passes the particles' ``density`` (the mass is then
  density x 4/3 pi r^3 per sphere, computed as LIGGGHTS computes it, to the last bit) or the mass itself
  (``sphere_mass``); the reader reads no configuration. A density cannot give the mass of a multisphere clump
  (LIGGGHTS writes the clump's mass on each of its spheres, and the spheres overlap): such a dump needs
  ``sphere_mass``, the clump's mass.
- no ``id_multisphere``: every sphere is its own clump (clump id = sphere id).
- no forces or angular velocities: the frame has None for them.

Frames are not cached: an uncompressed ``.npz`` copy of a frame is 6-11 % larger than the binary dump it caches,
and loading it took 1.0-1.3 times as long as :func:`read_frame` (``tests/bench/bench_dumps.py``).

All quantities are SI: metres, seconds, kilograms, newtons, radians.
"""

from __future__ import annotations

import itertools
import logging
import os
import re
import warnings
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

import numpy as np

from siloflow.model.frames import ClumpFrame, ParticleFrame, clumps_from_frame
from siloflow.model.file_messages import refuse_irregular, unreadable
from siloflow.engines.liggghts.dump_text import FIRST_LINE, CustomDumpSnapshot, parse_custom_dump, read_custom_dump
from siloflow.engines.liggghts.vtk_legacy import DumpFormatError, parse_legacy_vtk_polydata, parse_legacy_vtk_views

__all__ = [
    "DumpFormatError",
    "ParticleFrame",
    "ClumpFrame",
    "CustomDumpSnapshot",
    "DAMAGED_DUMP_POLICIES",
    "parse_legacy_vtk_polydata",
    "parse_custom_dump",
    "read_custom_dump",
    "frame_from_arrays",
    "clumps_from_frame",
    "dump_format",
    "dump_step",
    "list_dumps",
    "read_file_frames",
    "read_frame",
    "readable_frames",
    "read_frames",
]

#: Per-type values: one number for every atom type, or a number per atom type.
PerType = float | Mapping[int, float]

_VTK_MAGIC = b"# vtk DataFile Version"
_XML_MAGIC = (b"<?xml", b"<VTKFile")


# --------------------------------------------------------------------------- arrays to frames


def _vector_field(arrays: Mapping[str, np.ndarray], name: str, n: int, source: str) -> np.ndarray | None:
    if name not in arrays:
        return None
    values = np.asarray(arrays[name])
    if values.shape != (n, 3):
        raise DumpFormatError(f"{source}: field {name!r} has shape {values.shape}, expected ({n}, 3)")
    return values


def _integer_field(values: np.ndarray, name: str, source: str) -> np.ndarray:
    values = np.asarray(values)
    if values.dtype.kind not in "iu":
        raise DumpFormatError(f"{source}: field {name!r} must hold integers, got dtype {values.dtype}")
    return values


def _per_type_values(value: PerType, name: str, types: np.ndarray, source: str) -> np.ndarray:
    """``value`` (a number, or a number per atom type) for each sphere of the given types; checked finite, > 0."""
    table = dict(value) if isinstance(value, Mapping) else None
    numbers = np.array(list(table.values()) if table is not None else [value], dtype=np.float64)
    if numbers.size == 0 or not np.all(np.isfinite(numbers)) or not np.all(numbers > 0):
        raise ValueError(f"{name} must be a finite positive number or a mapping of atom types to such numbers, "
                         f"got {value!r}")
    if table is None:
        return np.full(types.shape, numbers[0])
    present, inverse = np.unique(types, return_inverse=True)
    missing = [int(atom_type) for atom_type in present if int(atom_type) not in table]
    if missing:
        raise ValueError(f"{source}: the dump has atom type(s) {missing} for which no {name} was given "
                         f"(types {sorted(table)})")
    return np.array([float(table[int(atom_type)]) for atom_type in present])[inverse.reshape(-1)]


def _mass(arrays: Mapping[str, np.ndarray], types: np.ndarray, radius: np.ndarray, in_clump: np.ndarray,
          density: PerType | None, sphere_mass: PerType | None, source: str) -> np.ndarray:
    """The dump's mass column, or the mass from ``density`` or ``sphere_mass`` when it has none [kg]."""
    if "mass" in arrays:
        return np.asarray(arrays["mass"])
    if sphere_mass is not None:
        return _per_type_values(sphere_mass, "sphere_mass", types, source)
    if in_clump.any():
        raise ValueError(
            f"{source}: no mass field, and {int(in_clump.sum())} spheres belong to multisphere clumps, whose mass "
            "(LIGGGHTS writes the clump's on each of its spheres) a density does not give, as their spheres "
            "overlap: dump 'mass' or pass sphere_mass (the clump's mass)"
        )
    # the order of LIGGGHTS' fix particletemplate/sphere (r*r*r*4*pi/3, then times the density): the same bits
    volume = radius * radius * radius * 4.0 * np.pi / 3.0
    return _per_type_values(density, "density", types, source) * volume


def frame_from_arrays(
    arrays: Mapping[str, np.ndarray], step: int, time: float, *, source: str = "<arrays>",
    density: PerType | None = None, sphere_mass: PerType | None = None,
) -> ParticleFrame:
    """Build a :class:`ParticleFrame` from the arrays of a dump parser.

    Parameters
    ----------
    arrays : mapping of str to numpy.ndarray
        As :func:`parse_legacy_vtk_polydata` or :func:`parse_custom_dump` name them: ``points`` (n, 3) [m],
        integer ``id`` and ``type``, ``radius`` [m], ``v`` (n, 3) [m/s]; optional: ``mass`` [kg], integer
        ``id_multisphere`` (absent, 0 or negative for a free sphere; LIGGGHTS writes -1), ``omega`` (n, 3)
        [rad/s] and ``f`` (n, 3) [N]. A frame with no points may lack every field.
    step : int
        Time step number of the dump [-].
    time : float
        Simulated time [s].
    source : str
        Name of the dump for error messages.
    density : float or mapping of int to float, optional
        Particle density [kg/m^3] (or per atom type), used only when ``arrays`` has no ``mass``: each
        sphere's mass is then density x 4/3 pi radius^3. Not for spheres of multisphere clumps.
    sphere_mass : float or mapping of int to float, optional
        The mass column the dump lacks [kg] (or per atom type): a free sphere's mass, or for a sphere of a
        clump the clump's mass (LIGGGHTS' convention). Used only when ``arrays`` has no ``mass``. Give
        ``density`` or ``sphere_mass``, not both.

    Returns
    -------
    ParticleFrame
        The frame; a free sphere gets its own sphere id as clump id, negated when the dump has
        ``id_multisphere`` so that it cannot collide with a clump id.

    Raises
    ------
    DumpFormatError
        When a required field is missing (``mass`` only when neither ``density`` nor ``sphere_mass`` is
        given) or malformed, or a position or velocity is not finite.
    ValueError
        When ``density`` or ``sphere_mass`` is not a finite positive number (or mapping of them), both are
        given, the mapping lacks an atom type of the dump, or ``density`` is asked to give the mass of clump
        spheres.
    """
    if density is not None and sphere_mass is not None:
        raise ValueError("give density or sphere_mass, not both")
    if "points" not in arrays:
        raise DumpFormatError(f"{source}: no positions (points; dump x y z)")
    position = np.asarray(arrays["points"])
    if position.ndim != 2 or position.shape[1] != 3:
        raise DumpFormatError(f"{source}: positions have shape {position.shape}, expected (n, 3)")
    n = position.shape[0]

    velocity = _vector_field(arrays, "v", n, source)
    angular_velocity = _vector_field(arrays, "omega", n, source)
    force = _vector_field(arrays, "f", n, source)
    # "vx vy vz" are the dump command's columns, which LIGGGHTS writes as the vector v.
    present = {"id": "id", "type": "type", "radius": "radius", "v (or vx vy vz)": "v"}
    if density is None and sphere_mass is None:
        present["mass"] = "mass"
    missing = [label for label, name in sorted(present.items()) if name not in arrays]
    if missing and n > 0:
        raise DumpFormatError(
            f"{source}: missing fields {', '.join(missing)} (dump at least 'id type x y z vx vy vz radius mass', "
            "or pass the density or the sphere mass for a dump without mass)"
        )

    def column(name: str) -> np.ndarray:
        if name not in arrays:  # only reached for an empty frame
            return np.empty(0, dtype=np.int32)
        values = np.asarray(arrays[name])
        if values.shape != (n,):
            raise DumpFormatError(f"{source}: field {name!r} has shape {values.shape}, expected ({n},)")
        return values

    for name, values in (("points", position), ("v", velocity), ("omega", angular_velocity)):
        if values is not None and not np.all(np.isfinite(values)):
            raise DumpFormatError(f"{source}: field {name!r} contains non-finite values")

    ids = _integer_field(column("id"), "id", source).astype(np.int64)
    types = _integer_field(column("type"), "type", source)
    radius = column("radius")
    clump_id = ids  # no id_multisphere: every sphere is its own clump
    in_clump = np.zeros(n, dtype=bool)
    if "id_multisphere" in arrays:
        body = _integer_field(column("id_multisphere"), "id_multisphere", source)
        # A sphere outside any body (a free sphere, or the remnant of a clump that was cut in two as it
        # left the domain) gets the negative of its sphere id, which can never equal a clump id.
        in_clump = body > 0
        clump_id = np.where(in_clump, body, -ids)
    mass = column("mass") if n == 0 else _mass(arrays, types, radius, in_clump, density, sphere_mass, source)
    empty_vectors = np.empty((0, 3))
    try:
        return ParticleFrame(
            time=time,
            step=step,
            id=ids,
            type=types,
            clump_id=clump_id,
            position=position,
            velocity=empty_vectors if velocity is None else velocity,
            angular_velocity=empty_vectors if angular_velocity is None and n == 0 else angular_velocity,
            radius=radius,
            mass=mass,
            force=force,
        )
    except ValueError as error:
        raise DumpFormatError(f"{source}: {error}") from None


# --------------------------------------------------------------------------- files


def dump_step(path: str | os.PathLike) -> int:
    """Time step number in a dump file name: the integer after the last underscore.

    Parameters
    ----------
    path : str or path-like
        E.g. ``dumps/silo_12000.vtk``.

    Returns
    -------
    int
        E.g. 12000.

    Raises
    ------
    ValueError
        When the name does not end in ``_<digits>`` before its extension.
    """
    stem = Path(path).stem
    _, underscore, digits = stem.rpartition("_")
    if not underscore or not digits.isdigit() or not digits.isascii():
        raise ValueError(f"{path}: file name does not end in _<step>")
    return int(digits)


def dump_format(path: str | os.PathLike) -> str:
    """Which kind of LIGGGHTS particle dump a file is, from its first line (as :func:`read_file_frames` tells them
    apart).

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    str
        ``"vtk"`` (legacy VTK: its step is in its name), ``"text"`` (``dump custom``: its steps are in it) or
        ``"other"`` (neither; :func:`read_file_frames` says why it refuses it).

    Raises
    ------
    DumpFormatError
        Naming the file: no regular file (a folder, a device, a pipe), or one that cannot be read.
    """
    # a folder cannot be read, a device (/dev/zero) never ends and a named pipe may never begin
    refuse_irregular(path, DumpFormatError)
    try:
        with open(path, "rb") as handle:
            head = handle.read(64)
    except OSError as error:
        raise DumpFormatError(f"{path}: {unreadable(error)}") from None
    if head.startswith(_VTK_MAGIC):
        return "vtk"
    if head.startswith(FIRST_LINE.encode()):
        return "text"
    return "other"


def list_dumps(dump_dir: str | os.PathLike, prefix: str, suffix: str = ".vtk") -> list[Path]:
    """Dump files ``<prefix>_<digits><suffix>`` in a folder, sorted by step (particle dumps ``.vtk``, contact
    dumps ``.txt``).

    Files such as ``<prefix>_boundingBox_<step>.vtk`` are ignored.

    Parameters
    ----------
    dump_dir : str or path-like
        Folder holding the dumps.
    prefix : str
        File name prefix (``silo`` for ``silo_*.vtk``).
    suffix : str
        File name ending, with its dot.

    Returns
    -------
    list of pathlib.Path
        Ascending by step number (numerically: 2000 before 10000).
    """
    pattern = re.compile(re.escape(prefix) + r"_([0-9]+)" + re.escape(suffix))
    matches = [
        (int(match.group(1)), entry)
        for entry in Path(dump_dir).iterdir()
        if (match := pattern.fullmatch(entry.name)) and entry.is_file()
    ]
    return [entry for _, entry in sorted(matches)]


def _check_timestep(timestep: float) -> float:
    timestep = float(timestep)
    if not np.isfinite(timestep) or timestep <= 0:
        raise ValueError(f"timestep must be a finite positive number of seconds, got {timestep!r}")
    return timestep


def read_file_frames(
    path: str | os.PathLike, timestep: float, *, density: PerType | None = None,
    sphere_mass: PerType | None = None, step: int | None = None,
) -> list[ParticleFrame]:
    """Read every frame of one LIGGGHTS particle dump file, legacy VTK or text ``dump custom`` (module docstring).

    Parameters
    ----------
    path : str or path-like
        The dump file; its format is told from its first line.
    timestep : float
        Simulation time step [s]; a frame's time is its step times it.
    density, sphere_mass : float or mapping of int to float, optional
        For a dump without a mass field: the particle density [kg/m^3] or the mass column [kg], one value or
        one per atom type (:func:`frame_from_arrays`).
    step : int, optional
        Time step number of a legacy VTK dump [-], which the file does not hold; by default the number after
        the last underscore of its name. A text dump holds its steps: giving one is an error.

    Returns
    -------
    list of ParticleFrame
        One frame for a VTK file; one per snapshot, in file order, for a text dump.

    Raises
    ------
    DumpFormatError
        When the file is no regular file (refused before it is opened) or cannot be read, or the dump is malformed
        or in neither format (the message names the file and the place, never what the file holds there).
    ValueError
        When ``timestep`` is not a finite positive number, a VTK file's name has no step and none is given, or
        the mass arguments are wrong (:func:`frame_from_arrays`).
    """
    path = Path(path)
    timestep = _check_timestep(timestep)
    refuse_irregular(path, DumpFormatError)
    # The file's bytes: the VTK parser's arrays are views into them, and the frame's arrays the one copy.
    try:
        content = np.fromfile(path, dtype=np.uint8)
    except OSError as error:
        raise DumpFormatError(f"{path}: {unreadable(error)}") from None
    head = bytes(content[:64])
    masses = {"density": density, "sphere_mass": sphere_mass}
    if head.startswith(_VTK_MAGIC):
        if step is None:
            try:
                step = dump_step(path)
            except ValueError as error:
                raise ValueError(f"{error} (a legacy VTK dump holds no step: pass it)") from None
        step = int(step)
        arrays = parse_legacy_vtk_views(content, str(path))
        return [frame_from_arrays(arrays, step, step * timestep, source=str(path), **masses)]
    if head.startswith(FIRST_LINE.encode()):
        if step is not None:
            raise ValueError(f"{path}: a text dump holds its own steps; do not pass step")
        # a snapshot is named by its place in the file: its step is a number the file holds
        return [
            frame_from_arrays(snapshot.arrays, snapshot.step, snapshot.step * timestep,
                              source=f"{path} (snapshot {number})", **masses)
            for number, snapshot in enumerate(parse_custom_dump(content.tobytes(), str(path)), start=1)
        ]
    if head.lstrip().startswith(_XML_MAGIC):
        raise DumpFormatError(f"{path}: an XML VTK file; siloflow reads legacy VTK (dump custom/vtk to a .vtk file) "
                              "and text dump custom")
    if not head:
        raise DumpFormatError(f"{path}: the file is empty")
    raise DumpFormatError(f"{path}: not a LIGGGHTS particle dump: its first line starts neither legacy VTK "
                          f"({_VTK_MAGIC.decode()!r}) nor a text dump custom ({FIRST_LINE!r})")


def read_frame(
    path: str | os.PathLike, timestep: float, *, density: PerType | None = None,
    sphere_mass: PerType | None = None, step: int | None = None,
) -> ParticleFrame:
    """Read one LIGGGHTS dump of one step into a :class:`ParticleFrame`.

    Parameters
    ----------
    path : str or path-like
        Dump file: legacy VTK ``<prefix>_<step>.vtk``, or a text ``dump custom`` file of one snapshot.
    timestep : float
        Simulation time step [s]; the frame time is ``step * timestep``.
    density, sphere_mass : float or mapping of int to float, optional
        For a dump without a mass field (:func:`read_file_frames`).
    step : int, optional
        Step of a VTK dump whose name does not end in ``_<step>`` (:func:`read_file_frames`).

    Returns
    -------
    ParticleFrame
        The spheres of that step.

    Raises
    ------
    DumpFormatError
        When the dump is malformed, or a text dump holds several snapshots (the message names the file).
    ValueError
        As :func:`read_file_frames`.
    """
    frames = read_file_frames(path, timestep, density=density, sphere_mass=sphere_mass, step=step)
    if len(frames) != 1:
        raise DumpFormatError(f"{path}: holds {len(frames)} snapshots; read them with read_file_frames")
    return frames[0]


DAMAGED_DUMP_POLICIES = ("error", "skip")


def readable_frames(
    paths: Iterable[str | os.PathLike], timestep: float, *, on_damaged: str = "error",
    density: PerType | None = None, sphere_mass: PerType | None = None, steps: Iterable[int | None] | None = None,
) -> Iterator[ParticleFrame]:
    """Read dumps one after another, lazily.

    Parameters
    ----------
    paths : iterable of str or path-like
        Dump files, in the order wanted (a text dump may hold several snapshots: all are yielded).
    timestep : float
        Simulation time step [s].
    on_damaged : {"error", "skip"}
        A damaged dump (truncated, wrong count, non-finite value) raises :class:`DumpFormatError`
        naming the file (``"error"``), or is left out with a warning (``warnings`` and the ``siloflow``
        logger) that names the file and the problem (``"skip"``).
    density, sphere_mass : float or mapping of int to float, optional
        For dumps without a mass field (:func:`frame_from_arrays`).
    steps : iterable of int or None, optional
        One per path, in their order: the time step number [-] of a legacy VTK dump whose name does not end in
        ``_<step>``, or None (a VTK dump's step from its name; a text dump, which holds its own)
        (:func:`read_file_frames`). Taken one at a time, just before its dump is read. By default None for every
        dump.

    Yields
    ------
    ParticleFrame
        The frames of every readable dump.

    Raises
    ------
    ValueError
        An unknown ``on_damaged``, ``steps`` not as many as ``paths``, or from :func:`read_file_frames`.
    DumpFormatError
        A damaged dump under ``on_damaged="error"``.
    """
    if on_damaged not in DAMAGED_DUMP_POLICIES:
        raise ValueError(f"on_damaged must be one of {DAMAGED_DUMP_POLICIES}, got {on_damaged!r}")
    paired = zip(paths, itertools.repeat(None)) if steps is None else zip(paths, steps, strict=True)
    for path, step in paired:
        try:
            frames = read_file_frames(path, timestep, density=density, sphere_mass=sphere_mass, step=step)
        except DumpFormatError as error:
            if on_damaged == "error":
                raise
            message = f"skipping damaged dump ({error})"
            warnings.warn(message, stacklevel=2)
            logging.getLogger("siloflow").warning(message)
            continue
        yield from frames


def read_frames(
    dump_dir: str | os.PathLike, prefix: str, timestep: float, on_damaged: str = "error", *, suffix: str = ".vtk",
    density: PerType | None = None, sphere_mass: PerType | None = None,
) -> list[ParticleFrame]:
    """Read every ``<prefix>_<step><suffix>`` dump of a folder, in step order.

    Parameters
    ----------
    dump_dir : str or path-like
        Folder holding the dumps.
    prefix : str
        Dump file name prefix.
    timestep : float
        Simulation time step [s].
    on_damaged : {"error", "skip"}
        What a damaged dump does (:func:`readable_frames`).
    suffix : str
        File name ending, with its dot: ``.vtk`` for legacy VTK, the text dumps' own (``.txt``, ...).
    density, sphere_mass : float or mapping of int to float, optional
        For dumps without a mass field (:func:`frame_from_arrays`).

    Returns
    -------
    list of ParticleFrame
        The frames of every readable dump, ascending step.
    """
    paths = list_dumps(dump_dir, prefix, suffix)
    return list(readable_frames(paths, timestep, on_damaged=on_damaged, density=density, sphere_mass=sphere_mass))
