"""Snakemake adapter: one cross-engine run's filling bulk density, steady flow rate and centreline velocity."""

import json
from pathlib import Path

from siloflow.model.frames import clumps_from_frame
from siloflow.model.record import read_run_record
from siloflow.analysis.io.tables import write_json
from siloflow.analysis.studies.cross_engine import centreline_vertical_velocity
from siloflow.analysis.studies.silo_flat.metrics import silo_flow_metrics
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    case = json.loads((run_dir / "deck" / "case.json").read_text())
    frames = engine_named(record.engine).read_frames(run_dir, record)
    discharge = [clumps_from_frame(frame) for frame in frames if frame.step >= record.open_step]
    diameter = case["equivalent_diameter_m"]
    metrics = silo_flow_metrics(discharge, width=case["width_m"], depth=case["depth_m"],
                                outlet_width=case["outlet_width_m"], particle_diameter=diameter)
    height = snakemake.params.profile_height_fraction * case["fill_height_m"]
    # the steady window is timed from the opening (the first discharge frame)
    opened = discharge[0].time
    velocity = centreline_vertical_velocity(discharge, height, diameter, diameter, opened + metrics.fit.t_start,
                                            opened + metrics.fit.t_end)
    summary = {"engine": record.engine, "run_id": record.run_id, "seed": case["parameters"]["silo"]["seed"],
               "filling_bulk_density_kg_m3": metrics.bulk_density.density,
               "mass_flow_rate_kg_s": metrics.fit.mass_flow_rate, "centreline_v_z_m_s": velocity,
               "profile_height_m": height}
    write_json(snakemake.output.metrics, summary)
    log.info("%s", summary)
