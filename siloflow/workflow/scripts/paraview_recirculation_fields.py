"""Snakemake adapter: the recirculating silo's depth-averaged field of every frame (clump velocity and solid fraction
on the bins of its Eulerian RTD, ``silo_recirculation.eulerian.bin_size``, as the blender's fields:
:func:`siloflow.analysis.studies.blender.window_fields.frame_fields`) as a ParaView series on the simulated clock, in the
plane of mid-depth."""

from siloflow.analysis.io.planar_fields_vtk import write_planar_field_series
from siloflow.analysis.numerics.eulerian_rtd import silo_bins
from siloflow.analysis.studies.blender.window_fields import frame_fields
from siloflow.analysis.studies.silo_recirculation.tracks_io import load_tracks
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = snakemake.params.case
    silo = case.silo
    loaded = load_tracks(snakemake.input.tracks)
    times = loaded.tracks.times
    grid = silo_bins(silo.width, silo.depth, case.domain_z[1], snakemake.params.bin_size)
    fields = frame_fields(loaded.tracks.position, loaded.velocity, loaded.mass, times, grid, (times[0], times[-1]),
                          silo.particle.mass / silo.particle.volume)
    write_planar_field_series(snakemake.output.pvd, fields, [field.window[0] for field in fields], y=0.5 * silo.depth)
    log.info("%s: %d frame fields on %s bins of %s m", case.run_id, len(fields), grid.shape, grid.spacing)
