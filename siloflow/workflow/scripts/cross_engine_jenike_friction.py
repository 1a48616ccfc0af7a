"""Snakemake adapter: the bulk friction of one Jenike run of the cross-engine check."""

from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.io.tables import write_json
from siloflow.calibration.friction import bulk_friction_of_shear
from siloflow.calibration.shear import shear_signals
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    history = engine_named(record.engine).wall_forces(run_dir, record)
    friction, window = bulk_friction_of_shear(
        shear_signals(history, record.labels["shear_start_s"], record.labels["shear_end_s"]))
    summary = {"engine": record.engine, "run_id": record.run_id, "point": snakemake.params.point,
               "bulk_friction": friction.coefficient, "bulk_friction_error": friction.standard_error,
               "bottom_bulk_friction": friction.bottom_coefficient, "window": window, "n_clumps": record.n_clumps}
    write_json(snakemake.output.metrics, summary)
    log.info("%s", summary)
