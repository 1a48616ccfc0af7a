"""LIGGGHTS (LIGGGHTS-PUBLIC 3.8): everything siloflow knows about this engine, its decks, runs and file formats.

Importing the package registers :class:`~siloflow.engines.liggghts.engine.LiggghtsEngine` under the name ``liggghts``
(:func:`siloflow.engines.interface.engine_named`).
"""

from siloflow.engines.liggghts.engine import LiggghtsEngine

__all__ = ["LiggghtsEngine"]
