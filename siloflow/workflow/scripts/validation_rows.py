"""Snakemake adapter: one validation group's rows of the validation table, from the products of the runs behind it
(siloflow.analysis.studies.validation.group_rows), each with its agreement and its scale verdict (the latter from the
configuration alone)."""

from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.io.validation_products import read_group_products
from siloflow.analysis.studies.validation.group_rows import judged_rows
from siloflow.analysis.studies.validation.scale import scale_verdict
from siloflow.calibration.table import point_table
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    kind, config = snakemake.params.kind, snakemake.config
    # a named input of one file is a string, of several a list
    named = {key: snakemake.input[key] for key in snakemake.input.keys()}
    data = read_group_products(kind, {key: [paths] if isinstance(paths, str) else list(paths)
                                      for key, paths in named.items()})
    if kind == "jenike":
        data["points"] = point_table(data["summaries"])
    rows = judged_rows(kind, data, snakemake.params.rows, config["validation"],
                       lambda finding, as_study: scale_verdict(finding, kind, config, as_study))
    write_flow_table(snakemake.output.rows, rows)
    log.info("%s: %d rows, %d judged against a finding of the study", snakemake.params.rows["group"], len(rows),
             sum(r["finding"] != "-" for r in rows))
