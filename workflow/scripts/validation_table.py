"""Snakemake adapter: the validation table (CSV and report page) from the products of every stage."""

import json
from pathlib import Path

import yaml

from analysis.io.tables import read_table, write_flow_table, write_text
from analysis.report.summary import summary_html
from analysis.studies.validation.blending import blender_rows, gravity_rows, recirculation_rows
from analysis.studies.validation.calibration import calibration_rows
from analysis.studies.validation.rows import Criteria
from analysis.studies.validation.silo import SiloRun, front_wall_series_rows, silo_rows
from analysis.studies.validation.table import PAGE_EXPLANATION, page_sections
from engines.cases.particles import particle_template
from engines.logs import logged_to


def _json(path):
    return json.loads(Path(path).read_text())


with logged_to(snakemake.log[0]) as log:
    inputs, params = snakemake.input, snakemake.params
    criteria = Criteria.from_config(params.criteria)
    diameters = {shape: particle_template(shape, model, params.density).equivalent_diameter
                 for shape, model in params.shapes.items()}
    rows = calibration_rows(read_table(inputs.bulk), yaml.safe_load(Path(inputs.parameters).read_text()),
                            params.cell_diameter, diameters, params.base_restitution, params.lid, criteria)
    silo_runs = [SiloRun(_json(case), _json(flow), _json(fields), _json(balance))
                 for case, flow, fields, balance in zip(inputs.silo_case, inputs.silo_flow, inputs.silo_fields,
                                                        inputs.silo_balance)]
    base = silo_runs[0]
    base.janssen, base.kinematic, base.boundary = (read_table(inputs.janssen), read_table(inputs.kinematic),
                                                   read_table(inputs.boundary))
    rows += silo_rows(base, criteria)
    rows += front_wall_series_rows(list(zip(params.labels, silo_runs)), params.profile_height, criteria)
    for case, summary, rtd in zip(inputs.recirculation_cases, inputs.recirculation_summaries, inputs.recirculation_rtds):
        rows += recirculation_rows(_json(case), _json(summary), read_table(rtd), criteria)
    blender = [_json(path) for path in inputs.blender]
    if blender:
        rows += blender_rows(blender, [_json(path) for path in inputs.blender_cases], criteria)
        rows += gravity_rows(blender, criteria)
    write_flow_table(snakemake.output.table, rows)
    write_text(snakemake.output.page, summary_html("siloflow: validation table", page_sections(rows),
                                                   intro=PAGE_EXPLANATION))
    shown = sum(r["scale_shows"] == "yes" for r in rows)
    log.info("%d rows, %d shown at this scale", len(rows), shown)
