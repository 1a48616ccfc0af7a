"""Snakemake adapter: VRR per recirculation of every flow pattern and batch layout, in one table and one plot."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.numerics.reference_spread import floor_table
from siloflow.analysis.numerics.replicates import combine_replicates
from siloflow.analysis.studies.silo_recirculation.vrr_summary_plot import plot_vrr_summary, vrr_replicate_curves
from siloflow.analysis.studies.silo_recirculation.tables import summary_rows
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.figure_findings import vrr_findings
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows, curves = summary_rows([json.loads(Path(path).read_text()) for path in snakemake.input.summaries])
    # the plot draws the seeds of one flow pattern and layout as their mean and band: group them before the table
    # combines them
    replicate_curves = vrr_replicate_curves(rows, curves)
    # replicates (the same flow pattern with other seeds) become one row per layout: their mean and its error
    rows = combine_replicates(rows, ["flow_pattern", "layout"])
    # a flow pattern run once takes the relative spread of the one run with several seeds (reference_replicates)
    rows = floor_table(rows)[0]
    write_flow_table(snakemake.output.table, rows)
    # the study's VRR at the end of 4 recirculations (B4) is the discharge's after them: drawn where the runs have one
    discharged = any(curve["discharge"] is not None for curve in replicate_curves)
    plot_vrr_summary(replicate_curves, snakemake.output.vrr_plot, "VRR per recirculation: flow patterns and layouts",
                     findings=vrr_findings(AgreementTolerances.from_config(snakemake.params.validation))
                     if discharged else None)
    log.info("%d flow pattern x layout rows", len(rows))
