"""The Jenike cell's contacts: its engine atom types, and the contact matrices of a sweep point while the sample is
poured and while it is tested (:func:`contact_sets`), with the materials they act between (:func:`material_table`).
Pure: a validated configuration and a point in, matrices out. The case that uses them is
:mod:`siloflow.model.cases.jenike`.
"""

from __future__ import annotations

from dataclasses import dataclass

from siloflow.model.cases.common import NEUTRAL_CONTACT, MaterialTable

__all__ = ["PARTICLE_TYPE", "RING_TYPE", "LID_TYPE", "PLATE_TYPE", "PARTICLE_FRICTION_KEY", "ContactSet",
           "contact_sets", "material_table"]

#: Engine atom types by role. The plate type exists only in wall tests; the rings share one material.
PARTICLE_TYPE, RING_TYPE, LID_TYPE, PLATE_TYPE = 1, 2, 3, 4
#: A wall test's particle-particle sliding friction, where a point sets it (a joint calibration varies it with the
#: wall friction); without it, ``jenike.sweep.wall_test_particle_friction``.
PARTICLE_FRICTION_KEY = "particle_sliding_friction"


@dataclass(frozen=True)
class ContactSet:
    """Per-pair contact matrices (row-major over the atom types) of one stage (-)."""

    sliding_friction: tuple[tuple[float, ...], ...]
    rolling_friction: tuple[tuple[float, ...], ...]
    restitution: tuple[tuple[float, ...], ...]


def _contact(config: dict, a: str, b: str) -> dict:
    for contact in config["contacts"]:
        if sorted(contact["materials"]) == sorted((a, b)):
            return contact
    raise ValueError(f"config key 'contacts': no contact parameters for the pair [{a}, {b}] used by jenike")


def _matrix(n_types: int, particle_row: dict[int, float], neutral: float) -> tuple[tuple[float, ...], ...]:
    """Symmetric matrix: particle (type 1) pairs from ``particle_row`` (type -> value), others neutral."""
    rows = [[neutral] * n_types for _ in range(n_types)]
    for other, value in particle_row.items():
        rows[PARTICLE_TYPE - 1][other - 1] = value
        rows[other - 1][PARTICLE_TYPE - 1] = value
    return tuple(tuple(float(v) for v in row) for row in rows)


def contact_sets(config: dict, point: dict, n_types: int) -> tuple[ContactSet, ContactSet]:
    """Contact matrices while filling and while testing.

    Testing: internal test, particle-particle sliding = point value; wall test, particle-plate sliding =
    point value and particle-particle sliding = the point's :data:`PARTICLE_FRICTION_KEY` or else
    ``jenike.sweep.wall_test_particle_friction``;
    particle-ring and particle-lid sliding from ``contacts``; rolling friction = point value for every
    particle contact (particles, rings, plate, lid); restitution = point value for every particle contact.
    Filling: every particle sliding friction = ``jenike.fill.sliding_friction`` (null: the test's particle-particle
    sliding friction; a rotation-blocked point's ``jenike.fill.rotation_blocked_sliding_friction`` where set),
    rolling = ``jenike.fill.rolling_friction``, restitution = ``jenike.fill.restitution`` (null: the test's). Pairs
    without a particle are neutral.
    """
    jenike = config["jenike"]
    particle = jenike["particle_material"]
    ring = _contact(config, particle, jenike["ring_material"])
    lid = _contact(config, particle, jenike["lid_material"])
    types = list(range(1, n_types + 1))
    wall_test = point["test"] != "internal"
    particle_particle = (point.get(PARTICLE_FRICTION_KEY, jenike["sweep"]["wall_test_particle_friction"]) if wall_test
                         else point["sliding_friction"])
    sliding = {PARTICLE_TYPE: particle_particle, RING_TYPE: ring["sliding_friction"], LID_TYPE: lid["sliding_friction"]}
    if wall_test:
        sliding[PLATE_TYPE] = point["sliding_friction"]
    rolling = {t: point["rolling_friction"] for t in types}
    restitution = {t: point["restitution"] for t in types}
    pour_friction = particle_particle if jenike["fill"]["sliding_friction"] is None else jenike["fill"]["sliding_friction"]
    if point["rotation_blocked"] and jenike["fill"]["rotation_blocked_sliding_friction"] is not None:
        pour_friction = jenike["fill"]["rotation_blocked_sliding_friction"]
    pour_restitution = jenike["fill"]["restitution"]
    test = ContactSet(
        sliding_friction=_matrix(n_types, sliding, NEUTRAL_CONTACT["sliding_friction"]),
        rolling_friction=_matrix(n_types, rolling, NEUTRAL_CONTACT["rolling_friction"]),
        restitution=_matrix(n_types, restitution, NEUTRAL_CONTACT["restitution"]),
    )
    fill = ContactSet(
        sliding_friction=_matrix(n_types, {t: pour_friction for t in types}, 0.0),
        rolling_friction=_matrix(n_types, {t: jenike["fill"]["rolling_friction"] for t in types}, 0.0),
        restitution=test.restitution if pour_restitution is None else _matrix(
            n_types, {t: pour_restitution for t in types}, NEUTRAL_CONTACT["restitution"]),
    )
    return fill, test


def material_table(config: dict, point: dict, test: ContactSet) -> MaterialTable:
    """The materials of a point's cell (particle, rings, lid and a wall test's plate, in atom-type order) with the
    test's contact matrices; a material the configuration does not define, or a particle material without a
    density, is refused naming its key."""
    jenike = config["jenike"]
    names = [jenike["particle_material"], jenike["ring_material"], jenike["lid_material"]]
    if point["test"] != "internal":
        names.append(point["test"])
    materials = config["materials"]
    for name in names:
        if name not in materials:
            raise ValueError(f"jenike: material '{name}' is not defined under materials")
    if "density" not in materials[names[0]]:
        raise ValueError(f"config key 'materials.{names[0]}.density': the particle material needs a density")
    return MaterialTable(
        names=tuple(names),
        youngs_modulus=tuple(float(materials[n]["youngs_modulus"]) for n in names),
        poisson_ratio=tuple(float(materials[n]["poisson_ratio"]) for n in names),
        sliding_friction=test.sliding_friction,
        rolling_friction=test.rolling_friction,
        restitution=test.restitution,
    )
