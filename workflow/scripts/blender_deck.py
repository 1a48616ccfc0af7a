"""Snakemake adapter: render the deck, wall meshes and case summary of one blender run."""

from pathlib import Path

from engines.cases.blender import blender_case_for_run
from engines.liggghts.blender import write_blender_inputs
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = blender_case_for_run(snakemake.config, snakemake.wildcards.run)
    deck = write_blender_inputs(case, Path(snakemake.output.deck).parent)
    insert = case.geometry.insert_summary()
    log.info("deck %s: configuration %s, gravity factor %g, %s discharge, %d clumps", deck, case.configuration,
             case.gravity_factor, case.mode, case.silo.fill.n_clumps)
    log.info("achieved insert area ratios: Ai %s, Ae %s, Ar %s", insert.get("interior_ratio"),
             insert.get("exterior_ratio"), insert.get("area_ratio"))
