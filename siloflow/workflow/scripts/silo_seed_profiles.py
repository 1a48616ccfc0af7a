"""Snakemake adapter: the flat-bottom silo's steady v_z profiles and kinematic constant B over the reference
configuration's seeds (their mean and its error), the figure the validation record shows beside the silo's rows."""

import json
from pathlib import Path

from siloflow.analysis.io.fields import load_fields_npz
from siloflow.analysis.io.tables import read_table
from siloflow.analysis.studies.silo_flat.field_comparisons import seed_kinematic, seed_profiles
from siloflow.analysis.studies.silo_flat.plots import plot_seed_profiles
from siloflow.analysis.studies.validation.figure_findings import kinematic_findings
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    profiles = seed_profiles([load_fields_npz(path) for path in snakemake.input.fields], snakemake.params.heights)
    kinematic = seed_kinematic([read_table(path) for path in snakemake.input.kinematic])
    start, end = json.loads(Path(snakemake.input.summaries[0]).read_text())["average_window_s"]
    seeds = f"{profiles.seeds} seed{'s' if profiles.seeds > 1 else ''}"
    plot_seed_profiles(profiles, kinematic, snakemake.output.plot,
                       f"Flat-bottom silo, averaged over {start:g}-{end:g} s after opening: {seeds}",
                       kinematic_findings())
    log.info("profiles of %s at %s m", seeds, ", ".join(f"{z:g}" for z in profiles.heights))
