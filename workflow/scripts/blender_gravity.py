"""Snakemake adapter: gravity scaling of every configuration run at several gravity factors."""

import json
from pathlib import Path

import numpy as np

from analysis.studies.blender.gravity import gravity_scaling
from analysis.studies.blender.plots import plot_gravity_scaling
from analysis.io.tables import write_flow_table
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    summaries = [json.loads(Path(path).read_text()) for path in snakemake.input.summaries]
    rows, curves = [], []
    for configuration in sorted({s["configuration"] for s in summaries}):
        runs = sorted((s for s in summaries if s["configuration"] == configuration), key=lambda s: s["gravity_factor"])
        factors = [s["gravity_factor"] for s in runs]
        if 1.0 not in factors or len(factors) < 2:
            log.info("%s: gravity factors %s, no scaling without 1 g and another factor", configuration, factors)
            continue
        quantities = {
            "mass_flow_rate_kg_s": [s["metrics"]["mass_flow_rate_kg_s"] for s in runs],
            "exterior_v_z_m_s": [s["metrics"]["exterior_v_z_m_s"] for s in runs],
            "interior_v_z_m_s": [s["metrics"]["interior_v_z_m_s"] for s in runs],
        }
        quantities = {k: v for k, v in quantities.items() if np.all(np.isfinite(v))}
        scaling = gravity_scaling(factors, quantities, tolerance=0.1)
        rows += [{"configuration": configuration, **row} for row in scaling.rows]
        curves += [(configuration, s["gravity_factor"], s["flow_history"]["time_since_open_s"],
                    s["flow_history"]["mean_v_z_m_s"]) for s in runs]
    if not rows:
        raise ValueError("no configuration was run at gravity factor 1 and another factor; set blender.gravity_factors")
    write_flow_table(snakemake.output.table, rows)
    plot_gravity_scaling(curves, snakemake.output.plot, "Gravity scaling: mean v_z of the silo content",
                         quantity="mean v_z")
    log.info("%d rows: %s", len(rows), rows)
