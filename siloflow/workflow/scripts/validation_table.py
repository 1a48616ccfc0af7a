"""Snakemake adapter: the validation table (CSV and report page), every group's rows in the groups' order."""

from siloflow.analysis.io.tables import write_flow_table, write_text
from siloflow.analysis.io.validation_record import read_validation_rows
from siloflow.analysis.report.summary import summary_html
from siloflow.analysis.studies.validation.table import PAGE_EXPLANATION, page_sections
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    rows = [row for path in snakemake.input.rows for row in read_validation_rows(path)]
    write_flow_table(snakemake.output.table, rows)
    write_text(snakemake.output.page, summary_html("siloflow: validation table", page_sections(rows),
                                                   intro=PAGE_EXPLANATION))
    log.info("%d rows, %d judged against a finding of the study", len(rows), sum(r["finding"] != "-" for r in rows))
