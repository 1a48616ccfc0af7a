"""Snakemake adapter: the study's shortcut (RTD from one residence time after the tracer is marked, LTI beyond)
measured against the full analysis of one recirculation run."""

from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.studies.silo_recirculation.rtd_plots import plot_vrr_versus_period
from siloflow.analysis.studies.silo_recirculation.shortcut import shortcut_rows, tracks_until
from siloflow.analysis.studies.silo_recirculation.configured import analyse_configured
from siloflow.analysis.studies.silo_recirculation.tracks_io import load_tracks
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    out = snakemake.output
    settings = snakemake.params.blending
    case = snakemake.params.case
    tracks = load_tracks(snakemake.input.tracks).tracks
    # the recirculating part only, as the analysis rule takes it: the discharge after it is no recirculation
    reentry_stop = case.reentry_stop(tracks.times[0])
    tracks = tracks if reentry_stop is None else tracks.until(reentry_stop)
    bottom, top = case.domain_z
    tracer = settings["tracer"]
    # the full run again, without what the shortcut cannot have: a few seconds, and the analysis rule's product
    # (its tables) does not hold the arrays the comparison needs
    full = analyse_configured(tracks, bottom, top, settings, with_transit=False)
    stop_nr = tracer["start_recirculations"] + settings["shortcut"]["residence_times"]
    t_stop = full.timing.t_open + stop_nr * full.timing.residence_time
    log.info("full run: Nr = %.2f; the shortcut stops at Nr = %.2f (t = %.4g s)", full.timing.recirculations, stop_nr,
             t_stop)
    short = analyse_configured(tracks_until(tracks, t_stop), bottom, top, settings, with_transit=False)
    rows = shortcut_rows(full, short)
    write_flow_table(out.table, rows)
    for row in rows:
        log.info("%s: t_m %.4g +- %.2g s (full) vs %.4g +- %.2g s (shortcut, %.0f %% of its tracer out), "
                 "%.2f errors apart; homogenised after Nr %s (direct), %s (model, full RTD), %s (model, shortcut); "
                 "model RMS difference %.3g; largest VRR difference %.3g", row["layout"], row["t_mean_full_s"],
                 row["t_mean_full_error_s"], row["t_mean_shortcut_s"], row["t_mean_shortcut_error_s"],
                 100.0 * row["tracer_exited_shortcut"], row["t_mean_difference_over_error"],
                 row["homogenised_direct"], row["homogenised_model_full"], row["homogenised_model_shortcut"],
                 row["model_rms_difference"], row["vrr_largest_relative_difference"])
    plot_vrr_versus_period(
        full.vrr_sine.period_over_tm,
        [(f"sine, full run (Nr {full.timing.recirculations:.1f})", full.vrr_sine.vrr),
         (f"sine, shortcut (Nr {short.timing.recirculations:.1f})", short.vrr_sine.vrr)],
        out.plot, f"Shortcut vs full run, {case.pattern} ({case.run_id})",
    )
