"""Snakemake adapter: the blender study of one run (profiles, passages, flow channel, pathlines, RTD, modes), and the
figures the study's PIV gives on the depth average and on the wall layer (the vertical section's uniformity, the
passages at the insert outlet)."""

import json
from functools import partial
from pathlib import Path

from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.errors import steady_flow_rate_estimate
from siloflow.analysis.studies.blender.sections import (
    exclusion_of,
    section_heights,
    section_uniformity,
    wall_layer_summary,
)
from siloflow.analysis.studies.blender.window_fields import wall_layer_depth
from siloflow.analysis.studies.blender.window_fields_io import (
    read_frame_fields,
    read_planar_fields,
    read_wall_layer_fields,
)
from siloflow.analysis.studies.blender.plots import (
    plot_channel_boundary,
    plot_continuous_mode,
    plot_discontinuous_mode,
    plot_passage_distributions,
    plot_profiles_over_time,
    plot_rtd_theta,
    plot_tracer_pathlines,
)
from siloflow.analysis.studies.blender.study import (
    BlenderSettings,
    analyse_blender,
    key_heights,
    study_metrics,
    top_internal,
)
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.figure_findings import insert_findings
from siloflow.analysis.studies.blender.tables import (
    blender_summary,
    profile_rows,
    residence_rows,
    rtd_rows,
    vrr_period_rows,
)
from siloflow.analysis.io.tables import write_flow_table, write_json
from siloflow.model.cases.blender_passages import annulus_bounds, geometry_summary
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    blender = snakemake.params.blender
    case = snakemake.params.case
    flow = json.loads(Path(snakemake.input.flow).read_text())
    geometry = case.geometry
    # the insert's key levels as the case summary states them, for the profile heights and blender.json
    insert = geometry_summary(geometry)
    steady, windows = read_planar_fields(snakemake.input.fields)
    settings = BlenderSettings.from_config(blender)
    heights = key_heights(insert, blender["bin_size"], blender["fill_height"], blender["profile_heights_above"])
    window_times = [0.5 * (w.window[0] + w.window[1]) - windows[0].window[0] for w in windows]
    study = analyse_blender(BlenderField.from_planar(steady), [BlenderField.from_planar(w) for w in windows],
                            window_times, heights, partial(annulus_bounds, geometry), geometry.wall_x, settings)
    name = f"{case.configuration} ({case.gravity_factor:g} g)"
    rate = steady_flow_rate_estimate(flow["time_since_open_s"], flow["discharged_mass_kg"], case.steady_window)
    frames = [BlenderField.from_planar(frame) for frame in read_frame_fields(snakemake.input.frames)]
    metrics = study_metrics(case.configuration, study, flow["mass_flow_rate_kg_s"], settings.comparison_fractions,
                            mass_flow_rate_error=rate.std_error, frames=frames, resolution=settings.integration_step)
    # the vertical section above every internal wall; "close to the tube" is within one tube width of its outline
    section = section_heights(heights, insert["z_transition"], top_internal(insert))
    tube = ((geometry.tube_half_width + 0.5 * geometry.wall_thickness, geometry.z_tube_inlet)
            if geometry.has_tube else None)
    exclusion = exclusion_of(insert["tube_width"])
    wall_steady, wall_frames = read_wall_layer_fields(snakemake.input.wall_layer)
    levels = {name: (heights[name], annulus_bounds(geometry, heights[name]))
              for name in ("insert outlet", "insert inlet") if name in heights}
    wall_layer = wall_layer_summary(
        BlenderField.from_planar(wall_steady), [BlenderField.from_planar(frame) for frame in wall_frames],
        wall_layer_depth(case.silo.particle.equivalent_diameter), levels, section, tube, exclusion)
    write_json(snakemake.output.summary, blender_summary(
        flow, study, metrics, run_id=case.run_id, configuration=case.configuration,
        gravity_factor=case.gravity_factor, geometry=insert, mode=case.mode, n_clumps=case.silo.fill.n_clumps,
        steady_window=case.steady_window,
        vertical_section=section_uniformity(BlenderField.from_planar(steady), frames, section, tube, exclusion),
        wall_layer=wall_layer))
    write_flow_table(snakemake.output.profiles, profile_rows(study.profiles))
    write_flow_table(snakemake.output.residence, residence_rows(study.pathlines))
    write_flow_table(snakemake.output.rtd, rtd_rows(study.rtd.rtd))
    write_flow_table(snakemake.output.vrr, vrr_period_rows(study.continuous))

    plot_profiles_over_time(study.profiles, snakemake.output.profiles_plot, f"Normalised v_z profiles: {name}")
    inlet = study.inlet if study.inlet is not None else study.outlet
    plot_passage_distributions(inlet, study.outlet, snakemake.output.distribution_plot,
                               f"Velocity across the insert inlet and outlet: {name}",
                               findings=insert_findings(case.configuration,
                                                        AgreementTolerances.from_config(snakemake.params.validation)))
    plot_channel_boundary(BlenderField.from_planar(steady), study.boundary, snakemake.output.fcb_plot,
                          f"Flow channel boundary (10 % of centreline, wall velocity subtracted): {name}")
    plot_tracer_pathlines(study.pathlines, snakemake.output.pathlines_plot, f"Pathlines and residence times: {name}")
    plot_rtd_theta({name: study.rtd}, snakemake.output.rtd_plot, f"RTD of a {settings.rtd_tracer_fraction:.0%} tracer: {name}")
    plot_discontinuous_mode(study.discontinuous, snakemake.output.discontinuous_plot,
                            f"Discontinuous mode ({settings.discontinuous_tracer_fraction:.0%} tracer on top): {name}")
    plot_continuous_mode({name: study.continuous}, snakemake.output.vrr_plot, f"Continuous mode, sine inputs: {name}")
    log.info("%s: flow %.4g +- %.2g kg/s (batch rate of %d batches); exterior/interior/tube v_z %.3g/%.3g/%.3g "
             "+- %.2g/%.2g/%.2g m/s (batch means of %d frames); RTD t_m %.3g +- %.2g s, sigma/t_m %.3g +- %.2g, "
             "t_s/t_d %.3g +- %.2g; homogenised after %.3g passes; VRR %s +- %s (ceiling %.4g)", case.run_id,
             metrics.mass_flow_rate, metrics.mass_flow_rate_error, rate.n, metrics.exterior_v_z, metrics.interior_v_z,
             metrics.tube_v_z, metrics.exterior_v_z_error, metrics.interior_v_z_error, metrics.tube_v_z_error,
             len(frames), metrics.rtd_mean, metrics.rtd_mean_error, metrics.rtd_spread, metrics.rtd_spread_error,
             metrics.ts_over_td, metrics.ts_over_td_error, metrics.recirculations_to_homogenise,
             metrics.vrr_by_period, metrics.vrr_errors, metrics.vrr_ceiling)
