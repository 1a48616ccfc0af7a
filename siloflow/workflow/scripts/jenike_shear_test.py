"""Snakemake adapter of one Jenike shear test, for two rules: its bulk friction (output ``summary``, JSON) or its
force history with the window the bulk friction is read from (output ``plot``), whichever the rule names.

Each rule reads the force history and finds the window again rather than the plot reading the summary back: both
take about 0.05 s for a validation-scale test (a few hundred force samples), less than a job's own start."""

from pathlib import Path

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.charts import plot_force_history
from siloflow.calibration.friction import bulk_friction_of_shear
from siloflow.calibration.shear_record import shear_test_summary
from siloflow.model.record import read_run_record
from siloflow.calibration.shear import shear_signals
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    point = snakemake.params.point
    history = engine_named(record.engine).wall_forces(run_dir, record)
    signals = shear_signals(history, record.labels["shear_start_s"], record.labels["shear_end_s"])
    friction, window_method = bulk_friction_of_shear(signals)
    if "summary" in snakemake.output.keys():
        write_json(snakemake.output.summary,
                   shear_test_summary(point, record.run_id, record.n_clumps, friction, window_method))
        log.info("bulk friction %.4f +- %.4f (%s window), bottom side %.4f", friction.coefficient,
                 friction.standard_error, window_method, friction.bottom_coefficient)
    if "plot" in snakemake.output.keys():
        plot_force_history(signals, friction, snakemake.output.plot,
                           title=f"{point['shape']} {point['test']}: mu = {point['sliding_friction']}, "
                                 f"mu_r = {point['rolling_friction']}")
