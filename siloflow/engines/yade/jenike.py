"""YADE scripts of the Jenike direct shear cell: the rendering context of ``siloflow/templates/yade/jenike.py.j2``, the inputs
written into a run's ``deck/`` folder, the run checked as every engine's Jenike runs are
(:mod:`siloflow.engines.jenike_checks`), and its contact snapshots read back.

How the script carries out the case's stages (:mod:`siloflow.model.cases.jenike`): the rings, the mould and a wall test's
plate are facets from the case's meshes; the shear ring and the mould move by their prescribed velocity (YADE moves a
non-dynamic body by its velocity). The rigid lid is a clump of the case's lid spheres with x and y held (its x
velocity is the shear velocity during the shear), free to tilt, as the LIGGGHTS deck's ``fix rigid``. The servo lid is
a downward-facing infinite plane (``utils.wall``), dynamic in z only: the particles stay inside the rings and the mould,
so it touches what the LIGGGHTS deck's lid disc touches, and like that deck's proxy body it moves under the particles'
force minus F_N. Both lids get their weight back from a permanent force, so only F_N loads the sample. F_N is ramped
in steps of one force sample. The contact parameters switch from the fill's to the test's when the lid is placed, on
the contacts present as well (sliding friction, rolling cap and stiffness).

Run directory layout (the script sees relative paths)::

    <run>/deck/run.py                        the rendered script
    <run>/deck/case.json                     derived case quantities
    <run>/log.yade                           stage markers, progress, errors
    <run>/jenike_force_history.txt           the force history (format: siloflow.engines.jenike_checks)
    <run>/dumps/particles_<step>.npz         particle frames during consolidation and shear
    <run>/dumps/pair_contacts_<step>.npz     particle-particle contacts at the same steps
    <run>/dumps/wall_contacts_<step>.npz     particle-wall contacts (the rigid lid's spheres count as wall ``lid``)
    <run>/dumps/settled_fill_<step>.npz      the levelled sample at the end of its relaxation
    <run>/run.json                           written last, only after every check passed
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from siloflow.model.contacts import ContactFrame, WallContactFrame
from siloflow.model.record import RunRecord
from siloflow.model.cases.jenike import JenikeCase
from siloflow.model.cases.jenike_contacts import LID_TYPE, PLATE_TYPE, RING_TYPE
from siloflow.engines.jenike_checks import SETTLED_WALLS, check_jenike_run, jenike_run_record
from siloflow.engines.templating import render_deck
from siloflow.engines.yade.inputs import (
    ENGINE_NAME, GEOMETRY_PATH, common_context, exploded_speed, materials_context, rolling_friction, write_script_inputs,
)
from siloflow.engines.yade.outputs import DamagedOutput, read_archive
from siloflow.engines.yade.run import DUMP_PREFIX, SETTLED_FILL_PREFIX, YadeOptions, frame_files, run_script_checked

__all__ = ["FORCES_NAME", "check_jenike_case", "read_pair_contacts", "read_wall_contacts", "render_jenike_script", "run_jenike",
           "write_jenike_inputs"]

FORCES_NAME = "jenike_force_history.txt"
PAIR_CONTACTS_STEM = "pair_contacts"
WALL_CONTACTS_STEM = "wall_contacts"
#: The walls of the contact snapshots, by their index there.
WALL_NAMES = ("base", "shear_ring", "mould", "lid")
#: The rigid lid's sphere centres (x, y) [m] in the deck's geometry archive.
LID_POSITIONS = "lid_sphere_positions"
#: Steps of the settled fill's snapshot at the end of the relaxation.
SNAPSHOT_STEPS = 2


def check_jenike_case(case: JenikeCase) -> None:
    """Refuse a Jenike point whose test or fill contacts have different rolling frictions (YADE takes one eta).

    Raises
    ------
    CaseNotSupported
        Naming the config key.
    """
    rolling_friction(case.materials, f"jenike run {case.run_id}")
    fill = case.fill_contacts
    rolling_friction(dataclasses.replace(case.materials, rolling_friction=fill.rolling_friction),
                     f"the fill of jenike run {case.run_id}")


def _meshes(case: JenikeCase) -> dict:
    # the servo lid is a plane in the script, not the case's lid mesh
    return case.geometry.meshes("rigid")


def jenike_script_context(case: JenikeCase) -> dict:
    """The rendering context of ``siloflow/templates/yade/jenike.py.j2``."""
    context = common_context(case, case.materials)
    fill = case.fill_contacts
    fill_table = dataclasses.replace(case.materials, sliding_friction=fill.sliding_friction,
                                     rolling_friction=fill.rolling_friction, restitution=fill.restitution)
    fill_materials = materials_context(case, fill_table)
    geometry = case.geometry
    base_type = PLATE_TYPE if geometry.wall_test else RING_TYPE
    materials = {"base": base_type - 1, "shear_ring": RING_TYPE - 1, "mould": RING_TYPE - 1}
    if case.lid_kind == "rigid":
        lid = case.rigid_lid
        lid_context = {"sphere_radius": lid.sphere_radius, "mass": lid.mass}
    else:
        lid = case.servo_lid
        lid_context = {"sphere_radius": 0.0, "mass": lid.mass}
    lid_context.update(kind=case.lid_kind, material=LID_TYPE - 1, height_above_sample=lid.height_above_sample)
    x0, x1, y0, y1, z0, z1 = case.domain
    context.update({
        "title": f"siloflow-jenike-{case.run_id}",
        "exploded_speed": exploded_speed(z1 - z0),
        "fill_contacts": {"pairs": fill_materials["pairs"], "rolling_friction": fill_materials["rolling_friction"],
                          "rolling_stiffness": fill_materials["rolling_stiffness"]},
        "domain": list(case.domain),
        "shear_plane": geometry.shear_plane,
        "clump_sphere_mass": case.clump_sphere_mass,
        "rotation_blocked": int(case.rotation_blocked),
        "meshes": [{"id": name, "material": materials[name]} for name in _meshes(case)],
        "geometry_path": GEOMETRY_PATH,
        "lid_positions": LID_POSITIONS,
        "wall_names": list(WALL_NAMES),
        "fill": {"seed": case.seeds[2], "n_clumps": case.fill.n_clumps,
                 "region_centres": list(case.fill.region_centres), "region_radius": case.fill.region_radius,
                 "region_z": list(case.fill.region_z), "steps": case.fill.steps, "level_z": case.fill.level_z,
                 "relax_steps": max(case.fill.relax_steps, SNAPSHOT_STEPS + 1)},
        "lid": lid_context,
        "normal_force": case.normal_force,
        "consolidation": {"ramp_steps": case.ramp_steps, "hold_steps": case.hold_steps},
        "shear": {"velocity": case.shear_velocity, "steps": case.shear_steps},
        "output_every": case.output_every,
        "force_sample_every": case.force_sample_every,
        "dump_every": case.dump_every,
        "settled_fill": {"steps": SNAPSHOT_STEPS, "walls": list(SETTLED_WALLS)},
        "forces_path": FORCES_NAME,
        "paths": {"dumps": DUMP_PREFIX, "settled": SETTLED_FILL_PREFIX, "pair_contacts": PAIR_CONTACTS_STEM,
                  "wall_contacts": WALL_CONTACTS_STEM},
    })
    return context


def render_jenike_script(case: JenikeCase) -> str:
    """The YADE script of a Jenike shear run."""
    return render_deck("yade/jenike.py.j2", jenike_script_context(case))


def write_jenike_inputs(case: JenikeCase, deck_dir: str | Path) -> Path:
    """Write the script and ``case.json`` into ``deck_dir``; returns the script path."""
    lid = {} if case.rigid_lid is None else {LID_POSITIONS: np.asarray(case.rigid_lid.positions, dtype=float)}
    return write_script_inputs(case.summary(), render_jenike_script(case), deck_dir, _meshes(case), lid)


def run_jenike(case: JenikeCase, run_dir: str | Path, options: YadeOptions) -> RunRecord:
    """Run a rendered Jenike script, check it and write ``run.json``; returns the record."""
    run_dir = Path(run_dir)
    duration = (case.fill.steps + case.fill.relax_steps + case.ramp_steps + case.hold_steps
                + case.shear_steps) * case.timestep
    return run_script_checked(
        run_dir, options, duration,
        lambda markers, dumps: {**check_jenike_run(case, markers, run_dir, run_dir / FORCES_NAME),
                                "n_frames": len(dumps)},
        lambda checked: jenike_run_record(ENGINE_NAME, case, checked, checked["n_frames"], checked["mpi_ranks"],
                                          checked["output_bytes"]),
        extra_outputs=(FORCES_NAME,),
    )


# ---------------------------------------------------------------------------------------------- reading


def read_pair_contacts(path: str | Path) -> ContactFrame:
    """One pair-contact snapshot (``dumps/pair_contacts_<step>.npz``: both centres, both ids, the force on the first
    sphere) as a frame.

    Raises
    ------
    DamagedOutput
        Naming the file, when it is truncated or lacks a quantity.
    """
    path = Path(path)
    data = read_archive(path, ("step", "contacts"))
    table = data["contacts"].reshape(-1, 11)
    return ContactFrame(step=int(data["step"]), position_i=table[:, 0:3], position_j=table[:, 3:6],
                        id_i=table[:, 6].astype(np.int64), id_j=table[:, 7].astype(np.int64), force=table[:, 8:11])


def read_wall_contacts(path: str | Path) -> WallContactFrame:
    """One wall-contact snapshot (``dumps/wall_contacts_<step>.npz``: contact point, sphere centre, wall index, sphere
    id, the wall's normal and tangential force on the sphere) as a frame.

    Raises
    ------
    DamagedOutput
        Naming the file, when it is truncated, lacks a quantity or names a wall index it does not list.
    """
    path = Path(path)
    data = read_archive(path, ("step", "contacts", "walls"))
    table = data["contacts"].reshape(-1, 14)
    walls = np.asarray(data["walls"], dtype=object)
    index = table[:, 6].astype(int)
    if index.size and (index.min() < 0 or index.max() >= walls.size):
        raise DamagedOutput(f"{path}: a wall index outside 0..{walls.size - 1}")
    return WallContactFrame(step=int(data["step"]), point=table[:, 0:3], centre=table[:, 3:6], wall=walls[index],
                            particle_id=table[:, 7].astype(np.int64), normal_force=table[:, 8:11],
                            tangential_force=table[:, 11:14])


def jenike_contacts(run_dir: str | Path, kind: str) -> list:
    """The contact snapshots of a Jenike run, oldest first: ``pair`` or ``wall``."""
    if kind == "pair":
        return [read_pair_contacts(path) for path in frame_files(run_dir, PAIR_CONTACTS_STEM)]
    return [read_wall_contacts(path) for path in frame_files(run_dir, WALL_CONTACTS_STEM)]
