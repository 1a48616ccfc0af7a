"""Snakemake adapter: VRR per recirculation of every flow pattern and batch layout, in one table and one plot."""

import json
from pathlib import Path

from analysis.studies.silo_recirculation.plots import plot_vrr_versus_recirculations
from analysis.io.tables import write_flow_table
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows, curves = [], []
    for path in snakemake.input.summaries:
        summary = json.loads(Path(path).read_text())
        for name, layout in summary["layouts"].items():
            vrr = [v if v is not None else float("nan") for v in layout["vrr_by_recirculation"]]
            curves.append((f"{summary['flow_pattern']} {name}", [k + 0.5 for k in range(len(vrr))], vrr))
            rows.append({
                "flow_pattern": summary["flow_pattern"], "layout": name, "run_id": summary["run_id"],
                "residence_time_s": summary["residence_time_s"], "t_s_over_t_d": summary["rtd_particle_ids"]["t_s_over_t_d"],
                "rtd_mean_ids_s": summary["rtd_particle_ids"]["t_mean_s"],
                "rtd_mean_eulerian_s": summary["rtd_eulerian"]["t_mean_s"],
                **{f"vrr_nr{k + 1}": v for k, v in enumerate(vrr)},
                "prediction_rms_error": layout["prediction_rms_error"],
                "homogenised_after_recirculations": layout["homogenised_after_recirculations"],
                "model_homogenised_after_recirculations": layout["model_homogenised_after_recirculations"],
            })
    write_flow_table(snakemake.output.table, rows)
    plot_vrr_versus_recirculations(curves, snakemake.output.vrr_plot, "VRR per recirculation: flow patterns and layouts")
    log.info("%d flow pattern x layout rows", len(rows))
