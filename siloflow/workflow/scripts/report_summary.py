"""Snakemake adapter: the report's summary page from the results of every stage."""

import json
from pathlib import Path

import yaml

from siloflow.analysis.io.tables import read_table, write_text
from siloflow.analysis.report.summary import summary_html, summary_sections
from siloflow.analysis.studies.validation.table import against_the_study
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    inputs = snakemake.input
    sections = summary_sections(
        yaml.safe_load(Path(inputs.parameters).read_text()),
        [json.loads(Path(path).read_text()) for path in inputs.flows],
        [row for path in inputs.measured for row in read_table(path)],
        [row for path in inputs.blending for row in read_table(path)],
        [row for path in inputs.blender for row in read_table(path)],
        [json.loads(Path(path).read_text()) for path in inputs.balances],
        [row for path in inputs.blender_differences for row in read_table(path)],
        against_the_study(read_table(inputs.validation)),
    )
    write_text(snakemake.output.page, summary_html("siloflow: figures of merit", sections))
    log.info("summary page: %s rows", ", ".join(f"{len(section.rows)} {section.title.lower()}" for section in sections))
