"""LIGGGHTS: the Jenike direct shear deck, its inputs, running it and reading its force history.

How the deck carries out the case's stages: levelling deletes clumps with ``delete_atoms region`` (LIGGGHTS
removes the partner spheres of a deleted sphere's clump at the start of the next run, so a one-step run follows).
The mould stays after levelling: removing it would mean re-creating the single mesh wall, which LIGGGHTS refuses
while ``compute wall/gran/local`` (the wall-contact diagnostics, defined before the first run) exists. The servo
lid is not LIGGGHTS' ``mesh/surface/stress/servo`` (it cannot be combined with ``move/mesh``, so it could not follow
the shear ring, and its proportional controller lags behind the dilation of the sheared sample): the lid mesh
moves with ``move/mesh linear/variable``, z with a proxy rigid body of two atoms (fix rigid needs two).

Run directory layout (the engine runs inside the run directory; relative paths are what the deck sees)::

    <run>/deck/in.liggghts     the rendered deck
    <run>/deck/meshes/*.stl    base (bottom ring or plate), shear_ring, mould, and lid (servo lid only)
    <run>/deck/case.json       derived case quantities
    <run>/dumps/               particle dumps during consolidation and shear (binary legacy VTK), and
                               contact dumps pair_contacts_<step>.txt, wall_contacts_<step>.txt (rigid lid)
    <run>/forces.txt           force history during consolidation and shear (see siloflow.engines.jenike_checks;
                               siloflow.engines.liggghts.forces reads it as a WallForceHistory)
    <run>/log.liggghts         the engine log
    <run>/engine.out           the engine's screen output
    <run>/run.json             written last, only after every check passed
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from siloflow.model.contacts import ContactFrame, WallContactFrame
from siloflow.model.cases.geometry import write_stl
from siloflow.model.cases.jenike import JenikeCase
from siloflow.model.cases.jenike_contacts import LID_TYPE, PARTICLE_TYPE, PLATE_TYPE, RING_TYPE, ContactSet
from siloflow.model.record import RunRecord
from siloflow.engines.jenike_checks import SETTLED_WALLS, check_jenike_run, jenike_run_record
from siloflow.engines.layout import RUN_RECORD
from siloflow.engines.liggghts.contacts import parse_local_table
from siloflow.engines.liggghts.dumps import list_dumps
from siloflow.engines.layout import write_text_atomic
from siloflow.engines.liggghts.inputs import DECK_NAME, ENGINE_NAME, common_context, flat_matrix, processor_grid
from siloflow.engines.liggghts.rolling import cdt_matrix
from siloflow.model.rolling import RollingGeometry
from siloflow.engines.markers import parse_markers
from siloflow.engines.liggghts.run import (
    DUMP_PREFIX,
    RUN_OUTPUTS,
    output_bytes,
    run_engine,
    set_aside_previous_attempt,
    settled_fill_context,
    write_run_record,
)
from siloflow.engines.templating import render_deck

#: The force history the deck writes (``fix ave/time``; the format of :mod:`siloflow.engines.jenike_checks`).
FORCES_NAME = "forces.txt"

#: The one name the LIGGGHTS deck gives the Jenike force history (format: :mod:`siloflow.engines.jenike_checks`).
PAIR_CONTACT_PREFIX = "pair_contacts"
#: The pair contacts of the levelled, settled fill (before the lid), beside ``settled_fill_<step>.txt``; their own
#: prefix keeps them out of the consolidation and shear contact frames.
SETTLED_CONTACT_PREFIX = "settled_contacts"
#: The meshes of the cell's one mesh wall, by their index in the wall contact dumps.
WALL_MESHES = ("base", "shear_ring", "mould", "lid")
WALL_CONTACT_PREFIX = "wall_contacts"

#: Columns of the contact dumps (``compute pair/gran/local`` and ``wall/gran/local`` with ``pos id
#: force_normal force_tangential``). Pair contacts: both sphere centres, both atom ids and a periodic
#: flag. Wall contacts: the contact point on the wall, the sphere centre, the mesh index in the wall
#: (0 base, 1 shear ring, 2 mould, 3 lid), the triangle index and the atom id. Forces (N) act on the
#: first sphere; normal and tangential parts along the line of centres. Caution (LIGGGHTS-PUBLIC 3.8):
#: the tangential parts are not the applied forces: summed over the plate contacts they exceed the
#: plate's measured horizontal force by about 20 %, and weak contacts show |F_t| / |F_n| far above the
#: sliding friction; normal parts add up to the measured loads. The computes do not change the dynamics.
CONTACT_COLUMNS = (
    "x1", "y1", "z1", "x2", "y2", "z2", "id1", "id2", "id3",
    "fn_x", "fn_y", "fn_z", "ft_x", "ft_y", "ft_z",
)  # fmt: skip


def _contact_context(contacts: ContactSet, n_types: int, geometry: RollingGeometry) -> dict:
    return {
        "n_types": n_types,
        "restitution": flat_matrix(contacts.restitution),
        "sliding_friction": flat_matrix(contacts.sliding_friction),
        # the study's coefficients, as LIGGGHTS' CDT gives their torque (siloflow.engines.liggghts.rolling)
        "rolling_friction": flat_matrix(cdt_matrix(contacts.rolling_friction, geometry)),
    }


def jenike_deck_context(case: JenikeCase) -> dict:
    """The rendering context of ``siloflow/templates/liggghts/jenike.lmp.j2``.

    Contact matrices start at the fill values (``materials``) and are replaced by the test values
    (``test_materials``) once the lid is in place.
    """
    context = common_context(case)
    n_types = len(case.materials.names)
    context["materials"].update(_contact_context(case.fill_contacts, n_types, case.particle.rolling))
    geometry = case.geometry
    base_type = PLATE_TYPE if geometry.wall_test else RING_TYPE
    meshes = {
        "base": {"file": "deck/meshes/base.stl", "type": base_type},
        "shear_ring": {"file": "deck/meshes/shear_ring.stl", "type": RING_TYPE},
        "mould": {"file": "deck/meshes/mould.stl", "type": RING_TYPE},
    }
    if case.lid_kind == "rigid":
        lid_spec = case.rigid_lid
        lid = {
            "kind": "rigid",
            "type": LID_TYPE,
            "positions": [[float(x), float(y)] for x, y in lid_spec.positions],
            "sphere_diameter": 2.0 * lid_spec.sphere_radius,
            "density": lid_spec.density,
            "n_spheres": lid_spec.n_spheres,
            "normal_force": lid_spec.normal_force,
            "sphere_weight": lid_spec.sphere_weight,
            "share": 1.0 / lid_spec.n_spheres,
            "height_above_sample": lid_spec.height_above_sample,
        }
    else:
        servo = case.servo_lid
        meshes["lid"] = {"file": "deck/meshes/lid.stl", "type": LID_TYPE}
        lid = {
            "kind": "servo",
            "type": LID_TYPE,
            "normal_force": servo.normal_force,
            "proxy_positions": [[float(x), float(y)] for x, y in servo.proxy_positions],
            "proxy_diameter": 2.0 * servo.proxy_radius,
            "proxy_density": servo.proxy_density,
            "proxy_weight": servo.weight / len(servo.proxy_positions),
            "proxy_share": 1.0 / len(servo.proxy_positions),
            "proxy_height": servo.proxy_height,
            "height_above_sample": servo.height_above_sample,
        }
    x0, x1, y0, y1, z0, z1 = case.domain
    context.update(
        {
            "title": f"siloflow-jenike-{case.run_id}",
            "boundary": ["f", "f", "f"],
            "domain": {"x": [x0, x1], "y": [y0, y1], "z": [z0, z1]},
            "test_materials": _contact_context(case.test_contacts, n_types, case.particle.rolling),
            "shear_plane": geometry.shear_plane,
            "ring_centre": list(geometry.ring_centre),
            "clump_sphere_mass": case.clump_sphere_mass,
            "meshes": meshes,
            "fill": {
                "seed": case.seeds[2],
                "n_clumps": case.fill.n_clumps,
                "region_centres": list(case.fill.region_centres),
                "region_radius": case.fill.region_radius,
                "region_z": list(case.fill.region_z),
                "steps": case.fill.steps,
                "level_z": case.fill.level_z,
                "relax_steps": case.fill.relax_steps,
            },
            "lid": lid,
            "rotation_blocked": case.rotation_blocked,
            "consolidation": {"ramp_steps": case.ramp_steps, "hold_steps": case.hold_steps},
            "shear": {"velocity": case.shear_velocity, "steps": case.shear_steps},
            "output_every": case.output_every,
            "force_sample_every": case.force_sample_every,
            "force_samples": case.output_every // case.force_sample_every,
            "forces_path": FORCES_NAME,
            "dump": {"id": "particle_dump", "every": case.dump_every, "path": f"dumps/{DUMP_PREFIX}_*.vtk"},
            "contact_dumps": {
                "pair_path": f"dumps/{PAIR_CONTACT_PREFIX}_*.txt",
                "wall_path": f"dumps/{WALL_CONTACT_PREFIX}_*.txt",
                # compute wall/gran/local blocks unfixing the wall, which the servo lid needs to join it
                "wall": case.lid_kind == "rigid",
                "columns": len(CONTACT_COLUMNS),
            },
            "thermo_every": case.output_every * 10,
            "settled_fill": {**settled_fill_context(SETTLED_CONTACT_PREFIX, len(CONTACT_COLUMNS), case.timestep),
                             "walls": list(SETTLED_WALLS)},
        }
    )
    assert context["particle"]["type"] == PARTICLE_TYPE
    context["processors"] = processor_grid(context["domain"])
    return context


def render_jenike_deck(case: JenikeCase) -> str:
    """The LIGGGHTS deck of a Jenike shear run."""
    return render_deck("liggghts/jenike.lmp.j2", jenike_deck_context(case))


def write_jenike_inputs(case: JenikeCase, deck_dir: str | Path) -> Path:
    """Write deck, meshes and ``case.json`` into ``deck_dir``; returns the deck path."""
    deck_dir = Path(deck_dir)
    for name, mesh in case.geometry.meshes(case.lid_kind).items():
        write_stl(mesh, deck_dir / "meshes" / f"{name}.stl")
    write_text_atomic(deck_dir / "case.json", json.dumps(case.summary(), indent=2, sort_keys=True, default=float))
    deck_path = deck_dir / DECK_NAME
    write_text_atomic(deck_path, render_jenike_deck(case))
    return deck_path


# ---------------------------------------------------------------------------------------------- reading


def read_contact_dump(path: str | Path) -> dict[str, np.ndarray]:
    """Read one contact dump (``dump local``) into named columns (:data:`CONTACT_COLUMNS`) plus ``step``.

    Raises
    ------
    ValueError
        Naming the file, if the header is incomplete, the entry count disagrees with the rows, or a row
        has the wrong number of columns.
    """
    path = Path(path)
    step, table = parse_local_table(
        path.read_text(encoding="utf-8", errors="replace"), len(CONTACT_COLUMNS), str(path)
    )
    count = table.shape[0]
    contacts = {name: table[:, i] for i, name in enumerate(CONTACT_COLUMNS)}
    contacts["step"] = np.full(count, step)
    return contacts


def _columns(table: dict, *names: str) -> np.ndarray:
    return np.column_stack([table[name] for name in names]) if names else np.empty((0, 3))


def _step(table: dict) -> int:
    return int(table["step"][0]) if table["step"].size else 0


def read_jenike_pair_contacts(path: str | Path) -> ContactFrame:
    """One pair-contact dump (:data:`CONTACT_COLUMNS`) as a frame."""
    return _pair_frame(read_contact_dump(path))


def read_jenike_wall_contacts(path: str | Path) -> WallContactFrame:
    """One wall-contact dump (:data:`CONTACT_COLUMNS`, the mesh named by :data:`WALL_MESHES`) as a frame."""
    return _wall_frame(read_contact_dump(path))


def _pair_frame(table: dict) -> ContactFrame:
    """A Jenike pair-contact dump (both centres, both ids, normal and tangential force on the first) as a frame."""
    return ContactFrame(
        step=_step(table),
        position_i=_columns(table, "x1", "y1", "z1"),
        position_j=_columns(table, "x2", "y2", "z2"),
        id_i=table["id1"].astype(np.int64),
        id_j=table["id2"].astype(np.int64),
        force=_columns(table, "fn_x", "fn_y", "fn_z") + _columns(table, "ft_x", "ft_y", "ft_z"),
    )


def _wall_frame(table: dict) -> WallContactFrame:
    """A Jenike wall-contact dump (contact point, centre, mesh index, triangle, atom id, forces) as a frame."""
    mesh = table["id1"].astype(int)
    if mesh.size and (mesh.min() < 0 or mesh.max() >= len(WALL_MESHES)):
        raise ValueError(f"wall contact dump at step {_step(table)}: mesh index outside 0..{len(WALL_MESHES) - 1}")
    return WallContactFrame(
        step=_step(table),
        point=_columns(table, "x1", "y1", "z1"),
        centre=_columns(table, "x2", "y2", "z2"),
        wall=np.array(WALL_MESHES, dtype=object)[mesh] if mesh.size else np.empty(0, dtype=object),
        particle_id=table["id3"].astype(np.int64),
        normal_force=_columns(table, "fn_x", "fn_y", "fn_z"),
        tangential_force=_columns(table, "ft_x", "ft_y", "ft_z"),
    )


# ---------------------------------------------------------------------------------------------- running


def set_aside_previous_jenike_attempt(run_dir: str | Path) -> Path | None:
    """Move an earlier attempt's dumps, log, screen output and force history to ``failed_attempts/<UTC time>/``.

    Returns the new location, if anything was moved; nothing is deleted.
    """
    return set_aside_previous_attempt(Path(run_dir), RUN_OUTPUTS + (FORCES_NAME,))


def run_jenike(
    case: JenikeCase, run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1, mpirun: str = "mpirun"
) -> RunRecord:
    """Run a rendered Jenike deck, check it and write ``run.json``; returns the record.

    Output of an earlier unfinished attempt (dumps, log, screen output, force history) is moved to
    ``failed_attempts/`` first.
    """
    run_dir = Path(run_dir)
    deck = run_dir / "deck" / DECK_NAME
    if not deck.exists():
        raise FileNotFoundError(f"no deck at {deck}; render it first")
    (run_dir / RUN_RECORD).unlink(missing_ok=True)
    set_aside_previous_jenike_attempt(run_dir)
    log_text = run_engine(run_dir, executable, mpi_ranks, mpirun)
    checked = check_jenike_run(case, parse_markers(log_text), run_dir, run_dir / FORCES_NAME)
    record = jenike_run_record(ENGINE_NAME, case, checked, len(list_dumps(run_dir / "dumps", DUMP_PREFIX)),
                               mpi_ranks, output_bytes(run_dir))
    write_run_record(run_dir, record)
    return record
