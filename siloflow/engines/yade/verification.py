"""YADE scripts of the verification problems (``siloflow/templates/yade/verification.py.j2``): free spheres or clumps
of one material, the floor as an infinite wall of a second material of the same properties, every sphere's state
saved."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from siloflow.model.constants import GRAVITY
from siloflow.model.record import RunRecord
from siloflow.model.cases.verification import VerificationCase
from siloflow.engines.templating import render_deck
from siloflow.engines.verification_checks import check_verification_run, verification_record
from siloflow.engines.yade.inputs import ENGINE_NAME, hertz_stiffness_at_load, write_script_inputs
from siloflow.engines.yade.run import DUMP_PREFIX, YadeOptions, run_script_checked


def verification_script_context(case: VerificationCase) -> dict:
    """The rendering context of ``siloflow/templates/yade/verification.py.j2``."""
    material = {"youngs_modulus": case.youngs_modulus, "poisson_ratio": case.poisson_ratio, "density": case.density}
    kn = hertz_stiffness_at_load(case.radius, case.youngs_modulus, case.poisson_ratio, case.mass * GRAVITY)
    eta = case.rolling_friction * case.rolling.ratio
    return {
        "title": f"siloflow-verification-{case.run_id}",
        "timestep": case.timestep,
        "gravity": abs(case.gravity[2]),
        "gravity_vector": list(case.gravity),
        "materials": {
            "list": [material, material],
            "pairs": [{"i": i, "j": j, "sliding_friction": case.sliding_friction, "restitution": case.restitution}
                      for i, j in ((0, 0), (0, 1), (1, 1))],
            # the study's coefficient, as Mindlin's cap eta r |Fn| gives its torque at the particle's mean lever arm
            # (siloflow.engines.yade.inputs)
            "rolling_friction": eta,
            "rolling_stiffness": 2.25 * kn * eta**2 * case.radius**2,
        },
        "radius": case.radius,
        "spheres": [asdict(sphere) for sphere in case.spheres],
        "floor": case.floor,
        "steps": case.steps,
        "output_every": case.output_every,
        "frame_prefix": DUMP_PREFIX,
        # a clump problem's clump (one at each of its spheres): centres in its principal frame, the exact mass and
        # principal inertia
        "clump": ({"centres": [list(c) for c in case.clump_spheres], "mass": case.clump_mass,
                   "inertia": list(case.clump_inertia)} if case.clump_spheres else None),
    }


def write_verification_inputs(case: VerificationCase, deck_dir: str | Path) -> Path:
    """Write the script and ``case.json`` into ``deck_dir``; returns the script path."""
    script = render_deck("yade/verification.py.j2", verification_script_context(case))
    return write_script_inputs(case.summary(), script, deck_dir)


def run_verification(case: VerificationCase, run_dir: str | Path, options: YadeOptions) -> RunRecord:
    """Run a rendered verification script, check it and write ``run.json``; returns the record."""
    return run_script_checked(
        run_dir, options, case.steps * case.timestep,
        lambda markers, frames: check_verification_run(case, markers, frames, Path(run_dir)),
        lambda checked: verification_record(ENGINE_NAME, case, checked),
    )
