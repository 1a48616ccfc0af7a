"""Snakemake adapter: one validation group's rows of the validation table, from the products of the runs behind it.

The reference configuration's seeds (params.reference) become one summary and lend their spread to the
configurations run once (siloflow.analysis.numerics.reference_spread) before the rows are judged.
"""

import json
from pathlib import Path

import yaml

from siloflow.analysis.io.tables import read_table, write_flow_table
from siloflow.analysis.studies.validation.blending import blender_rows, gravity_rows, recirculation_rows
from siloflow.analysis.studies.validation.calibration import calibration_rows
from siloflow.analysis.studies.validation.rows import Criteria
from siloflow.analysis.numerics.reference_spread import floor_table, seed_note, with_reference_spread
from siloflow.analysis.studies.validation.silo import SiloRun, front_wall_series_rows, silo_rows
from siloflow.calibration.table import point_table
from siloflow.model.cases.particles import particle_template
from siloflow.engines.logs import logged_to


def _json(path):
    return json.loads(Path(path).read_text())


def _noted(rows, reference_case, spread):
    """Rows with the evidence of their seeds appended."""
    for entry in rows:
        note = seed_note(reference_case, spread, entry["case"] == reference_case)
        entry["evidence"] = f"{entry['evidence']}; {note}"
    return rows


def _silo(inputs, params, criteria):
    files = ("case", "flow", "fields", "balance")
    runs = [{key: _json(path) for key, path in zip(files, paths)}
            for paths in zip(inputs.case, inputs.flow, inputs.fields, inputs.balance)]
    for run, janssen, kinematic, boundary in zip(runs, inputs.janssen, inputs.kinematic, inputs.boundary):
        run.update(janssen=read_table(janssen), kinematic=read_table(kinematic), boundary=read_table(boundary))
    run_ids = [run["case"]["run_id"] for run in runs]
    base, others, spread = with_reference_spread(runs, run_ids, set(params.reference))
    silo = {key: SiloRun(**summary) for key, summary in [("base", base), *others]}
    if params.group == "silo":
        return _noted(silo_rows(silo["base"], criteria), base["case"]["run_id"], spread)
    series = [(params.labels[base["case"]["run_id"]], silo["base"])]
    series += [(params.labels[run], silo[run]) for run, _ in others]
    return _noted(front_wall_series_rows(series, params.profile_height, criteria), series[0][0], spread)


def _blending(inputs, params, criteria):
    runs = [{"case": _json(case), "summary": _json(summary), "rtd": read_table(rtd)}
            for case, summary, rtd in zip(inputs.cases, inputs.summaries, inputs.rtds)]
    reference, others, spread = with_reference_spread(runs, [run["case"]["run_id"] for run in runs], set(params.reference))
    rows = []
    for run in [reference, *(summary for _, summary in others)]:
        rows += recirculation_rows(run["case"], run["summary"], run["rtd"], criteria)
    return _noted(rows, reference["summary"]["flow_pattern"], spread)


def _blender(inputs, params, criteria):
    runs = [{"case": _json(case), "summary": _json(summary)} for case, summary in zip(inputs.cases, inputs.summaries)]
    reference, others, spread = with_reference_spread(runs, [run["case"]["run_id"] for run in runs], set(params.reference))
    chosen = [reference, *(summary for _, summary in others)]
    summaries = [run["summary"] for run in chosen]
    rows = blender_rows(summaries, [run["case"] for run in chosen], criteria) + gravity_rows(summaries, criteria)
    return _noted(rows, reference["summary"]["configuration"], spread)


def _calibration(inputs, params, criteria):
    diameters = {shape: particle_template(shape, model, params.density).equivalent_diameter
                 for shape, model in params.shapes.items()}
    points, spread, replicated = floor_table(point_table([_json(path) for path in inputs.summaries]),
                                             ("bulk_friction", "bulk_friction_angle_deg"))
    parameters = yaml.safe_load(Path(inputs.parameters).read_text()) if "parameters" in inputs.keys() else None
    rows = calibration_rows(points, parameters, params.cell_diameter, diameters, params.base_restitution, params.lid,
                            params.shear_velocity, criteria, sections=params.sections)
    if spread.seeds >= 2:
        reference = "; ".join(f"{row['shape']} {row['test']}, particle friction {row['particle_friction']}, rolling "
                              f"{row['rolling_friction']}" for row in replicated)
        for entry in rows:
            entry["evidence"] += (f"; point errors include the spread between the {spread.seeds} seeds of the "
                                  f"reference point ({reference}), relative to the value")
    return rows


ROWS = {"jenike": _calibration, "silo_flat": _silo, "silo_recirculation": _blending, "blender": _blender}

with logged_to(snakemake.log[0]) as log:
    criteria = Criteria.from_config(snakemake.params.criteria)
    rows = ROWS[snakemake.params.kind](snakemake.input, snakemake.params, criteria)
    write_flow_table(snakemake.output.rows, rows)
    log.info("%s: %d rows, %d shown at this scale", snakemake.params.group, len(rows),
             sum(r["scale_shows"] == "yes" for r in rows))
