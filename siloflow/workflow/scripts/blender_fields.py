"""Snakemake adapter: steady and windowed depth-averaged fields, the field of every frame of the steady window (the
series whose batch means give the errors of the steady passage velocities), the same steady field and frames of the
layer at the front and back walls (what the study's PIV sees) and the discharge rate of one blender run."""

from pathlib import Path

import numpy as np

from siloflow.analysis.studies.blender.window_fields import (
    discharged_mass_history,
    frame_fields,
    mean_velocity_history,
    wall_layer_depth,
    wall_layer_positions,
    window_average_field,
)
from siloflow.analysis.studies.blender.window_fields_io import (
    write_frame_fields,
    write_planar_fields,
    write_wall_layer_fields,
)
from siloflow.model.record import read_run_record
from siloflow.analysis.numerics.clump_tracks import tracks_from_frames
from siloflow.analysis.numerics.eulerian_rtd import silo_bins
from siloflow.analysis.numerics.flow import steady_flow_rate
from siloflow.analysis.io.tables import write_json
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    case = snakemake.params.case
    silo = case.silo
    frames = engine_named(record.engine).read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
    recorded = tracks_from_frames(frames, record.domain_z)
    tracks = recorded.tracks
    since_open = tracks.times - record.open_time_s
    grid = silo_bins(silo.width, silo.depth, silo.fill_height, snakemake.params.bin_size)
    density = silo.particle.mass / silo.particle.volume
    steady_window = case.steady_window

    def averaged(window):
        return window_average_field(tracks.position, recorded.velocity, recorded.mass, since_open, grid, window, density)

    steady = averaged(steady_window)
    edges = np.linspace(0.0, steady_window[1], case.profile_windows + 1)
    windows = [averaged((start, end)) for start, end in zip(edges[:-1], edges[1:])]
    write_planar_fields(snakemake.output.fields, steady, windows)
    steady_frames = frame_fields(tracks.position, recorded.velocity, recorded.mass, since_open, grid, steady_window,
                                 density)
    write_frame_fields(snakemake.output.frames, steady_frames)
    # the clumps within a diameter of either wall, on bins one layer deep
    layer = wall_layer_depth(silo.particle.equivalent_diameter)
    folded = wall_layer_positions(tracks.position, silo.depth)
    layer_grid = silo_bins(silo.width, layer, silo.fill_height, snakemake.params.bin_size)
    write_wall_layer_fields(
        snakemake.output.wall_layer,
        window_average_field(folded, recorded.velocity, recorded.mass, since_open, layer_grid, steady_window, density),
        frame_fields(folded, recorded.velocity, recorded.mass, since_open, layer_grid, steady_window, density))

    time, discharged = discharged_mass_history(tracks, recorded.mass, case.mode, case.outlet_z, case.domain_z)
    fit = steady_flow_rate(time - record.open_time_s, discharged, window=steady_window)
    write_json(snakemake.output.flow, {
        "run_id": case.run_id, "configuration": case.configuration, "gravity_factor": case.gravity_factor,
        "mode": case.mode, "n_clumps": silo.fill.n_clumps, "mass_flow_rate_kg_s": fit.mass_flow_rate,
        "mass_flow_rate_standard_error_kg_s": fit.standard_error, "steady_window_s": list(steady_window),
        "time_since_open_s": (time - record.open_time_s).tolist(), "discharged_mass_kg": discharged.tolist(),
        "mean_v_z_m_s": mean_velocity_history(tracks, recorded.velocity, recorded.mass, case.outlet_z).tolist(),
    })
    log.info("%s: %d frames, steady window %s s (%d frames, %d frame fields), wall layer %.4g m deep, mass flow rate "
             "%.5g +- %.2g kg/s", case.run_id, tracks.n_times, steady_window, steady.n_frames, len(steady_frames),
             layer, fit.mass_flow_rate, fit.standard_error)
