"""Snakemake adapter: flow metrics, tables and the discharge plot of a flat-bottom silo run siloflow did not make.
Reads its dumps through its engine, calls :func:`siloflow.analysis.studies.silo_flat.existing_run.existing_flow`, writes."""

from siloflow.model.existing_run import ExistingSiloRun
from siloflow.analysis.io.tables import write_discharge_history_csv, write_flow_table, write_json
from siloflow.analysis.studies.silo_flat.existing_run import existing_flow, existing_flow_row
from siloflow.analysis.studies.silo_flat.plots import plot_discharge
from siloflow.engines.existing_runs import read_existing_frames
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run = ExistingSiloRun.from_config(snakemake.wildcards.existing, snakemake.params.run)
    analysis = snakemake.params.analysis
    beverloo = analysis["beverloo"]
    frames = read_existing_frames(run, on_damaged=snakemake.params.on_damaged)
    log.info("%d frames of %s/%s", len(frames), run.folder, run.dumps)

    flow = existing_flow(frames, run, steady_window=tuple(analysis["steady_window"]),
                         discharge_coefficient=beverloo["discharge_coefficient"],
                         shape_coefficient=beverloo["shape_coefficient"],
                         beverloo_diameter=beverloo["particle_diameter"])
    metrics = flow.metrics
    row = existing_flow_row(run, flow)
    write_flow_table(snakemake.output.table, [row])
    write_discharge_history_csv(snakemake.output.history, metrics.history)
    write_json(snakemake.output.summary, {**row, "beverloo": beverloo, "steady_window": analysis["steady_window"],
                                          "settled_step": flow.settled_step})
    plot_discharge(metrics.history, metrics.fit, metrics.beverloo_rate, snakemake.output.plot,
                   title=f"Flat-bottom silo {run.name}", rate_error=metrics.mass_flow_rate_error)
    log.info("fill at the opening: step %d, %d particles, %.4g kg; discharged %.4g kg; mass flow rate %.4g +- %.2g "
             "kg/s, Beverloo %.4g kg/s, bulk density %.1f kg/m3", flow.settled_step, flow.n_particles,
             metrics.initial_mass, metrics.history.discharged_mass[-1], metrics.fit.mass_flow_rate,
             metrics.mass_flow_rate_error, metrics.beverloo_rate, metrics.bulk_density.density)
