"""The settled fill's snapshot written by the silo-type and Jenike decks (``settled_fill_snapshot`` in
``siloflow/templates/liggghts/macros.j2``), read into neutral :class:`SettledFill` objects, one per step.

The deck writes, at the last two steps of a short run after the settle stage, a text ``dump custom`` of the spheres
(``dumps/settled_fill_<step>.txt``: ``id type id_multisphere x y z vx vy vz radius mass`` and the summed force of
every wall fix on the sphere, ``v_settled_wall_fx/fy/fz``, from their ``store_force``), the pair contacts
(``dumps/contacts_<step>.txt`` of the silos, read by :mod:`siloflow.engines.liggghts.contacts`; the Jenike deck's
``dumps/settled_contacts_<step>.txt`` in its own column layout) with 12 significant digits, and every wall's force
on the particles (``dumps/settled_walls.txt``, the format of the wall force history, :mod:`siloflow.engines.liggghts.forces`:
6 digits). Two steps, because a LIGGGHTS fill at rest alternates about equilibrium from step to step, and the last
of a run, because its set-up kicks the fill (the macro says by how much);
:func:`siloflow.analysis.numerics.force_balance.settled_fill_balance` averages them.

Why not a library reader: the text dump is the header of a ``dump local`` plus a table; the contact reader's
strict parser (which names the file and the fault of a truncated dump) reads both.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from siloflow.model.contacts import ContactFrame
from siloflow.model.frames import ParticleFrame
from siloflow.model.settled import SettledFill
from siloflow.engines.liggghts.contacts import ContactDumpError, parse_local_table, read_contacts
from siloflow.engines.liggghts.dumps import frame_from_arrays, list_dumps
from siloflow.engines.liggghts.forces import QUANTITIES, read_wall_force_file
from siloflow.engines.liggghts.run import CONTACT_PREFIX, SETTLED_FILL_PREFIX, SETTLED_WALLS_PATH

__all__ = ["SETTLED_COLUMNS", "read_settled_spheres", "read_settled_fill"]

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
    if header is None or tuple(header) != SETTLED_COLUMNS:  # the file's columns are not quoted: any text may be there
        raise ContactDumpError(f"{path}: no 'ITEM: ATOMS' line of the settled fill's columns {list(SETTLED_COLUMNS)}")
    step, table = parse_local_table(text, len(SETTLED_COLUMNS), str(path), "NUMBER OF ATOMS", "ATOMS")
    column = {name: table[:, index] for index, name in enumerate(SETTLED_COLUMNS)}
    # the arrays of a particle dump, so that the one reader rule (free spheres, clump ids) applies
    arrays = {"points": table[:, 3:6], "v": table[:, 6:9], "radius": column["radius"], "mass": column["mass"],
              **{name: column[name].astype(np.int64) for name in ("id", "type", "id_multisphere")}}
    frame = frame_from_arrays(arrays, step, step * timestep, source=str(path))
    return frame, table[:, 11:14].copy()


def read_settled_fill(
    dumps_dir: str | Path, timestep: float, floor_walls: tuple[str, ...], contacts_prefix: str = CONTACT_PREFIX,
    read_pair_contacts: Callable[[Path], ContactFrame] = read_contacts,
) -> tuple[SettledFill, ...]:
    """The settled fill at each step of its snapshot, oldest first: the sphere dump, the pair contacts and every
    wall's force of that step.

    Parameters
    ----------
    dumps_dir : str or Path
        The run's ``dumps`` directory.
    timestep : float
        The run's time step [s].
    floor_walls : tuple of str
        The walls of ``settled_walls.txt`` that make the floor (plates, gate, base).
    contacts_prefix, read_pair_contacts : optional
        The file prefix of the snapshot's pair contacts and their reader (the silos' by default; the Jenike deck's
        :data:`~siloflow.engines.liggghts.jenike.SETTLED_CONTACT_PREFIX` and
        :func:`~siloflow.engines.liggghts.jenike.read_jenike_pair_contacts`).

    Raises
    ------
    FileNotFoundError
        When the run wrote no settled fill dump, no contact dump at its step, or no wall forces (a deck from before
        the two-step snapshot: render the run again).
    ValueError
        When the wall forces have no row at a dump's step.
    ContactDumpError
        When a dump is damaged (see :func:`read_settled_spheres`).
    """
    dumps_dir = Path(dumps_dir)
    paths = list_dumps(dumps_dir, SETTLED_FILL_PREFIX, ".txt")
    if not paths:
        raise FileNotFoundError(f"{dumps_dir}: no {SETTLED_FILL_PREFIX}_<step>.txt (a deck from before the force "
                                "balance? render the run again)")
    walls_path = dumps_dir / Path(SETTLED_WALLS_PATH).name
    if not walls_path.exists():
        raise FileNotFoundError(f"{walls_path}: the walls' forces of the settled fill are missing (a deck from before "
                                "the two-step snapshot? render the run again)")
    _, walls, steps, values = read_wall_force_file(walls_path)
    fills = []
    for path in paths:
        frame, wall_force = read_settled_spheres(path, timestep)
        contacts_path = dumps_dir / f"{contacts_prefix}_{frame.step}.txt"
        if not contacts_path.exists():
            raise FileNotFoundError(f"{contacts_path}: the contacts of the settled fill (step {frame.step}) are missing")
        row = np.flatnonzero(steps == frame.step)
        if not row.size:
            raise ValueError(f"{walls_path} has no row at step {frame.step}, the step of {path.name}")
        forces = values[row[0]].reshape(len(walls), len(QUANTITIES))[:, :3]
        fills.append(SettledFill(frame=frame, wall_force=wall_force, contacts=read_pair_contacts(contacts_path),
                                 wall_forces=dict(zip(walls, forces)), floor_walls=tuple(floor_walls)))
    return tuple(fills)
