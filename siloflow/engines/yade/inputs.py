"""What every YADE script of siloflow shares: the rendering context of materials, contact law, clump and time step,
and the writing of a run's inputs (``case.json``, the script) into its ``deck/`` folder.

The contact law is Hertz-Mindlin (``Ip2_FrictMat_FrictMat_MindlinPhys`` with ``en`` = the configured restitution,
per material pair, and the pair's sliding friction) with Mindlin's rolling moment (``includeMoment``). It has no
tangential dashpot (``es = 1``), unlike the LIGGGHTS decks: YADE sizes the dashpot with the masses of the two contacting
spheres, while the mass a tangential force moves at the contact point of a clump is smaller (the clump turns), and at
the study's restitution 0.1 the dashpot went unstable under the Jenike lid's load (a consolidated sample exploded;
without it, or at e = 0.5, it did not). A sliding contact has no tangential dashpot in either engine.

Rolling: Mindlin's moment is an elastic-plastic spring of stiffness ``krot`` capped at ``eta (refR1 + refR2) / 2
|Fn|``, along the contact's relative rolling. For two clump spheres the reference radii are the spheres' radii, so
the cap is ``eta r |Fn|``; the study's torque is ``mu_r R |Fn|`` at the distance R from the contact point to the
clump's centre of mass (:mod:`siloflow.model.rolling`). ``eta`` is therefore the study's coefficient times the clump's
mean lever arm over its contact sphere's radius (1.115 for the two-sphere clump, 1 for a sphere). On a facet (a mesh
wall) YADE's reference radius of the facet is twice the sphere's, so the cap there is 1.5 times the pair's; on a
``utils.wall`` plane it is the pair's. YADE 2023.02 has no constant directional torque (CDT): its moment reaches the
cap once the contact has rolled ``cap / krot`` and pushes back elastically before, where the study's (EDEM's CDT)
sits at the cap as soon as the particle spins. ``krot`` is a constant in YADE: it is set to the EPSD rule
``2.25 kn eta^2 r^2`` with ``kn`` the Hertz stiffness of a particle-particle contact carrying one clump's weight.
``eta`` is one number for all contacts in YADE, so a case whose contacts with a particle have different rolling
frictions is refused (:func:`rolling_friction`).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from siloflow.model.constants import GRAVITY
from siloflow.model.cases.particles import clump_inertia
from siloflow.engines.interface import CaseNotSupported
from siloflow.engines.layout import write_text_atomic

#: The engine's registry name (engine.kind), written into every run record.
ENGINE_NAME = "yade"
DECK_NAME = "run.py"
#: The case's meshes and long arrays, as the script sees them (it runs in the run directory).
GEOMETRY_PATH = "deck/geometry.npz"


def rolling_friction(table, where: str) -> float:
    """The one rolling friction of every contact with a particle in it (YADE's ``eta`` is global).

    Raises
    ------
    CaseNotSupported
        Naming the config key ``contacts`` and the differing pairs.
    """
    values = {(table.names[0], table.names[j]): float(v) for j, v in enumerate(table.rolling_friction[0])}
    distinct = sorted(set(values.values()))
    if len(distinct) > 1:
        raise CaseNotSupported(
            f"config key 'contacts': rolling_friction differs between the pairs with a particle "
            f"({', '.join(f'[{a}, {b}]: {v:g}' for (a, b), v in values.items())}) in {where}; YADE's Mindlin rolling "
            "moment takes one eta for all contacts: give every pair with the particle material the same "
            "rolling_friction, or run this case on LIGGGHTS"
        )
    return distinct[0]


def hertz_stiffness_at_load(radius: float, youngs_modulus: float, poisson_ratio: float, load: float) -> float:
    """Normal stiffness dF/d(delta) [N/m] of a Hertz contact of two equal spheres carrying ``load`` [N].

    With ``E* = E / (2 (1 - nu^2))`` and ``R* = R / 2``, ``F = 4/3 E* sqrt(R*) delta^(3/2)``, so
    ``kn = 2 E* sqrt(R* delta) = (6 E*^2 R* F)^(1/3)``."""
    e_star = youngs_modulus / (2.0 * (1.0 - poisson_ratio**2))
    return (6.0 * e_star**2 * 0.5 * radius * load) ** (1.0 / 3.0)


def principal_clump(particle) -> tuple[np.ndarray, np.ndarray]:
    """The clump's sphere centres in its principal frame [m] and its principal moments of inertia [kg m2] (exact
    union, :func:`siloflow.model.cases.particles.clump_inertia`)."""
    tensor = clump_inertia(particle.sphere_positions, particle.sphere_radii, particle.density)
    moments, axes = np.linalg.eigh(tensor)
    return particle.sphere_positions @ axes, moments


def materials_context(case, table, wall_density: float = 1000.0, gravity: float = GRAVITY) -> dict:
    """The materials of ``table``: each material's elastic constants and density, each pair's sliding friction and
    restitution, and the one rolling law (eta, krot) of its particle contacts: eta the study's coefficient times the
    clump's lever arm over its contact sphere's radius, the stiffness the EPSD rule at the Hertz stiffness under a
    clump's weight at ``gravity`` (m/s^2)."""
    particle = case.particle
    # the study's coefficient, as Mindlin's cap eta r |Fn| (r the contact sphere's radius) gives its torque
    # mu_r R |Fn| at the clump's mean lever arm R (siloflow.model.rolling)
    rolling = rolling_friction(table, f"run {case.run_id}") * particle.rolling.ratio
    radius = float(particle.sphere_radii.min())
    kn = hertz_stiffness_at_load(radius, table.youngs_modulus[0], table.poisson_ratio[0], particle.mass * gravity)
    n = len(table.names)
    return {
        "list": [{"youngs_modulus": float(table.youngs_modulus[i]), "poisson_ratio": float(table.poisson_ratio[i]),
                  "density": float(particle.density if i == 0 else wall_density)} for i in range(n)],
        "pairs": [{"i": i, "j": j, "sliding_friction": float(table.sliding_friction[i][j]),
                   "restitution": float(table.restitution[i][j])} for i in range(n) for j in range(i, n)],
        "rolling_friction": rolling,
        "rolling_stiffness": 2.25 * kn * rolling**2 * radius**2,
    }


def common_context(case, table, wall_density: float = 1000.0, gravity: float = GRAVITY) -> dict:
    """The context of ``siloflow/templates/yade/base.py.j2``: materials, pair contacts, rolling law, clump, time step and
    gravity (m/s^2)."""
    particle = case.particle
    centres, moments = principal_clump(particle)
    return {
        "materials": materials_context(case, table, wall_density, gravity),
        "particle": {
            "spheres": [[*map(float, c), float(r)] for c, r in zip(centres, particle.sphere_radii)],
            "mass": float(particle.mass),
            "inertia": [float(m) for m in moments],
        },
        "timestep": case.timestep,
        "gravity": gravity,
    }


def exploded_speed(height: float, insertion_velocity: float = 0.0) -> float:
    """A clump speed no physical run of a case of ``height`` [m] reaches [m/s]: ten times free fall through it."""
    return 10.0 * (math.sqrt(2.0 * GRAVITY * height) + insertion_velocity)


def write_script_inputs(summary: dict, script_text: str, deck_dir: str | Path, meshes: dict | None = None,
                        arrays: dict | None = None) -> Path:
    """Write ``case.json``, the script, and the case's ``meshes`` (name -> triangle mesh) and other ``arrays`` (name ->
    array) into ``deck_dir`` (each atomically, the summary last); returns the script.

    Meshes and arrays go to ``geometry.npz`` (:data:`GEOMETRY_PATH` from the run directory), a mesh as one (n, 3, 3)
    array of triangle corners [m], which the script's ``add_meshes`` turns into facets: numbers too many to render
    into the script stay out of it (and out of its golden files).
    """
    deck_dir = Path(deck_dir)
    deck_dir.mkdir(parents=True, exist_ok=True)
    stored = {name: mesh.vertices[mesh.faces] for name, mesh in (meshes or {}).items()}
    stored.update(arrays or {})
    if stored:
        partial = deck_dir / f".{Path(GEOMETRY_PATH).name}.partial.npz"
        np.savez(partial, **stored)
        os.replace(partial, deck_dir / Path(GEOMETRY_PATH).name)
    script = deck_dir / DECK_NAME
    write_text_atomic(script, script_text)
    write_text_atomic(deck_dir / "case.json", json.dumps(summary, indent=2, sort_keys=True, default=float))
    return script
