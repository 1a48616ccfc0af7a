"""Snakemake adapter: one parametric silo study: v_z profiles at one height and flow rates of its runs."""

import json
from pathlib import Path

import numpy as np

from analysis.numerics.field_ops import depth_average
from analysis.io.fields import load_fields_npz
from analysis.numerics.profiles import velocity_profile
from analysis.studies.silo_flat.plots import plot_parametric_study
from analysis.io.tables import write_flow_table
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    labels, runs = snakemake.params.labels, snakemake.params.runs
    flows = [json.loads(Path(path).read_text()) for path in snakemake.input.flows]
    averaged = [depth_average(load_fields_npz(path)) for path in snakemake.input.fields]
    # The study's height, lowered to the highest row every run's fields cover.
    height = min([snakemake.params.profile_height] + [float(f.grid.z[-2]) for f in averaged])
    profiles = [velocity_profile(f, height) for f in averaged]
    x = profiles[0].x
    v_z = [np.interp(x, p.x, p.v_z) for p in profiles]
    rows = [
        {"study": snakemake.wildcards.study, "label": label, "run_id": run, "profile_height_m": height,
         "mass_flow_rate_kg_s": flow["mass_flow_rate_kg_s"], "mass_flow_rate_stderr_kg_s": flow["mass_flow_rate_stderr_kg_s"],
         "beverloo_ratio": flow["beverloo_ratio"], "filling_bulk_density_kg_m3": flow["filling_bulk_density_kg_m3"],
         "centreline_v_z_m_s": float(np.interp(0.0, x, profile))}
        for label, run, flow, profile in zip(labels, runs, flows, v_z)
    ]
    write_flow_table(snakemake.output.table, rows)
    plot_parametric_study(x, v_z, labels, [r["mass_flow_rate_kg_s"] for r in rows], height, snakemake.output.plot,
                          f"Parametric study: {snakemake.wildcards.study.replace('_', ' ')}")
    log.info("%d runs, profiles at z = %g m", len(rows), height)
