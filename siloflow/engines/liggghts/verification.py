"""LIGGGHTS decks of the verification problems (``siloflow/templates/liggghts/verification.lmp.j2``): free spheres of one
material, the floor as a primitive wall of a second material of the same properties, every sphere's state dumped."""

from __future__ import annotations

import math
from dataclasses import asdict
from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.verification import FIXED, FREE, HELD, VerificationCase
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
        "clumps": _clump_context(case),
        "steps": case.steps,
        "dump": {"id": "particle_dump", "every": case.output_every, "path": f"dumps/{DUMP_PREFIX}_*.vtk",
                 "fields": list(VERIFICATION_DUMP_FIELDS)},
    }


def _magnitude(vector) -> float:
    return math.sqrt(sum(v * v for v in vector))


#: LIGGGHTS wants the seeds of a template, its distribution and its insertion all different, and primes: per clump.
_CLUMP_SEEDS = ((15485863, 32452843, 49979687), (15485867, 32452867, 49979693))
#: Half the width of the region a held or fixed clump is inserted in [m]: where it is, to a thirty-thousandth of the
#: set overlap.
_EXACT_SPOT = 1e-10


def _clump_context(case: VerificationCase) -> list[dict]:
    """The clumps of a clump problem, one per entry of ``case.spheres``, each with its multisphere template, a spot
    around its start position and its velocity and spin; an empty list for free spheres.

    A free clump's template gets its mass and inertia by Monte Carlo (1e6 samples), as the silo decks', and a spot
    across 4 r and from its start height up by a fiftieth of a radius, where LIGGGHTS places it at random (a clump on
    the floor starts just above it). A held or fixed clump presses on its partner at a set overlap, which the
    Monte Carlo centre of mass (off by about a micrometre, a third of the overlap, the clump's spheres turning about
    it) and a random spot would not keep: it gets the exact mass and inertia (its spheres' centres are given about
    their centre of mass) and a spot 2e-10 m wide, below the region's default ``volume_limit`` (1e-10 m3), which
    is lowered for it. A held clump's template has its translation off (``fflag``), a fixed one's its rotation too
    (``tflag``): the body itself is held, where a ``setforce`` would act on its spheres and need a ``group``, which
    ``fix multisphere`` refuses.
    """
    if not case.clump_spheres:
        return []
    if len(case.spheres) > len(_CLUMP_SEEDS):
        raise ValueError(f"{case.name}: at most {len(_CLUMP_SEEDS)} clumps, got {len(case.spheres)}")
    spheres = [[*map(float, c), float(case.radius)] for c in case.clump_spheres]
    clumps = []
    for index, (sphere, seeds) in enumerate(zip(case.spheres, _CLUMP_SEEDS), start=1):
        centre = sphere.position
        exact = sphere.motion in (HELD, FIXED)
        half = _EXACT_SPOT if exact else 2.0 * case.radius
        spot = ([c + sign * half for c in centre for sign in (-1.0, 1.0)] if exact else
                [centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half, centre[2],
                 centre[2] + 0.02 * case.radius])
        clumps.append({
            "index": index,
            "insertion_seed": seeds[2],
            "particle": {"seed": seeds[0], "distribution_seed": seeds[1], "type": 1, "density": case.density,
                         "ntry": 1000000, "spheres": spheres,
                         # inertia_tensor: xx xy xz yy yz zz
                         "exact": ({"mass": case.clump_mass,
                                    "inertia": [case.clump_inertia[0], 0.0, 0.0, case.clump_inertia[1], 0.0,
                                                case.clump_inertia[2]]} if exact else None),
                         "translation": sphere.motion == FREE, "rotation": sphere.motion != FIXED},
            "spot": spot,
            "volume_limit": (2.0 * half) ** 3 / 10.0 if exact else None,
            # a held or fixed clump overlaps its partner by design
            "overlapcheck": not exact,
            "velocity": list(sphere.velocity),
            "omega": list(sphere.angular_velocity),
        })
    return clumps


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
