"""Snakemake adapter: clump tracks (ids, centres, velocities) of a recirculation run from its dumps."""

import json
from pathlib import Path

from analysis.studies.silo_recirculation.tracks_io import read_recirculation_tracks, write_tracks
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = json.loads(Path(snakemake.input.record).read_text())
    tracks = read_recirculation_tracks(run_dir / "dumps", record["dump_prefix"], record["timestep_s"],
                                       record["domain_z"], cache_dir=run_dir / "frames",
                                       on_damaged=snakemake.config["dumps"]["on_damaged"])
    write_tracks(tracks, snakemake.output.tracks)
    log.info("%d frames x %d clumps from %.4g s to %.4g s", tracks.tracks.n_times, tracks.tracks.n_clumps,
             tracks.tracks.times[0], tracks.tracks.times[-1])
