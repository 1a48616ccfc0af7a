"""What every LIGGGHTS deck of siloflow shares: the common rendering context (materials, particle template, time
step) and the writing of a run's inputs (wall meshes, ``case.json``, the deck) into its ``deck/`` folder."""

from __future__ import annotations

import json
from pathlib import Path

from siloflow.model.constants import GRAVITY
from siloflow.model.cases.geometry import write_stl
from siloflow.engines.layout import write_text_atomic
from siloflow.engines.liggghts.rolling import cdt_matrix

#: The engine's registry name (engine.kind), written into every run record.
ENGINE_NAME = "liggghts"
DECK_NAME = "in.liggghts"

# LIGGGHTS only accepts 5e6 <= E <= 1e9 Pa (SI) unless told otherwise.
SOFT_LIMIT = 5e6
HARD_LIMIT = 1e9


#: A horizontal axis at least this fraction of the widest horizontal extent of the domain is split among MPI ranks.
SPLIT_EXTENT_FRACTION = 0.5


def processor_grid(domain: dict) -> list[int]:
    """The MPI processor grid of a deck from its domain: ranks along the wide horizontal axes only (0: LIGGGHTS
    chooses the count along that axis, 1: not split).

    Every case of siloflow fills from the bottom up and empties from the top down, so slabs stacked along gravity
    (z) would leave the upper ranks idle through most of the fill and the discharge; slabs side by side across the
    width stay equally loaded at every fill level (a planar silo or blender is symmetric about its axis). A thin
    axis (a planar silo's depth) is not split either: its slabs would be mostly ghost atoms. LIGGGHTS' own choice
    (``processors * * *``) splits the longest axis, which for a silo is z.

    Parameters
    ----------
    domain : dict
        The deck's simulation box, ``{"x": [lo, hi], "y": [lo, hi], "z": [lo, hi]}`` (m).

    Returns
    -------
    list of int
        ``[px, py, pz]`` for the ``processors`` command, 0 for ``*``.
    """
    extents = [domain[axis][1] - domain[axis][0] for axis in ("x", "y")]
    if not all(extent > 0 for extent in extents):
        raise ValueError(f"the domain must have a positive extent along x and y, got {domain!r}")
    widest = max(extents)
    return [0 if extent >= SPLIT_EXTENT_FRACTION * widest else 1 for extent in extents] + [1]


#: A one-sphere particle model's second sphere, concentric, this fraction of its radius (-): LIGGGHTS 3.8's
#: ``particletemplate/multisphere`` refuses fewer than two spheres, and every siloflow deck integrates clumps.
#: Lying 0.99 r inside the surface, the inner sphere touches no neighbour and no wall unless an overlap reached
#: 0.99 r, and it adds nothing to the clump's volume (the template's Monte Carlo mass and inertia are the sphere's).
INNER_SPHERE_FRACTION = 0.01


def template_spheres(positions, radii) -> list[list[float]]:
    """The spheres of a clump template as the deck writes them, ``[[x, y, z, r], ...]`` (m): the model's, and for a
    one-sphere model a concentric inner sphere (:data:`INNER_SPHERE_FRACTION`)."""
    spheres = [[*map(float, position), float(radius)] for position, radius in zip(positions, radii)]
    if len(spheres) == 1:
        x, y, z, radius = spheres[0]
        spheres.append([x, y, z, INNER_SPHERE_FRACTION * radius])
    return spheres


def flat_matrix(matrix) -> list[float]:
    return [float(value) for row in matrix for value in row]


def contact_coefficients(table, particle) -> dict:
    """The per-type-pair contact coefficients of ``table`` as the deck's ``contact_coefficients`` macro takes them:
    restitution, sliding friction, and the rolling friction as LIGGGHTS' CDT gives the study's torque for
    ``particle`` (:mod:`siloflow.engines.liggghts.rolling`)."""
    return {
        "n_types": len(table.names),
        "restitution": flat_matrix(table.restitution),
        "sliding_friction": flat_matrix(table.sliding_friction),
        "rolling_friction": flat_matrix(cdt_matrix(table.rolling_friction, particle.rolling)),
    }


def common_context(case) -> dict:
    table = case.materials
    moduli = table.youngs_modulus
    particle = case.particle
    spheres = template_spheres(particle.sphere_positions, particle.sphere_radii)
    return {
        "materials": {
            "youngs_modulus": list(moduli),
            "poisson_ratio": list(table.poisson_ratio),
            **contact_coefficients(table, particle),
        },
        "switches": {
            "soft_particles": min(moduli) < SOFT_LIMIT,
            "hard_particles": max(moduli) > HARD_LIMIT,
        },
        "timestep": case.timestep,
        "gravity": GRAVITY,
        "neighbor_skin": 0.4 * particle.smallest_radius,
        "particle": {
            "name": particle.name,
            "seed": case.seeds[0],
            "distribution_seed": case.seeds[1],
            "type": 1,
            "density": particle.density,
            "spheres": spheres,
            "ntry": 1000000,
        },
    }


def write_case_inputs(meshes: dict, summary: dict, deck_text: str, deck_dir: str | Path) -> Path:
    """Write wall meshes, ``case.json`` and the deck into ``deck_dir`` (each atomically); returns the deck path."""
    deck_dir = Path(deck_dir)
    for name, mesh in meshes.items():
        write_stl(mesh, deck_dir / "meshes" / f"{name}.stl")
    write_text_atomic(deck_dir / "case.json", json.dumps(summary, indent=2, sort_keys=True, default=float))
    deck_path = deck_dir / DECK_NAME
    write_text_atomic(deck_path, deck_text)
    return deck_path
