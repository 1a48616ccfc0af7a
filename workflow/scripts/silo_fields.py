"""Snakemake adapter: coarse-grained fields, profiles, flow channel boundary, kinematic constant, Janssen and
force chains of one flat-bottom silo run. Reads the run, calls
:func:`analysis.studies.silo_flat.field_study.analyse_silo_fields`, writes the tables, VTI/PVD files and plots."""

import json
from pathlib import Path

from analysis.data.frames import clumps_from_frame
from analysis.data.record import read_run_record
from analysis.io.fields import save_fields_npz, write_fields_vti, write_pvd
from analysis.io.tables import write_flow_table, write_json
from analysis.studies.silo_flat.field_study import (
    SiloDimensions,
    SiloFieldOptions,
    analyse_silo_fields,
    boundary_rows,
    centreline_rows,
    field_summary,
    instantaneous_profile_rows,
    janssen_rows,
    kinematic_rows,
    profile_rows,
    vtk_series,
)
from analysis.studies.silo_flat.plots import (
    plot_centreline_velocity,
    plot_force_chains,
    plot_janssen,
    plot_kinematic_constant,
    plot_kinematic_horizontal_velocity,
    plot_profiles_over_silo,
    plot_velocity_contour,
)
from engines.interface import engine_named
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    engine = engine_named(record.engine)
    case = json.loads(Path(snakemake.input.case).read_text())
    flow = json.loads(Path(snakemake.input.flow).read_text())
    silo = SiloDimensions.from_case_summary(case)
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

    # ParaView: a time series of every n-th frame, the time average, and the settled fill with its contact stress.
    fields_dir = Path(snakemake.output.pvd).parent
    series = vtk_series(study.steps, study.times, options.vtk_every)
    for index, time, name in series:
        write_fields_vti(fields_dir / name, study.grid, study.fields[index], time=time)
    write_pvd(snakemake.output.pvd, [(time, name) for _, time, name in series])
    write_fields_vti(fields_dir / "averaged.vti", study.grid, study.averaged)
    save_fields_npz(snakemake.output.arrays, study.averaged)
    write_fields_vti(fields_dir / "settled_stress.vti", study.grid, study.fields[0], time=0.0,
                     extra_arrays={"contact_stress": study.stress})

    write_flow_table(snakemake.output.profiles, profile_rows(study.profiles, study.front))
    write_flow_table(snakemake.output.boundaries, boundary_rows(study.profiles, study.uncertainty))
    write_flow_table(snakemake.output.kinematic, kinematic_rows(study.profiles, study.uncertainty))
    write_flow_table(snakemake.output.instantaneous,
                     instantaneous_profile_rows(study.times, study.depth_series, study.heights))
    write_flow_table(snakemake.output.centreline, centreline_rows(study.times, study.heights, study.centreline))
    write_flow_table(snakemake.output.janssen, janssen_rows(study.janssen))
    write_json(snakemake.output.summary, field_summary(study, flow["mass_flow_rate_kg_s"]))

    run = case["run_id"]
    plane = study.averaged_depth
    plot_profiles_over_silo(study.profiles, silo.width, silo.outlet_width, study.top, snakemake.output.profile_plot,
                            f"Time-averaged v_z, {run}", uncertainty=study.uncertainty)
    plot_velocity_contour(plane.grid.x, plane.grid.z, plane.velocity[:, 0, :, 2], silo.width, silo.outlet_width,
                          snakemake.output.contour_plot, f"Depth-averaged v_z, {run}")
    plot_kinematic_constant(study.profiles.heights, study.profiles.kinematic_B, snakemake.output.kinematic_plot,
                            "Kinematic constant B(z)", B_error=study.uncertainty.kinematic_B_error)
    plot_kinematic_horizontal_velocity(study.profiles, snakemake.output.kinematic_u_plot,
                                       "Horizontal velocity: DEM against the kinematic model")
    plot_centreline_velocity(study.times, study.heights, study.centreline, snakemake.output.centreline_plot,
                             "Centreline velocity")
    plot_janssen(study.janssen, snakemake.output.janssen_plot, "Vertical stress at the end of filling")
    plot_force_chains(study.segments, silo.width, silo.outlet_width, study.top, snakemake.output.force_chain_plot,
                      f"Force chains in a {1e3 * options.force_chain_slice:g} mm slice")
    log.info("profile flow rate %.4g kg/s vs outflow %.4g kg/s (ratio %.3f)", study.profile_rate,
             flow["mass_flow_rate_kg_s"], study.profile_rate / flow["mass_flow_rate_kg_s"])
