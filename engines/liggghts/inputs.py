"""What every LIGGGHTS deck of siloflow shares: the common rendering context (materials, particle template, time
step) and the writing of a run's inputs (wall meshes, ``case.json``, the deck) into its ``deck/`` folder."""

from __future__ import annotations

import json
from pathlib import Path

from analysis.data.constants import GRAVITY
from engines.cases.geometry import write_stl
from engines.layout import write_text_atomic

#: The engine's registry name (engine.kind), written into every run record.
ENGINE_NAME = "liggghts"
DECK_NAME = "in.liggghts"

# LIGGGHTS only accepts 5e6 <= E <= 1e9 Pa (SI) unless told otherwise.
SOFT_LIMIT = 5e6
HARD_LIMIT = 1e9


def flat_matrix(matrix) -> list[float]:
    return [float(value) for row in matrix for value in row]


def common_context(case) -> dict:
    table = case.materials
    moduli = table.youngs_modulus
    particle = case.particle
    spheres = [[*map(float, position), float(radius)] for position, radius in zip(particle.sphere_positions, particle.sphere_radii)]
    return {
        "materials": {
            "n_types": len(table.names),
            "youngs_modulus": list(moduli),
            "poisson_ratio": list(table.poisson_ratio),
            "restitution": flat_matrix(table.restitution),
            "sliding_friction": flat_matrix(table.sliding_friction),
            "rolling_friction": flat_matrix(table.rolling_friction),
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
