"""YADE (Debian ``yade`` 2023.02): everything siloflow knows about this engine, its scripts, runs and file formats.

Importing the package registers :class:`~siloflow.engines.yade.engine.YadeEngine` under the name ``yade``
(:func:`siloflow.engines.interface.engine_named`).
"""

from siloflow.engines.yade.engine import YadeEngine

__all__ = ["YadeEngine"]
