"""Snakemake adapter: coarse-grained fields, profiles, flow channel boundary, kinematic constant and centreline
velocity of a flat-bottom silo run siloflow did not make. Reads its dumps through its engine, calls
:func:`siloflow.analysis.studies.silo_flat.existing_run.existing_field_study`, writes the tables, VTI/PVD files and plots
(:func:`siloflow.analysis.io.silo_field_study.write_silo_field_study`), and ``analyses.json``: what was read, made and skipped
(what needs contact or wall forces), and why."""

import json
from pathlib import Path

from siloflow.model.existing_run import ExistingSiloRun
from siloflow.analysis.io.silo_field_study import write_silo_field_study
from siloflow.analysis.io.tables import write_json
from siloflow.analysis.studies.silo_flat.existing_run import analyses_summary, existing_field_study
from siloflow.analysis.studies.silo_flat.field_study import SiloFieldOptions
from siloflow.analysis.studies.validation.figure_findings import kinematic_findings
from siloflow.engines.existing_runs import read_existing_frames
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run = ExistingSiloRun.from_config(snakemake.wildcards.existing, snakemake.params.run)
    flow = json.loads(Path(snakemake.input.flow).read_text())
    options = SiloFieldOptions.from_config(snakemake.params.settings)
    frames = read_existing_frames(run, on_damaged=snakemake.params.on_damaged)

    study = existing_field_study(frames, run, options,
                                 steady_window=(flow["steady_window_start_s"], flow["steady_window_end_s"]),
                                 bulk_density=flow["filling_bulk_density_kg_m3"],
                                 bulk_density_error=flow.get("filling_bulk_density_kg_m3_error"))
    log.info("grid %s cells of %s m, %d frames", study.grid.shape, study.grid.spacing, len(study.fields))

    write_silo_field_study(snakemake.output, study, options.vtk_every, flow["mass_flow_rate_kg_s"], run.width,
                           run.outlet_width, run.name, kinematic_findings=kinematic_findings())
    summary = analyses_summary(run, study.steps, flow["settled_step"], snakemake.params.made)
    write_json(snakemake.output.analyses, summary)
    for skipped in summary["skipped"]:
        log.info("skipped %s: %s", skipped["analysis"], skipped["reason"])
