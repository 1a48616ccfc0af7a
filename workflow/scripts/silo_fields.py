"""Snakemake adapter: coarse-grained fields, profiles, flow channel boundary, kinematic constant, Janssen and
force chains of one flat-bottom silo run."""

import json
import math
from pathlib import Path

import numpy as np

from analysis.numerics.field_ops import depth_average, front_wall_slice
from analysis.numerics.force_chains import force_chain_segments
from analysis.data.frames import clumps_from_frame
from analysis.data.record import read_run_record
from analysis.io.fields import save_fields_npz, write_fields_vti, write_pvd
from analysis.numerics.flow import column_surface_heights
from analysis.numerics.profiles import profile_flow_rate, velocity_profile
from analysis.studies.silo_flat.fields import (
    FieldSettings,
    analyse_profiles,
    centreline_velocity,
    clump_fields,
    compare_janssen,
    contact_stress_field,
    profile_mass_flow_rate,
    silo_grid,
    time_average,
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
from analysis.io.tables import write_flow_table, write_json
from engines.interface import engine_named
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    engine = engine_named(record.engine)
    case = json.loads(Path(snakemake.input.case).read_text())
    flow = json.loads(Path(snakemake.input.flow).read_text())
    options = snakemake.params.settings
    width, depth, outlet = case["width_m"], case["depth_m"], case["outlet_width_m"]
    radius = 0.5 * case["equivalent_diameter_m"]
    settings = FieldSettings(tuple(options["spacing"]), options["kernel"], options["width_radii"] * radius,
                             options["cutoff"])

    frames = [clumps_from_frame(frame) for frame in
              engine.read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
              if frame.step >= record.open_step]
    settled = frames[0]
    surface = column_surface_heights(settled.position[:, 0], settled.position[:, 2], radius, width,
                                     max(1, int(width / (4 * 2 * radius))))
    top = float(np.nanmax(surface))
    grid = silo_grid(width, depth, top, settings.spacing)
    times = np.array([frame.time for frame in frames]) - frames[0].time
    fields = [clump_fields(frame, grid, settings) for frame in frames]
    log.info("grid %s cells of %s m, %d frames", grid.shape, grid.spacing, len(fields))

    # ParaView time series (every n-th frame) and the time-averaged field.
    fields_dir = Path(snakemake.output.pvd).parent
    entries = []
    for index in range(0, len(fields), options["vtk_every"]):
        name = f"fields_{frames[index].step}.vti"
        write_fields_vti(fields_dir / name, grid, fields[index], time=float(times[index]))
        entries.append((float(times[index]), name))
    write_pvd(snakemake.output.pvd, entries)
    window = tuple(options["average_window"] or (flow["steady_window_start_s"], flow["steady_window_end_s"]))
    averaged = time_average(fields, times, window)
    write_fields_vti(fields_dir / "averaged.vti", grid, averaged)
    save_fields_npz(snakemake.output.arrays, averaged)
    averaged_depth = depth_average(averaged)

    # Profiles at the configured heights that lie inside the settled fill, away from the floor row.
    heights = [z for z in options["profile_heights"] if grid.z[0] <= z <= min(top, grid.z[-1]) - settings.spacing[2]]
    if not heights:
        raise ValueError(f"no profile height lies inside the fill (surface at {top:.3f} m): lower fields.profile_heights")
    profiles = analyse_profiles(averaged_depth, heights, options["fcb_fractions"], options["subtract_wall_velocity"],
                                kernel_width=settings.width)
    # What a camera behind the front wall sees, next to the depth average.
    front = analyse_profiles(front_wall_slice(averaged), heights, options["fcb_fractions"])
    write_flow_table(snakemake.output.profiles, [
        {"z_m": z, "x_m": x, "v_z_m_s": vz, "v_x_m_s": vx, "u_kinematic_m_s": u,
         "v_z_front_wall_m_s": fz, "v_x_front_wall_m_s": fx}
        for i, z in enumerate(profiles.heights)
        for x, vz, vx, u, fz, fx in zip(profiles.x, profiles.v_z[i], profiles.v_x[i], profiles.kinematic_u[i],
                                        front.v_z[i], front.v_x[i])
    ])
    write_flow_table(snakemake.output.boundaries, [
        {"z_m": z, "fraction": f, "x_left_m": profiles.fcb_left[i, j], "x_right_m": profiles.fcb_right[i, j]}
        for i, z in enumerate(profiles.heights) for j, f in enumerate(profiles.fcb_fractions)
    ])
    write_flow_table(snakemake.output.kinematic, [
        {"z_m": z, "B_m": b} for z, b in zip(profiles.heights, profiles.kinematic_B)
    ])

    depth_series = [depth_average(f) for f in fields]
    centre = centreline_velocity(depth_series, heights)
    instantaneous_rows = []
    for t, frame_fields in zip(times, depth_series):
        for z in heights:
            profile = velocity_profile(frame_fields, z)
            instantaneous_rows.extend(
                {"time_s": t, "z_m": z, "x_m": x, "v_z_m_s": vz, "v_x_m_s": vx}
                for x, vz, vx in zip(profile.x, profile.v_z, profile.v_x))
    write_flow_table(snakemake.output.instantaneous, instantaneous_rows)
    write_flow_table(snakemake.output.centreline, [
        {"time_s": t, **{f"v_z_at_{1e3 * z:g}mm_m_s": centre[i, j] for j, z in enumerate(heights)}}
        for i, t in enumerate(times)
    ])

    # Mass flow rate through the lowest profile height, from the averaged momentum density.
    profile_rate = profile_mass_flow_rate(averaged_depth, heights[0], depth)
    # The same with the study's formula W = rho_b T integral(v_z dx), at the filling bulk density.
    bulk_rate = profile_flow_rate(profiles.x, profiles.v_z[0], flow["filling_bulk_density_kg_m3"], depth)

    # Janssen: mean vertical contact stress of the settled fill against the formula.
    contacts = engine.contacts(run_dir, record, "pair")[-1]
    stress = contact_stress_field(contacts, grid, settings)
    # The settled fill with its contact stress (compression positive), for ParaView.
    write_fields_vti(fields_dir / "settled_stress.vti", grid, fields[0], time=0.0,
                     extra_arrays={"contact_stress": stress})
    janssen_options = options["janssen"]
    comparison = compare_janssen(
        stress, grid, float(np.nanmin(surface)), flow["filling_bulk_density_kg_m3"], width, depth,
        math.tan(math.radians(janssen_options["side_wall_friction_angle_deg"])),
        math.tan(math.radians(janssen_options["front_wall_friction_angle_deg"])),
        janssen_options["internal_friction_angle_deg"], margin=settings.cutoff * settings.width)
    write_flow_table(snakemake.output.janssen, [
        {"depth_below_surface_m": h, "sigma_v_dem_Pa": s, "sigma_v_janssen_Pa": j}
        for h, s, j in zip(comparison.depth_below_surface, comparison.simulated, comparison.janssen)
    ])
    particle_weight = case["clump_mass_kg"] * 9.81
    segments = force_chain_segments(contacts, 0.5 * depth, options["force_chain_slice"], cap=50 * particle_weight)

    summary = {
        "grid_shape": list(grid.shape),
        "grid_spacing_m": list(grid.spacing),
        "kernel": settings.kernel,
        "kernel_width_m": settings.width,
        "average_window_s": list(window),
        "profile_heights_m": heights,
        "profile_flow_height_m": heights[0],
        "profile_mass_flow_rate_kg_s": profile_rate,
        "outflow_mass_flow_rate_kg_s": flow["mass_flow_rate_kg_s"],
        "profile_over_outflow": profile_rate / flow["mass_flow_rate_kg_s"],
        "profile_bulk_density_mass_flow_rate_kg_s": bulk_rate,
        "kinematic_B_m": {f"{z:g}": b for z, b in zip(profiles.heights, profiles.kinematic_B)},
        "surface_height_m": top,
        "contacts": len(contacts),
    }
    write_json(snakemake.output.summary, summary)

    run = case["run_id"]
    plot_profiles_over_silo(profiles, width, outlet, top, snakemake.output.profile_plot, f"Time-averaged v_z, {run}")
    plot_velocity_contour(averaged_depth.grid.x, averaged_depth.grid.z, averaged_depth.velocity[:, 0, :, 2], width,
                          outlet, snakemake.output.contour_plot, f"Depth-averaged v_z, {run}")
    plot_kinematic_constant(profiles.heights, profiles.kinematic_B, snakemake.output.kinematic_plot,
                            "Kinematic constant B(z)")
    plot_kinematic_horizontal_velocity(profiles, snakemake.output.kinematic_u_plot,
                                       "Horizontal velocity: DEM against the kinematic model")
    plot_centreline_velocity(times, heights, centre, snakemake.output.centreline_plot, "Centreline velocity")
    plot_janssen(comparison, snakemake.output.janssen_plot, "Vertical stress at the end of filling")
    plot_force_chains(segments, width, outlet, top, snakemake.output.force_chain_plot,
                      f"Force chains in a {1e3 * options['force_chain_slice']:g} mm slice")
    log.info("profile flow rate %.4g kg/s vs outflow %.4g kg/s (ratio %.3f)", profile_rate,
             flow["mass_flow_rate_kg_s"], profile_rate / flow["mass_flow_rate_kg_s"])
