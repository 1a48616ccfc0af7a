"""Snakemake adapter: a run's particle frames as ParaView files, ``paraview/particles.pvd`` indexing one .vtp per
frame by simulated time (:func:`siloflow.analysis.io.particle_series.write_particle_series`), for a run of either engine."""

from pathlib import Path

from siloflow.analysis.io.particle_series import write_particle_series
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to
from siloflow.model.record import read_run_record

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    frames = engine_named(record.engine).read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
    write_particle_series(snakemake.output.pvd, frames)
    log.info("%s: %d particle frames from %.4g s to %.4g s, up to %d spheres", record.run_id, len(frames),
             frames[0].time, frames[-1].time, max(len(frame) for frame in frames))
