"""Snakemake adapter: compare the insert configurations (at the lowest gravity factor run) in one table and plots,
and say which differences between them exceed their uncertainty."""

import json
from pathlib import Path

from siloflow.analysis.studies.blender.comparison import (
    SIGNIFICANCE_COLUMNS,
    best_blender,
    comparison_table,
    figure_columns,
    significance_rows,
)
from siloflow.analysis.studies.blender.plots import plot_configuration_comparison, plot_rtd_theta
from siloflow.analysis.studies.blender.study import metrics_from_summary, rtd_from_summary
from siloflow.analysis.studies.blender.tables import comparison_markdown, lowest_gravity_runs, rtd_label
from siloflow.analysis.io.tables import write_flow_table, write_text
from siloflow.analysis.numerics.reference_spread import floor_table
from siloflow.analysis.numerics.replicates import combine_replicates
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    summaries = [json.loads(Path(path).read_text()) for path in snakemake.input.summaries]
    lowest, chosen = lowest_gravity_runs(summaries)
    metrics = [metrics_from_summary(summary) for summary in chosen]
    # replicates (the same configuration with other seeds) become one row: their mean and its error
    rows = combine_replicates(comparison_table(metrics), ["configuration"])
    # an insert run once takes the relative spread of the one run with several seeds (reference_replicates)
    rows = floor_table(rows)[0]
    best = best_blender(metrics)
    significance = significance_rows(rows)
    write_flow_table(snakemake.output.table, rows)
    write_text(snakemake.output.markdown, comparison_markdown(lowest, rows, best, snakemake.params.tolerance))
    if significance:
        write_flow_table(snakemake.output.significance, significance)
    else:  # a single configuration: no pair to compare, a header-only table
        write_text(snakemake.output.significance, ",".join(SIGNIFICANCE_COLUMNS) + "\n")
    plot_configuration_comparison(rows, figure_columns(rows[0]), snakemake.output.plot,
                                  f"Insert configurations at {lowest:g} g", best=best)
    plot_rtd_theta({rtd_label(s, chosen): rtd_from_summary(s["rtd_curve"]) for s in chosen},
                   snakemake.output.rtd_plot, f"RTD of the configurations at {lowest:g} g")
    log.info("best blender: %s; %s; significant differences: %s", best, rows,
             [(r["figure"], r["configuration_a"], r["configuration_b"]) for r in significance
              if r["significance"] == "significant"])
