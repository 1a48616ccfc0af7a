"""Snakemake adapter: Eulerian RTD against real particle tracks in the one-particle-thick silo."""

from siloflow.analysis.studies.silo_recirculation.tracks_io import load_tracks
from siloflow.analysis.studies.silo_recirculation.plots import plot_paths_comparison
from siloflow.analysis.studies.silo_recirculation.rtd_plots import plot_residence_time_comparison
from siloflow.analysis.studies.silo_recirculation.study import verify_eulerian_rtd
from siloflow.analysis.studies.silo_recirculation.tables import verification_rows, verification_summary
from siloflow.analysis.io.tables import write_flow_table, write_json
from siloflow.engines.logs import logged_to


with logged_to(snakemake.log[0]) as log:
    out = snakemake.output
    settings = snakemake.params.blending
    verification = settings["verification"]
    case = snakemake.params.case
    silo = case.silo
    loaded = load_tracks(snakemake.input.tracks)
    bottom, top = case.domain_z
    result = verify_eulerian_rtd(
        loaded.tracks, loaded.velocity, loaded.mass, silo.width, silo.depth, bottom, top,
        silo.outlet_width, verification["bin_sizes"], settings["tracer"]["start_recirculations"],
        settings["eulerian"]["integration_step"], settings["eulerian"]["max_recirculations"],
        verification["paths_shown"], settings["tracer"]["volume_fraction"],
    )
    write_flow_table(out.table, verification_rows(result))
    summary = verification_summary(result, run_id=case.run_id)
    write_json(out.summary, summary)
    samples = [("particle tracks", result.particle_residence)] + [
        (f"Eulerian, {1000 * b:g} mm bins", t) for b, t in result.eulerian_residence.items()]
    plot_residence_time_comparison(samples, out.residence_plot,
                                   f"Residence times, one-particle-thick silo ({case.pattern})")
    finest = min(result.pathlines)
    plot_paths_comparison(result.particle_paths, result.pathlines[finest], silo.width, silo.outlet_width,
                          top, out.paths_plot,
                          f"Particle tracks (solid) and pathlines in {1000 * finest:g} mm bins (dashed)")
    log.info("particles (%d tracers): %s; Eulerian: %s", summary["n_tracers"], summary["particles"],
             summary["eulerian"])
