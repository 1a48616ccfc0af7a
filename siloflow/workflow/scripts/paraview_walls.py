"""Snakemake adapter: a run's wall meshes, as its case kind's registry entry builds them from the case, in one .vtp
(:func:`siloflow.analysis.io.vtk_walls.write_walls_vtp`): the same walls on either engine."""

from siloflow.analysis.io.vtk_walls import write_walls_vtp
from siloflow.engines.logs import logged_to
from siloflow.model.cases.kinds import case_kind

with logged_to(snakemake.log[0]) as log:
    meshes = case_kind(snakemake.params.kind).walls(snakemake.params.case)
    write_walls_vtp(snakemake.output.walls, meshes)
    log.info("%s: walls %s", snakemake.params.case.run_id, ", ".join(meshes))
