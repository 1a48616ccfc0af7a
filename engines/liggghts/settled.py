"""The settled fill's snapshot written by the silo-type decks (``settled_fill_snapshot`` in
``templates/liggghts/macros.j2``), read into a neutral :class:`SettledFill`.

The deck writes, at one ``run 0`` after the settle stage, a text ``dump custom`` of the spheres
(``dumps/settled_fill_<step>.txt``: ``id type id_multisphere x y z vx vy vz radius mass`` and the summed force of
every wall fix on the sphere, ``v_settled_wall_fx/fy/fz``, from their ``store_force``), and the pair contacts
(``dumps/contacts_<step>.txt``, read by :mod:`engines.liggghts.contacts`). Values are written with 12 significant
digits. The per-wall split comes from the wall force history (:mod:`engines.liggghts.forces`), at its last sample
up to the snapshot.

The Jenike deck writes the same sphere dump of its levelled fill before the lid is placed, with its pair contacts
in its own column layout (``dumps/settled_contacts_<step>.txt``) and each mesh's force in the ``levelled`` stage
marker (:func:`read_settled_jenike_fill`).

Why not a library reader: the text dump is the header of a ``dump local`` plus a table; the contact reader's
strict parser (which names the file and the fault of a truncated dump) reads both.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from analysis.data.contacts import ContactFrame
from analysis.data.forces import WallForceHistory
from analysis.data.frames import ParticleFrame
from analysis.data.settled import SettledFill
from engines.liggghts.contacts import ContactDumpError, parse_local_table, read_contacts
from engines.liggghts.dumps import frame_from_arrays, list_dumps
from engines.liggghts.jenike import (
    JENIKE_FLOOR_WALLS,
    SETTLED_CONTACT_PREFIX,
    SETTLED_WALLS,
    read_jenike_pair_contacts,
)
from engines.liggghts.run import CONTACT_PREFIX, SETTLED_FILL_PREFIX

__all__ = ["SETTLED_COLUMNS", "read_settled_spheres", "read_settled_fill", "read_settled_jenike_fill"]

#: The columns of the settled fill's sphere dump, in the deck's order.
SETTLED_COLUMNS = ("id", "type", "id_multisphere", "x", "y", "z", "vx", "vy", "vz", "radius", "mass",
                   "v_settled_wall_fx", "v_settled_wall_fy", "v_settled_wall_fz")


def read_settled_spheres(path: str | Path, timestep: float) -> tuple[ParticleFrame, np.ndarray]:
    """The spheres of a settled fill dump and the walls' force on each.

    Parameters
    ----------
    path : str or Path
        A ``settled_fill_<step>.txt`` dump.
    timestep : float
        The run's time step [s] (the frame's time is step times it).

    Returns
    -------
    (ParticleFrame, numpy.ndarray of shape (n, 3))
        The spheres, and the force of all walls on each [N].

    Raises
    ------
    ContactDumpError
        Naming the file, when it is truncated, malformed, or its columns are not :data:`SETTLED_COLUMNS`.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8", errors="replace")
    header = next((line.split()[2:] for line in text.splitlines() if line.startswith("ITEM: ATOMS")), None)
    if header is None or tuple(header) != SETTLED_COLUMNS:
        raise ContactDumpError(f"{path}: columns {header} are not the settled fill's {list(SETTLED_COLUMNS)}")
    step, table = parse_local_table(text, len(SETTLED_COLUMNS), str(path), "NUMBER OF ATOMS", "ATOMS")
    column = {name: table[:, index] for index, name in enumerate(SETTLED_COLUMNS)}
    # the arrays of a particle dump, so that the one reader rule (free spheres, clump ids) applies
    arrays = {"points": table[:, 3:6], "v": table[:, 6:9], "radius": column["radius"], "mass": column["mass"],
              **{name: column[name].astype(np.int64) for name in ("id", "type", "id_multisphere")}}
    frame = frame_from_arrays(arrays, step, step * timestep, source=str(path))
    return frame, table[:, 11:14].copy()


def _snapshot(dumps_dir: Path, timestep: float, contacts_prefix: str, read_pair_contacts: Callable[[Path], ContactFrame]):
    """The newest sphere dump of the snapshot, the walls' force on each sphere and the contacts of its step."""
    paths = list_dumps(dumps_dir, SETTLED_FILL_PREFIX, ".txt")
    if not paths:
        raise FileNotFoundError(f"{dumps_dir}: no {SETTLED_FILL_PREFIX}_<step>.txt (a deck from before the force "
                                "balance? render the run again)")
    frame, wall_force = read_settled_spheres(paths[-1], timestep)
    contacts_path = dumps_dir / f"{contacts_prefix}_{frame.step}.txt"
    if not contacts_path.exists():
        raise FileNotFoundError(f"{contacts_path}: the contacts of the settled fill (step {frame.step}) are missing")
    return frame, wall_force, read_pair_contacts(contacts_path)


def read_settled_fill(
    dumps_dir: str | Path, timestep: float, history: WallForceHistory | None, floor_walls: tuple[str, ...]
) -> SettledFill:
    """The settled fill of a silo-type run: its sphere dump, the contacts of the same step and, from ``history``
    (None: no per-wall split), each wall's force at its last sample up to the snapshot.

    Raises
    ------
    FileNotFoundError
        When the run wrote no settled fill dump, or no contact dump at its step.
    ContactDumpError
        When a dump is damaged (see :func:`read_settled_spheres`).
    """
    frame, wall_force, contacts = _snapshot(Path(dumps_dir), timestep, CONTACT_PREFIX, read_contacts)
    wall_forces = {}
    if history is not None:
        before = np.flatnonzero(history.time <= frame.time * (1.0 + 1e-12))
        if before.size:
            sample = int(before[-1])
            wall_forces = {name: history.force[name][sample] for name in history.walls}
    return SettledFill(frame=frame, wall_force=wall_force, contacts=contacts, wall_forces=wall_forces,
                       floor_walls=floor_walls if wall_forces else ())


def read_settled_jenike_fill(
    dumps_dir: str | Path, timestep: float, marker: Mapping[str, float], walls: Sequence[str] = SETTLED_WALLS,
    floor_walls: tuple[str, ...] = JENIKE_FLOOR_WALLS, contacts_prefix: str = SETTLED_CONTACT_PREFIX,
    read_pair_contacts: Callable[[Path], ContactFrame] = read_jenike_pair_contacts,
) -> SettledFill:
    """The levelled, settled fill of a Jenike run (before the lid), with each mesh's force from the ``levelled``
    marker.

    Parameters
    ----------
    marker : mapping
        The marker's values; ``<wall>_f<x|y|z>`` is the force of the particles ON mesh ``wall`` [N] (negated here:
        :class:`SettledFill` holds the walls' forces on the particles).
    walls : sequence of str, optional
        The meshes the marker names (the Jenike deck's :data:`~engines.liggghts.jenike.SETTLED_WALLS`).
    floor_walls : tuple of str, optional
        Those of ``walls`` that are the floor (the base).
    contacts_prefix, read_pair_contacts : optional
        The file prefix of the snapshot's pair contacts and their reader (the Jenike deck's).

    Raises
    ------
    FileNotFoundError
        When the run wrote no snapshot.
    KeyError
        When the marker lacks a wall's force (a deck from before the force balance).
    """
    frame, wall_force, contacts = _snapshot(Path(dumps_dir), timestep, contacts_prefix, read_pair_contacts)
    missing = [f"{wall}_fz" for wall in walls if f"{wall}_fz" not in marker]
    if missing:
        raise KeyError(f"the levelled marker has no {missing[0]} (a deck from before the force balance? render the "
                       "run again)")
    wall_forces = {wall: -np.array([float(marker[f"{wall}_f{axis}"]) for axis in "xyz"]) for wall in walls}
    return SettledFill(frame=frame, wall_force=wall_force, contacts=contacts, wall_forces=wall_forces,
                       floor_walls=tuple(floor_walls))
