"""Snakemake adapter: the flat-bottom silo's vertical stress at the end of filling over the reference configuration's
seeds (combined as the validation rows combine them) beside Janssen's, the figure the validation record shows beside
the silo's rows."""

from siloflow.analysis.io.tables import read_table
from siloflow.analysis.studies.silo_flat.field_comparisons import seed_janssen
from siloflow.analysis.studies.silo_flat.plots import plot_janssen
from siloflow.analysis.studies.validation.figure_findings import janssen_findings
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    seeds = len(snakemake.input.janssen)
    comparison = seed_janssen([read_table(path) for path in snakemake.input.janssen])
    plot_janssen(comparison, snakemake.output.plot,
                 f"Vertical stress at the end of filling: {seeds} seed{'s' if seeds > 1 else ''}", janssen_findings())
    log.info("stresses of %d seeds at %d heights", seeds, comparison.height.size)
