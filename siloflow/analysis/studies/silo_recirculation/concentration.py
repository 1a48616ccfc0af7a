"""Batch layers and the blue concentration at the outlet of a recirculating silo, measured and predicted.

Pure functions on numpy arrays; no file I/O. SI units: times in s, E in 1/s; concentrations are blue
fractions [-].

Batch layers and outlet concentration
-------------------------------------
The batch is coloured after the fact from one assembly (:func:`layer_colours`): clumps ranked by
height, ``r = (rank + 0.5) / N`` (``1 - r`` when counting from the top), blue iff
``frac(r * sublayers) < blue_fraction``. The outlet concentration in a time window is the number
of blue outlet crossings over the number of all outlet crossings in it
(:func:`outlet_concentration`).

Renewal model
-------------
Material that leaves re-enters at once and the flow is steady, so the blue outflow is the first
outlet crossing of what the loop held at the start plus whatever re-entered and leaves again:
``c = c_first + c * E`` with ``E`` the loop RTD (outlet crossing to the next outlet crossing)
and ``*`` the convolution. Its series solution ``c = c_first + c_first * E + c_first * E * E + ...``
is :func:`predicted_concentration_from_first_pass` (:func:`siloflow.analysis.numerics.lti.recirculate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, finite_number, integer_at_least, positive_number
from siloflow.analysis.numerics.lti import recirculate
from siloflow.analysis.studies.silo_recirculation.tracks import RecirculationEvents
from siloflow.analysis.studies.silo_recirculation.validation import event_times, open_fraction

__all__ = [
    "OutletConcentration",
    "layer_colours",
    "batch_inlet_signal",
    "outlet_concentration",
    "first_pass_concentration",
    "predicted_concentration_from_first_pass",
]


@dataclass(frozen=True, eq=False)
class OutletConcentration:
    """Blue fraction of the outlet crossings in consecutive time windows.

    Attributes
    ----------
    edges : numpy.ndarray, shape (n_w + 1,)
        Window edges ``t_start + i window`` [s]; window i is ``[edges[i], edges[i + 1])``.
    centres : numpy.ndarray, shape (n_w,)
        Window centres [s].
    n_total : numpy.ndarray of int64, shape (n_w,)
        Outlet crossings in each window [-].
    n_blue : numpy.ndarray of int64, shape (n_w,)
        Blue crossings counted in each window [-].
    concentration : numpy.ndarray, shape (n_w,)
        ``n_blue / n_total`` [-]; NaN where ``n_total`` is 0.
    window : float
        Window length [s].
    """

    edges: np.ndarray
    centres: np.ndarray
    n_total: np.ndarray
    n_blue: np.ndarray
    concentration: np.ndarray
    window: float

    @property
    def mean_crossings(self) -> float:
        """Mean number of crossings per window (the ``n`` of :func:`siloflow.analysis.studies.silo_recirculation.vrr.sampling_noise_vrr_limit`) [-]."""
        return float(np.mean(self.n_total))

    def rows(self) -> list[dict]:
        """One dict per window (for :func:`siloflow.analysis.io.tables.write_flow_table`)."""
        return [
            {
                "t_start_s": float(a),
                "t_end_s": float(b),
                "t_centre_s": float(c),
                "n_total": int(n),
                "n_blue": int(nb),
                "concentration": float(x),
            }
            for a, b, c, n, nb, x in zip(
                self.edges[:-1], self.edges[1:], self.centres, self.n_total, self.n_blue, self.concentration
            )
        ]


def _blue_at(value) -> str:
    if value not in ("bottom", "top"):
        raise ValueError(f"blue_at must be 'bottom' or 'top', got {value!r}")
    return value


def _mask(name: str, values, shape: tuple) -> np.ndarray:
    """A boolean mask (bool, or numbers that are all 0 or 1) of the given shape."""
    array = np.asarray(values)
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if array.dtype == bool:
        return array
    if array.dtype.kind in "iuf" and np.all((array == 0) | (array == 1)):
        return array.astype(bool)
    raise ValueError(f"{name} must be a boolean mask (True/False or 0/1)")


def _window_edges(window, t_start, t_end) -> tuple[np.ndarray, float]:
    window = positive_number("window", window)
    t_start = finite_number("t_start", t_start)
    t_end = finite_number("t_end", t_end)
    if t_end <= t_start:
        raise ValueError(f"t_end must be > t_start = {t_start!r} s, got {t_end!r}")
    n_windows = int(math.floor((t_end - t_start) / window + 1.0e-9))
    if n_windows < 1:
        raise ValueError(f"window ({window!r} s) must fit at least once into [t_start, t_end] = [{t_start!r}, {t_end!r}] s")
    return t_start + np.arange(n_windows + 1) * window, window


def _window_counts(edges: np.ndarray, times: np.ndarray, counted: np.ndarray | None = None) -> np.ndarray:
    """Number of ``times`` (NaN ignored; only where ``counted``) in each window ``[edges[i], edges[i + 1])``."""
    n_windows = edges.size - 1
    keep = np.isfinite(times) if counted is None else np.isfinite(times) & counted
    index = np.searchsorted(edges, times[keep], side="right") - 1
    index = index[(index >= 0) & (index < n_windows)]
    return np.bincount(index, minlength=n_windows).astype(np.int64)


def _concentration(edges: np.ndarray, n_total: np.ndarray, n_blue: np.ndarray, window: float) -> OutletConcentration:
    with np.errstate(invalid="ignore", divide="ignore"):
        concentration = np.where(n_total > 0, n_blue / np.maximum(n_total, 1), np.nan)
    return OutletConcentration(
        edges=edges,
        centres=0.5 * (edges[1:] + edges[:-1]),
        n_total=n_total,
        n_blue=n_blue,
        concentration=concentration,
        window=float(window),
    )


def layer_colours(initial_height, blue_fraction: float, sublayers: int = 1, blue_at: str = "bottom") -> np.ndarray:
    """Colour the clumps of one assembly in horizontal batch layers (True = blue).

    The clumps are ranked by height (stable sort: equal heights by index), ``r_i = (rank_i + 0.5) / N``
    counted from the bottom (``1 - r_i``, i.e. ranked from the top, when ``blue_at = "top"``), and clump i is
    blue iff ``frac(r_i * sublayers) < blue_fraction``. The rule is evaluated in integers,
    ``((2 rank + 1) sublayers mod 2N) / 2N < p``, so the counts are exact. With ``sublayers = 1``
    the lowest (highest) fraction ``p`` is blue; ``sublayers = 3`` with ``p = 0.5`` gives six equal
    layers B W B W B W from the bottom (from the top with ``blue_at = "top"``).

    Parameters
    ----------
    initial_height : array_like, shape (N,)
        Heights of the clumps at the assembly, finite [m] (e.g. ``tracks.z[0]``; pass a subset to
        colour only, say, the clumps above the outlet).
    blue_fraction : float
        Blue fraction ``p`` of each layer pair, in (0, 1) [-].
    sublayers : int, optional
        Number of blue/white layer pairs, >= 1; default 1.
    blue_at : {"bottom", "top"}, optional
        Whether each pair starts with blue at its bottom (default) or the ranks count from the top.

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        True for blue clumps.
    """
    heights = finite_array("initial_height", initial_height, ndim=1)
    p = open_fraction("blue_fraction", blue_fraction)
    sublayers = integer_at_least("sublayers", sublayers, 1)
    blue_at = _blue_at(blue_at)
    n = heights.size
    if n == 0:
        return np.zeros(0, dtype=bool)
    rank = np.empty(n, dtype=np.int64)
    rank[np.argsort(heights, kind="stable")] = np.arange(n, dtype=np.int64)
    if blue_at == "top":
        rank = n - 1 - rank
    numerator = ((2 * rank + 1) * sublayers) % (2 * n)
    return numerator / (2.0 * n) < p


def batch_inlet_signal(
    blue_fraction: float, sublayers: int, blue_at: str, residence_time: float, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """The layered batch as an inlet concentration fed over one mean residence time.

    The batch is fed bottom layer first over ``t_res``: the material entering at time t is the
    layer at relative height ``r = t / t_res`` of the batch, blue (1) iff
    ``frac(r * sublayers) < blue_fraction`` (``r -> 1 - r`` for ``blue_at = "top"``), the rule of
    :func:`layer_colours`. The signal has ``N = round(t_res / dt)`` samples at the midpoints
    ``t_i = (i + 0.5) dt``, i = 0 ... N - 1, each standing for ``[i dt, (i + 1) dt)``; its mean is
    ``p`` up to discretisation, exactly when ``N dt = t_res`` and ``N / sublayers`` and
    ``N p / sublayers`` are whole numbers (every layer boundary then falls between samples).
    Feed it to :func:`siloflow.analysis.numerics.lti.recirculate` with an RTD sampled with the same ``dt``.

    Parameters
    ----------
    blue_fraction : float
        Blue fraction ``p``, in (0, 1) [-].
    sublayers : int
        Number of blue/white layer pairs, >= 1.
    blue_at : {"bottom", "top"}
        Where the blue layer of each pair lies (bottom enters first).
    residence_time : float
        Mean residence time ``t_res`` over which the batch is fed [s], > 0.
    dt : float
        Sample step [s], > 0 and at most ``2 t_res`` (at least one sample).

    Returns
    -------
    time : numpy.ndarray, shape (N,)
        Sample times ``(i + 0.5) dt`` [s].
    c_in : numpy.ndarray, shape (N,)
        Inlet concentration, 1.0 blue or 0.0 white [-].
    """
    p = open_fraction("blue_fraction", blue_fraction)
    sublayers = integer_at_least("sublayers", sublayers, 1)
    blue_at = _blue_at(blue_at)
    t_res = positive_number("residence_time", residence_time)
    dt = positive_number("dt", dt)
    n = int(round(t_res / dt))
    if n < 1:
        raise ValueError(f"dt ({dt!r} s) must be at most twice residence_time ({t_res!r} s): no sample")
    time = (np.arange(n) + 0.5) * dt
    r = time / t_res
    if blue_at == "top":
        r = 1.0 - r
    scaled = r * sublayers
    c_in = np.where(scaled - np.floor(scaled) < p, 1.0, 0.0)
    return time, c_in


def outlet_concentration(exit_times, is_blue, window: float, t_start: float, t_end: float) -> OutletConcentration:
    """Blue fraction of the outlet crossings in consecutive windows of ``[t_start, t_end]``.

    The span is cut into ``floor((t_end - t_start) / window)`` windows ``[t_start + i window,
    t_start + (i + 1) window)`` (the incomplete last one is dropped); each counts the crossings in it
    and the blue ones. For every outlet crossing of a run use
    ``outlet_concentration(events.exit_times_all, colours[events.exit_clump_index], ...)``.

    Parameters
    ----------
    exit_times : array_like, shape (n,)
        Crossing times [s]; NaN entries (no crossing) are ignored.
    is_blue : array_like of bool, shape (n,)
        Colour of each crossing clump.
    window : float
        Window length [s], > 0.
    t_start, t_end : float
        Span to cut into windows [s], ``t_end > t_start``.

    Returns
    -------
    OutletConcentration
        ``concentration = n_blue / n_total`` per window (NaN where no crossing).
    """
    exits = event_times("exit_times", exit_times)
    blue = _mask("is_blue", is_blue, exits.shape)
    edges, window = _window_edges(window, t_start, t_end)
    n_total = _window_counts(edges, exits)
    n_blue = _window_counts(edges, exits, blue)
    return _concentration(edges, n_total, n_blue, window)


def first_pass_concentration(
    events: RecirculationEvents, is_blue, window: float, t_start: float, t_end: float
) -> OutletConcentration:
    """Blue first exits of the initial contents over all outlet crossings, per window.

    The initial contents are everything the loop holds at the first frame; the first exit of a
    clump is its first outlet crossing after that (``events.first_exit_time``): the exit of its
    pass 0, or, for a clump that started in the channel below the outlet, the exit after its first
    re-entry (in a run whose channel is empty at the first frame, exactly the exits with
    ``pass_number`` 0). ``n_blue`` counts the blue first exits in each window and ``n_total`` every
    outlet crossing (``events.exit_times_all``), so ``c_first + c_recycled = c`` with
    ``c = outlet_concentration(events.exit_times_all, is_blue[events.exit_clump_index], ...)``.
    ``c_first`` is the source term of the renewal equation
    (:func:`predicted_concentration_from_first_pass`).

    Parameters
    ----------
    events : RecirculationEvents
        Crossings and passes of the run.
    is_blue : array_like of bool, shape (n_c,)
        Colour of each clump, in the column order of the events (e.g. :func:`layer_colours`).
    window : float
        Window length [s], > 0.
    t_start, t_end : float
        Span to cut into windows [s] (as in :func:`outlet_concentration`).

    Returns
    -------
    OutletConcentration
        ``concentration`` is ``c_first`` (NaN where no crossing at all).
    """
    blue = _mask("is_blue", is_blue, (events.n_clumps,))
    edges, window = _window_edges(window, t_start, t_end)
    n_total = _window_counts(edges, np.asarray(events.exit_times_all, dtype=float))
    n_blue = _window_counts(edges, np.asarray(events.first_exit_time, dtype=float), blue)
    return _concentration(edges, n_total, n_blue, window)


def predicted_concentration_from_first_pass(c_first, E, dt: float, passes: int) -> np.ndarray:
    """Outlet concentration predicted from the first exits of the initial contents (renewal equation).

    Model: material leaving the outlet re-enters at once (the periodic silo) and the flow is
    steady, so the outlet concentration is the first-exit contribution of the initial contents
    plus the re-entered outflow that leaves again:

        c(t) = c_first(t) + integral_0^t c(t - tau) E(tau) dtau,

    a renewal equation whose series solution ``c = c_first + c_first * E + c_first * E * E + ...``
    is summed by :func:`siloflow.analysis.numerics.lti.recirculate` (its pass-1 output is ``c_first * E``), plus
    ``c_first`` itself, on the axis of ``c_first`` (longer parts are cut). ``E`` must be the RTD of
    the whole loop, from an outlet crossing to the next one of the same clump (channel and free
    fall included: :func:`~siloflow.analysis.studies.silo_recirculation.tracers.tracer_passes` with
    ``entry_at = "outlet"``); "at once" then holds by
    construction. Discretisation is that of :mod:`siloflow.analysis.numerics.lti` (rectangle rule, first order in
    ``dt``); ``E`` is normalised to unit area (a closed loop loses nothing).

    The sum is complete on the axis once pass ``passes + 1`` contributes nothing there: if ``E``
    vanishes below the lag of ``m0`` samples, ``passes >= len(c_first) / m0`` suffices; with
    ``E[0] > 0`` the terms decay geometrically instead.

    Parameters
    ----------
    c_first : array_like, shape (N,)
        First-exit concentration per window (:func:`first_pass_concentration`), finite, N >= 2 [-].
    E : array_like, shape (m,)
        Loop RTD at residence times ``0, dt, 2 dt, ...`` [1/s] (for a histogram from
        :func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times` with bins of width ``dt`` from 0, its ``E``).
    dt : float
        Window length, the step of ``c_first`` and ``E`` [s], > 0.
    passes : int
        Number of recirculations summed, >= 1.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Predicted outlet concentration on the windows of ``c_first`` [-].
    """
    c1 = finite_array("c_first", c_first, ndim=1)
    if c1.size < 2:
        raise ValueError(f"c_first must have at least 2 samples, got {c1.size}")
    dt = positive_number("dt", dt)
    passes = integer_at_least("passes", passes, 1)
    loop = recirculate(c1, E, np.arange(c1.size) * dt, passes, normalise=True)
    return c1 + loop.concentration[: c1.size]
