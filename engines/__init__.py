"""Turning siloflow cases into engine input decks and running the engines.

LIGGGHTS specifics live in :mod:`engines.liggghts.run` and ``templates/liggghts/``; the case descriptions
(:mod:`engines.cases.silo_flat`) and the physics helpers (:mod:`engines.cases.physics`) are engine-neutral.
"""
