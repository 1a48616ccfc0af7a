"""Snakemake adapter: the blender's pathlines, virtual tracers released across the width through its steady field as
its study releases them (:func:`siloflow.analysis.studies.blender.tracers.tracer_pathlines`, ``blender.pathlines``), as a
ParaView .vtp in the plane of mid-depth, each line carrying its residence time."""

from siloflow.analysis.io.vtk_lines import write_pathlines_vtp
from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.tracers import tracer_pathlines
from siloflow.analysis.studies.blender.window_fields_io import read_planar_fields
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    case = snakemake.params.case
    settings = snakemake.params.pathlines
    steady, _ = read_planar_fields(snakemake.input.fields)
    pathlines = tracer_pathlines(BlenderField.from_planar(steady), settings["release_height"], settings["max_time"],
                                 spacing=settings["spacing"], dt=settings["integration_step"])
    write_pathlines_vtp(snakemake.output.pathlines, pathlines.pathlines, plane_y=0.5 * case.silo.depth)
    log.info("%s: %d pathlines, %d did not leave within %.4g s", case.run_id, pathlines.release_x.size,
             pathlines.n_not_exited, settings["max_time"])
