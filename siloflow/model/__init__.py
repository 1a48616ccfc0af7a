"""The neutral model that the engines and the analysis share: what a run is and what it holds.

The cases (:mod:`siloflow.model.cases`: each case kind's geometry, materials, particle template and stages, built from the
configuration, engine-neutral; :mod:`siloflow.model.cases.kinds` registers each kind once), what a run costs
(:mod:`siloflow.model.cost`), the typed run record (:mod:`siloflow.model.record`), particle frames and contacts (:mod:`siloflow.model.frames`, :mod:`siloflow.model.contacts`),
wall forces (:mod:`siloflow.model.forces`), the settled fill (:mod:`siloflow.model.settled`), a run siloflow did not make
(:mod:`siloflow.model.existing_run`), physical constants (:mod:`siloflow.model.constants`), read-only arrays (:mod:`siloflow.model.arrays`),
argument checks (:mod:`siloflow.model.checks`) and what a file reader says of a file it refuses (:mod:`siloflow.model.file_messages`).
It imports nothing else of siloflow: ``engines`` and ``analysis`` both build on it, and neither on the other's
internals.
"""
