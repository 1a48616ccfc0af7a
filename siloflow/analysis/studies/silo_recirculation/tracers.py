"""The tracer of the particle RTD in a recirculating silo: passes entering after a start time, and its size.

Pure functions on the events of :mod:`siloflow.analysis.studies.silo_recirculation.tracks`; no file I/O. SI units:
times in s, volumes in m^3, densities in kg/m^3, masses in kg.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number, integer_at_least, positive_number
from siloflow.analysis.studies.silo_recirculation.tracks import RecirculationEvents

__all__ = ["TracerPasses", "tracer_passes", "tracer_count"]


@dataclass(frozen=True, eq=False)
class TracerPasses:
    """A tracer made of the passes that enter first after a start time.

    Attributes
    ----------
    entry_time : numpy.ndarray, shape (n,)
        Entry time of each tracer pass, ascending [s].
    exit_time : numpy.ndarray, shape (n,)
        Its exit time; NaN when not out by the last frame [s].
    pass_index : numpy.ndarray of int64, shape (n,)
        Row of the pass in :class:`RecirculationEvents` [-].
    clump_index : numpy.ndarray of int64, shape (n,)
        Clump column [-].
    clump_id : numpy.ndarray of int64, shape (n,)
        Clump id [-].
    entry_at : str
        ``"wrap"`` (entry = re-entry at the top) or ``"outlet"`` (entry = the previous outlet
        crossing of the clump).
    """

    entry_time: np.ndarray
    exit_time: np.ndarray
    pass_index: np.ndarray
    clump_index: np.ndarray
    clump_id: np.ndarray
    entry_at: str

    @property
    def n_tracer(self) -> int:
        """Number of tracer passes ``N0``."""
        return int(self.entry_time.shape[0])

    @property
    def n_exited(self) -> int:
        """Tracer passes that left by the last frame."""
        return int(np.count_nonzero(np.isfinite(self.exit_time)))

    @property
    def residence_time(self) -> np.ndarray:
        """``exit_time - entry_time`` [s] (NaN where not out)."""
        return self.exit_time - self.entry_time


def tracer_passes(events: RecirculationEvents, start_time: float, n_tracer: int, entry_at: str = "wrap") -> TracerPasses:
    """The tracer of the particle RTD: the first ``n_tracer`` passes entering at or after ``start_time``.

    Passes are ordered by entry time (ties by pass row) and the first ``n_tracer`` with
    ``entry >= start_time`` are taken. ``entry_at = "wrap"`` (default): the entry is the re-entry at
    the top, so ``exit - entry`` is the residence time of a pass through the silo (free fall from
    the top included). ``entry_at = "outlet"``: the entry is the previous outlet crossing of the
    clump, so ``exit - entry`` is the loop time (channel, re-entry and silo), the ``E`` of the
    renewal equation
    (:func:`siloflow.analysis.studies.silo_recirculation.concentration.predicted_concentration_from_first_pass`).
    Feed the result to ``siloflow.analysis.numerics.rtd.rtd_from_exit_times(tracer.exit_time, t_entry=tracer.entry_time,
    n_total=tracer.n_tracer)``.

    Parameters
    ----------
    events : RecirculationEvents
        Passes of the run.
    start_time : float
        Earliest entry time [s].
    n_tracer : int
        Number of tracer passes, >= 1 (e.g. :func:`tracer_count`).
    entry_at : {"wrap", "outlet"}, optional
        Which event is the entry; default ``"wrap"``.

    Returns
    -------
    TracerPasses
        Exit times are NaN for passes not out by the last frame.

    Raises
    ------
    ValueError
        If fewer than ``n_tracer`` passes enter at or after ``start_time``.
    """
    start = finite_number("start_time", start_time)
    n_tracer = integer_at_least("n_tracer", n_tracer, 1)
    if entry_at == "wrap":
        entry = np.asarray(events.entry_time, dtype=float)
    elif entry_at == "outlet":
        entry = np.asarray(events.previous_exit_time, dtype=float)
    else:
        raise ValueError(f"entry_at must be 'wrap' or 'outlet', got {entry_at!r}")
    candidates = np.flatnonzero(np.isfinite(entry) & (entry >= start))
    if candidates.size < n_tracer:
        raise ValueError(
            f"n_tracer: only {candidates.size} passes enter at or after start_time = {start!r} s "
            f"(entry_at = {entry_at!r}), {n_tracer} wanted"
        )
    chosen = candidates[np.argsort(entry[candidates], kind="stable")[:n_tracer]]
    clump_index = np.asarray(events.pass_clump_index, dtype=np.int64)[chosen]
    return TracerPasses(
        entry_time=entry[chosen],
        exit_time=np.asarray(events.exit_time, dtype=float)[chosen],
        pass_index=chosen.astype(np.int64),
        clump_index=clump_index,
        clump_id=np.asarray(events.clump_id, dtype=np.int64)[clump_index],
        entry_at=entry_at,
    )


def tracer_count(silo_volume: float, tracer_fraction: float, bulk_density: float, clump_mass: float) -> int:
    """Number of tracer clumps filling a fraction of the silo: ``round(f V rho_b / m)``, at least 1.

    Rounded half up. The same number serves as the count of virtual tracers seeded for the
    Eulerian RTD (:func:`siloflow.analysis.numerics.tracer_seeds.lattice_seeds`), so that both RTDs carry the same
    sampling noise.

    Parameters
    ----------
    silo_volume : float
        Volume ``V`` of the silo contents [m^3], > 0.
    tracer_fraction : float
        Fraction ``f`` of that volume the tracer fills, in (0, 1] [-].
    bulk_density : float
        Bulk density ``rho_b`` [kg/m^3], > 0.
    clump_mass : float
        Mass ``m`` of one clump [kg], > 0.

    Returns
    -------
    int
        Number of tracer clumps, >= 1.
    """
    volume = positive_number("silo_volume", silo_volume)
    fraction = float(tracer_fraction)
    if not math.isfinite(fraction) or not 0.0 < fraction <= 1.0:
        raise ValueError(f"tracer_fraction must be a number in (0, 1], got {tracer_fraction!r}")
    density = positive_number("bulk_density", bulk_density)
    mass = positive_number("clump_mass", clump_mass)
    return max(1, int(math.floor(fraction * volume * density / mass + 0.5)))
