"""Snakemake adapter: one validation group's rows of the validation table, from that group's products."""

import json
from pathlib import Path

import yaml

from analysis.io.tables import read_table, write_flow_table
from analysis.studies.validation.blending import blender_rows, gravity_rows, recirculation_rows
from analysis.studies.validation.calibration import calibration_rows
from analysis.studies.validation.rows import Criteria
from analysis.studies.validation.silo import SiloRun, front_wall_series_rows, silo_rows
from engines.cases.particles import particle_template
from engines.logs import logged_to


def _json(path):
    return json.loads(Path(path).read_text())


with logged_to(snakemake.log[0]) as log:
    inputs, params = snakemake.input, snakemake.params
    criteria = Criteria.from_config(params.criteria)
    if params.group == "calibration":
        diameters = {shape: particle_template(shape, model, params.density).equivalent_diameter
                     for shape, model in params.shapes.items()}
        rows = calibration_rows(read_table(inputs.bulk), yaml.safe_load(Path(inputs.parameters).read_text()),
                                params.cell_diameter, diameters, params.base_restitution, params.lid, criteria)
    elif params.group == "silo":
        silo_runs = [SiloRun(_json(case), _json(flow), _json(fields), _json(balance))
                     for case, flow, fields, balance in zip(inputs.silo_case, inputs.silo_flow, inputs.silo_fields,
                                                            inputs.silo_balance)]
        base = silo_runs[0]
        base.janssen, base.kinematic, base.boundary = (read_table(inputs.janssen), read_table(inputs.kinematic),
                                                       read_table(inputs.boundary))
        rows = silo_rows(base, criteria)
        rows += front_wall_series_rows(list(zip(params.labels, silo_runs)), params.profile_height, criteria)
    elif params.group == "blending":
        rows = []
        for case, summary, rtd in zip(inputs.cases, inputs.summaries, inputs.rtds):
            rows += recirculation_rows(_json(case), _json(summary), read_table(rtd), criteria)
    else:
        summaries = [_json(path) for path in inputs.summaries]
        rows = blender_rows(summaries, [_json(path) for path in inputs.cases], criteria) + gravity_rows(summaries,
                                                                                                      criteria)
    write_flow_table(snakemake.output.rows, rows)
    log.info("%s: %d rows, %d shown at this scale", params.group, len(rows),
             sum(r["scale_shows"] == "yes" for r in rows))
