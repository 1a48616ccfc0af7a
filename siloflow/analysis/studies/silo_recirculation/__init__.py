"""The blending study in the recirculating silo.

- ``tracks``: the outlet crossings, re-entries and passes of the clump tracks (those of
  :mod:`siloflow.analysis.numerics.exit_times`, on the tracks of :mod:`siloflow.analysis.numerics.clump_tracks`) with what the study
  adds to them, and the holdup; ``tracks_io``: the tracks' ``.npz`` store.
- ``concentration``: batch layers, outlet concentration measured and predicted (renewal equation).
- ``vrr``: recirculation number, holdup residence time, VRR per recirculation.
- ``final_discharge``: the VRR of the discharge after the recirculations, once the re-entry stops (the study's VRR
  "at the end of Nr recirculations", §6.4.2).
- ``tracers``: the tracer passes of the particle RTD. ``validation``: argument checks they share.
- ``transit``: Little's law on the passes that leave within a horizon (the tracer's clumps) and the stagnant
  holdup that makes holdup / throughput exceed the tracer's mean.
- ``study``: the composed study of one run; ``plots`` and ``rtd_plots``: its figures (``rtd_plots`` is shared
  with the blender).
"""
