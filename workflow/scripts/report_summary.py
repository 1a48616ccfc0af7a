"""Snakemake adapter: the report's summary page from the results of every stage."""

import csv
import json
from pathlib import Path

import yaml

from analysis.report.summary import calibration_rows, summary_html
from analysis.io.tables import write_text
from engines.logs import logged_to


def csv_rows(path):
    with open(path, newline="") as handle:
        return [{key: _number(value) for key, value in row.items()} for row in csv.DictReader(handle)]


def _number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return text if text != "" else None


with logged_to(snakemake.log[0]) as log:
    parameters = yaml.safe_load(Path(snakemake.input.parameters).read_text())
    calibration = calibration_rows(parameters)
    silo = []
    for path in snakemake.input.flows:
        flow = json.loads(Path(path).read_text())
        silo.append({key: flow[key] for key in ("run_id", "n_clumps", "filling_bulk_density_kg_m3", "mass_flow_rate_kg_s",
                                                "beverloo_mass_flow_rate_kg_s", "beverloo_ratio")})
    measured = [row for path in snakemake.input.measured for row in csv_rows(path)]
    blending = [{key: row.get(key) for key in ("flow_pattern", "layout", "residence_time_s", "t_s_over_t_d", "vrr_nr1",
                                               "vrr_nr2", "vrr_nr3", "vrr_nr4", "prediction_rms_error")}
                for path in snakemake.input.blending for row in csv_rows(path)]
    blender = [row for path in snakemake.input.blender for row in csv_rows(path)]
    page = summary_html("siloflow: figures of merit", [
        ("Calibration", f"Contact parameters chosen from the Jenike shear sweep (particle model {parameters.get('shape')}, "
                        f"rolling friction {parameters.get('rolling_friction')}), with the band that reproduces the "
                        f"target angles {parameters.get('targets_deg')} deg within {parameters.get('tolerance_deg')} deg.",
         calibration),
        ("Silo validation", "Steady discharge rate of each flat-bottom silo run against Beverloo's prediction.", silo),
        ("Silo against measurements", "Velocity profile errors against the measured profiles.", measured),
        ("Blending", "Mean residence time, RTD spread and VRR after each recirculation per flow pattern and batch "
                     "layout, and the RMS error of the LTI prediction.", blending),
        ("Blender", "Insert configurations compared (see the blender comparison table).", blender),
    ])
    write_text(snakemake.output.page, page)
    log.info("summary page: %d calibration, %d silo, %d measured, %d blending, %d blender rows", len(calibration),
             len(silo), len(measured), len(blending), len(blender))
