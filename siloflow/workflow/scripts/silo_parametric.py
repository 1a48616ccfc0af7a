"""Snakemake adapter: one parametric silo study: v_z profiles at one height (from each run's depth-averaged fields)
and flow rates of its runs."""

import json
from pathlib import Path

from siloflow.analysis.io.fields import load_fields_npz
from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.studies.silo_flat.field_comparisons import parametric_profiles, parametric_rows
from siloflow.analysis.studies.silo_flat.plots import plot_parametric_study
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    labels, runs = snakemake.params.labels, snakemake.params.runs
    flows = [json.loads(Path(path).read_text()) for path in snakemake.input.flows]
    depth_averaged = [load_fields_npz(path) for path in snakemake.input.fields]
    profiles = parametric_profiles(depth_averaged, snakemake.params.profile_height)
    rows = parametric_rows(snakemake.wildcards.study, labels, runs, flows, profiles)
    write_flow_table(snakemake.output.table, rows)
    plot_parametric_study(profiles.x, profiles.v_z, labels, [r["mass_flow_rate_kg_s"] for r in rows], profiles.height,
                          snakemake.output.plot, f"Parametric study: {snakemake.wildcards.study.replace('_', ' ')}")
    log.info("%d runs, profiles at z = %g m", len(rows), profiles.height)
