"""Snakemake adapter: the depth-averaged field of every frame of a blender run's steady window (the series whose
batch means give the errors of the steady passage velocities)."""

import json
from pathlib import Path

from analysis.data.record import read_run_record
from analysis.numerics.eulerian_rtd import silo_bins
from analysis.studies.blender.window_fields import frame_fields
from analysis.studies.blender.window_fields_io import write_frame_fields
from analysis.studies.silo_recirculation.tracks import recirculation_tracks
from engines.interface import engine_named
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    case = json.loads(Path(snakemake.input.case).read_text())
    frames = engine_named(record.engine).read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
    recorded = recirculation_tracks(frames, record.domain_z)
    grid = silo_bins(case["width_m"], case["depth_m"], case["fill_height_m"], snakemake.params.bin_size)
    fields = frame_fields(recorded.tracks.position, recorded.velocity, recorded.mass,
                          recorded.tracks.times - record.open_time_s, grid, tuple(case["steady_window"]),
                          case["clump_mass_kg"] / case["clump_volume_m3"])
    write_frame_fields(snakemake.output.frames, fields)
    log.info("%s: %d frame fields in the steady window %s s", case["run_id"], len(fields), case["steady_window"])
