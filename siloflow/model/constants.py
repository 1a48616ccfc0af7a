"""Physical constants, each defined once, for the case model, the engines and the analysis alike."""

from __future__ import annotations

__all__ = ["GRAVITY"]

GRAVITY = 9.81
"""Gravitational acceleration g [m/s2]: the rounded value the simulations run with (not scipy's standard
9.80665), so weights and stresses computed by the analysis match the simulated ones."""
