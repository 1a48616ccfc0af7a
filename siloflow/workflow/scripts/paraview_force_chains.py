"""Snakemake adapter: the force chains of a run's settled fill, every pair contact of its last settled step as a line
carrying its normal force (:func:`siloflow.analysis.io.vtk_lines.write_force_chains_vtp`). ParaView slices and thresholds, so
the slice and the cap of the silo's force-chain plot are left out: an infinite slice and cap keep every contact and
its force as computed."""

from pathlib import Path

from siloflow.analysis.io.vtk_lines import write_force_chains_vtp
from siloflow.analysis.numerics.force_chains import all_force_chains
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to
from siloflow.model.record import read_run_record

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    settled = engine_named(record.engine).settled_fill(run_dir, record)[-1]
    segments = all_force_chains(settled.contacts)
    write_force_chains_vtp(snakemake.output.chains, segments)
    log.info("%s: %d contacts at step %d, normal force up to %.4g N", record.run_id, len(segments.normal_force),
             settled.contacts.step, segments.normal_force.max() if segments.normal_force.size else 0.0)
