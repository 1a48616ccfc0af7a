"""Snakemake adapter: the silo at the Bayesian posterior's mean and draws: each run's flow rate and base vertical
stress, and the calibration's error bar of each beside the runs' own error."""

import json
from pathlib import Path

import yaml

from siloflow.analysis.io.tables import read_table, write_flow_table, write_json
from siloflow.analysis.studies.silo_flat.plots import plot_posterior_draws
from siloflow.analysis.studies.silo_flat.posterior_draws import base_vertical_stress, calibration_spread, posterior_draw_rows
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    parameters = [yaml.safe_load(Path(snakemake.input.parameters).read_text(encoding="utf-8")),
                  *yaml.safe_load(Path(snakemake.input.draws).read_text(encoding="utf-8"))]
    flows = [json.loads(Path(path).read_text()) for path in snakemake.input.flows]
    stresses = [base_vertical_stress(read_table(path)) for path in snakemake.input.janssen]
    rows = posterior_draw_rows(snakemake.params.labels, snakemake.params.runs, parameters, flows, stresses)
    spread = calibration_spread(rows)
    write_flow_table(snakemake.output.table, rows)
    write_flow_table(snakemake.output.spread, spread)
    write_json(snakemake.output.summary, {"engine": snakemake.params.engine, "runs": rows, "spread": spread})
    plot_posterior_draws(rows, spread, snakemake.output.plot,
                         f"Silo at the posterior's draws ({snakemake.params.engine})")
    for summary in spread:
        log.info("%s: posterior mean %.6g ± %.3g, draws' sd %.3g, runs' error %.3g, calibration sd %.3g %s",
                 summary["figure"], summary["posterior_mean"], summary["posterior_mean_error"], summary["draws_sd"],
                 summary["run_error"], summary["calibration_sd"], summary["unit"])
