"""Snakemake adapter: render the deck, meshes and case summary of one flat-bottom silo run."""

from pathlib import Path

from calibration.parameters import calibrated_config
from engines.liggghts.silo_flat import write_silo_inputs
from engines.logs import logged_to
from engines.cases.silo_flat import silo_case_for_run

with logged_to(snakemake.log[0]) as log:
    config = calibrated_config(snakemake.config, snakemake.input.get("parameters"))
    case = silo_case_for_run(config, snakemake.wildcards.run)
    deck = write_silo_inputs(case, Path(snakemake.output.deck).parent)
    log.info("deck %s: %d clumps of %s, time step %.4g s (%.3g of the Rayleigh time %.4g s)",
             deck, case.fill.n_clumps, case.particle.name, case.timestep,
             case.timestep / case.rayleigh_time, case.rayleigh_time)
