"""Snakemake adapter: the cross-engine table (CSV and report page) from every run's metrics: the silo's quantities,
then each Jenike point's bulk friction."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_flow_table, write_text
from siloflow.analysis.report.summary import summary_html
from siloflow.analysis.studies.cross_engine import CROSS_ENGINE_QUANTITIES, compare_engines
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    runs = [json.loads(Path(path).read_text()) for path in snakemake.input.metrics]
    engines = snakemake.params.engines
    rows = []
    for key, (label, unit) in CROSS_ENGINE_QUANTITIES.items():
        values = {engine: [run[key] for run in runs if run["engine"] == engine] for engine in engines}
        rows.append(compare_engines(values, label, unit))
    jenike = [json.loads(Path(path).read_text()) for path in snakemake.input.jenike]
    for point in dict.fromkeys(run["point"] for run in jenike):  # each point once, in the order of the runs
        values = {engine: [run["bulk_friction"] for run in jenike if run["engine"] == engine and run["point"] == point]
                  for engine in engines}
        rows.append(compare_engines(values, point, "-"))
    write_flow_table(snakemake.output.table, rows)
    explanation = snakemake.params.explanation
    write_text(snakemake.output.page, summary_html(
        "Cross-engine check: the same silo and Jenike points on two engines",
        [("The small flat-bottom silo and Jenike cell", explanation, rows)]))
    for row in rows:
        log.info("%s: %s %.5g +- %.2g, %s %.5g +- %.2g (std over seeds); difference %.3g = %.2f standard errors%s",
                 row["quantity"], engines[0], row[f"{engines[0]}_mean"], row[f"{engines[0]}_std"], engines[1],
                 row[f"{engines[1]}_mean"], row[f"{engines[1]}_std"], row["difference"], row["difference_in_errors"],
                 " (larger than 2)" if row["larger_than_2_errors"] else "")
