"""The neutral model that the engines and the analysis share: what a run is and what it holds.

The cases (:mod:`model.cases`: each case kind's geometry, materials, particle template and stages, built from the
configuration, engine-neutral; :mod:`model.cases.kinds` registers each kind once), what a run costs
(:mod:`model.cost`), the typed run record (:mod:`model.record`), particle frames and contacts (:mod:`model.frames`, :mod:`model.contacts`),
wall forces (:mod:`model.forces`), the settled fill (:mod:`model.settled`), a run siloflow did not make
(:mod:`model.existing_run`), physical constants (:mod:`model.constants`), read-only arrays (:mod:`model.arrays`),
argument checks (:mod:`model.checks`) and what a file reader says of a file it refuses (:mod:`model.file_messages`).
It imports nothing else of siloflow: ``engines`` and ``analysis`` both build on it, and neither on the other's
internals.
"""
