"""Snakemake adapter: clump tracks (ids, centres, velocities) of a recirculation run from its frames."""

from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.numerics.clump_tracks import tracks_from_frames
from siloflow.analysis.studies.silo_recirculation.tracks_io import write_tracks
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    frames = engine_named(record.engine).read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
    tracks = tracks_from_frames(frames, record.domain_z)
    write_tracks(tracks, snakemake.output.tracks)
    log.info("%d frames x %d clumps from %.4g s to %.4g s", tracks.tracks.n_times, tracks.tracks.n_clumps,
             tracks.tracks.times[0], tracks.tracks.times[-1])
