"""Snakemake adapter: compare the simulated time-averaged profiles with measured ones (e.g. PIV)."""

from siloflow.analysis.io.fields import load_fields_npz
from siloflow.analysis.io.tables import write_flow_table
from siloflow.analysis.studies.silo_flat.field_comparisons import (
    compare_with_measurements,
    comparison_plane,
    measured_comparison_rows,
)
from siloflow.analysis.studies.silo_flat.measured import read_measured_profiles
from siloflow.analysis.studies.silo_flat.plots import plot_measured_comparison
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    plane = comparison_plane(load_fields_npz(snakemake.input.fields), snakemake.params.plane)
    comparisons = compare_with_measurements(plane, read_measured_profiles(snakemake.input.measured))
    write_flow_table(snakemake.output.table, measured_comparison_rows(comparisons))
    plot_measured_comparison(comparisons, snakemake.output.plot, f"DEM ({snakemake.params.plane}) vs measurement")
    for c in comparisons:
        log.info("z = %g m, %s: mean error %.1f %%, RMS %.3g m/s", c.measured.z, c.measured.window,
                 c.errors.mean_error_percent, c.errors.rms_error)
