"""Snakemake adapter: render and run one run of the cross-engine check on its engine (run.json last)."""

from pathlib import Path

from siloflow.model.cases.cross_engine import cross_engine_cases
from siloflow.engines.interface import EngineOptions, engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]):
    engine = engine_named(snakemake.wildcards.engine)
    case = cross_engine_cases(snakemake.config)[engine.name][snakemake.wildcards.run]
    run_dir = Path(snakemake.output.record).parent
    engine.write_inputs(case, run_dir)
    engine.run(case, run_dir, EngineOptions.from_config(snakemake.config, engine.name))
