"""Snakemake adapter: the synthetic PIV study of one silo run (table and plot)."""

from pathlib import Path

import numpy as np

from siloflow.model.record import read_run_record
from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.piv.accuracy import PivSettings, accuracy_table
from siloflow.analysis.studies.silo_flat.piv_plots import plot_piv_accuracy
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    case = snakemake.params.case
    piv = snakemake.params.piv
    frames = [f for f in engine_named(record.engine).read_frames(run_dir, record, snakemake.params.on_damaged)
              if f.step > record.open_step]
    if not frames:
        raise ValueError(f"{run_dir}: no particle frame after the outlet opened; synthetic PIV needs the discharge")
    # frame pairs spread over the middle half of the discharge
    spread = np.linspace(len(frames) // 4, 3 * len(frames) // 4, piv["frame_pairs"]).astype(int)
    chosen = [frames[i] for i in sorted(set(spread.tolist()))]
    settings = PivSettings(window_px=piv["window_px"], overlap_px=piv["overlap_px"], passes=piv["passes"],
                           band=piv["band_diameters"] * case.particle.equivalent_diameter, blur_px=piv["blur_px"],
                           noise=piv["noise"])
    rows, profiles = accuracy_table(chosen, case.width, piv["resolutions"], piv["frame_rates"], settings,
                                    snakemake.params.heights, piv["fcb_fraction"])
    write_flow_table(snakemake.output.table, rows)
    write_flow_table(snakemake.output.profiles, profiles)
    plot_piv_accuracy(rows, snakemake.output.plot)
    for row in rows:
        log.info("%d x %d px (%.3g mm/px), %g frames/s: v_z bias %.3g m/s, RMS %.3g +- %.2g m/s over %d nodes; "
                 "centreline %.3g m/s, FCB %.3g m, B %.3g %% %s", row["width_px"], row["height_px"], row["mm_per_px"],
                 row["frame_rate_hz"], row["bias_w_m_s"], row["rms_w_m_s"], row["rms_w_spread_m_s"], row["nodes"],
                 row["centreline_w_error_m_s"], row["fcb_error_m"], row["kinematic_b_error_percent"], row["note"])
