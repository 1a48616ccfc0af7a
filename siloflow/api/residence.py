"""Residence times of a run: the residence time distribution (RTD) of its passes through the silo, from the exit
times of its clumps, and the variance reduction ratio (VRR) of periodic inputs that RTD predicts.

The exit times themselves are :func:`siloflow.analysis.numerics.exit_times.exit_times` (``siloflow.exit_times``). SI units:
times in s, E in 1/s.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from siloflow.analysis.numerics.exit_times import ExitTimes
from siloflow.analysis.numerics.lti import VRRTable, vrr_versus_period
from siloflow.analysis.numerics.rtd import RTD, rtd_from_exit_times

__all__ = ["residence_time_distribution", "vrr"]


def residence_time_distribution(exits: ExitTimes, bins=None, entered_from: float | None = None,
                                entered_until: float | None = None) -> RTD:
    """The RTD of the passes through the silo that begin with a re-entry at the top: from the re-entry to the first
    outlet crossing after it.

    Every pass entering in ``[entered_from, entered_until]`` counts in the total ``N0``; one that had not left
    by the last frame counts as not left (in ``N0``, not in the histogram), so ``E`` integrates to the fraction
    that left. Passes entering shortly before the end of the run had little time to leave: end the entries a few
    mean residence times before the last frame to keep them from cutting off the RTD's tail.

    Parameters
    ----------
    exits : ExitTimes
        Exit times of a run with a periodic boundary (:func:`siloflow.exit_times` with the run's ``domain_z``).
    bins : None, int or array_like, optional
        As :func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times`: numpy's automatic equal bins over ``[0, t_last]``
        (None, default), that many equal bins, or bin edges [s].
    entered_from, entered_until : float, optional
        Window of the re-entry times [s]; default from the first to the last frame.

    Returns
    -------
    RTD
        Bin centres and edges [s], ``E`` [1/s], the mean ``t_mean`` [s] and variance [s^2] of the passes that left,
        first and last appearance [s], the counts.

    Raises
    ------
    ValueError
        When no pass begins with a re-entry in the window (a run without a periodic boundary has none), or none of
        them left.

    Examples
    --------
    A conveyor: 10 clumps evenly spaced along a periodic domain of 1 m, falling at 0.1 m/s, outlet 0.25 m above
    the bottom; every pass takes the 7.5 s from the top to the outlet.

    >>> import numpy as np
    >>> from siloflow.analysis.numerics.clump_tracks import clump_tracks
    >>> from siloflow.analysis.numerics.exit_times import outlet_exits
    >>> times = np.arange(0.0, 30.0, 0.05)
    >>> z = np.mod(0.05 + 0.1 * np.arange(10) - 0.1 * times[:, None], 1.0)
    >>> tracks = clump_tracks(times, [np.arange(10)] * len(times), [np.column_stack([np.zeros(10), np.zeros(10), zk])
    ...                                                             for zk in z])
    >>> rtd = residence_time_distribution(outlet_exits(tracks, 0.25, (0.0, 1.0)), bins=5, entered_until=20.0)
    >>> rtd.n_total, rtd.n_exited, round(rtd.t_mean, 9), round(rtd.variance, 9)
    (20, 20, 7.5, 0.0)
    >>> float(np.sum(rtd.E * rtd.widths))
    1.0
    """
    entry = np.asarray(exits.entry_time, dtype=float)
    start = exits.first_frame_time if entered_from is None else float(entered_from)
    end = exits.last_frame_time if entered_until is None else float(entered_until)
    chosen = np.isfinite(entry) & (entry >= start) & (entry <= end)
    if not np.any(chosen):
        raise ValueError(
            f"no pass begins with a re-entry between {start:.4g} s and {end:.4g} s "
            f"({'a run without a periodic boundary has none' if exits.domain_z is None else 'widen the window'})")
    return rtd_from_exit_times(np.asarray(exits.exit_time, dtype=float)[chosen], t_entry=entry[chosen], bins=bins)


def vrr(rtd: RTD, periods_over_tm: Sequence[float], waveform: str = "sine", n_periods: int = 10) -> VRRTable:
    """The variance reduction ratio ``var(c_in) / var(c_out)`` of periodic inputs against their period, through
    the silo as a linear time-invariant system whose impulse response is the RTD (convolution,
    :func:`siloflow.analysis.numerics.lti.vrr_versus_period`).

    The RTD's bins are its samples: bin ``k`` of width ``dt`` is ``E`` at residence time ``k dt``, normalised to
    unit area (the passes that had not left drop out), with the RTD's own mean ``t_mean``.

    Parameters
    ----------
    rtd : RTD
        An RTD with equal bins from 0 (:func:`residence_time_distribution` with ``bins`` None or an int).
    periods_over_tm : sequence of float
        Input periods as fractions of the mean residence time ``t_mean`` [-]; each at least 4 bins long.
    waveform : {"sine", "square"}, optional
        The input's shape.
    n_periods : int, optional
        Whole periods over which the output's variance is taken, after the RTD's memory [-] (default 10).

    Returns
    -------
    VRRTable
        ``period_over_tm`` [-], ``period`` [s] and ``vrr`` [-] per period.

    Raises
    ------
    ValueError
        For an RTD whose bins are not equal or do not start at 0, or a period shorter than 4 bins.

    Examples
    --------
    Residence times spread evenly over 0 to 1 s damp a sine of period 2 s by ``sin(pi/2) / (pi/2)`` in amplitude,
    so ``VRR = pi^2 / 4 = 2.467``; 100 bins give it within their width:

    >>> import numpy as np
    >>> rtd = rtd_from_exit_times((np.arange(1000) + 0.5) / 1000, bins=100)
    >>> table = vrr(rtd, [4.0])
    >>> table.period.round(3).tolist(), table.vrr.round(2).tolist()
    ([2.0], [2.46])
    """
    edges = np.asarray(rtd.edges, dtype=float)
    widths = np.diff(edges)
    if edges[0] != 0.0 or not np.allclose(widths, widths[0], rtol=1e-9, atol=0.0):
        raise ValueError("the RTD must have equal bins from 0 (residence_time_distribution with bins None or an int)")
    return vrr_versus_period(rtd.E, edges[:-1], periods_over_tm, waveform=waveform, n_periods=n_periods,
                             t_mean=rtd.t_mean)
