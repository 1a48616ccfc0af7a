"""Snakemake adapter: one flat-bottom silo run's front wall against the measured PIV sequence (table and plot)."""

from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.io.measured_piv import load_measured_piv
from siloflow.analysis.io.tables import read_table, write_flow_table
from siloflow.analysis.piv.compare import piv_comparison
from siloflow.analysis.piv.measured import measured_piv_settings
from siloflow.analysis.studies.silo_flat.piv_plots import plot_piv_comparison
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    case = snakemake.params.case
    piv, measured = snakemake.params.piv, snakemake.params.piv["measured"]
    settings = measured_piv_settings(measured)
    fields = load_measured_piv(measured, settings, [Path(p) for p in snakemake.input.measured])
    frames = engine_named(record.engine).read_frames(run_dir, record, snakemake.params.on_damaged)
    rows, pairs = piv_comparison(
        frames, fields, read_table(snakemake.input.profiles), snakemake.params.heights, measured["windows"],
        piv["band_diameters"] * case.particle.equivalent_diameter,
        settings.scale.scale if settings.scale is not None else measured["pixel_size"], settings.frame_rate,
        piv["fcb_fraction"], measured["min_valid_fraction"], record.open_time_s)
    write_flow_table(snakemake.output.table, rows)
    plot_piv_comparison(pairs, snakemake.output.plot)
    for row in rows:
        log.info("%g-%g s, z = %g m: DEM - PIV v_z mean %.3g, RMS %.3g m/s against %.3g m/s (larger than twice: %s)",
                 row["window_start_s"], row["window_end_s"], row["z_m"], row["mean_difference_m_s"],
                 row["rms_difference_m_s"], row["uncertainty_m_s"], row["larger_than_2_uncertainties"])
