"""General numerics on neutral objects (frames, arrays), shared by every study; no file I/O.

- ``grid``: the Cartesian grid and the fields on its nodes (:class:`Grid`, :class:`Fields`).
- ``coarse_graining``: kernels and deposition of particle data onto the grid; density, velocity, kinetic stress.
- ``contact_stress``: the contact part of the stress, deposited with the same kernels.
- ``field_ops``: time average, depth average and the front-wall layer of fields.
- ``profiles``: velocity profiles at a height, flow channel boundary, flow rate, comparison with measurements.
- ``kinematic``: the kinematic model fitted to a profile. ``janssen``: Janssen's vertical stress.
- ``flow``: discharge (bulk density, discharged mass, steady mass flow rate, Beverloo).
- ``clump_tracks``: clump centres, velocities and masses over a run's frames, one column per clump;
  ``exit_times``: when the clumps cross an outlet plane, re-enter through a periodic boundary, and their passes.
- ``rtd``: residence time distributions from exit times, moments, models. ``lti``: convolution with the RTD,
  VRR, recirculation (imports ``rtd``, never the reverse).
- ``pathlines``: virtual tracers integrated through velocity fields; ``tracer_seeds``: where they start;
  ``eulerian_rtd``: the RTD from bin velocities of a run.
- ``force_chains``: strong contact force networks.
"""
