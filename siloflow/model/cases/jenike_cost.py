"""What a run of the Jenike shear cell costs: its deck's stages (fill, settle, consolidate, shear) as work.

Pure computation on cases, with :mod:`siloflow.model.cost`'s pieces.
"""

from __future__ import annotations

from siloflow.model.cases.jenike import FILL_SOLID_FRACTION, JenikeCase
from siloflow.model.cost import CostModel, RunEstimate, StageWork, dump_frames, estimate_run

#: The Jenike deck runs one step after ``delete_atoms`` so LIGGGHTS removes the partner spheres of the
#: deleted clumps (:mod:`siloflow.model.cases.jenike`, stage 2).
JENIKE_LEVEL_DELETION_STEPS = 1


def jenike_run_steps(case: JenikeCase) -> int:
    """Steps of a Jenike deck: fill + one deletion step + relaxation + load ramp + hold + shear."""
    return (
        case.fill.steps + JENIKE_LEVEL_DELETION_STEPS + case.fill.relax_steps
        + case.ramp_steps + case.hold_steps + case.shear_steps
    )


def jenike_lid_atoms(case: JenikeCase) -> int:
    """Atoms of the lid: the glued spheres of a rigid lid, or the proxy atoms of a servo lid."""
    if case.rigid_lid is not None:
        return case.rigid_lid.n_spheres
    if case.servo_lid is not None:
        return len(case.servo_lid.proxy_positions)
    return 0


def jenike_levelled_clumps(case: JenikeCase) -> int:
    """Clumps left after levelling: those the sample volume holds at the solid fraction the pour was sized with,
    ``round(phi A H / V_clump)`` (:data:`siloflow.model.cases.jenike.FILL_SOLID_FRACTION`), at most the clumps created."""
    geometry = case.geometry
    kept = int(round(FILL_SOLID_FRACTION * geometry.area * geometry.sample_height / case.particle.volume))
    return min(case.fill.n_clumps, kept)


def jenike_stage_work(case: JenikeCase) -> tuple[StageWork, ...]:
    """Steps and sphere-steps of the stages of a Jenike deck.

    - fill: all clumps created at once, held for the fall and settling;
    - settle: the deletion step still at that count (the engine removes the spheres of the deleted clumps in
      it), then the relaxation at the levelled count (:func:`jenike_levelled_clumps`);
    - consolidate (load ramp and hold) and shear: the levelled clumps plus the lid's atoms, placed after levelling.
    """
    spheres = case.particle.n_spheres
    created = spheres * case.fill.n_clumps
    levelled = spheres * jenike_levelled_clumps(case)
    loaded = levelled + jenike_lid_atoms(case)
    relax = case.fill.relax_steps
    consolidation = case.ramp_steps + case.hold_steps
    return (
        StageWork("fill", case.fill.steps, float(created * case.fill.steps)),
        StageWork("settle", JENIKE_LEVEL_DELETION_STEPS + relax,
                  float(created * JENIKE_LEVEL_DELETION_STEPS + levelled * relax)),
        StageWork("consolidate", consolidation, float(loaded * consolidation)),
        StageWork("shear", case.shear_steps, float(loaded * case.shear_steps)),
    )


def estimate_jenike_case(case: JenikeCase, mpi_ranks: int = 1, model: CostModel = CostModel()) -> RunEstimate:
    """Estimate a Jenike shear-cell run: work stage by stage (:func:`jenike_stage_work`).

    Disk (upper bounds): every dump counts the clumps created (``fill.n_clumps``) and the lid's atoms
    (:func:`jenike_lid_atoms`), although levelling deletes the overfill first; particle dumps over consolidation
    and shear (:func:`dump_frames` of ramp + hold + shear at ``dump_every``), and as many pair-and-wall contact
    dumps (the deck writes one fewer); the calibration analysis keeps no parsed-frame cache.
    """
    dumped_steps = case.ramp_steps + case.hold_steps + case.shear_steps
    frames = dump_frames(dumped_steps, case.dump_every)
    stages = jenike_stage_work(case)
    return estimate_run(
        case.run_id,
        "jenike",
        clumps=case.fill.n_clumps,
        spheres_per_clump=case.particle.n_spheres,
        steps=jenike_run_steps(case),
        timestep=case.timestep,
        dump_frames=frames,
        mpi_ranks=mpi_ranks,
        model=model,
        extra_spheres=jenike_lid_atoms(case),
        contact_frames=frames,
        stages=stages,
    )
