"""Snakemake adapter: coarse-grained fields, profiles, flow channel boundary, kinematic constant, Janssen and
force chains of one flat-bottom silo run. Reads the run, calls
:func:`siloflow.analysis.studies.silo_flat.field_study.analyse_silo_fields`, writes the tables, VTI/PVD files and plots
(:func:`siloflow.analysis.io.silo_field_study.write_silo_field_study`, and those that need contacts here)."""

import json
from pathlib import Path

from siloflow.model.frames import clumps_from_frame
from siloflow.model.record import read_run_record
from siloflow.analysis.io.fields import write_fields_vti
from siloflow.analysis.io.silo_field_study import write_silo_field_study
from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.studies.silo_flat.field_study import SiloDimensions, SiloFieldOptions, analyse_silo_fields, janssen_rows
from siloflow.analysis.studies.silo_flat.plots import plot_force_chains, plot_janssen
from siloflow.analysis.studies.validation.figure_findings import janssen_findings, kinematic_findings
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    engine = engine_named(record.engine)
    case = snakemake.params.case
    flow = json.loads(Path(snakemake.input.flow).read_text())
    silo = SiloDimensions.from_case(case)
    options = SiloFieldOptions.from_config(snakemake.params.settings)
    frames = [clumps_from_frame(frame) for frame in
              engine.read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
              if frame.step >= record.open_step]
    contacts = engine.contacts(run_dir, record, "pair")[-1]

    study = analyse_silo_fields(frames, contacts, silo, options,
                                steady_window=(flow["steady_window_start_s"], flow["steady_window_end_s"]),
                                bulk_density=flow["filling_bulk_density_kg_m3"],
                                bulk_density_error=flow.get("filling_bulk_density_kg_m3_error"))
    log.info("grid %s cells of %s m, %d frames", study.grid.shape, study.grid.spacing, len(study.fields))

    fields_dir = write_silo_field_study(snakemake.output, study, options.vtk_every, flow["mass_flow_rate_kg_s"],
                                        silo.width, silo.outlet_width, case.run_id,
                                        kinematic_findings=kinematic_findings())
    # What needs the settled fill's contacts: its contact stress (ParaView, beside the time series), Janssen, chains.
    write_fields_vti(fields_dir / "settled_stress.vti", study.grid, study.fields[0], time=0.0,
                     extra_arrays={"contact_stress": study.stress})
    write_flow_table(snakemake.output.janssen, janssen_rows(study.janssen))
    plot_janssen(study.janssen, snakemake.output.janssen_plot, "Vertical stress at the end of filling",
                 findings=janssen_findings())
    plot_force_chains(study.segments, silo.width, silo.outlet_width, study.top, snakemake.output.force_chain_plot,
                      f"Force chains in a {1e3 * options.force_chain_slice:g} mm slice")
    log.info("profile flow rate %.4g kg/s vs outflow %.4g kg/s (ratio %.3f)", study.profile_rate,
             flow["mass_flow_rate_kg_s"], study.profile_rate / flow["mass_flow_rate_kg_s"])
