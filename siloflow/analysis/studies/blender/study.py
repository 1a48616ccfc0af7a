"""The blender study of one run: profiles, passage velocities, flow channel, pathlines, RTD and blending modes.

Composes the modules of :mod:`siloflow.analysis.studies.blender` (profiles, tracers, modes) on the steady field and the
window fields of one run. Pure computation: the geometry comes in as plain numbers and two functions of height
(the clear passages and the inner wall position), so nothing here reads files or knows the engine.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, fields

import numpy as np

from siloflow.model.checks import number_or_nan, positive_number
from siloflow.analysis.numerics.rtd import RTD
from siloflow.analysis.studies.blender.comparison import BlenderMetrics
from siloflow.analysis.studies.blender.errors import (
    passage_velocity_estimates,
    residence_time_error,
    sine_vrr_error,
    tracer_errors,
)
from siloflow.analysis.studies.blender.modes import ContinuousMode, DiscontinuousMode, continuous_mode, discontinuous_mode
from siloflow.analysis.studies.blender.profiles import (
    ChannelBoundary,
    PassageVelocities,
    ProfilesOverTime,
    flow_channel_boundary_over_height,
    passage_velocities,
    profiles_over_time,
)
from siloflow.analysis.studies.blender.steady_field import BlenderField
from siloflow.analysis.studies.blender.tracers import TracerPathlines, VirtualTracerRTD, tracer_pathlines, virtual_tracer_rtd

__all__ = ["BlenderSettings", "BlenderStudy", "key_heights", "top_internal", "analyse_blender", "study_metrics",
           "study_summary", "metrics_from_summary", "rtd_from_summary"]

#: Samples of the shortest input period in the continuous mode.
SAMPLES_PER_SHORTEST_PERIOD = 8


@dataclass(frozen=True)
class BlenderSettings:
    """Analysis settings of a run (the ``blender`` config keys that only steer the analysis).

    Attributes
    ----------
    fill_height : float
        Fill height [m].
    release_height, release_spacing : float
        Pathline release height and spacing across the width [m].
    integration_step, max_time : float
        Pathline time step and longest residence time followed [s].
    rtd_tracer_fraction : float
        Tracer layer volume fraction of the RTD [-].
    rtd_bins : int
        Residence-time bins of E(t).
    discontinuous_tracer_fraction : float
        Top-layer fraction of the two-layer fill [-].
    passes : int
        Passes followed in the discontinuous mode.
    tolerance : float
        Homogenisation band around the mean [-].
    period_fractions, comparison_fractions : tuple of float
        Sine input periods over t_m, and those reported in the comparison [-].
    """

    fill_height: float
    release_height: float
    release_spacing: float
    integration_step: float
    max_time: float
    rtd_tracer_fraction: float
    rtd_bins: int
    discontinuous_tracer_fraction: float
    passes: int
    tolerance: float
    period_fractions: tuple[float, ...]
    comparison_fractions: tuple[float, ...]

    @classmethod
    def from_config(cls, blender: Mapping) -> "BlenderSettings":
        """Settings from a validated ``blender`` configuration section."""
        return cls(
            fill_height=blender["fill_height"],
            release_height=blender["pathlines"]["release_height"],
            release_spacing=blender["pathlines"]["spacing"],
            integration_step=blender["pathlines"]["integration_step"],
            max_time=blender["pathlines"]["max_time"],
            rtd_tracer_fraction=blender["rtd"]["tracer_fraction"],
            rtd_bins=blender["rtd"]["bins"],
            discontinuous_tracer_fraction=blender["discontinuous"]["tracer_fraction"],
            passes=blender["discontinuous"]["passes"],
            tolerance=blender["discontinuous"]["tolerance"],
            period_fractions=tuple(blender["continuous"]["period_fractions"]),
            comparison_fractions=tuple(blender["continuous"]["comparison_fractions"]),
        )


def key_heights(insert: Mapping, bin_size: float, fill_height: float, heights_above_tube: Sequence[float]) -> dict:
    """The heights where profiles are taken, by name [m].

    One bin inside the insert at its outlet and inlet (so the profile row lies between the plates' ends), one
    bin above the tube inlet, and ``heights_above_tube`` above that inlet; heights that do not lie at least one
    bin below the fill height are left out. Without an insert the reference outlet level stands in for its
    outlet; without a tube its inlet level is left out.

    Parameters
    ----------
    insert : mapping
        ``z_insert_outlet``, ``inlet`` (the plate's upper end (x, z); None without an insert) and ``z_tube_inlet``
        (None without a tube), as in :func:`siloflow.model.cases.blender_passages.geometry_summary` [m].
    bin_size : float
        Bin edge of the fields [m].
    fill_height : float
        Fill height [m].
    heights_above_tube : sequence of float
        Extra heights above the tube inlet (or the insert inlet without a tube) [m].
    """
    step = positive_number("bin_size", bin_size)
    heights = {"insert outlet": insert["z_insert_outlet"] + step}
    if insert.get("inlet") is not None:
        heights["insert inlet"] = insert["inlet"][1] - step
    if insert.get("z_tube_inlet") is not None:
        heights["tube inlet"] = insert["z_tube_inlet"] + step
    for extra in heights_above_tube:
        heights[f"{extra * 1000:g} mm above"] = top_internal(insert) + step + extra
    return {name: float(z) for name, z in heights.items() if 0.0 < z <= fill_height - step}


def top_internal(insert: Mapping) -> float:
    """The highest end of an internal wall [m]: the tube inlet, the insert inlet or the insert outlet (the reference
    outlet level without an insert), whichever is highest; above it no internal wall crosses the section.

    Parameters
    ----------
    insert : mapping
        ``z_insert_outlet``, ``inlet`` ((x, z) or None) and ``z_tube_inlet`` (or None), as in
        :func:`siloflow.model.cases.blender_passages.geometry_summary` [m].
    """
    insert_inlet = insert["inlet"][1] if insert.get("inlet") is not None else None
    return float(max(z for z in (insert.get("z_tube_inlet"), insert_inlet, insert["z_insert_outlet"]) if z is not None))


@dataclass(frozen=True, eq=False)
class BlenderStudy:
    """Everything computed for one blender run."""

    heights: dict
    profiles: ProfilesOverTime
    inlet: PassageVelocities | None
    outlet: PassageVelocities
    boundary: ChannelBoundary
    pathlines: TracerPathlines
    rtd: VirtualTracerRTD
    discontinuous: DiscontinuousMode
    continuous: ContinuousMode


def analyse_blender(
    steady: BlenderField,
    windows: Sequence[BlenderField],
    window_times,
    heights: Mapping[str, float],
    passages_at: Callable[[float], dict],
    wall_x: Callable,
    settings: BlenderSettings,
) -> BlenderStudy:
    """Compose the blender analysis of one run.

    Parameters
    ----------
    steady : BlenderField
        Field averaged over the steady window.
    windows : sequence of BlenderField
        Fields of consecutive windows from the opening (profiles over time).
    window_times : array_like
        Centre of each window since the opening [s].
    heights : mapping name -> float
        Key heights (:func:`key_heights`) [m]; ``"insert outlet"`` is required, ``"insert inlet"`` optional.
    passages_at : callable
        ``passages_at(z)`` -> clear intervals of the right half at height z [m].
    wall_x : callable
        ``wall_x(z)`` -> inner wall position [m], vectorised.
    settings : BlenderSettings
    """
    if "insert outlet" not in heights:
        raise ValueError("heights must include 'insert outlet'")
    levels = list(heights.values())
    profiles = profiles_over_time(windows, window_times, levels, passages=[passages_at(z) for z in levels])
    outlet = passage_velocities(steady, heights["insert outlet"], passages_at(heights["insert outlet"]))
    inlet = (passage_velocities(steady, heights["insert inlet"], passages_at(heights["insert inlet"]))
             if "insert inlet" in heights else None)
    boundary = flow_channel_boundary_over_height(steady, wall_x(steady.z))
    step = settings.integration_step
    pathlines = tracer_pathlines(steady, settings.release_height, settings.max_time, spacing=settings.release_spacing,
                                 dt=step)
    rtd = virtual_tracer_rtd(steady, settings.fill_height, settings.max_time, settings.rtd_tracer_fraction, dt=step,
                             bins=settings.rtd_bins)
    discontinuous = discontinuous_mode(steady, settings.fill_height, settings.max_time, passes=settings.passes,
                                       tracer_fraction=settings.discontinuous_tracer_fraction,
                                       tolerance=settings.tolerance, dt=step)
    periods = sorted({*settings.period_fractions, *settings.comparison_fractions})
    sample_step = periods[0] * rtd.rtd.t_mean / SAMPLES_PER_SHORTEST_PERIOD
    continuous = continuous_mode(rtd.residence_time, sample_step, periods, weights=rtd.weights)
    return BlenderStudy(heights=dict(heights), profiles=profiles, inlet=inlet, outlet=outlet, boundary=boundary,
                        pathlines=pathlines, rtd=rtd, discontinuous=discontinuous, continuous=continuous)


def study_metrics(name: str, study: BlenderStudy, mass_flow_rate: float, comparison_fractions, *,
                  mass_flow_rate_error: float = math.nan, frames: Sequence[BlenderField] = (),
                  resolution: float = math.nan) -> BlenderMetrics:
    """The figures of merit of one run for the configuration comparison, with their standard errors.

    The passage means are those at the insert outlet. The errors (:mod:`siloflow.analysis.studies.blender.errors`): the
    passage means' from the batch means of ``frames``
    (:func:`~siloflow.analysis.studies.blender.errors.passage_velocity_estimates`); those of ``t_m``, ``sigma / t_m`` and
    ``t_s / t_d`` from the RTD's virtual tracers (:func:`~siloflow.analysis.studies.blender.errors.tracer_errors`), ``t_m``'s
    with the flow rate's relative error added (:func:`~siloflow.analysis.studies.blender.errors.residence_time_error`); the
    VRRs' from the same tracers (:func:`~siloflow.analysis.studies.blender.errors.sine_vrr_error`), whose effective number
    is also the VRR's counting-noise ceiling. The recirculations to homogenise have none.

    Parameters
    ----------
    name : str
        Configuration.
    study : BlenderStudy
        The run's study (:func:`analyse_blender`).
    mass_flow_rate : float
        Steady mass flow rate [kg/s].
    comparison_fractions : iterable of float
        Periods over ``t_m`` whose VRRs are reported [-].
    mass_flow_rate_error : float, optional
        Its standard error [kg/s] (:func:`~siloflow.analysis.studies.blender.errors.steady_flow_rate_estimate`); NaN when
        not known (then ``t_m``'s error is unknown too).
    frames : sequence of BlenderField, optional
        Fields of the single frames of the steady window, in time order; without them the passage means have
        unknown errors.
    resolution : float, optional
        Time resolution of the tracers' exit detection, >= 0 [s] (the pathline integration step); NaN leaves
        ``t_s / t_d`` without an error.
    """
    means = study.outlet.mean_v_z
    rtd = study.rtd.rtd
    interior = "interior" if "interior" in means else "open"
    passages = (passage_velocity_estimates(frames, study.heights["insert outlet"], study.outlet.passages)
                if len(frames) else {})

    def passage_error(passage: str) -> float:
        estimate = passages.get(passage)
        return math.nan if estimate is None else estimate.std_error

    tracers = tracer_errors(study.rtd.residence_time, study.rtd.weights, resolution)
    vrr = {float(f): study.continuous.vrr_at(f) for f in comparison_fractions}
    return BlenderMetrics(
        name=name,
        mass_flow_rate=float(mass_flow_rate),
        exterior_v_z=float(means.get("exterior", math.nan)),
        interior_v_z=float(means.get(interior, math.nan)),
        tube_v_z=float(means.get("tube", math.nan)),
        rtd_mean=float(rtd.t_mean),
        rtd_spread=float(math.sqrt(rtd.variance) / rtd.t_mean),
        ts_over_td=float(rtd.ts_over_td),
        recirculations_to_homogenise=float(study.discontinuous.homogenised_after),
        recirculations_to_homogenise_error=float(study.discontinuous.homogenised_after_error),
        vrr_by_period=vrr,
        mass_flow_rate_error=float(mass_flow_rate_error),
        exterior_v_z_error=passage_error("exterior"),
        interior_v_z_error=passage_error(interior),
        tube_v_z_error=passage_error("tube"),
        rtd_mean_error=residence_time_error(rtd.t_mean, tracers.t_mean, mass_flow_rate, mass_flow_rate_error),
        rtd_spread_error=tracers.spread,
        ts_over_td_error=tracers.ts_over_td,
        vrr_errors={period: sine_vrr_error(value, tracers.n_effective) for period, value in vrr.items()},
        vrr_ceiling=tracers.n_effective,
    )


def study_summary(study: BlenderStudy, metrics: BlenderMetrics) -> dict:
    """Plain-data summary of a run's study (for ``blender.json``); each figure's standard error sits beside it as
    ``<key>_error`` (``vrr_by_period_error`` for the VRRs), with the VRRs' counting-noise ceiling ``vrr_ceiling``."""
    continuous = study.continuous
    values = {}
    for attribute, key in _METRIC_KEYS:
        values[key] = getattr(metrics, attribute)
        if attribute in _ERROR_ATTRIBUTES:
            values[key + "_error"] = getattr(metrics, attribute + "_error")
    return {
        "metrics": {
            "configuration": metrics.name,
            **values,
            "vrr_by_period": {f"{period:g}": value for period, value in metrics.vrr_by_period.items()},
            "vrr_by_period_error": {f"{period:g}": value for period, value in metrics.vrr_errors.items()},
            "vrr_ceiling": metrics.vrr_ceiling,
        },
        "heights_m": study.heights,
        "passages_at_insert_outlet": {"mean_v_z_m_s": study.outlet.mean_v_z, "n_bins": study.outlet.n_bins},
        "passages_at_insert_inlet": (None if study.inlet is None else
                                     {"mean_v_z_m_s": study.inlet.mean_v_z, "n_bins": study.inlet.n_bins}),
        "pathlines": {"n_released": int(study.pathlines.release_x.size),
                      "n_not_exited": study.pathlines.n_not_exited},
        "rtd": {"t_mean_s": study.rtd.rtd.t_mean, "variance_s2": study.rtd.rtd.variance,
                "t_first_s": study.rtd.rtd.t_first, "t_last_s": study.rtd.rtd.t_last,
                "n_tracers": int(study.rtd.residence_time.size), "n_not_exited": study.rtd.n_not_exited,
                "layer_m": [study.rtd.layer_bottom, study.rtd.layer_top]},
        "discontinuous": {"homogenised_after": study.discontinuous.homogenised_after,
                          "pass_mean": study.discontinuous.pass_mean.tolist(),
                          "tracer_fraction": study.discontinuous.tracer_fraction,
                          "n_not_exited": study.discontinuous.n_not_exited},
        "continuous": {"period_over_tm": continuous.period_over_tm.tolist(), "vrr": continuous.vrr.tolist(),
                       "cov_in": continuous.cov_in, "cov_out": continuous.cov_out.tolist(),
                       "weakest_damping_period_over_tm": continuous.weakest_damping_period_over_tm,
                       "resonant_periods_over_tm": continuous.resonant_periods_over_tm.tolist()},
    }


_METRIC_KEYS = (
    ("mass_flow_rate", "mass_flow_rate_kg_s"), ("exterior_v_z", "exterior_v_z_m_s"), ("interior_v_z", "interior_v_z_m_s"),
    ("tube_v_z", "tube_v_z_m_s"), ("rtd_mean", "rtd_mean_s"), ("rtd_spread", "rtd_spread"), ("ts_over_td", "ts_over_td"),
    ("recirculations_to_homogenise", "recirculations_to_homogenise"),
)


#: Figures of :data:`_METRIC_KEYS` with a standard error (``<attribute>_error``, written as ``<key>_error``).
_ERROR_ATTRIBUTES = tuple(item.name.removesuffix("_error") for item in fields(BlenderMetrics)
                          if item.name.endswith("_error"))


def metrics_from_summary(summary: Mapping) -> BlenderMetrics:
    """The :class:`BlenderMetrics` of a run back from its :func:`study_summary` (as read from JSON); errors and the
    VRR ceiling a summary lacks (one written before they existed) are unknown (NaN)."""
    values = summary["metrics"]
    return BlenderMetrics(
        name=values["configuration"],
        **{field: number_or_nan(values[key]) for field, key in _METRIC_KEYS},
        vrr_by_period={float(period): number_or_nan(vrr) for period, vrr in values["vrr_by_period"].items()},
        **{f"{field}_error": number_or_nan(values.get(f"{key}_error")) for field, key in _METRIC_KEYS
           if field in _ERROR_ATTRIBUTES},
        vrr_errors={float(period): number_or_nan(error) for period, error in values.get("vrr_by_period_error", {}).items()},
        vrr_ceiling=number_or_nan(values.get("vrr_ceiling")),
    )


def rtd_summary(rtd: RTD) -> dict:
    """Plain-data form of an :class:`siloflow.analysis.numerics.rtd.RTD` (for JSON); :func:`rtd_from_summary` reads it back."""
    return {"time": rtd.time.tolist(), "E": rtd.E.tolist(), "edges": rtd.edges.tolist(), "t_mean": rtd.t_mean,
            "variance": rtd.variance, "t_first": rtd.t_first, "t_last": rtd.t_last, "n_exited": rtd.n_exited,
            "n_total": rtd.n_total}


def rtd_from_summary(curve: Mapping) -> RTD:
    """The :class:`siloflow.analysis.numerics.rtd.RTD` written by :func:`rtd_summary` (as read from JSON, NaN as null)."""
    arrays = {key: np.array([number_or_nan(v) for v in curve[key]]) for key in ("time", "E", "edges")}
    numbers = {key: number_or_nan(curve[key]) for key in ("t_mean", "variance", "t_first", "t_last")}
    return RTD(**arrays, **numbers, n_exited=int(curve["n_exited"]), n_total=int(curve["n_total"]))
