"""Snakemake adapter: render the deck, meshes and case summary of one Jenike shear-cell sweep point."""

from pathlib import Path

from engines.cases.jenike import build_jenike_case
from engines.liggghts.jenike import write_jenike_inputs
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = build_jenike_case(snakemake.config, snakemake.params.point)
    if case.run_id != snakemake.wildcards.point:
        raise RuntimeError(f"sweep point {snakemake.params.point} is run {case.run_id}, not {snakemake.wildcards.point}")
    deck = write_jenike_inputs(case, Path(snakemake.output.deck).parent)
    log.info("deck %s for sweep point %s", deck, snakemake.params.point)
