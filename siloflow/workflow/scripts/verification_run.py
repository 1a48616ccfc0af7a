"""Snakemake adapter: render and run one verification problem on one engine; the run record is the product."""

from pathlib import Path

from siloflow.model.cases.verification import verification_cases
from siloflow.engines.interface import EngineOptions, engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = verification_cases()[snakemake.params.problem]
    engine = engine_named(snakemake.wildcards.engine)
    run_dir = Path(snakemake.output.record).parent
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions.from_config(snakemake.config, engine.name))
    log.info("%s on %s: %d frames", case.name, engine.name, record.n_frames)
