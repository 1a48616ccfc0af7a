"""Turning siloflow cases into engine input decks and running the engines.

LIGGGHTS specifics live in :mod:`engines.liggghts` and ``templates/liggghts/``; the case descriptions
(:mod:`engines.silo`) and the physics helpers (:mod:`engines.physics`) are engine-neutral.
"""
