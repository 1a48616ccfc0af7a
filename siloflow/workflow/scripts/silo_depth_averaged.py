"""Snakemake adapter: the depth average of one flat-bottom silo run's time-averaged fields, the small product the
parametric studies read (and the validation record keeps) instead of the full 3-D fields."""

from siloflow.analysis.io.fields import load_fields_npz, save_fields_npz
from siloflow.analysis.numerics.field_ops import depth_average
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    averaged = depth_average(load_fields_npz(snakemake.input.arrays))
    save_fields_npz(snakemake.output.arrays, averaged)
    log.info("depth-averaged fields on a %s grid", "x".join(str(n) for n in averaged.grid.shape))
