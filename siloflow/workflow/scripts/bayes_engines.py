"""Snakemake adapter: the Bayesian calibration's posterior on every engine side by side
(siloflow.calibration.bayes.report.engines_rows)."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_flow_table
from siloflow.calibration.bayes.report import engines_rows
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    engines = list(snakemake.params.engines)
    if len(engines) != len(snakemake.input.posteriors):
        raise ValueError(f"{len(snakemake.input.posteriors)} posteriors for the engines {engines}")
    posteriors = {engine: json.loads(Path(path).read_text())
                  for engine, path in zip(engines, snakemake.input.posteriors)}
    rows = engines_rows(posteriors)
    write_flow_table(snakemake.output.table, rows)
    log.info("%d parameters on %s -> %s", len(rows), ", ".join(engines), snakemake.output.table)
