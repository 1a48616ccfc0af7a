"""Snakemake adapter: the recirculating silo's clump tracks cut into passes (one line per pass, carrying its residence
time: :func:`siloflow.analysis.studies.silo_recirculation.pass_paths.pass_paths`) as a ParaView .vtp."""

from siloflow.analysis.io.vtk_lines import write_pass_paths_vtp
from siloflow.analysis.studies.silo_recirculation.pass_paths import pass_paths
from siloflow.analysis.studies.silo_recirculation.tracks_io import load_tracks
from siloflow.engines.logs import logged_to

#: The outlet plane, z = 0 in the coordinates of every case (as the recirculation study takes it).
OUTLET_Z = 0.0

with logged_to(snakemake.log[0]) as log:
    case = snakemake.params.case
    bottom, top = case.domain_z
    paths = pass_paths(load_tracks(snakemake.input.tracks), OUTLET_Z, bottom, top)
    write_pass_paths_vtp(snakemake.output.tracks, paths)
    log.info("%s: %d passes of %d clumps", case.run_id, paths.n_passes, len(set(paths.clump_id.tolist())))
