"""The blender's figures that the study's PIV gives, on one plane of the steady field: the passages at the insert
outlet with their errors (M1, thesis §7.5.1.1), and how uniform the vertical velocity is across the vertical
section away from the blending tube (M2, §7.5.3).

Pure computation on :class:`siloflow.analysis.studies.blender.steady_field.BlenderField`; no file I/O. SI units:
lengths in m, velocities in m/s. A plane is the depth-averaged field or the wall layer's
(:func:`siloflow.analysis.studies.blender.window_fields.wall_layer_positions`, what the PIV sees through the front
wall); each comes as the steady field (its clumps pooled over the steady window) and the fields of the single frames
of that window, whose batch means give the errors (:mod:`siloflow.analysis.studies.blender.errors`).

Vertical section
----------------
:func:`section_heights` keeps the key heights above every internal wall and above the hopper transition, where the
cross-section is the full width W. There the study finds the velocity uniform across the width "except close to the
blending tube" (§7.5.3); :func:`vertical_uniformity` leaves out the bins whose centre lies within one tube width of
the tube (:func:`tube_distance`) and takes the largest deviation of a bin's v_z from the mean of the bins kept,
relative to that mean.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import finite_number, positive_number
from siloflow.analysis.numerics.uncertainty import batch_means
from siloflow.analysis.studies.blender.errors import DEFAULT_BATCHES, passage_velocity_estimates
from siloflow.analysis.studies.blender.profiles import passage_velocities
from siloflow.analysis.studies.blender.steady_field import BlenderField, at_height, checked_field

__all__ = ["WALL_LAYER_WALLS", "section_heights", "tube_distance", "exclusion_of", "VerticalUniformity",
           "vertical_uniformity", "uniformity_summary", "section_uniformity", "passage_figures", "wall_layer_summary"]

#: How ``blender.json`` names the walls whose layer the wall-layer figures pool
#: (:func:`siloflow.analysis.studies.blender.window_fields.wall_layer_positions`).
WALL_LAYER_WALLS = "front and back walls, folded onto the front"


def section_heights(heights: Mapping[str, float], z_transition: float, top_internal: float) -> dict[str, float]:
    """The key heights in the vertical section above every internal wall [m], by name, in their order.

    Parameters
    ----------
    heights : mapping name -> float
        Key heights (:func:`siloflow.analysis.studies.blender.study.key_heights`) [m].
    z_transition : float
        Height of the hopper transition, where the vertical section begins [m].
    top_internal : float
        Highest end of an internal wall: the tube inlet, the insert inlet or the insert outlet, whichever is
        highest [m].

    Returns
    -------
    dict
        The heights ``z >= z_transition`` and ``z > top_internal``: the cross-section there is the full width.
    """
    bottom, top = finite_number("z_transition", z_transition), finite_number("top_internal", top_internal)
    return {name: float(z) for name, z in heights.items() if float(z) >= bottom and float(z) > top}


def tube_distance(x, z: float, tube_x: float, tube_inlet_z: float) -> np.ndarray:
    """Distance from points at height ``z`` to the blending tube, taken as the solid ``|x| <= tube_x`` below its inlet
    ``tube_inlet_z`` [m].

    ``sqrt(max(|x| - tube_x, 0)^2 + max(z - tube_inlet_z, 0)^2)``: 0 inside the tube's outline, the distance to its
    inlet's edge above and beside it.

    Parameters
    ----------
    x : array_like
        Positions across the width [m] (0 on the axis).
    z : float
        Height [m].
    tube_x : float
        Half-width of the tube's outline (its walls' outer surfaces) [m], >= 0.
    tube_inlet_z : float
        Height of the tube inlet [m].
    """
    tube_x = finite_number("tube_x", tube_x)
    if tube_x < 0.0:
        raise ValueError(f"tube_x must be >= 0, got {tube_x!r}")
    across = np.maximum(np.abs(np.asarray(x, dtype=float)) - tube_x, 0.0)
    above = max(finite_number("z", z) - finite_number("tube_inlet_z", tube_inlet_z), 0.0)
    return np.hypot(across, above)


@dataclass(frozen=True)
class VerticalUniformity:
    """How uniform the steady vertical velocity is across the vertical section at one height.

    Attributes
    ----------
    z : float
        Height [m].
    mean_v_z, mean_v_z_error : float
        Mean v_z over the bins kept [m/s] and its batch-means standard error [m/s] (NaN when not known).
    largest_deviation, largest_deviation_error : float
        ``|v_b / mean - 1|`` of the bin b that deviates most from the mean [-], and the standard error of that bin's
        deviation [-] (NaN when not known).
    deviation_x : float
        Centre of that bin [m].
    n_bins : int
        Bins with particles kept across the width [-].
    excluded_bins : int
        Bins with particles left out within ``exclusion`` of the tube [-].
    exclusion : float
        The distance from the tube within which bins are left out [m] (0 without a tube).
    batches : int
        Batches of frames behind the errors [-] (0 when none).
    """

    z: float
    mean_v_z: float
    mean_v_z_error: float
    largest_deviation: float
    largest_deviation_error: float
    deviation_x: float
    n_bins: int
    excluded_bins: int
    exclusion: float
    batches: int


def _kept(x: np.ndarray, z: float, tube: tuple[float, float] | None, exclusion: float) -> np.ndarray:
    """The bins not within ``exclusion`` of the tube (all of them without a tube)."""
    if tube is None:
        return np.ones(x.shape, dtype=bool)
    return tube_distance(x, z, *tube) >= exclusion


def vertical_uniformity(steady: BlenderField, frames: Sequence[BlenderField], z_value: float,
                        tube: tuple[float, float] | None, exclusion: float,
                        n_batches: int = DEFAULT_BATCHES) -> VerticalUniformity | None:
    """The largest deviation of the steady v_z across the width from its mean, away from the tube, with its error.

    At ``z_value`` (v_z linear in height between the bin rows,
    :func:`siloflow.analysis.studies.blender.steady_field.at_height`) the bins with particles whose centre lies at
    least ``exclusion`` from the tube (:func:`tube_distance`) are kept; their plain mean ``m`` (equal bins: the width
    average) and each bin's deviation ``v_b / m - 1`` follow from the steady field, and the bin of the largest
    ``|v_b / m - 1|`` gives the figure. Its error is the batch-means error
    (:func:`siloflow.analysis.numerics.uncertainty.batch_means`) of that same bin's deviation frame by frame (each
    frame's mean over its own kept bins with particles; frames where the bin is empty left out), taken with the sign
    of the steady deviation; the mean's error likewise. Picking the largest of several noisy deviations biases it
    upward by about their noise: the figure errs towards "not uniform".

    Parameters
    ----------
    steady : BlenderField
        The field of the steady window.
    frames : sequence of BlenderField
        The fields of its single frames, in time order (empty: errors NaN).
    z_value : float
        Height in the vertical section [m].
    tube : tuple of float or None
        ``(tube_x, tube_inlet_z)`` of :func:`tube_distance` [m]; None without a tube.
    exclusion : float
        Bins closer to the tube than this are left out [m], >= 0 (one tube width: the study's "close to the tube").
    n_batches : int, optional
        Largest number of batches (at most one frame each), >= 2.

    Returns
    -------
    VerticalUniformity or None
        None when fewer than two bins with particles are kept at that height, or their mean is 0.
    """
    steady = checked_field(steady)
    z_value = finite_number("z_value", z_value)
    exclusion = finite_number("exclusion", exclusion)
    if exclusion < 0.0:
        raise ValueError(f"exclusion must be >= 0, got {exclusion!r}")
    near = ~_kept(steady.x, z_value, tube, exclusion)
    v = at_height(steady, steady.v_z, z_value)
    kept = np.isfinite(v) & ~near
    if np.count_nonzero(kept) < 2:
        return None
    mean = float(np.mean(v[kept]))
    if mean == 0.0:
        return None
    deviation = np.where(kept, v / mean - 1.0, 0.0)
    chosen = int(np.argmax(np.abs(deviation)))
    sign = 1.0 if deviation[chosen] >= 0.0 else -1.0
    frame_means, frame_deviations = [], []
    for frame in frames:
        frame = checked_field(frame)
        if frame.x.shape != steady.x.shape or np.any(frame.x != steady.x):
            raise ValueError("the frames must have the bins of the steady field")
        u = at_height(frame, frame.v_z, z_value)
        here = np.isfinite(u) & ~near
        if np.count_nonzero(here) < 2:
            continue
        frame_mean = float(np.mean(u[here]))
        frame_means.append(frame_mean)
        if np.isfinite(u[chosen]) and frame_mean != 0.0:
            frame_deviations.append(sign * (u[chosen] / frame_mean - 1.0))
    mean_error, batches = _batch_error(frame_means, n_batches)
    deviation_error, _ = _batch_error(frame_deviations, n_batches)
    return VerticalUniformity(
        z=z_value, mean_v_z=mean, mean_v_z_error=mean_error, largest_deviation=abs(float(deviation[chosen])),
        largest_deviation_error=deviation_error, deviation_x=float(steady.x[chosen]),
        n_bins=int(np.count_nonzero(kept)), excluded_bins=int(np.count_nonzero(np.isfinite(v) & near)),
        exclusion=exclusion, batches=batches,
    )


def _batch_error(series: Sequence[float], n_batches: int) -> tuple[float, int]:
    """The batch-means standard error of a series and its batches (NaN and 0 with fewer than two values)."""
    count = min(int(n_batches), len(series))
    if count < 2:
        return math.nan, 0
    estimate = batch_means(np.asarray(series, dtype=float), n_batches=count)
    return estimate.std_error, count


def uniformity_summary(uniformity: Mapping[str, VerticalUniformity | None], heights: Mapping[str, float]) -> dict:
    """Plain data of :func:`vertical_uniformity` per key height (for ``blender.json``), keyed by the height in m
    (``f"{z:g}"``): ``name``, ``height_m``, ``mean_v_z_m_s`` and ``_error`` [m/s], ``largest_deviation`` and ``_error``
    [-], ``deviation_x_m``, ``exclusion_m`` [m], ``n_bins``, ``excluded_bins``, ``batches``; a height without a figure
    is left out."""
    return {
        f"{heights[name]:g}": {
            "name": name, "height_m": item.z, "mean_v_z_m_s": item.mean_v_z, "mean_v_z_m_s_error": item.mean_v_z_error,
            "largest_deviation": item.largest_deviation, "largest_deviation_error": item.largest_deviation_error,
            "deviation_x_m": item.deviation_x, "exclusion_m": item.exclusion, "n_bins": item.n_bins,
            "excluded_bins": item.excluded_bins, "batches": item.batches}
        for name, item in uniformity.items() if item is not None
    }


def passage_figures(steady: BlenderField, frames: Sequence[BlenderField], z_value: float,
                    passages: Mapping) -> dict:
    """Each passage's mean v_z at a height with its error and bins, as ``blender.json`` keeps them.

    The means are those of the steady field (:func:`siloflow.analysis.studies.blender.profiles.passage_velocities`,
    its bins with particles); their errors the batch means of the frames' passage means
    (:func:`siloflow.analysis.studies.blender.errors.passage_velocity_estimates`), NaN without frames.

    Parameters
    ----------
    steady : BlenderField
        The field of the steady window.
    frames : sequence of BlenderField
        The fields of its single frames, in time order.
    z_value : float
        Height [m].
    passages : mapping name -> (x_lo, x_hi)
        Clear intervals at that height [m].

    Returns
    -------
    dict
        ``mean_v_z_m_s`` (name -> m/s), ``mean_v_z_m_s_error`` (name -> m/s, NaN when not known) and ``n_bins``
        (name -> bins).
    """
    velocities = passage_velocities(checked_field(steady), z_value, passages)
    estimates = passage_velocity_estimates(frames, z_value, passages) if len(frames) else {}
    errors = {name: (math.nan if estimates.get(name) is None else estimates[name].std_error)
              for name in velocities.mean_v_z}
    return {"mean_v_z_m_s": dict(velocities.mean_v_z), "mean_v_z_m_s_error": errors, "n_bins": dict(velocities.n_bins)}


def exclusion_of(tube_width: float | None) -> float:
    """The distance from the tube within which the study's "close to the blending tube" lies: one tube width [m]
    (0 without a tube)."""
    return 0.0 if not tube_width else positive_number("tube_width", tube_width)


def section_uniformity(steady: BlenderField, frames: Sequence[BlenderField], section: Mapping[str, float],
                       tube: tuple[float, float] | None, exclusion: float) -> dict:
    """:func:`vertical_uniformity` at each height of ``section`` (:func:`section_heights`) as
    :func:`uniformity_summary` lays it out; arguments as :func:`vertical_uniformity`'s."""
    return uniformity_summary({name: vertical_uniformity(steady, frames, z, tube, exclusion)
                               for name, z in section.items()}, section)


def wall_layer_summary(steady: BlenderField, frames: Sequence[BlenderField], depth: float,
                       levels: Mapping[str, tuple[float, Mapping]], section: Mapping[str, float],
                       tube: tuple[float, float] | None, exclusion: float) -> dict:
    """The wall layer's figures for ``blender.json``: its depth, the passages at the insert outlet and inlet
    (:func:`passage_figures`) and the vertical section's uniformity (:func:`section_uniformity`).

    Parameters
    ----------
    steady, frames
        The wall layer's steady field and the fields of its single frames (:class:`BlenderField`).
    depth : float
        Depth of the layer from each wall [m]
        (:func:`siloflow.analysis.studies.blender.window_fields.wall_layer_depth`).
    levels : mapping name -> (float, mapping)
        ``"insert outlet"`` and, where the insert has one, ``"insert inlet"``: the key height of its profile [m] and
        the clear intervals there (name -> (x_lo, x_hi)) [m].
    section, tube, exclusion
        As :func:`section_uniformity`.

    Returns
    -------
    dict
        ``depth_m``, ``walls`` (:data:`WALL_LAYER_WALLS`), ``passages_at_insert_outlet`` and
        ``passages_at_insert_inlet`` (null without an inlet level), as the depth average's of the same names with
        ``mean_v_z_m_s_error`` beside, and ``vertical_section``.
    """
    passages = {name: None if name not in levels else passage_figures(steady, frames, *levels[name])
                for name in ("insert outlet", "insert inlet")}
    return {"depth_m": positive_number("depth", depth), "walls": WALL_LAYER_WALLS,
            "passages_at_insert_outlet": passages["insert outlet"],
            "passages_at_insert_inlet": passages["insert inlet"],
            "vertical_section": section_uniformity(steady, frames, section, tube, exclusion)}
