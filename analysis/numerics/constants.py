"""Physical constants the analysis uses, each defined once.

The engine-neutral case model carries its own copy of the simulated gravity (``GRAVITY`` of the cases'
common module); analysis may not import the engines, so the value the analysis compares with lives here.
"""

from __future__ import annotations

__all__ = ["GRAVITY"]

GRAVITY = 9.81
"""Gravitational acceleration g [m/s2]: the rounded value the simulations run with (not scipy's standard
9.80665), so weights and stresses computed here match the simulated ones."""
