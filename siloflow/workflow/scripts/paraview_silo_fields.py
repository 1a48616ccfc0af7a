"""Snakemake adapter: the flat-bottom silo's field series (``fields/fields.pvd``, timed from the opening) indexed
again on the run's simulated clock, so that ParaView plays it in step with the particles: the same .vti files, their
times shifted by the time of the first frame at or after the opening
(:func:`siloflow.analysis.studies.silo_flat.field_clock.field_clock_origin`)."""

from siloflow.analysis.io.fields import read_pvd, write_pvd
from siloflow.analysis.studies.silo_flat.field_clock import field_clock_origin
from siloflow.engines.logs import logged_to
from siloflow.model.record import read_run_record

with logged_to(snakemake.log[0]) as log:
    record = read_run_record(snakemake.input.record)
    fields = read_pvd(snakemake.input.fields)
    frame_times = [time for time, _ in read_pvd(snakemake.input.particles)]
    origin = field_clock_origin(frame_times, record.open_time_s, record.timestep_s)
    write_pvd(snakemake.output.pvd, [(time + origin, file.resolve()) for time, file in fields])
    log.info("%s: %d fields, shifted by %.6g s (the first frame after the opening at %.6g s)", record.run_id,
             len(fields), origin, record.open_time_s)
