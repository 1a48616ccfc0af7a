"""The multi-flow blender study.

- ``window_fields``: window-averaged planar fields and the discharge history from clump tracks;
  ``window_fields_io``: their ``.npz`` store.
- ``steady_field``: :class:`BlenderField`, the steady field every analysis below runs on.
- ``profiles``: profiles at heights and over time, passage velocities, flow channel boundary.
- ``tracers``: virtual-tracer pathlines, the RTD of a tracer layer, tabulated RTDs.
- ``modes``: discontinuous (recirculated two-layer fill) and continuous (sine input) blending.
- ``gravity``: gravity scaling. ``comparison``: metrics, comparison table, best configuration and the significance of
  the differences; ``errors``: the standard errors of the figures, from the run's own data.
- ``study``: the composed study of one run; ``plots``: its figures.
"""
