"""Snakemake adapter: a run's ParaView state, ``paraview/state.py``
(:func:`siloflow.analysis.io.paraview_state.write_paraview_state`): walls, particles coloured by speed, fields, and the run's
lines (tracks, pathlines, force chains) hidden, each coloured by what it carries."""

from siloflow.analysis.io.paraview_state import StateLines, write_paraview_state
from siloflow.engines.logs import logged_to

#: The lines a run may have (by input name): the array each is coloured by, cell data.
LINE_COLOURS = {"tracks": "residence_time", "pathlines": "residence_time", "force_chains": "normal_force"}

with logged_to(snakemake.log[0]) as log:
    inputs = snakemake.input
    lines = [StateLines(name, inputs[name], array) for name, array in LINE_COLOURS.items() if name in inputs.keys()]
    write_paraview_state(snakemake.output.state, snakemake.params.title, inputs.particles, walls=inputs.walls,
                         fields=inputs.fields, lines=lines)
    log.info("%s: state of %s", snakemake.params.title, ", ".join(inputs.keys()))
