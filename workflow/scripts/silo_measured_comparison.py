"""Snakemake adapter: compare the simulated time-averaged profiles with measured ones (e.g. PIV)."""

from analysis.numerics.field_ops import depth_average, front_wall_slice
from analysis.io.fields import load_fields_npz
from analysis.studies.silo_flat.measured import compare_with_measurement, read_measured_profiles
from analysis.numerics.profiles import velocity_profile
from analysis.studies.silo_flat.plots import plot_measured_comparison
from analysis.io.tables import write_flow_table
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    averaged = load_fields_npz(snakemake.input.fields)
    plane = front_wall_slice(averaged) if snakemake.params.plane == "front_wall" else depth_average(averaged)
    comparisons = []
    for measured in read_measured_profiles(snakemake.input.measured):
        simulated = velocity_profile(plane, measured.z)
        comparisons.append(compare_with_measurement(simulated.x, simulated.v_z, measured))
    write_flow_table(snakemake.output.table, [
        {"z_m": c.measured.z, "window": c.measured.window, "n_points": c.errors.n_points,
         "mean_error_percent": c.errors.mean_error_percent, "rms_error_m_s": c.errors.rms_error,
         "max_abs_error_m_s": c.errors.max_abs_error,
         "fraction_within_uncertainty": c.errors.fraction_within_uncertainty}
        for c in comparisons
    ])
    plot_measured_comparison(comparisons, snakemake.output.plot, f"DEM ({snakemake.params.plane}) vs measurement")
    for c in comparisons:
        log.info("z = %g m, %s: mean error %.1f %%, RMS %.3g m/s", c.measured.z, c.measured.window,
                 c.errors.mean_error_percent, c.errors.rms_error)
