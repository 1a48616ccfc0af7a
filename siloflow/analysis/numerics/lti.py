"""Linear time-invariant (LTI) blending model of a silo: convolution of an input with the RTD.

Pure functions on numpy arrays; no file I/O. SI units: times in s, E in 1/s; concentrations in
any unit (e.g. a mass fraction of blue pellets), outputs in the unit of the input.

Model (thesis ch. 6)
-----------------------------
The silo is a linear, time-invariant system whose impulse response is its RTD ``E``:

    c_out(t) = integral_0^inf c_in(t - tau) E(tau) dtau.

Discretisation
--------------
Signals live on a uniform time grid ``t_n = t_0 + n dt``. ``E`` is tabulated at residence times
``tau_k = k dt`` (k = 0 ... m - 1, first sample at tau = 0, the same step as the signal; zero beyond
its table). The integral is the rectangle rule

    c_out[n] = dt * sum_{k=0}^{min(n, m-1)} c_in[n - k] E[k]  (+ the part from before t_0, below),

which is causal (c_out[n] uses c_in up to sample n only) and exact for a unit impulse: an input
``1/dt`` at sample 0 (unit area) returns ``E`` itself. It is a first-order rule: for a smooth
``E`` the effective RTD is shifted by up to half a step; use ``dt`` much smaller than the time
scales of interest (e.g. ``dt <= t_m / 500`` for a 1 % accurate variance reduction ratio of a
perfect mixer).

Continuous mode
    Any input signal (:func:`sine_input`, :func:`square_input`, measured data) -> output; the
    variance reduction ratio ``VRR = sigma_in^2 / sigma_out^2`` over the steady part
    (:func:`variance_reduction_ratio`, :func:`vrr_versus_period`).
Discontinuous (recirculation) mode
    The output of pass n is the input of pass n + 1 (:func:`recirculate`); the number of
    recirculations until the outlet concentration stays within +-10 % of its mean
    (:func:`recirculations_to_homogenise`).
Recycle of a measured first pass (Carson and Royal)
    The outflow of each pass of a unit pulse, by repeated convolution (:func:`carson_royal_recycle`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import convolve

from siloflow.model.checks import (
    finite_array,
    finite_number,
    integer_at_least,
    non_negative_number,
    positive_number,
    uniform_step,
)
from siloflow.analysis.numerics.rtd import rtd_moments

__all__ = [
    "VRRTable",
    "Recirculation",
    "convolve_with_rtd",
    "sine_input",
    "square_input",
    "variance_reduction_ratio",
    "coefficient_of_variation",
    "vrr_versus_period",
    "recirculate",
    "recirculations_to_homogenise",
    "carson_royal_recycle",
]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True, eq=False)
class VRRTable:
    """Variance reduction ratio of periodic inputs against their period.

    Attributes
    ----------
    period_over_tm : numpy.ndarray, shape (n,)
        Input period as a fraction of the mean residence time [-].
    period : numpy.ndarray, shape (n,)
        Input period [s].
    vrr : numpy.ndarray, shape (n,)
        ``var(c_in) / var(c_out)`` over the steady part [-] (inf if the output is constant).
    t_mean : float
        Mean residence time used [s].
    waveform : str
        ``"sine"`` or ``"square"``.
    n_periods : int
        Number of whole periods in the steady window.
    """

    period_over_tm: np.ndarray
    period: np.ndarray
    vrr: np.ndarray
    t_mean: float
    waveform: str
    n_periods: int

    def rows(self) -> list[dict]:
        """One dict per period (for :func:`siloflow.analysis.io.tables.write_flow_table`)."""
        return [
            {
                "period_over_tm": float(f),
                "period_s": float(p),
                "vrr": float(v),
                "t_mean_s": self.t_mean,
                "waveform": self.waveform,
            }
            for f, p, v in zip(self.period_over_tm, self.period, self.vrr)
        ]


@dataclass(frozen=True, eq=False)
class Recirculation:
    """Outlet concentration of a closed recirculation, pass by pass.

    Attributes
    ----------
    time : numpy.ndarray, shape (L,)
        Common time axis ``t_0 + k dt`` [s], long enough for the last pass.
    concentration : numpy.ndarray, shape (L,)
        Outlet concentration: the sum of the outputs of all passes (material on its first, second,
        ... pass leaves the outlet at the same instant) [unit of the input].
    pass_time : tuple of numpy.ndarray
        Time axis of the output of each pass (pass n: ``N + n (m - 1)`` samples from ``t_0``) [s].
    pass_concentration : tuple of numpy.ndarray
        Output of each pass; pass n + 1 has the output of pass n as its input.
    pass_mass : numpy.ndarray, shape (passes,)
        ``sum(c) dt`` of each pass output; all equal to :attr:`input_mass` for a normalised RTD.
    input_mass : float
        ``sum(c_first_input) dt``.
    next_pass : numpy.ndarray, shape (L,)
        Output of the first pass not included (pass ``passes + 1``), cut to :attr:`time`: the
        leading term missing from :attr:`concentration`. Where it is not negligible, more passes
        are needed.
    """

    time: np.ndarray
    concentration: np.ndarray
    pass_time: tuple
    pass_concentration: tuple
    pass_mass: np.ndarray
    input_mass: float
    next_pass: np.ndarray


# --------------------------------------------------------------------------- validation


def _unit_area(e: np.ndarray, dt: float) -> np.ndarray:
    """``e`` scaled so that ``sum(e) dt = 1`` (the discrete RTD of a process that loses nothing)."""
    area = float(np.sum(e)) * dt
    if not area > 0.0:
        raise ValueError("E must have a positive area to be normalised")
    return e / area


def _method(method: str) -> str:
    if method not in ("auto", "direct", "fft"):
        raise ValueError(f"method must be 'auto', 'direct' or 'fft', got {method!r}")
    return method


# --------------------------------------------------------------------------- convolution


def _series_on_axis(time, name: str, values, from_zero: bool = False) -> tuple[np.ndarray, float, np.ndarray]:
    """(time axis, its uniform step, ``values`` checked to be finite and sampled on it); with ``from_zero`` the
    axis must start at 0 (time[k] = k dt). Errors name the argument."""
    t = finite_array("time", time, ndim=1)
    dt = uniform_step("time", t)
    if from_zero and abs(t[0]) > 1.0e-9 * dt:
        raise ValueError(f"time must start at 0 (time[k] = k dt), got time[0] = {t[0]!r}")
    series = finite_array(name, values, ndim=1)
    if series.shape != t.shape:
        raise ValueError(f"{name} must have the shape of time {t.shape}, got {series.shape}")
    return t, dt, series


def convolve_with_rtd(time, c_in, E, c_before: float = 0.0, method: str = "auto") -> np.ndarray:
    """Outlet signal of the LTI model: ``c_out(t) = integral c_in(t - tau) E(tau) dtau`` on a uniform grid.

    Discretisation (see the module docstring): ``c_out[n] = dt sum_{k=0}^{min(n, m-1)} c_in[n-k] E[k]
    + c_before dt sum_{k=n+1}^{m-1} E[k]``, with ``E[k]`` the RTD at residence time ``k dt``. The
    second term is the material that entered before ``time[0]`` with concentration ``c_before``;
    with ``c_before = c`` and ``sum(E) dt = 1`` a constant input ``c`` gives the constant output
    ``c`` from the first sample. Causal; a unit impulse (``1/dt`` at sample 0, ``c_before = 0``)
    returns ``E`` (to round-off; bit for bit when ``dt`` is a power of 2).

    Parameters
    ----------
    time : array_like, shape (n,)
        Uniform time axis of the input, ``n >= 2`` [s].
    c_in : array_like, shape (n,)
        Input concentration at ``time``.
    E : array_like, shape (m,)
        RTD at residence times ``0, dt, 2 dt, ...`` [1/s], ``m >= 1`` (any length; zero beyond).
    c_before : float, optional
        Input concentration before ``time[0]``; default 0 (the silo holds only material of
        concentration 0 at the start).
    method : {"auto", "direct", "fft"}, optional
        Passed to :func:`scipy.signal.convolve`: the direct sum (exact to round-off), FFT (error
        about 1e-16 of the largest term) or ``"auto"`` (default), scipy's choice of the faster one.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Output concentration at ``time``.
    """
    t, dt, c = _series_on_axis(time, "c_in", c_in)
    e = finite_array("E", E, ndim=1)
    if e.size == 0:
        raise ValueError("E must have at least 1 sample")
    c_before = finite_number("c_before", c_before)
    method = _method(method)
    out = dt * convolve(c, e, method=method)[: c.size]
    if c_before != 0.0:
        # sum_{k=n+1}^{m-1} E[k] for n = 0 .. N-1 (zero once n >= m - 1)
        tail = np.cumsum(e[::-1])[::-1]  # tail[j] = sum_{k>=j} E[k]
        remaining = np.zeros(c.size)
        count = min(c.size, e.size - 1)
        remaining[:count] = tail[1 : count + 1]
        out = out + c_before * dt * remaining
    return out


# --------------------------------------------------------------------------- continuous mode


def sine_input(time, mean: float, amplitude: float, period: float, phase: float = 0.0) -> np.ndarray:
    """Sinusoidal input ``mean + amplitude sin(2 pi t / period + phase)``.

    Parameters
    ----------
    time : array_like
        Times [s].
    mean : float
        Mean concentration.
    amplitude : float
        Amplitude (>= 0); the variance over whole periods is ``amplitude^2 / 2``.
    period : float
        Period [s], > 0.
    phase : float, optional
        Phase at t = 0 [rad]; default 0.

    Returns
    -------
    numpy.ndarray
        The signal, the shape of ``time``.
    """
    t = finite_array("time", time, ndim=None)
    mean = finite_number("mean", mean)
    amplitude = non_negative_number("amplitude", amplitude)
    period = positive_number("period", period)
    phase = finite_number("phase", phase)
    return mean + amplitude * np.sin(2.0 * np.pi * t / period + phase)


def square_input(time, mean: float, amplitude: float, period: float, duty: float = 0.5) -> np.ndarray:
    """Square-wave input alternating between ``mean + amplitude`` and ``mean - amplitude``.

    The high level holds for the first ``duty`` fraction of each period (periods start at t = 0,
    ``period``, ...), the low level for the rest. ``mean`` is the midpoint of the two levels; it
    is the time average only for ``duty = 0.5`` (variance ``amplitude^2`` over whole periods). A
    sample within 1e-9 periods before a switching instant takes the level after the switch, so
    that round-off in ``t / period`` does not move switches by a sample.

    Parameters
    ----------
    time : array_like
        Times [s].
    mean : float
        Midpoint of the two levels.
    amplitude : float
        Half the difference between the levels, >= 0.
    period : float
        Period [s], > 0.
    duty : float, optional
        Fraction of the period at the high level, in (0, 1); default 0.5.

    Returns
    -------
    numpy.ndarray
        The signal, the shape of ``time``.
    """
    t = finite_array("time", time, ndim=None)
    mean = finite_number("mean", mean)
    amplitude = non_negative_number("amplitude", amplitude)
    period = positive_number("period", period)
    duty = float(duty)
    if not math.isfinite(duty) or not 0.0 < duty < 1.0:
        raise ValueError(f"duty must be a number in (0, 1), got {duty!r}")
    cycles = t / period
    fraction = cycles - np.floor(cycles + 1.0e-9)
    return np.where(fraction < duty - 1.0e-9, mean + amplitude, mean - amplitude)


def variance_reduction_ratio(c_in, c_out, steady_from=0, time=None) -> float:
    """Variance reduction ratio ``VRR = var(c_in) / var(c_out)`` over the steady part.

    Both variances are population variances (``ddof = 0``) over the same samples. For a periodic
    input, take a window of whole periods.

    Parameters
    ----------
    c_in, c_out : array_like, shape (n,)
        Input and output concentration on the same samples.
    steady_from : int or float, optional
        Start of the steady part: a sample index (default 0) or, when ``time`` is given, a time [s]
        (samples with ``time >= steady_from``).
    time : array_like, shape (n,), optional
        Sample times [s].

    Returns
    -------
    float
        VRR [-]; ``inf`` if the output is constant over the window.

    Raises
    ------
    ValueError
        If the shapes differ, the window has fewer than 2 samples, or the input is constant
        over it.
    """
    a = finite_array("c_in", c_in, ndim=1)
    b = finite_array("c_out", c_out, ndim=1)
    if b.shape != a.shape:
        raise ValueError(f"c_out must have the shape of c_in {a.shape}, got {b.shape}")
    if time is None:
        start = integer_at_least("steady_from", steady_from, 0)
        window = slice(start, None)
        n = max(a.size - start, 0)
    else:
        t = finite_array("time", time, ndim=1)
        if t.shape != a.shape:
            raise ValueError(f"time must have the shape of c_in {a.shape}, got {t.shape}")
        window = t >= finite_number("steady_from", steady_from)
        n = int(window.sum())
    if n < 2:
        raise ValueError(f"steady_from leaves {n} samples; at least 2 are needed")
    var_in = float(np.var(a[window]))
    var_out = float(np.var(b[window]))
    if var_in == 0.0:
        raise ValueError("c_in is constant over the steady part; the VRR is undefined")
    return math.inf if var_out == 0.0 else var_in / var_out


def coefficient_of_variation(c) -> float:
    """Coefficient of variation ``std(c) / mean(c)`` (population standard deviation) [-].

    Raises
    ------
    ValueError
        If ``c`` is empty or its mean is 0.
    """
    values = finite_array("c", c, ndim=None).ravel()
    if values.size == 0:
        raise ValueError("c must not be empty")
    mean = float(np.mean(values))
    if mean == 0.0:
        raise ValueError("c has mean 0; the coefficient of variation is undefined")
    return float(np.std(values)) / mean


def vrr_versus_period(
    E,
    time,
    periods_over_tm,
    mean: float = 0.5,
    amplitude: float = 0.5,
    waveform: str = "sine",
    n_periods: int = 10,
    t_mean: float | None = None,
    normalise: bool = True,
    method: str = "auto",
) -> VRRTable:
    """VRR of periodic inputs against their period (as a fraction of the mean residence time).

    For each period ``P = f t_m`` the input (sine or square, starting at t = 0) runs for
    ``m - 1`` samples (the memory of the tabulated RTD, after which the output is exactly periodic)
    plus ``round(n_periods P / dt)`` samples; the VRR is taken over the latter (the steady window).

    Parameters
    ----------
    E : array_like, shape (m,)
        RTD at residence times ``time`` [1/s].
    time : array_like, shape (m,)
        Uniform residence-time axis starting at 0 (``time[k] = k dt``) [s].
    periods_over_tm : array_like, shape (n,)
        Periods as fractions of ``t_m``, each > 0 and at least 4 samples long.
    mean, amplitude : float, optional
        Input mean (midpoint) and amplitude; default 0.5 and 0.5 (a 0/1 square wave). The VRR does
        not depend on them.
    waveform : {"sine", "square"}, optional
        Input shape; default ``"sine"``.
    n_periods : int, optional
        Whole periods in the steady window; default 10.
    t_mean : float, optional
        Mean residence time [s]; default the trapezoid mean of ``E``
        (:func:`siloflow.analysis.numerics.rtd.rtd_moments`).
    normalise : bool, optional
        Divide ``E`` by ``sum(E) dt`` first (default True), so that the discrete RTD has unit
        area; it removes the first-order error of sampling a smooth curve.
    method : {"auto", "direct", "fft"}, optional
        Convolution method (see :func:`convolve_with_rtd`).

    Returns
    -------
    VRRTable
    """
    t, dt, e = _series_on_axis(time, "E", E, from_zero=True)
    fractions = finite_array("periods_over_tm", periods_over_tm, ndim=None).ravel()
    if fractions.size == 0 or np.any(fractions <= 0.0):
        raise ValueError("periods_over_tm must be a non-empty array of numbers > 0")
    if waveform not in ("sine", "square"):
        raise ValueError(f"waveform must be 'sine' or 'square', got {waveform!r}")
    n_periods = integer_at_least("n_periods", n_periods, 1)
    method = _method(method)
    if normalise:
        e = _unit_area(e, dt)
    tm = rtd_moments(t, e).mean if t_mean is None else positive_number("t_mean", t_mean)
    periods = fractions * tm
    vrr = np.empty(fractions.size)
    memory = e.size - 1
    for index, period in enumerate(periods):
        if period < 4.0 * dt:
            raise ValueError(
                f"periods_over_tm: period {period!r} s is shorter than 4 samples of dt = {dt!r} s"
            )
        steady = max(2, int(round(n_periods * period / dt)))
        signal_time = np.arange(memory + steady) * dt
        if waveform == "sine":
            c_in = sine_input(signal_time, mean, amplitude, period)
        else:
            c_in = square_input(signal_time, mean, amplitude, period)
        c_out = convolve_with_rtd(signal_time, c_in, e, method=method)
        vrr[index] = variance_reduction_ratio(c_in, c_out, steady_from=memory)
    return VRRTable(
        period_over_tm=fractions,
        period=periods,
        vrr=vrr,
        t_mean=float(tm),
        waveform=waveform,
        n_periods=n_periods,
    )


# --------------------------------------------------------------------------- discontinuous mode


def recirculate(c_first_input, E, time, passes: int, normalise: bool = True, method: str = "auto") -> Recirculation:
    """Closed recirculation: the output of pass n is the input of pass n + 1.

    Model: material leaving the outlet re-enters at once (the periodic silo of the study), so in a
    steady flow the silo is an LTI system fed with its own output. The first input
    ``c_first_input`` on ``time`` (e.g. the layered batch expressed as the inlet concentration over
    one residence time, ``N = t_m / dt`` samples) makes its first pass; pass 1 outputs
    ``c_1 = c_first_input * E`` (full discrete convolution, no truncation, on an axis of ``N + m - 1``
    samples from ``time[0]``), pass n + 1 takes ``c_n`` as input and outputs ``c_{n+1} = c_n * E``
    (``N + (n + 1)(m - 1)`` samples). The outlet concentration is the sum of the pass outputs, since
    material on its first, second, ... pass leaves at the same instant (the series solution of the
    renewal equation ``c = c_1 + c * E``). Every pass conserves the tracer: ``sum(c_n) dt =
    sum(c_first_input) dt`` when ``sum(E) dt = 1`` (``normalise``).

    The sum stops after ``passes`` passes, so it is complete only while pass ``passes + 1``
    contributes nothing; :attr:`Recirculation.next_pass` is that first omitted term. Before
    ``time[0]`` the silo holds material of concentration 0.

    Parameters
    ----------
    c_first_input : array_like, shape (N,)
        Inlet concentration of the first pass on ``time``.
    E : array_like, shape (m,)
        RTD at residence times ``0, dt, 2 dt, ...`` [1/s].
    time : array_like, shape (N,)
        Uniform time axis of the first input [s].
    passes : int
        Number of passes, >= 1.
    normalise : bool, optional
        Divide ``E`` by ``sum(E) dt`` first (default True): a closed recirculation loses no material.
    method : {"auto", "direct", "fft"}, optional
        Convolution method (see :func:`convolve_with_rtd`).

    Returns
    -------
    Recirculation
    """
    t, dt, c = _series_on_axis(time, "c_first_input", c_first_input)
    e = finite_array("E", E, ndim=1)
    if e.size == 0:
        raise ValueError("E must have at least 1 sample")
    passes = integer_at_least("passes", passes, 1)
    method = _method(method)
    if normalise:
        e = _unit_area(e, dt)
    outputs = []
    current = c
    for _ in range(passes + 1):
        current = dt * convolve(current, e, method=method)
        outputs.append(current)
    next_pass_full = outputs.pop()
    length = outputs[-1].size
    total = np.zeros(length)
    for output in outputs:
        total[: output.size] += output
    pass_time = tuple(t[0] + np.arange(output.size) * dt for output in outputs)
    return Recirculation(
        time=t[0] + np.arange(length) * dt,
        concentration=total,
        pass_time=pass_time,
        pass_concentration=tuple(outputs),
        pass_mass=np.array([float(np.sum(output)) * dt for output in outputs]),
        input_mass=float(np.sum(c)) * dt,
        next_pass=next_pass_full[:length],
    )


def recirculations_to_homogenise(c, mean=None, tolerance: float = 0.10, per_pass_length: float = 1.0) -> float:
    """Number of recirculations after which ``c`` stays within ``+-tolerance`` of its mean.

    The answer is ``s / per_pass_length`` where ``s`` is the first sample from which every sample
    to the end satisfies ``|c - mean| <= tolerance |mean|`` (``s = 0`` if all do). With ``c`` on an
    axis starting at t = 0 and ``per_pass_length = t_m / dt`` samples, this is
    ``N_r = t / t_m`` at homogenisation (a real number; ``math.ceil`` gives whole passes).

    Parameters
    ----------
    c : array_like, shape (n,)
        Outlet concentration (e.g. :attr:`Recirculation.concentration`).
    mean : float, optional
        The mean to stay around, e.g. the blue fraction of the batch; default ``mean(c)``. Non-zero.
    tolerance : float, optional
        Relative band half-width, > 0; default 0.10 (+-10 %).
    per_pass_length : float, optional
        Samples per recirculation (> 0; need not be whole); default 1 (the answer is then a sample
        index).

    Returns
    -------
    float
        Recirculations to homogenise; NaN if the last sample is outside the band (not homogenised
        within the record).
    """
    values = finite_array("c", c, ndim=1)
    if values.size == 0:
        raise ValueError("c must not be empty")
    target = float(np.mean(values)) if mean is None else finite_number("mean", mean)
    if target == 0.0:
        raise ValueError("mean must be non-zero (the band is relative to it)")
    tolerance = positive_number("tolerance", tolerance)
    per_pass_length = positive_number("per_pass_length", per_pass_length)
    outside = np.abs(values - target) > tolerance * abs(target)
    if outside[-1]:
        return math.nan
    hits = np.flatnonzero(outside)
    start = 0 if hits.size == 0 else int(hits[-1]) + 1
    return start / per_pass_length


# --------------------------------------------------------------------------- recycle of a measured first pass


def carson_royal_recycle(first_pass_E, time, passes: int) -> np.ndarray:
    """Carson and Royal's recycle blending: the outflow after each pass from a measured first-pass curve.

    Material recycled from the outlet back to the inlet makes a second, third, ... pass through
    the bin. With a linear, time-invariant bin whose single-pass RTD is the measured first-pass
    curve ``E1``, the outflow of a unit tracer pulse injected at t = 0 is, for its n-th pass, the
    n-fold convolution ``E_n = E1 * E1 * ... * E1`` (n factors), and the outlet concentration of the
    closed recycle loop is ``sum_n E_n``. Each convolution is the discrete rule of
    :func:`convolve_with_rtd`: ``E_{n+1}[j] = dt sum_k E_n[j - k] E1[k]``.

    Parameters
    ----------
    first_pass_E : array_like, shape (m,)
        First-pass RTD sampled at residence times ``time`` [1/s].
    time : array_like, shape (m,)
        Uniform residence-time axis starting at 0: ``time[k] = k dt`` [s]. (For a histogram from
        :func:`siloflow.analysis.numerics.rtd.rtd_from_exit_times` with equal bins starting at 0, use its left edges
        ``rtd.edges[:-1]``.)
    passes : int
        Number of passes, >= 1.

    Returns
    -------
    numpy.ndarray, shape (passes, m)
        Row ``n - 1`` is the outflow of the n-th pass ``E_n`` on ``time`` [1/s] (row 0 is the input
        curve). Parts of ``E_n`` beyond ``time[-1]`` are cut off, so the axis must be long enough for
        the passes wanted (``sum(E_n) dt`` falls below ``sum(E1) dt`` when it is not).
        ``rows.sum(axis=0)`` is the outlet concentration of the recycle loop after a unit pulse.
    """
    t, _, e1 = _series_on_axis(time, "first_pass_E", first_pass_E, from_zero=True)
    passes = integer_at_least("passes", passes, 1)
    rows = np.empty((passes, t.size))
    rows[0] = e1
    for n in range(1, passes):
        rows[n] = convolve_with_rtd(t, rows[n - 1], e1)
    return rows
