"""Snakemake adapter: the bulk friction of one Jenike run of the Bayesian calibration, or the record that it failed."""

import json
from pathlib import Path

from siloflow.analysis.io.tables import write_json
from siloflow.calibration.friction import bulk_friction_of_shear
from siloflow.calibration.shear_record import shear_test_summary
from siloflow.calibration.shear import shear_signals
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to
from siloflow.engines.layout import RUN_RECORD
from siloflow.model.record import read_run_record

with logged_to(snakemake.log[0]) as log:
    outcome = json.loads(Path(snakemake.input.outcome).read_text())
    if not outcome["completed"]:
        write_json(snakemake.output.summary, {"run_id": outcome["run_id"], "failed": True, "error": outcome["error"]})
        log.warning("run %s failed: no bulk friction", outcome["run_id"])
    else:
        run_dir = Path(snakemake.input.outcome).parent
        record = read_run_record(run_dir / RUN_RECORD)
        signals = shear_signals(engine_named(record.engine).wall_forces(run_dir, record), record.labels["shear_start_s"],
                                record.labels["shear_end_s"])
        friction, window_method = bulk_friction_of_shear(signals)
        write_json(snakemake.output.summary, shear_test_summary(snakemake.params.point, record.run_id, record.n_clumps,
                                                                friction, window_method))
        log.info("bulk friction %.4f +- %.4f (%s window)", friction.coefficient, friction.standard_error, window_method)
