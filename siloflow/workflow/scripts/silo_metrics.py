"""Snakemake adapter: flow metrics, tables and the discharge plot of one flat-bottom silo run."""

from pathlib import Path

from siloflow.model.frames import clumps_from_frame
from siloflow.model.record import read_run_record
from siloflow.analysis.studies.silo_flat.plots import plot_discharge
from siloflow.analysis.studies.silo_flat.metrics import flow_table_row, silo_flow_metrics
from siloflow.analysis.io.tables import write_discharge_history_csv, write_flow_table, write_json
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    case = snakemake.params.case
    analysis = snakemake.params.analysis
    beverloo = analysis["beverloo"]

    frames = engine_named(record.engine).read_frames(run_dir, record, on_damaged=snakemake.params.on_damaged)
    discharge = [clumps_from_frame(frame) for frame in frames if frame.step >= record.open_step]
    log.info("%d discharge frames of %s", len(discharge), run_dir)

    metrics = silo_flow_metrics(
        discharge,
        width=case.width,
        depth=case.depth,
        outlet_width=case.outlet_width,
        particle_diameter=beverloo["particle_diameter"] or case.particle.equivalent_diameter,
        steady_window=tuple(analysis["steady_window"]),
        discharge_coefficient=beverloo["discharge_coefficient"],
        shape_coefficient=beverloo["shape_coefficient"],
    )
    row = flow_table_row(case.run_id, case.particle.name, case.fill.n_clumps, metrics)
    write_flow_table(snakemake.output.table, [row])
    write_discharge_history_csv(snakemake.output.history, metrics.history)
    write_json(snakemake.output.summary, {**row, "beverloo": beverloo, "steady_window": analysis["steady_window"]})
    plot_discharge(metrics.history, metrics.fit, metrics.beverloo_rate, snakemake.output.plot,
                   title=f"Flat-bottom silo {case.run_id}", rate_error=metrics.mass_flow_rate_error)
    log.info("mass flow rate %.4g +- %.2g kg/s (batch means; least-squares %.2g), Beverloo %.4g kg/s "
             "(ratio %.3f +- %.2g), bulk density %.1f +- %.2g kg/m3",
             metrics.fit.mass_flow_rate, metrics.mass_flow_rate_error, metrics.fit.standard_error,
             metrics.beverloo_rate, metrics.beverloo_ratio, metrics.beverloo_ratio_error,
             metrics.bulk_density.density, metrics.bulk_density_error)
