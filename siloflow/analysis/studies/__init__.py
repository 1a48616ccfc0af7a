"""Per-case studies composed from :mod:`siloflow.analysis.numerics`: ``silo_flat`` (flat-bottom silo), ``silo_recirculation``
(blending in the recirculating silo) and ``blender`` (the multi-flow blender)."""
