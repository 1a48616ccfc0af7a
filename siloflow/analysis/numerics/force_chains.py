"""Force-chain geometry: the branch vectors of the contacts in a slice, coloured by their normal force."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.contacts import ContactFrame

__all__ = ["ForceChainSegments", "all_force_chains", "force_chain_segments"]


@dataclass(frozen=True)
class ForceChainSegments:
    """Branch vectors of contacts in a slice, for a force-chain picture.

    Attributes
    ----------
    start, end : numpy.ndarray
        (n, 3) sphere centres (m).
    normal_force : numpy.ndarray
        (n,) compressive normal force, capped (N).
    cap : float
        The cap applied (N).
    """

    start: np.ndarray
    end: np.ndarray
    normal_force: np.ndarray
    cap: float


def force_chain_segments(
    contacts: ContactFrame, slice_centre_y: float, slice_thickness: float, cap: float
) -> ForceChainSegments:
    """Contacts whose two centres lie in the slice |y - y_c| <= thickness / 2, normal force capped at ``cap``.

    The study drew branch vectors in a 6 mm slice coloured by normal force capped at 50 particle weights.
    """
    if slice_thickness <= 0 or cap <= 0:
        raise ValueError("slice_thickness and cap must be positive")
    half = 0.5 * slice_thickness
    inside = (np.abs(contacts.position_i[:, 1] - slice_centre_y) <= half) & (
        np.abs(contacts.position_j[:, 1] - slice_centre_y) <= half
    )
    force = np.clip(contacts.normal_force[inside], 0.0, cap)
    return ForceChainSegments(contacts.position_i[inside], contacts.position_j[inside], force, float(cap))


def all_force_chains(contacts: ContactFrame) -> ForceChainSegments:
    """Every contact as a segment with its normal force as computed (no slice, no cap): what a viewer that slices
    and thresholds itself (ParaView) takes."""
    return force_chain_segments(contacts, 0.0, math.inf, math.inf)
