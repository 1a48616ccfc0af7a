"""Flowing bulk density of the recirculating silo: how much the fill dilates while it recirculates.

The study reports the drop of bulk density from the settled fill to the flowing one. Here it is measured in a
horizontal slab of the silo body, clear of the outlet below and the heaped surface above, from clump centres:
the mass of the clumps whose centre lies in the slab over the slab's volume (width x depth x thickness). A slab
several clump sizes thick keeps the error of counting by centres small against the dilation sought. The settled
value is the first frame's (the fill at rest when the outlet opens); the flowing value is the batch mean
(:func:`siloflow.analysis.numerics.uncertainty.batch_means`) over the frames from ``flowing_from`` on. Pure: arrays in, numbers out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, positive_number
from siloflow.analysis.numerics.uncertainty import batch_means

__all__ = ["FlowingBulkDensity", "slab_bulk_density", "flowing_bulk_density"]


@dataclass(frozen=True)
class FlowingBulkDensity:
    """Bulk density of a slab of the fill at rest and while it flows.

    Attributes
    ----------
    slab : tuple of float
        ``(z_low, z_high)`` of the slab (m).
    settled : float
        Bulk density of the slab in the first frame (kg/m3).
    flowing, flowing_error : float
        Batch mean of the slab's bulk density over the flowing frames and its standard error (kg/m3).
    drop, drop_error : float
        ``1 - flowing / settled`` and its standard error (-); the settled value is one exact count.
    frames, batches : int
        Flowing frames and the batches their error rests on (-).
    """

    slab: tuple[float, float]
    settled: float
    flowing: float
    flowing_error: float
    drop: float
    drop_error: float
    frames: int
    batches: int

    def summary(self) -> dict:
        """The figures as a flat dict for a run's JSON summary (SI units in the key names)."""
        return {
            "bulk_density_slab_m": list(self.slab),
            "settled_bulk_density_kg_m3": self.settled,
            "flowing_bulk_density_kg_m3": self.flowing,
            "flowing_bulk_density_kg_m3_error": self.flowing_error,
            "bulk_density_drop": self.drop,
            "bulk_density_drop_error": self.drop_error,
            "bulk_density_batches": self.batches,
        }


def slab_bulk_density(z, mass, width: float, depth: float, slab: tuple[float, float]) -> np.ndarray:
    """Bulk density of the slab ``z_low <= z < z_high`` in each frame (kg/m3).

    Parameters
    ----------
    z : array_like, shape (frames, clumps)
        Height of each clump's centre in each frame (m).
    mass : array_like, shape (clumps,)
        Clump masses (kg).
    width, depth : float
        Cross-section of the silo body (m).
    slab : tuple of float
        ``(z_low, z_high)`` (m), increasing.
    """
    heights = finite_array("z", z, ndim=2)
    masses = finite_array("mass", mass, ndim=1)
    if masses.size != heights.shape[1]:
        raise ValueError(f"mass has {masses.size} clumps, z has {heights.shape[1]}")
    low, high = (float(v) for v in slab)
    if not high > low:
        raise ValueError(f"slab must be an increasing pair of heights, got {slab!r}")
    volume = positive_number("width", width) * positive_number("depth", depth) * (high - low)
    inside = (heights >= low) & (heights < high)
    return inside @ masses / volume


def flowing_bulk_density(times, z, mass, width: float, depth: float, slab: tuple[float, float],
                         flowing_from: float, n_batches: int = 10) -> FlowingBulkDensity:
    """The slab's bulk density at rest (first frame) and its batch mean over the frames at ``t >= flowing_from``.

    Parameters
    ----------
    times : array_like, shape (frames,)
        Frame times (s), the first the settled fill's.
    z, mass, width, depth, slab
        As for :func:`slab_bulk_density`.
    flowing_from : float
        Time from which the flow counts as established (s), after the first frame.
    n_batches : int, optional
        Batches for the error, >= 2 (fewer when there are fewer flowing frames).
    """
    t = finite_array("times", times, ndim=1)
    density = slab_bulk_density(z, mass, width, depth, slab)
    if t.size != density.size:
        raise ValueError(f"times has {t.size} frames, z has {density.size}")
    if not flowing_from > t[0]:
        raise ValueError(f"flowing_from ({flowing_from} s) must come after the first (settled) frame ({t[0]} s)")
    flowing = density[t >= flowing_from]
    if flowing.size < 2:
        raise ValueError(f"fewer than two frames at t >= {flowing_from} s: no flowing bulk density")
    settled = float(density[0])
    if settled <= 0.0:
        raise ValueError(f"no clump in the slab {slab} of the settled fill: choose a slab inside the fill")
    estimate = batch_means(flowing, min(n_batches, flowing.size))
    return FlowingBulkDensity(
        slab=(float(slab[0]), float(slab[1])), settled=settled, flowing=estimate.value,
        flowing_error=estimate.std_error, drop=1.0 - estimate.value / settled,
        drop_error=estimate.std_error / settled, frames=int(flowing.size), batches=estimate.n,
    )
