"""The case model and the engine seam: engine-neutral cases (:mod:`model.cases`), the engine interface and its
registry (:mod:`engines.interface`), one package per engine (``engines/<name>/``, the only place that knows an
engine's syntax, file names and formats), the results layout (:mod:`engines.layout`) and run planning
(:mod:`engines.estimates`, :mod:`engines.planning`, :mod:`engines.runs`).
"""
