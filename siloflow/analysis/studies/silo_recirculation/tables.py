"""Table rows and JSON summaries of the blending study of one recirculation run, and of its Eulerian verification.

Pure functions from the results of :mod:`siloflow.analysis.studies.silo_recirculation.study` to plain rows (one dict per
row, for :func:`siloflow.analysis.io.tables.write_flow_table`) and summary dicts (for :func:`siloflow.analysis.io.tables.write_json`);
no file I/O. The column names and their order are the file formats the summary, report and thesis read, so they
change only together with their readers (new columns are appended, never renamed). SI units: times in s, E in
1/s, lengths in m; concentrations and VRRs are dimensionless.

Every measured VRR comes with its counting-noise ceiling (:func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`,
``clumps_per_window`` for a 0/1 batch) and a flag where it lies within a factor 2 of it
(:func:`siloflow.analysis.numerics.vrr_noise.vrr_near_ceiling`): such a VRR is a lower bound, so it is not compared with
the LTI prediction as if it were a measurement.

Standard errors follow the convention of the summary page: the error of a figure ``<key>`` is ``<key>_error``,
in its unit, beside it (NaN, written null or empty, when not known). Their sources:

- ``residence_time_s``: batch means of the holdup and batch rates of the discharge over the steady part,
  propagated (:func:`siloflow.analysis.studies.silo_recirculation.vrr.littles_law`); the same for
  ``transit_residence_time_s`` over the transit window
  (:func:`siloflow.analysis.studies.silo_recirculation.transit.transit_littles_law`);
- ``t_s_over_t_d``: the order-statistic gaps of the tracer (tracer counting) and the frame interval (time
  resolution), propagated (:func:`siloflow.analysis.numerics.residence_statistics.appearance_times`);
- RTD means: ``s / sqrt(n)`` over the tracers that left (:attr:`siloflow.analysis.numerics.rtd.RTD.t_mean_error`), or
  that left within the transit horizon (``t_mean_transit_s``);
- VRR: ``sqrt(2 / (N - 1)) VRR`` over the ``N`` windows of the recirculation
  (:func:`siloflow.analysis.studies.silo_recirculation.vrr.vrr_standard_error`), or of the discharge after the
  recirculations (``final_discharge``, :mod:`siloflow.analysis.studies.silo_recirculation.final_discharge`).

Two residence times
-------------------
``residence_time_s`` is the *holdup* residence time, every clump above the outlet over the throughput: it
counts the stagnant zones of the flat-bottom silo, whose clumps stay longer than the run, and is the time scale
of ``Nr``. The tracer's ``rtd_particle_ids.t_mean_s`` is the mean over the tracers that left by the end of the
run, blind to those clumps, so it is shorter. Little's law is checked on the same clumps:
``transit_residence_time_s`` (holdup of the passes lasting at most ``transit_horizon_s`` over their
throughput) against ``rtd_particle_ids.t_mean_transit_s`` (the tracer's residence times up to the same
horizon), with their difference ``littles_law_difference_s``; ``slow_holdup_clumps`` is the rest of the holdup.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.rtd import RTD, johanson_rtd
from siloflow.analysis.numerics.residence_statistics import appearance_times, residence_time_resolution
from siloflow.analysis.numerics.uncertainty import Significance, combine_independent, difference_significant
from siloflow.analysis.numerics.vrr_noise import CEILING_FACTOR, vrr_near_ceiling
from siloflow.analysis.studies.silo_recirculation.final_discharge import FinalDischarge
from siloflow.analysis.studies.silo_recirculation.study import BlendingResult, VerificationResult, residence_summary
from siloflow.analysis.studies.silo_recirculation.vrr import sampling_noise_vrr_limit

__all__ = [
    "concentration_rows",
    "vrr_rows",
    "model_rows",
    "johanson_curve",
    "rtd_rows",
    "vrr_period_rows",
    "clumps_per_window",
    "blending_summary",
    "transit_summary",
    "verification_rows",
    "mean_comparison",
    "verification_summary",
    "summary_rows",
]


def concentration_rows(result: BlendingResult) -> list[dict]:
    """Outlet concentration per window of every batch layout, measured and predicted (``concentration.csv``).

    Parameters
    ----------
    result : BlendingResult
        The study of the run (:func:`siloflow.analysis.studies.silo_recirculation.study.analyse_blending`).

    Returns
    -------
    list of dict
        One row per layout and window, in layout order then time order, with the columns ``layout``,
        ``time_s`` (window centre [s]), ``recirculations`` (its Nr [-]), ``crossings`` (outlet crossings in
        the window [-]), ``concentration`` (measured blue fraction [-], NaN without crossings),
        ``first_exit_concentration`` (first exits of the initial fill [-]), ``predicted`` (renewal prediction
        with the measured loop RTD [-]) and ``predicted_johanson`` (with Johanson's RTD [-]).
    """
    rows = []
    for layout in result.layouts:
        c = layout.concentration
        for i in range(c.centres.size):
            rows.append({
                "layout": layout.layout.name, "time_s": c.centres[i], "recirculations": layout.recirculation_number[i],
                "crossings": int(c.n_total[i]), "concentration": c.concentration[i],
                "first_exit_concentration": layout.first_pass.concentration[i], "predicted": layout.predicted[i],
                "predicted_johanson": layout.predicted_johanson[i],
            })
    return rows


def vrr_rows(result: BlendingResult, factor: float = CEILING_FACTOR) -> list[dict]:
    """VRR per recirculation of every batch layout, measured and predicted, with the counting-noise ceiling
    (``vrr.csv``).

    Parameters
    ----------
    result : BlendingResult
        The study of the run.
    factor : float, optional
        A measured VRR at or above ``ceiling / factor`` is flagged as at the ceiling, >= 1 [-].

    Returns
    -------
    list of dict
        One row per layout and recirculation: ``layout``, then the columns of
        :meth:`siloflow.analysis.studies.silo_recirculation.vrr.RecirculationVRR.rows` (``recirculation_number`` [-],
        ``vrr`` [-], ``sigma_out`` [-], ``n_windows`` [-], ``sigma_in`` [-], ``blue_fraction`` [-]) of the
        measured VRR, ``vrr_predicted`` (the VRR of the renewal prediction [-]), then ``vrr_ceiling`` (the
        counting-noise ceiling for :func:`clumps_per_window` clumps per window [-]), ``vrr_at_ceiling`` (bool:
        the measured VRR is within ``factor`` of it), ``vrr_kind`` (``"value"``; ``"lower bound"`` when at the
        ceiling; ``"none"`` without a VRR) and ``vrr_predicted_over_measured`` (the prediction over a measured
        value [-]; NaN where the measurement is only a lower bound or missing), then ``vrr_error`` (standard error
        of the measured VRR, ``sqrt(2 / (n_windows - 1)) vrr`` [-],
        :func:`siloflow.analysis.studies.silo_recirculation.vrr.vrr_standard_error`; NaN without a finite VRR).
    """
    particles_per_window = clumps_per_window(result)
    rows = []
    for layout in result.layouts:
        ceiling = layout.vrr.ceiling(particles_per_window)
        flags = layout.vrr.at_ceiling(particles_per_window, factor)
        errors = layout.vrr.vrr_error
        for row, predicted, at_ceiling, error in zip(layout.vrr.rows(), layout.vrr_predicted.vrr, flags, errors):
            measured = row["vrr"]
            kind = "none" if math.isnan(measured) else "lower bound" if at_ceiling else "value"
            rows.append({
                "layout": layout.layout.name, **row, "vrr_predicted": float(predicted), "vrr_ceiling": ceiling,
                "vrr_at_ceiling": bool(at_ceiling), "vrr_kind": kind,
                "vrr_predicted_over_measured": float(predicted) / measured if kind == "value" else math.nan,
                "vrr_error": float(error),
            })
    return rows


def model_rows(result: BlendingResult) -> list[dict]:
    """The discontinuous LTI model of every batch layout: the batch recirculated through the silo RTD
    (``recirculation_model.csv``).

    Parameters
    ----------
    result : BlendingResult
        The study of the run.

    Returns
    -------
    list of dict
        One row per layout and model sample: ``layout``, ``recirculations`` (Nr [-]) and ``concentration``
        (modelled outlet blue fraction [-]).
    """
    return [
        {"layout": layout.layout.name, "recirculations": nr, "concentration": value}
        for layout in result.layouts
        for nr, value in zip(layout.model_time_nr, layout.model_concentration)
    ]


def johanson_curve(result: BlendingResult) -> np.ndarray:
    """Johanson's triangular RTD fitted to the particle RTD, on the particle RTD's bin centres [1/s].

    Parameters
    ----------
    result : BlendingResult
        The study of the run; its ``rtd.silo`` gives the time axis and ``t_m``, its ``rtd.johanson_V1`` and
        ``rtd.johanson_P`` the shape (:func:`siloflow.analysis.numerics.rtd.johanson_rtd`).

    Returns
    -------
    numpy.ndarray, shape (n_bins,)
        ``E(t)`` [1/s] at ``result.rtd.silo.time``.
    """
    silo = result.rtd.silo
    return johanson_rtd(silo.time, silo.t_mean, result.rtd.johanson_V1, result.rtd.johanson_P)


def rtd_rows(result: BlendingResult, eulerian_rtd: RTD, johanson) -> list[dict]:
    """The three RTDs of the run in one long table (``rtd.csv``): particle ids, Eulerian, Johanson.

    Parameters
    ----------
    result : BlendingResult
        The study of the run (its particle RTD, ``result.rtd.silo``).
    eulerian_rtd : siloflow.analysis.numerics.rtd.RTD
        The Eulerian RTD of the run (:func:`siloflow.analysis.studies.silo_recirculation.study.main_run_eulerian_rtd`).
    johanson : array_like, shape (n_bins,)
        Johanson's RTD on the particle RTD's bin centres [1/s] (:func:`johanson_curve`).

    Returns
    -------
    list of dict
        Rows ``method`` (``"particle_ids"``, ``"eulerian"``, ``"johanson"``, in that order), ``time_s`` (bin
        centre [s]), ``E_per_s`` [1/s] and ``t_mean_s`` (the curve's mean residence time [s]; Johanson's is the
        particle RTD's).
    """
    silo = result.rtd.silo
    return [
        {"method": method, "time_s": t, "E_per_s": e, "t_mean_s": tm}
        for method, rtd_time, values, tm in (
            ("particle_ids", silo.time, silo.E, silo.t_mean),
            ("eulerian", eulerian_rtd.time, eulerian_rtd.E, eulerian_rtd.t_mean),
            ("johanson", silo.time, johanson, silo.t_mean),
        )
        for t, e in zip(rtd_time, values)
    ]


def vrr_period_rows(result: BlendingResult) -> list[dict]:
    """VRR of the continuous mode against the input period, sine rows then square rows (``vrr_period.csv``).

    Parameters
    ----------
    result : BlendingResult
        The study of the run (its ``vrr_sine`` and ``vrr_square`` tables).

    Returns
    -------
    list of dict
        The rows of :meth:`siloflow.analysis.numerics.lti.VRRTable.rows`: ``period_over_tm`` [-], ``period_s`` [s],
        ``vrr`` [-], ``t_mean_s`` [s], ``waveform``.
    """
    return result.vrr_sine.rows() + result.vrr_square.rows()


def clumps_per_window(result: BlendingResult) -> float:
    """Mean outlet crossings per concentration window, throughput x window [-].

    The ``n`` of :func:`siloflow.analysis.numerics.vrr_noise.vrr_ceiling`: the largest VRR that windows of that many
    crossings can measure (the exact ceiling of windows of unequal size is the harmonic mean of their crossings,
    at most a few per cent lower in a steady flow).

    Parameters
    ----------
    result : BlendingResult
        The study of the run (``timing.throughput`` [1/s], ``window`` [s]).

    Returns
    -------
    float
        Clumps per window [-].
    """
    return result.timing.throughput * result.window


def blending_summary(result: BlendingResult, eulerian_rtd: RTD, eulerian_bin_size: float, *, run_id: str,
                     flow_pattern: str, estimated_residence_time: float, nominal_residence_time: float,
                     factor: float = CEILING_FACTOR,
                     k: float = 2.0, final_discharge: FinalDischarge | None = None) -> dict:
    """The summary of one recirculation run (``blending.json``).

    Parameters
    ----------
    result : BlendingResult
        The study of the run.
    eulerian_rtd : siloflow.analysis.numerics.rtd.RTD
        Its Eulerian RTD.
    eulerian_bin_size : float
        Bin edge of the Eulerian RTD's velocity field [m].
    run_id : str
        The run's id.
    flow_pattern : str
        Its flow-pattern preset.
    estimated_residence_time : float
        The a-priori residence time the run was sized with [s].
    nominal_residence_time : float
        The study's nominal mean residence time ``W H / (B0 V_out)`` [s]
        (:attr:`siloflow.model.cases.silo_recirculation.RecirculationCase.nominal_residence_time`).
    factor : float, optional
        A measured VRR at or above ``vrr_sampling_limit / factor`` is flagged as at the ceiling, >= 1 [-].
    k : float, optional
        Coverage factor of the Little's law check (:func:`siloflow.analysis.numerics.uncertainty.difference_significant`),
        > 0 [-].
    final_discharge : FinalDischarge or None, optional
        The discharge after the recirculations of a run that has one
        (:func:`siloflow.analysis.studies.silo_recirculation.final_discharge.final_discharge`); ``result`` is then the
        study of the recirculating part.

    Returns
    -------
    dict
        ``run_id``, ``flow_pattern``, the timing (``residence_time_s`` [s], ``estimated_residence_time_s`` [s],
        ``nominal_residence_time_s`` [s],
        ``holdup_clumps`` [-], ``throughput_clumps_per_s`` [1/s], ``recirculations`` [-], ``window_s`` [s],
        ``clumps_per_window`` [-], ``vrr_sampling_limit`` (the counting-noise ceiling of the VRR [-]),
        ``vrr_ceiling_factor`` (``factor`` [-])), the RTDs (``rtd_particle_ids``, ``rtd_eulerian``: moments [s,
        s^2], first and last residence times [s], fraction exited [-]), Johanson's ``V1`` and ``P`` [-], and per
        layout its VRRs with ``vrr_at_ceiling`` (bool per recirculation: a lower bound, within ``factor`` of the
        ceiling), prediction error and homogenisation Nr [-].

        Standard errors (same unit, NaN when not known): ``residence_time_s_error``, ``holdup_clumps_error`` and
        ``throughput_clumps_per_s_error`` (batch means and batch rates of the steady part), with the
        ``frame_interval_s`` [s] of the record; in ``rtd_particle_ids`` ``t_mean_s_error`` (``s / sqrt(n)``),
        ``t_s_error``, ``t_d_error`` and ``t_s_over_t_d_error`` (order-statistic gaps and time resolution) and the
        ``time_resolution_s`` of one residence time (``frame_interval_s / sqrt(6)``) [s]; in ``rtd_eulerian``
        ``t_mean_s_error``; per layout ``vrr_by_recirculation_error`` (``sqrt(2 / (N - 1)) VRR``).

        Little's law on the clumps that pass through (:attr:`BlendingResult.transit`; NaN, and None for the
        counts, when the result has none): ``transit_horizon_s`` ``h`` [s], ``transit_holdup_clumps`` [-],
        ``transit_throughput_clumps_per_s`` [1/s] and ``transit_residence_time_s`` [s] of the passes lasting at
        most ``h``, ``transit_fraction`` of the crossings they make [-], ``slow_holdup_clumps`` (the rest of
        the holdup: stagnant zones and slow creep [-]) and ``stagnant_clumps`` (above the outlet all run [-]),
        each number with its ``_error``; in ``rtd_particle_ids`` ``t_mean_transit_s`` with its error (the
        tracer's residence times up to ``h`` [s]) and ``n_transit`` (those tracers [-]); and
        ``littles_law_difference_s`` (``transit_residence_time_s - t_mean_transit_s`` [s]) with its error
        (the two independent) and ``littles_law_significance`` (beyond ``k`` errors: ``"significant"``,
        ``"not significant"`` or ``"unknown"``) with ``littles_law_coverage_factor`` ``k`` [-].

        With a ``final_discharge``, its
        :meth:`~siloflow.analysis.studies.silo_recirculation.final_discharge.FinalDischarge.summary` under
        ``"final_discharge"``: the study's VRR after the recirculations (§6.4.2) per layout, ``vrr`` with
        ``vrr_error``, the ``windows`` and ``clumps`` it used, the ``left_out_fraction`` of the outflow and
        ``at_ceiling``, with the discharge's ``recirculations`` (Nr), ``start_s`` and ``end_s``. A run without one has
        no such key.
    """
    timing = result.timing
    silo_rtd = result.rtd.silo
    particles_per_window = clumps_per_window(result)
    resolution = residence_time_resolution(timing.frame_interval)
    appearance = appearance_times(result.rtd.tracer.residence_time, resolution)
    transit = transit_summary(result, k)
    transit_tracer = transit.pop("rtd_particle_ids")
    return {
        "run_id": run_id, "flow_pattern": flow_pattern,
        "residence_time_s": timing.residence_time, "residence_time_s_error": timing.residence_time_error,
        "estimated_residence_time_s": estimated_residence_time, "nominal_residence_time_s": nominal_residence_time,
        "holdup_clumps": timing.holdup, "holdup_clumps_error": timing.holdup_error,
        "throughput_clumps_per_s": timing.throughput, "throughput_clumps_per_s_error": timing.throughput_error,
        "frame_interval_s": timing.frame_interval, "recirculations": timing.recirculations, "window_s": result.window,
        "clumps_per_window": particles_per_window,
        "vrr_sampling_limit": sampling_noise_vrr_limit(0.5, particles_per_window), "vrr_ceiling_factor": factor,
        "rtd_particle_ids": {"t_mean_s": silo_rtd.t_mean, "variance_s2": silo_rtd.variance, "t_s": silo_rtd.t_first,
                             "t_d": silo_rtd.t_last, "t_s_over_t_d": silo_rtd.ts_over_td,
                             "n_tracer": result.rtd.n_tracer, "fraction_exited": silo_rtd.fraction_exited,
                             "t_mean_s_error": silo_rtd.t_mean_error, "t_s_error": appearance.t_first.std_error,
                             "t_d_error": appearance.t_last.std_error,
                             "t_s_over_t_d_error": appearance.ts_over_td.std_error, "time_resolution_s": resolution,
                             **transit_tracer},
        "rtd_eulerian": {"t_mean_s": eulerian_rtd.t_mean, "variance_s2": eulerian_rtd.variance,
                         "t_s": eulerian_rtd.t_first, "t_d": eulerian_rtd.t_last,
                         "fraction_exited": eulerian_rtd.fraction_exited, "bin_size_m": eulerian_bin_size,
                         "t_mean_s_error": eulerian_rtd.t_mean_error},
        "johanson": {"V1": result.rtd.johanson_V1, "P": result.rtd.johanson_P},
        "layouts": {
            layout.layout.name: {
                "blue_fraction": layout.layout.blue_fraction, "sublayers": layout.layout.sublayers,
                "vrr_by_recirculation": layout.vrr.vrr, "vrr_predicted": layout.vrr_predicted.vrr,
                "vrr_at_ceiling": [bool(flag) for flag in layout.vrr.at_ceiling(particles_per_window, factor)],
                "prediction_rms_error": layout.prediction_rms_error(),
                "homogenised_after_recirculations": layout.homogenised_after,
                "model_homogenised_after_recirculations": layout.model_homogenised_after,
                "vrr_by_recirculation_error": layout.vrr.vrr_error,
            }
            for layout in result.layouts
        },
        **transit,
        **({} if final_discharge is None else {"final_discharge": final_discharge.summary()}),
    }


def transit_summary(result: BlendingResult, k: float = 2.0) -> dict:
    """The Little's law keys of :func:`blending_summary` (its docstring lists them), those of the tracer under
    ``"rtd_particle_ids"``; NaN (None for counts) when ``result.transit`` is None."""
    little, mean = result.transit, result.tracer_transit_mean
    if little is None or mean is None:
        nan = math.nan
        return {
            "transit_horizon_s": nan, "transit_holdup_clumps": nan, "transit_holdup_clumps_error": nan,
            "transit_throughput_clumps_per_s": nan, "transit_throughput_clumps_per_s_error": nan,
            "transit_residence_time_s": nan, "transit_residence_time_s_error": nan, "transit_fraction": nan,
            "transit_fraction_error": nan, "slow_holdup_clumps": nan, "slow_holdup_clumps_error": nan,
            "stagnant_clumps": None, "littles_law_difference_s": nan, "littles_law_difference_s_error": nan,
            "littles_law_significance": Significance.UNKNOWN.value, "littles_law_coverage_factor": float(k),
            "rtd_particle_ids": {"t_mean_transit_s": nan, "t_mean_transit_s_error": nan, "n_transit": None},
        }
    transit = little.transit
    residence = transit.residence_time
    significance = difference_significant(residence.value, residence.std_error, mean.value, mean.std_error, k)
    return {
        "transit_horizon_s": little.horizon,
        "transit_holdup_clumps": transit.holdup.value, "transit_holdup_clumps_error": transit.holdup.std_error,
        "transit_throughput_clumps_per_s": transit.throughput.value,
        "transit_throughput_clumps_per_s_error": transit.throughput.std_error,
        "transit_residence_time_s": residence.value, "transit_residence_time_s_error": residence.std_error,
        "transit_fraction": little.transit_fraction.value, "transit_fraction_error": little.transit_fraction.std_error,
        "slow_holdup_clumps": little.slow_holdup.value, "slow_holdup_clumps_error": little.slow_holdup.std_error,
        "stagnant_clumps": little.stagnant_clumps,
        "littles_law_difference_s": residence.value - mean.value,
        "littles_law_difference_s_error": combine_independent([residence.std_error, mean.std_error]),
        "littles_law_significance": significance.value, "littles_law_coverage_factor": float(k),
        "rtd_particle_ids": {"t_mean_transit_s": mean.value, "t_mean_transit_s_error": mean.std_error,
                             "n_transit": mean.n},
    }


def verification_rows(result: VerificationResult) -> list[dict]:
    """Residence times of the real tracer passes and of the virtual tracers of each bin size
    (``residence_times.csv``).

    Parameters
    ----------
    result : VerificationResult
        Particle tracks against Eulerian pathlines
        (:func:`siloflow.analysis.studies.silo_recirculation.study.verify_eulerian_rtd`).

    Returns
    -------
    list of dict
        Rows ``method`` (``"particles"`` first, then ``"eulerian"`` per bin size in the result's order),
        ``bin_size_m`` (bin edge [m]; empty for the particles) and ``residence_time_s`` [s] (NaN: not out).
    """
    rows = [{"method": "particles", "bin_size_m": "", "residence_time_s": t} for t in result.particle_residence]
    for bin_size, times in result.eulerian_residence.items():
        rows += [{"method": "eulerian", "bin_size_m": bin_size, "residence_time_s": t} for t in times]
    return rows


def mean_comparison(particles: Mapping, eulerian: Mapping, k: float = 2.0) -> dict:
    """Whether the Eulerian mean residence time agrees with the particles' within ``k`` combined standard errors.

    Parameters
    ----------
    particles, eulerian : mapping
        :func:`~siloflow.analysis.studies.silo_recirculation.study.residence_summary` of the real tracer and of the
        virtual tracers of one bin size (``mean_s`` and ``mean_s_error`` [s], None or NaN when not known).
    k : float, optional
        Coverage factor of :func:`siloflow.analysis.numerics.uncertainty.difference_significant`, > 0 [-].

    Returns
    -------
    dict
        ``mean_difference_s`` (Eulerian minus particles [s]; None without both means),
        ``mean_difference_s_error`` (``sqrt(u_E^2 + u_p^2)`` [s], the two samples independent; NaN when either
        error is unknown), ``mean_difference_significance`` (``"significant"``, ``"not significant"`` or
        ``"unknown"``) and ``means_agree`` (True when the difference is not significant, False when it is,
        None when unknown).

    Notes
    -----
    The particle error is ``s / sqrt(n)`` over the tracer passes, taken as independent draws. The virtual
    tracers are not random draws: they sample the inlet on a lattice in one given velocity field, so their
    mean is a quadrature over the inlet, and ``s / sqrt(n)`` is the error of sampling the inlet at ``n``
    random points. It stands for the lattice's error: a regular lattice does better where the residence
    time varies smoothly across the inlet and about as well where it jumps (paths splitting at a stagnant
    zone), in the two dimensions of a thin silo's inlet. Neither error holds the noise of the flow itself
    during the one release, which both sides largely share since the bin velocities come from the same
    clumps at the same times, nor the discretisation of the velocity field by the bins: that bias is what the
    comparison over bin sizes exists to show, and a "significant" difference measures it.
    """
    missing = particles["mean_s"] is None or eulerian["mean_s"] is None
    if missing:
        significance = Significance.UNKNOWN
        difference, difference_error = None, math.nan
    else:
        errors = [math.nan if summary["mean_s_error"] is None else summary["mean_s_error"]
                  for summary in (eulerian, particles)]
        difference = eulerian["mean_s"] - particles["mean_s"]
        difference_error = combine_independent(errors)
        significance = difference_significant(eulerian["mean_s"], errors[0], particles["mean_s"], errors[1], k)
    agree = {Significance.NOT_SIGNIFICANT: True, Significance.SIGNIFICANT: False}.get(significance)
    return {"mean_difference_s": difference, "mean_difference_s_error": difference_error,
            "mean_difference_significance": significance.value, "means_agree": agree}


def verification_summary(result: VerificationResult, *, run_id: str, k: float = 2.0) -> dict:
    """The summary of the Eulerian RTD verification (``verification.json``).

    Parameters
    ----------
    result : VerificationResult
        Particle tracks against Eulerian pathlines.
    run_id : str
        The verification run's id.
    k : float, optional
        Coverage factor of the agreement of the means (:func:`mean_comparison`), > 0 [-].

    Returns
    -------
    dict
        ``run_id``, ``residence_time_s`` (holdup over throughput [s]) with ``residence_time_s_error`` [s],
        ``n_tracers`` (the real tracer passes [-]), ``coverage_factor`` (``k`` [-]), ``particles`` (the
        :func:`~siloflow.analysis.studies.silo_recirculation.study.residence_summary` of the real tracer: counts,
        ``mean_s`` with ``mean_s_error`` and ``std_s`` [s]) and ``eulerian`` (bin size as ``"<mm> mm"`` -> the
        same summary of its virtual tracers, with the :func:`mean_comparison` against the particles:
        ``mean_difference_s``, ``mean_difference_s_error``, ``mean_difference_significance``,
        ``means_agree``).
    """
    particles = residence_summary(result.particle_residence)
    eulerian = {}
    for bin_size, times in result.eulerian_residence.items():
        summary = residence_summary(times)
        eulerian[f"{1000 * bin_size:g} mm"] = {**summary, **mean_comparison(particles, summary, k)}
    return {"run_id": run_id, "residence_time_s": result.timing.residence_time,
            "residence_time_s_error": result.timing.residence_time_error,
            "n_tracers": int(np.asarray(result.particle_residence).size), "coverage_factor": float(k),
            "particles": particles, "eulerian": eulerian}


def summary_rows(summaries: Sequence[Mapping], factor: float = CEILING_FACTOR) -> tuple[list[dict], list[tuple]]:
    """The rows of the summary table of every flow pattern and batch layout, and their VRR curves.

    Parameters
    ----------
    summaries : sequence of mapping
        The ``metrics/blending.json`` of each recirculation run, as read (:func:`blending_summary`).
    factor : float, optional
        Flag factor for summaries written without ``vrr_at_ceiling`` (a VRR at or above ``ceiling / factor``),
        >= 1 [-]; the flags a summary holds are taken as they are.

    Returns
    -------
    rows : list of dict
        One row per run and layout: residence time (s), t_s/t_d, RTD means (s), ``vrr_nr<k>`` per recirculation
        (NaN where the JSON has null), the LTI prediction's RMS error and the recirculations to homogenise, then
        ``vrr_ceiling`` (the run's counting-noise ceiling, ``vrr_sampling_limit`` [-]; NaN if the summary has
        none) and ``vrr_at_ceiling_nr<k>`` (bool: that VRR is only a lower bound), then the standard errors
        ``residence_time_s_error`` [s], ``t_s_over_t_d_error`` [-], ``rtd_mean_ids_s_error`` [s],
        ``rtd_mean_eulerian_s_error`` [s] and ``vrr_nr<k>_error`` [-] (NaN where the summary has none, e.g. one
        written before the errors were), then Little's law on the same clumps: ``transit_residence_time_s``
        (holdup of the passes lasting at most the transit horizon over their throughput [s]) and
        ``rtd_mean_ids_transit_s`` (the tracer's mean up to that horizon [s]), each with its ``_error`` (NaN
        for a summary without them). ``residence_time_s`` is the holdup residence time, stagnant zones
        included; ``rtd_mean_ids_s`` the mean of the tracers that left in the run. Last, the discharge after the
        recirculations (NaN and False for a summary without one): ``final_discharge_recirculations`` (its Nr [-]),
        ``final_discharge_vrr`` with ``final_discharge_vrr_error`` [-] and ``final_discharge_vrr_at_ceiling``.
    curves : list of tuple
        ``(label, recirculation at mid-window, VRR, ceiling, VRR error)`` per row, for
        :func:`siloflow.analysis.studies.silo_recirculation.plots.plot_vrr_versus_recirculations` (``ceiling`` None if the
        summary has none, the errors NaN where unknown).
    """
    rows, curves = [], []
    for summary in summaries:
        ceiling = summary.get("vrr_sampling_limit")
        particle_rtd, eulerian_rtd = summary["rtd_particle_ids"], summary["rtd_eulerian"]
        for name, layout in summary["layouts"].items():
            vrr = [number_or_nan(v) for v in layout["vrr_by_recirculation"]]
            errors = [number_or_nan(e) for e in layout.get("vrr_by_recirculation_error", [None] * len(vrr))]
            flags = layout.get("vrr_at_ceiling")
            if flags is None:
                flags = ([False] * len(vrr) if ceiling is None else
                         [bool(flag) for flag in vrr_near_ceiling(vrr, ceiling, factor)])
            curves.append((f"{summary['flow_pattern']} {name}", [k + 0.5 for k in range(len(vrr))], vrr, ceiling,
                           errors))
            rows.append({
                "flow_pattern": summary["flow_pattern"], "layout": name, "run_id": summary["run_id"],
                "residence_time_s": summary["residence_time_s"], "t_s_over_t_d": particle_rtd["t_s_over_t_d"],
                "rtd_mean_ids_s": particle_rtd["t_mean_s"],
                "rtd_mean_eulerian_s": eulerian_rtd["t_mean_s"],
                **{f"vrr_nr{k + 1}": v for k, v in enumerate(vrr)},
                "prediction_rms_error": layout["prediction_rms_error"],
                "homogenised_after_recirculations": layout["homogenised_after_recirculations"],
                "model_homogenised_after_recirculations": layout["model_homogenised_after_recirculations"],
                "vrr_ceiling": float("nan") if ceiling is None else ceiling,
                **{f"vrr_at_ceiling_nr{k + 1}": bool(flag) for k, flag in enumerate(flags)},
                "residence_time_s_error": number_or_nan(summary.get("residence_time_s_error")),
                "t_s_over_t_d_error": number_or_nan(particle_rtd.get("t_s_over_t_d_error")),
                "rtd_mean_ids_s_error": number_or_nan(particle_rtd.get("t_mean_s_error")),
                "rtd_mean_eulerian_s_error": number_or_nan(eulerian_rtd.get("t_mean_s_error")),
                **{f"vrr_nr{k + 1}_error": e for k, e in enumerate(errors)},
                "transit_residence_time_s": number_or_nan(summary.get("transit_residence_time_s")),
                "transit_residence_time_s_error": number_or_nan(summary.get("transit_residence_time_s_error")),
                "rtd_mean_ids_transit_s": number_or_nan(particle_rtd.get("t_mean_transit_s")),
                "rtd_mean_ids_transit_s_error": number_or_nan(particle_rtd.get("t_mean_transit_s_error")),
                **_final_discharge_columns(summary.get("final_discharge"), name),
            })
    return rows, curves


def _final_discharge_columns(discharge: Mapping | None, name: str) -> dict:
    """The summary table's columns of the discharge after the recirculations of one layout (NaN and False
    without one)."""
    layout = (discharge or {}).get("layouts", {}).get(name) or {}
    return {"final_discharge_recirculations": number_or_nan((discharge or {}).get("recirculations")),
            "final_discharge_vrr": number_or_nan(layout.get("vrr")),
            "final_discharge_vrr_error": number_or_nan(layout.get("vrr_error")),
            "final_discharge_vrr_at_ceiling": bool(layout.get("at_ceiling", False))}


