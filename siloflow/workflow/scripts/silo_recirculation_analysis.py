"""Snakemake adapter: direct blending measurement, RTDs (particle ids and Eulerian) and LTI predictions of one run,
and the VRR of the discharge after its recirculations when it has one."""

from pathlib import Path

import numpy as np

from siloflow.analysis.studies.silo_recirculation.bulk_density import flowing_bulk_density
from siloflow.analysis.studies.silo_recirculation.tracks_io import load_tracks
from siloflow.analysis.studies.silo_recirculation.plots import (
    plot_coloured_snapshots,
    plot_outlet_concentration,
    plot_vrr_versus_recirculations,
)
from siloflow.analysis.studies.silo_recirculation.rtd_plots import (
    plot_lti_comparison,
    plot_recirculation_model,
    plot_rtd_comparison,
    plot_vrr_versus_period,
)
from siloflow.analysis.studies.silo_recirculation.configured import analyse_configured
from siloflow.analysis.studies.silo_recirculation.final_discharge import final_discharge
from siloflow.analysis.studies.silo_recirculation.study import main_run_eulerian_rtd, snapshot_frames
from siloflow.analysis.studies.silo_recirculation.tables import (
    blending_summary,
    clumps_per_window,
    concentration_rows,
    johanson_curve,
    model_rows,
    rtd_rows,
    vrr_period_rows,
    vrr_rows,
)
from siloflow.analysis.io.tables import write_flow_table, write_json
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    out = snakemake.output
    settings = snakemake.params.blending
    case = snakemake.params.case
    plot_format = snakemake.params.plot_format  # plots.format, the suffix of the plots named here
    silo = case.silo
    whole = load_tracks(snakemake.input.tracks)
    bottom, top = case.domain_z
    lti = settings["lti"]
    # with a discharge after the recirculations, every figure but that discharge's is of the recirculating part:
    # the frames up to the stop of the re-entry (the tracks' clock starts at the opening)
    t_stop = case.reentry_stop(whole.tracks.times[0])
    loaded = whole if t_stop is None else whole.until(t_stop)
    tracks = loaded.tracks
    result = analyse_configured(tracks, bottom, top, settings)
    timing = result.timing
    log.info("t_res %.4g +- %.2g s (holdup %.1f +- %.2g clumps, throughput %.1f +- %.2g clumps/s), run covers "
             "Nr = %.2f", timing.residence_time, timing.residence_time_error, timing.holdup, timing.holdup_error,
             timing.throughput, timing.throughput_error, timing.recirculations)
    transit, tracer_transit = result.transit, result.tracer_transit_mean
    log.info("Little's law on the passes out within %.3g s: %.4g +- %.2g s (holdup %.1f, %.3f of the throughput); "
             "tracer mean within it %.4g +- %.2g s; slow holdup %.1f clumps (%d never left), which t_res counts "
             "and the tracer mean cannot", transit.horizon, transit.transit.residence_time.value,
             transit.transit.residence_time.std_error, transit.transit.holdup.value, transit.transit_fraction.value,
             tracer_transit.value, tracer_transit.std_error, transit.slow_holdup.value, transit.stagnant_clumps)
    eulerian = settings["eulerian"]
    eulerian_rtd = main_run_eulerian_rtd(
        tracks, loaded.velocity, loaded.mass, result, silo.width, silo.depth, top, silo.outlet_width,
        eulerian["bin_size"], eulerian["integration_step"], eulerian["max_recirculations"],
        settings["tracer"]["bins"],
    )
    silo_rtd = result.rtd.silo
    title = f"{case.pattern} ({case.run_id})"

    # --- tables
    write_flow_table(out.concentration, concentration_rows(result))
    write_flow_table(out.vrr, vrr_rows(result))
    write_flow_table(out.model, model_rows(result))
    johanson = johanson_curve(result)
    write_flow_table(out.rtd, rtd_rows(result, eulerian_rtd, johanson))
    write_flow_table(out.vrr_period, vrr_period_rows(result))
    low, high = settings["bulk_density_slab"]
    density = flowing_bulk_density(
        tracks.times, tracks.position[:, :, 2], loaded.mass, silo.width, silo.depth,
        (low * silo.fill_height, high * silo.fill_height), tracks.times[0] + timing.residence_time,
    )
    log.info("bulk density in the slab %s m: settled %.1f, flowing %.1f +- %.2g kg/m3, drop %.4f +- %.2g",
             density.slab, density.settled, density.flowing, density.flowing_error, density.drop, density.drop_error)
    # the whole run's tracks of the recirculating part's clumps: LIGGGHTS gives what the fixed boundary leaves of a
    # clump a new id, below the outlet already
    discharge = None if t_stop is None else final_discharge(whole.tracks.of_clumps(tracks.clump_id), result, t_stop,
                                                            bottom, top)
    if discharge is not None:
        used = discharge.windows
        log.info("discharge after Nr = %.2f from t = %.4g s: %d windows (%d clumps) to %.4g s (%s), %.1f %% of its "
                 "%d crossings left out, %d re-entries after the stop; VRR %s", discharge.recirculations, t_stop,
                 used.n_windows, used.clumps, used.end, "faded" if used.faded else "the record ended first",
                 100.0 * used.left_out_fraction, used.crossings, discharge.reentries,
                 {name: round(layout.vrr, 2) for name, layout in discharge.layouts.items()})
    summary = blending_summary(result, eulerian_rtd, eulerian["bin_size"], run_id=case.run_id,
                               flow_pattern=case.pattern, estimated_residence_time=case.estimated_residence_time,
                               nominal_residence_time=case.nominal_residence_time,
                               final_discharge=discharge)
    write_json(out.summary, {**summary, **density.summary()})

    # --- plots
    plot_outlet_concentration(
        [(f"{l.layout.name}", l.recirculation_number, l.concentration.concentration) for l in result.layouts],
        result.layouts[0].layout.blue_fraction, out.concentration_plot, f"Outlet concentration, {title}",
        tolerance=lti["tolerance"],
    )
    plot_vrr_versus_recirculations(
        [(l.layout.name, l.vrr.recirculation_number, l.vrr.vrr, None, l.vrr.vrr_error) for l in result.layouts],
        out.vrr_plot, f"VRR per recirculation, {title}", noise_limit=clumps_per_window(result),
    )
    plot_rtd_comparison(
        [("particle ids", silo_rtd.time, silo_rtd.E, silo_rtd.t_mean),
         (f"Eulerian, {1000 * eulerian['bin_size']:g} mm bins", eulerian_rtd.time, eulerian_rtd.E, eulerian_rtd.t_mean),
         (f"Johanson V1={result.rtd.johanson_V1:.2f}, P={result.rtd.johanson_P:.2f}", silo_rtd.time, johanson,
          silo_rtd.t_mean)],
        out.rtd_plot, f"RTD, {title}",
    )
    plot_vrr_versus_period(
        result.vrr_sine.period_over_tm, [("sine", result.vrr_sine.vrr), ("square", result.vrr_square.vrr)],
        out.vrr_period_plot, f"LTI continuous mode, {title}",
    )
    Path(out.snapshots).mkdir(parents=True, exist_ok=True)
    Path(out.per_layout).mkdir(parents=True, exist_ok=True)
    frames = snapshot_frames(tracks.times, timing.t_open, timing.residence_time, settings["snapshots"])
    for index, layout in enumerate(result.layouts):
        name = layout.layout.name
        series = [("direct (particles)", layout.concentration.concentration, "direct"),
                  ("renewal prediction, measured loop RTD", layout.predicted, "predicted"),
                  ("renewal prediction, Johanson RTD", layout.predicted_johanson, "predicted"),
                  ("first exits of the initial fill", layout.first_pass.concentration, "first pass")]
        lti_paths = [Path(out.per_layout) / f"lti_{name}.{plot_format}"] + ([Path(out.lti_plot)] if index == 0 else [])
        for path in lti_paths:
            plot_lti_comparison(layout.recirculation_number, series, path, f"{name}: direct vs LTI, {title}",
                                blue_fraction=layout.layout.blue_fraction, x_label="Nr [-]")
        model_paths = ([Path(out.per_layout) / f"model_{name}.{plot_format}"]
                       + ([Path(out.model_plot)] if index == 0 else []))
        for path in model_paths:
            plot_recirculation_model(layout.model_time_nr, layout.model_concentration, layout.layout.blue_fraction,
                                     layout.model_homogenised_after, path,
                                     f"{name}: batch recirculated through the measured RTD, {title}",
                                     tolerance=lti["tolerance"])
        snapshots = [
            (round((tracks.times[k] - timing.t_open) / timing.residence_time, 2), tracks.position[k, :, 0],
             tracks.position[k, :, 2], layout.colours)
            for k in frames
        ]
        plot_coloured_snapshots(snapshots, silo.width, silo.outlet_width, top, case.channel_length,
                                Path(out.snapshots) / f"{name}.{plot_format}", f"{name}, {title}")
        log.info("%s: VRR per recirculation %s, predicted %s, RMS(prediction - direct) %.3f, homogenised after Nr %s",
                 name, np.round(layout.vrr.vrr, 2).tolist(), np.round(layout.vrr_predicted.vrr, 2).tolist(),
                 layout.prediction_rms_error(), layout.homogenised_after)
    log.info("RTD ids: t_m %.4g s, t_s/t_d %.3f; Eulerian: t_m %.4g s", silo_rtd.t_mean,
             silo_rtd.t_first / silo_rtd.t_last, eulerian_rtd.t_mean)
