"""The case model and the engine seam: engine-neutral cases (:mod:`siloflow.model.cases`), the engine interface and its
registry (:mod:`siloflow.engines.interface`), one package per engine (``engines/<name>/``, the only place that knows an
engine's syntax, file names and formats), the results layout (:mod:`siloflow.engines.layout`) and run planning
(:mod:`siloflow.engines.estimates`, :mod:`siloflow.engines.planning`, :mod:`siloflow.engines.runs`).
"""
