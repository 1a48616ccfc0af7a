"""LIGGGHTS decks of the verification problems (``siloflow/templates/liggghts/verification.lmp.j2``): free spheres of one
material, the floor as a primitive wall of a second material of the same properties, every sphere's state dumped."""

from __future__ import annotations

import math
from dataclasses import asdict
from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.verification import VerificationCase
from siloflow.engines.liggghts.inputs import ENGINE_NAME, flat_matrix, processor_grid, write_case_inputs
from siloflow.engines.liggghts.rolling import cdt_matrix
from siloflow.engines.liggghts.run import DUMP_PREFIX, run_checked
from siloflow.engines.templating import render_deck
from siloflow.engines.verification_checks import check_verification_run, verification_record

#: What the verification decks dump per sphere: the state the closed forms need, spin included.
VERIFICATION_DUMP_FIELDS = ("id", "type", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz", "radius",
                            "mass")


def verification_deck_context(case: VerificationCase) -> dict:
    """The rendering context of ``siloflow/templates/liggghts/verification.lmp.j2``."""
    pair = lambda value: [float(value)] * 4  # noqa: E731  (particle-particle and particle-floor alike)
    domain = {"x": list(case.domain[0:2]), "y": list(case.domain[2:4]), "z": list(case.domain[4:6])}
    return {
        "title": f"siloflow-verification-{case.run_id}",
        "boundary": ["f", "f", "f"],
        "domain": domain,
        "processors": processor_grid(domain),
        "switches": {"soft_particles": case.youngs_modulus < 5e6, "hard_particles": case.youngs_modulus > 1e9},
        "neighbor_skin": 0.4 * case.radius,
        "materials": {"n_types": 2, "youngs_modulus": [case.youngs_modulus] * 2, "poisson_ratio": [case.poisson_ratio] * 2,
                      "restitution": pair(case.restitution), "sliding_friction": pair(case.sliding_friction),
                      # the study's coefficient, as LIGGGHTS' CDT gives its torque (siloflow.engines.liggghts.rolling)
                      "rolling_friction": flat_matrix(cdt_matrix([[case.rolling_friction] * 2] * 2, case.rolling))},
        "timestep": case.timestep,
        "gravity": _magnitude(case.gravity),
        "gravity_direction": [g / _magnitude(case.gravity) for g in case.gravity] if any(case.gravity) else [0.0, 0.0, -1.0],
        "spheres": [asdict(sphere) for sphere in case.spheres],
        "diameter": 2.0 * case.radius,
        "density": case.density,
        "floor": case.floor,
        "clump": _clump_context(case),
        "steps": case.steps,
        "dump": {"id": "particle_dump", "every": case.output_every, "path": f"dumps/{DUMP_PREFIX}_*.vtk",
                 "fields": list(VERIFICATION_DUMP_FIELDS)},
    }


def _magnitude(vector) -> float:
    return math.sqrt(sum(v * v for v in vector))


def _clump_context(case: VerificationCase) -> dict | None:
    """The clump of a clump problem: its multisphere template (Monte Carlo inertia from 1e6 samples, as the silo
    decks), a spot around its start position, and its spin; None for free spheres."""
    if not case.clump_spheres:
        return None
    centre, spin = case.spheres[0].position, case.spheres[0].angular_velocity
    # LIGGGHTS places the clump at random in it (a smaller region has "no volume"): across 4 r, and from the start
    # height up by a fiftieth of a radius, so that a clump on the floor starts just above it
    half = 2.0 * case.radius
    return {
        # LIGGGHTS wants the seeds of the template, the distribution and the insertion all different
        "insertion_seed": 49979687,
        "particle": {"name": "clump", "seed": 15485863, "distribution_seed": 32452843, "type": 1,
                     "density": case.density, "ntry": 1000000,
                     "spheres": [[*map(float, c), float(case.radius)] for c in case.clump_spheres]},
        "spot": [centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half, centre[2],
                 centre[2] + 0.02 * case.radius],
        "omega": list(spin),
    }


def write_verification_inputs(case: VerificationCase, deck_dir: str | Path) -> Path:
    """Write the deck and ``case.json`` into ``deck_dir``; returns the deck path."""
    deck = render_deck("liggghts/verification.lmp.j2", verification_deck_context(case))
    return write_case_inputs({}, case.summary(), deck, deck_dir)


def run_verification(case: VerificationCase, run_dir: str | Path, executable: str = "liggghts", mpi_ranks: int = 1,
                     mpirun: str = "mpirun") -> RunRecord:
    """Run a rendered verification deck (serially: one or two spheres), check it and write ``run.json``."""
    return run_checked(
        run_dir,
        lambda markers, dumps: check_verification_run(case, markers, dumps, Path(run_dir)),
        {"executable": executable, "mpi_ranks": 1, "mpirun": mpirun},
        lambda checked: verification_record(ENGINE_NAME, case, checked),
    )
