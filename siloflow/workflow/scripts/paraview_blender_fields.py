"""Snakemake adapter: the blender's depth-averaged field of every frame of its steady window
(``fields/steady_frames.npz``) as a ParaView series on the run's simulated clock, in the plane of mid-depth
(:func:`siloflow.analysis.io.planar_fields_vtk.write_planar_field_series`)."""

from siloflow.analysis.io.planar_fields_vtk import write_planar_field_series
from siloflow.analysis.studies.blender.window_fields_io import read_frame_fields
from siloflow.engines.logs import logged_to
from siloflow.model.record import read_run_record

with logged_to(snakemake.log[0]) as log:
    record = read_run_record(snakemake.input.record)
    frames = read_frame_fields(snakemake.input.frames)
    # the frame fields are timed from the opening (blender_fields.py); the particles carry the simulated time
    times = [frame.window[0] + record.open_time_s for frame in frames]
    write_planar_field_series(snakemake.output.pvd, frames, times, y=0.5 * snakemake.params.case.silo.depth)
    log.info("%s: %d frame fields from %.4g s to %.4g s", record.run_id, len(frames), times[0], times[-1])
