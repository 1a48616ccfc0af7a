"""Snakemake adapter: the verification table (CSV and report page) from every problem's run on every engine."""

import json
from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.io.tables import write_flow_table, write_text
from siloflow.analysis.report.summary import summary_html
from siloflow.analysis.studies.verification import measure_problem, trajectories_from_frames, verification_table
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows = {}
    for path in snakemake.input.records:
        run_dir = Path(path).parent
        record = read_run_record(path)
        engine = engine_named(record.engine)
        parameters = json.loads((run_dir / "deck" / "case.json").read_text())
        trajectories = trajectories_from_frames(engine.read_frames(run_dir, record))
        rows.setdefault(record.engine, []).extend(measure_problem(record.labels["problem"], parameters, trajectories))
    table = verification_table(rows)
    keys = table["engine"] + "/" + table["problem"] + "/" + table["quantity"]
    table["note"] = [snakemake.params.known_differences.get(key, "") for key in keys]
    unexplained = table[~table["passes"] & (table["note"] == "")]
    write_flow_table(snakemake.output.table, table.to_dict("records"))
    sections = [(f"{problem}", snakemake.params.explanation[problem], part.drop(columns="problem").to_dict("records"))
                for problem, part in table.groupby("problem", sort=False)]
    write_text(snakemake.output.page, summary_html("DEM verification: closed forms on every engine", sections))
    for row in table.itertuples():
        log.info("%s %s %s: closed form %.6g, measured %.6g, error %+.4f (tolerance %.2f) %s", row.problem,
                 row.quantity, row.engine, row.closed_form, row.measured, row.error, row.tolerance,
                 "passes" if row.passes else f"DIFFERS: {row.note}")
    if len(unexplained):
        raise RuntimeError("verification rows outside their tolerance with no known reason:\n" + unexplained.to_string())
