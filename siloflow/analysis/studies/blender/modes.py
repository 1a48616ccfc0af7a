"""Blending modes of the multi-flow blender from its steady field: discontinuous (recirculated two-layer fill)
and continuous (sine inputs through the RTD).

Pure computation on :class:`siloflow.analysis.studies.blender.steady_field.BlenderField` and residence-time samples
of :mod:`siloflow.analysis.studies.blender.tracers`; no file I/O. SI units: lengths in m, times in s; concentrations
are tracer fractions [-].

1. Discontinuous mode: a two-layer fill recirculated (:func:`discontinuous_mode`).
2. Continuous mode: sine inputs through the RTD, VRR and CoV against the period
   (:func:`continuous_mode`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_array, positive_number
from siloflow.analysis.numerics.lti import VRRTable, recirculations_to_homogenise, vrr_versus_period
from siloflow.analysis.numerics.tracer_seeds import lattice_seeds
from siloflow.analysis.studies.blender.errors import homogenisation_error
from siloflow.analysis.studies.blender.steady_field import BlenderField, at_height, checked_field
from siloflow.analysis.studies.blender.tracers import (
    bin_index,
    integrate_tracers,
    lattice_spacing,
    layer_tracers,
    tabulated_rtd,
    tracer_layer,
    tracer_weights,
)
from siloflow.analysis.studies.silo_recirculation.concentration import predicted_concentration_from_first_pass

__all__ = ["DiscontinuousMode", "ContinuousMode", "discontinuous_mode", "continuous_mode"]


@dataclass(frozen=True, eq=False)
class DiscontinuousMode:
    """A two-layer fill (tracer on top of base) recirculated at constant head.

    Attributes
    ----------
    window : float
        Window length [s].
    window_start : numpy.ndarray, shape (N,)
        Start of each window ``j window`` [s].
    time_in_passes : numpy.ndarray, shape (N,)
        ``window_start / t_m`` [-].
    first_pass : numpy.ndarray, shape (N,)
        Tracer of the initial fill leaving in each window over the outflow in it [-].
    concentration : numpy.ndarray, shape (N,)
        Outlet tracer concentration, recirculated [-].
    pass_mean : numpy.ndarray, shape (n_passes,)
        Mean concentration over each pass ``[p t_m, (p + 1) t_m)`` (windows by their centres) [-].
    tracer_fraction : float
        Tracer share of the fill by weight, the level ``c`` settles at [-].
    tracer_bottom : float
        Bottom of the tracer layer [m].
    mean_residence_time : float
        ``t_m`` of material entering at the fill surface [s].
    entry_time, entry_E : numpy.ndarray
        That entry RTD tabulated at ``k window`` [s, 1/s].
    homogenised_after : float
        Passes after which ``c`` stays within ``+-tolerance`` of ``tracer_fraction``; NaN if not within
        the windows.
    homogenised_after_error : float
        Its standard error from the counting noise of the first pass and the window's resolution
        (:func:`siloflow.analysis.studies.blender.errors.homogenisation_error`) [-]; NaN when unknown.
    tolerance : float
        Relative band [-].
    n_not_exited : int
        Tracers of the fill that did not exit within ``max_time`` (their tracer never reaches the outlet).
    n_entry_not_exited : int
        Surface tracers of the entry RTD that did not exit.
    """

    window: float
    window_start: np.ndarray
    time_in_passes: np.ndarray
    first_pass: np.ndarray
    concentration: np.ndarray
    pass_mean: np.ndarray
    tracer_fraction: float
    tracer_bottom: float
    mean_residence_time: float
    entry_time: np.ndarray
    entry_E: np.ndarray
    homogenised_after: float
    homogenised_after_error: float
    tolerance: float
    n_not_exited: int
    n_entry_not_exited: int


def discontinuous_mode(
    field: BlenderField,
    fill_height: float,
    max_time: float,
    passes: int = 10,
    tracer_fraction: float = 0.20,
    window: float | None = None,
    tolerance: float = 0.10,
    tracer_spacing: float | None = None,
    dt: float | None = None,
    method: str = "rk2",
    backend: str = "auto",
) -> DiscontinuousMode:
    """Two-layer fill (tracer on top of base) discharged through the steady field and recirculated.

    Model (the renewal equation of
    :func:`siloflow.analysis.studies.silo_recirculation.concentration.predicted_concentration_from_first_pass`):
    the outflow is re-inserted at once at the fill surface and the flow is steady, so the outlet
    concentration is ``c = c_first + c * E``:

    - virtual tracers on a lattice over the whole fill ``[0, fill_height]`` (weights: bin solid fraction,
      as in :func:`~siloflow.analysis.studies.blender.tracers.layer_rtd`) give the first exits of the initial
      contents; those above the bottom of the top ``tracer_fraction`` by volume
      (:func:`~siloflow.analysis.studies.blender.tracers.tracer_layer`) are tracer;
    - ``E`` is the RTD of material entering at the surface: tracers released at ``fill_height`` with
      the lattice spacing across the width, weighted by the local flux ``solid_fraction |v_z|`` there,
      tabulated by :func:`siloflow.analysis.studies.blender.tracers.tabulated_rtd`; ``t_m`` is its weighted mean;
    - the outflow rate is the holdup over ``t_m`` (Little's law, which makes the model conserve the
      tracer: ``c`` settles at the tracer's share of the fill), so
      ``c_first[j] = (tracer weight leaving in window j) t_m / (fill weight * window)``.

    The number of recirculations to homogenise is :func:`siloflow.analysis.numerics.lti.recirculations_to_homogenise`
    of ``c`` around the tracer share, with ``t_m / window`` samples per pass; its error comes from the counting
    noise of ``c_first`` (variance: the squared tracer weights leaving in each window, scaled alike) through the
    same model (:func:`siloflow.analysis.studies.blender.errors.homogenisation_error`).

    Parameters
    ----------
    field : BlenderField
        The steady field (uniform bins).
    fill_height : float
        Fill height [m] (within the grid).
    max_time : float
        Longest residence time followed [s], > 0.
    passes : int, optional
        Passes covered by the windows, >= 1; default 10.
    tracer_fraction : float, optional
        Tracer share of the filled volume, in (0, 1); default 0.20.
    window : float, optional
        Window length [s]; default ``t_m / 100``.
    tolerance : float, optional
        Relative band of homogenisation, > 0; default 0.10.
    tracer_spacing, dt, method, backend : optional
        As in :func:`siloflow.analysis.studies.blender.tracers.layer_rtd`.

    Returns
    -------
    DiscontinuousMode
    """
    field = checked_field(field)
    max_time = positive_number("max_time", max_time)
    if isinstance(passes, (bool, np.bool_)) or int(passes) != passes or passes < 1:
        raise ValueError(f"passes must be an integer >= 1, got {passes!r}")
    tracer_fraction = positive_number("tracer_fraction", tracer_fraction)
    if tracer_fraction >= 1.0:
        raise ValueError(f"tracer_fraction must be in (0, 1), got {tracer_fraction!r}")
    tolerance = positive_number("tolerance", tolerance)
    tracer_bottom, _ = tracer_layer(field, fill_height, tracer_fraction)
    x, z, weights = layer_tracers(field, 0.0, fill_height, tracer_spacing)
    fill_residence = integrate_tracers(field, x, z, dt, max_time, method, backend).residence_time

    dx, dz = field.bin_size()
    # release just inside the grid box when the fill surface is its top face (round-off must not put it outside)
    release = min(float(fill_height), float(field.z[-1]) + 0.5 * dz * (1.0 - 1e-9))
    entry_x = lattice_seeds((field.x[0] - 0.5 * dx, 0.0, fill_height), (field.x[-1] + 0.5 * dx, 0.0, fill_height),
                            spacing=(lattice_spacing(field, tracer_spacing), 1.0, 1.0))[:, 0]
    surface = float(np.clip(fill_height, field.z[0], field.z[-1]))
    surface_flux = at_height(field, field.solid_fraction * np.abs(np.where(field.occupied, field.v_z, 0.0)), surface)
    flux = np.nan_to_num(surface_flux[bin_index(field.x, dx, entry_x)], nan=0.0)
    entry_x, flux = entry_x[flux > 0.0], flux[flux > 0.0]
    if entry_x.size == 0:
        raise ValueError(f"fill_height = {fill_height!r} m: no flux through the fill surface")
    entry_residence = integrate_tracers(field, entry_x, np.full(entry_x.size, release), dt, max_time, method,
                                 backend).residence_time
    entry_out = np.isfinite(entry_residence)
    if not np.any(entry_out):
        raise ValueError(f"no tracer released at the fill surface reached the outlet within max_time = {max_time!r} s")
    t_m = float(np.average(entry_residence[entry_out], weights=flux[entry_out]))
    step = t_m / 100.0 if window is None else positive_number("window", window)
    entry_time, entry_E = tabulated_rtd(entry_residence, step, flux)

    fill_out = np.isfinite(fill_residence)
    longest = float(fill_residence[fill_out].max()) if np.any(fill_out) else 0.0
    n_windows = max(int(math.ceil(passes * t_m / step - 1.0e-9)), int(math.floor(longest / step)) + 1, 2)
    is_tracer = z >= tracer_bottom
    index = np.floor(fill_residence[fill_out & is_tracer] / step).astype(np.int64)
    leaving = np.bincount(index, weights=weights[fill_out & is_tracer], minlength=n_windows)[:n_windows]
    scale = t_m / (float(weights.sum()) * step)
    c_first = leaving * scale
    # counting noise: each tracer's weight leaves in one window or another
    c_first_variance = np.bincount(index, weights=weights[fill_out & is_tracer] ** 2,
                                   minlength=n_windows)[:n_windows] * scale ** 2
    first_term = int(np.flatnonzero(entry_E > 0.0)[0])
    if first_term == 0:
        raise ValueError(f"window = {step!r} s: material entering at the fill surface leaves within half a window; "
                         "use a shorter window")
    terms = int(math.ceil(n_windows / first_term))
    c = predicted_concentration_from_first_pass(c_first, entry_E, step, terms)

    share = float(weights[is_tracer].sum() / weights.sum())
    starts = np.arange(n_windows) * step
    pass_index = np.floor((starts + 0.5 * step) / t_m).astype(np.int64)
    pass_mean = np.array([float(np.mean(c[pass_index == p])) for p in range(int(pass_index.max()) + 1)
                          if np.any(pass_index == p)])
    windows_per_pass = t_m / step

    def recycle(first_pass: np.ndarray) -> np.ndarray:
        return predicted_concentration_from_first_pass(first_pass, entry_E, step, terms)

    def homogenised_in(concentration: np.ndarray) -> float:
        return recirculations_to_homogenise(concentration, mean=share, tolerance=tolerance,
                                            per_pass_length=windows_per_pass)

    homogenised = homogenised_in(c)
    homogenised_error = (homogenisation_error(c_first, c_first_variance, recycle, homogenised_in, windows_per_pass)
                         if math.isfinite(homogenised) else math.nan)
    return DiscontinuousMode(
        window=step, window_start=starts, time_in_passes=starts / t_m, first_pass=c_first, concentration=c,
        pass_mean=pass_mean, tracer_fraction=share, tracer_bottom=tracer_bottom, mean_residence_time=t_m,
        entry_time=entry_time, entry_E=entry_E, homogenised_after=homogenised,
        homogenised_after_error=homogenised_error, tolerance=tolerance,
        n_not_exited=int(np.count_nonzero(~fill_out)), n_entry_not_exited=int(np.count_nonzero(~entry_out)),
    )


@dataclass(frozen=True, eq=False)
class ContinuousMode:
    """Sine inputs through the RTD: damping against the input period.

    Attributes
    ----------
    vrr_table : VRRTable
        VRR against ``period / t_m`` (:func:`siloflow.analysis.numerics.lti.vrr_versus_period`).
    cov_in : float
        CoV of the sine input, ``amplitude / (sqrt(2) mean)`` [-].
    cov_out : numpy.ndarray, shape (n,)
        CoV of the outlet, ``cov_in / sqrt(VRR)`` [-].
    weakest_damping_period_over_tm : float
        Period (over ``t_m``) with the smallest VRR [-].
    resonant_periods_over_tm : numpy.ndarray
        Periods (over ``t_m``) where the VRR has a local minimum inside the range (strictly below both
        neighbours): inputs in step with peaks of the RTD [-].
    """

    vrr_table: VRRTable
    cov_in: float
    cov_out: np.ndarray
    weakest_damping_period_over_tm: float
    resonant_periods_over_tm: np.ndarray

    @property
    def period_over_tm(self) -> np.ndarray:
        """Input periods over ``t_m`` [-]."""
        return self.vrr_table.period_over_tm

    @property
    def vrr(self) -> np.ndarray:
        """VRR per period [-]."""
        return self.vrr_table.vrr

    def vrr_at(self, period_over_tm: float) -> float:
        """The VRR at one of the computed periods (matched to 1e-9 relative)."""
        matches = np.flatnonzero(np.isclose(self.period_over_tm, float(period_over_tm), rtol=1.0e-9, atol=0.0))
        if matches.size == 0:
            raise ValueError(f"period_over_tm = {period_over_tm!r} was not computed ({self.period_over_tm.tolist()})")
        return float(self.vrr[matches[0]])


def continuous_mode(
    residence_time,
    step: float,
    periods_over_tm,
    weights=None,
    mean: float = 0.5,
    amplitude: float = 0.5,
    n_periods: int = 10,
) -> ContinuousMode:
    """VRR and CoV of sine inputs against the input period, through the RTD of a tracer sample.

    The RTD is the sample tabulated at ``k step`` (:func:`~siloflow.analysis.studies.blender.tracers.tabulated_rtd`);
    the periods are fractions of its weighted mean residence time ``t_m`` and
    :func:`siloflow.analysis.numerics.lti.vrr_versus_period` convolves each sine with it. The outlet keeps the input mean, so its CoV is ``sqrt(var_in / VRR) / mean`` with
    ``var_in = amplitude^2 / 2`` (whole periods).

    Parameters
    ----------
    residence_time : array_like, shape (n,)
        Residence times [s] (NaN: not out; counted in the total, then E is normalised).
    step : float
        Sample step of the RTD and the signals [s]; each period must span >= 4 steps.
    periods_over_tm : array_like, shape (k,)
        Input periods over ``t_m``, strictly increasing, > 0.
    weights : array_like, shape (n,), optional
        Tracer weights (e.g. :attr:`siloflow.analysis.studies.blender.tracers.VirtualTracerRTD.weights`).
    mean, amplitude : float, optional
        Input mean (> 0) and amplitude (> 0); default 0.5 and 0.5.
    n_periods : int, optional
        Whole periods in the steady window; default 10.

    Returns
    -------
    ContinuousMode
    """
    residence = np.asarray(residence_time, dtype=float)
    weight = tracer_weights(weights, residence.shape)
    exited = np.isfinite(residence)
    if not np.any(exited):
        raise ValueError("residence_time: no tracer exited")
    fractions = finite_array("periods_over_tm", periods_over_tm, ndim=1)
    if fractions.size == 0 or np.any(fractions <= 0.0) or np.any(np.diff(fractions) <= 0.0):
        raise ValueError("periods_over_tm must be non-empty, > 0 and strictly increasing")
    mean = positive_number("mean", mean)
    amplitude = positive_number("amplitude", amplitude)
    time, E = tabulated_rtd(residence, step, weight)
    t_m = float(np.average(residence[exited], weights=weight[exited]))
    table = vrr_versus_period(E, time, fractions, mean=mean, amplitude=amplitude, waveform="sine",
                              n_periods=n_periods, t_mean=t_m)
    cov_in = amplitude / (math.sqrt(2.0) * mean)
    vrr = table.vrr
    inner = np.arange(1, vrr.size - 1)
    local_minimum = inner[(vrr[inner] < vrr[inner - 1]) & (vrr[inner] < vrr[inner + 1])]
    return ContinuousMode(
        vrr_table=table, cov_in=cov_in, cov_out=cov_in / np.sqrt(vrr),
        weakest_damping_period_over_tm=float(fractions[int(np.argmin(vrr))]),
        resonant_periods_over_tm=fractions[local_minimum],
    )
