"""Time-averaged silo fields compared: with measured profiles (e.g. PIV) and across the runs of a parametric study.

Pure computation on :class:`~siloflow.analysis.numerics.grid.Fields` (read from ``averaged.npz`` by
:func:`siloflow.analysis.io.fields.load_fields_npz`) and on plain data; the workflow scripts read the files, call these
functions and write their rows and plots.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.field_ops import depth_average, front_wall_slice
from siloflow.analysis.numerics.grid import Fields
from siloflow.analysis.numerics.profiles import velocity_profile
from siloflow.analysis.numerics.reference_spread import combine_seeds
from siloflow.analysis.numerics.replicates import replicate_error
from siloflow.analysis.studies.silo_flat.fields import JanssenComparison
from siloflow.analysis.studies.silo_flat.measured import MeasuredProfile, ProfileComparison, compare_with_measurement

__all__ = [
    "MEASURED_PLANES",
    "comparison_plane",
    "compare_with_measurements",
    "measured_comparison_rows",
    "ParametricProfiles",
    "parametric_profiles",
    "parametric_rows",
    "SeedProfiles",
    "seed_profiles",
    "SeedKinematic",
    "seed_kinematic",
    "seed_janssen",
]

MEASURED_PLANES = ("front_wall", "depth_average")
"""Which simulated profiles measurements are compared with: the node layer at the front wall (what a camera
behind it sees) or the average over the depth."""


# --------------------------------------------------------------------------- measured profiles


def comparison_plane(averaged: Fields, plane: str) -> Fields:
    """The one-layer fields the measurements are compared with: ``plane`` is one of :data:`MEASURED_PLANES`."""
    if plane == "front_wall":
        return front_wall_slice(averaged)
    if plane == "depth_average":
        return depth_average(averaged)
    raise ValueError(f"plane must be one of {MEASURED_PLANES}, got {plane!r}")


def compare_with_measurements(plane: Fields, measured: Sequence[MeasuredProfile]) -> list[ProfileComparison]:
    """Each measured profile against the simulated v_z(x) of ``plane`` (one node layer) at its height."""
    comparisons = []
    for profile in measured:
        simulated = velocity_profile(plane, profile.z)
        comparisons.append(compare_with_measurement(simulated.x, simulated.v_z, profile))
    return comparisons


def measured_comparison_rows(comparisons: Sequence[ProfileComparison]) -> list[dict]:
    """Rows of ``measured_comparison.csv``: per measured profile, its height (m), window and error metrics
    (mean error in %, RMS and largest error in m/s, fraction within the measurement uncertainty)."""
    return [
        {"z_m": c.measured.z, "window": c.measured.window, "n_points": c.errors.n_points,
         "mean_error_percent": c.errors.mean_error_percent, "rms_error_m_s": c.errors.rms_error,
         "max_abs_error_m_s": c.errors.max_abs_error,
         "fraction_within_uncertainty": c.errors.fraction_within_uncertainty}
        for c in comparisons
    ]


# --------------------------------------------------------------------------- parametric studies


@dataclass(frozen=True)
class ParametricProfiles:
    """The v_z profiles of the runs of a study at one height, on the nodes of the first run.

    Attributes
    ----------
    height : float
        Profile height (m).
    x : numpy.ndarray
        Node x positions of the first run (m).
    v_z : list of numpy.ndarray
        Each run's v_z (m/s) interpolated onto ``x``.
    """

    height: float
    x: np.ndarray
    v_z: list[np.ndarray]


def parametric_profiles(depth_averaged: Sequence[Fields], height: float) -> ParametricProfiles:
    """v_z profiles of each run's depth-averaged, time-averaged fields at the study's ``height`` (m).

    Each run's fields have one node layer in y (:func:`~siloflow.analysis.numerics.field_ops.depth_average`, which the
    workflow writes per run as ``fields/depth_averaged.npz``). The height is lowered, if need be, to the
    second-highest node row of the run with the lowest grid, so that every run's fields cover it with a row above.
    """
    _one_layer(depth_averaged)
    height = min([height] + [float(f.grid.z[-2]) for f in depth_averaged])
    profiles = [velocity_profile(f, height) for f in depth_averaged]
    x = profiles[0].x
    return ParametricProfiles(height, x, [np.interp(x, p.x, p.v_z) for p in profiles])


def _one_layer(depth_averaged: Sequence[Fields]) -> None:
    if not depth_averaged:
        raise ValueError("depth_averaged must hold at least one run's fields")
    layers = sorted({f.grid.shape[1] for f in depth_averaged} - {1})
    if layers:
        raise ValueError(f"depth_averaged fields must have one node layer in y (use depth_average), got {layers}")


# --------------------------------------------------------------------------- seeds of one configuration


@dataclass(frozen=True)
class SeedProfiles:
    """The v_z profiles of one configuration's seeds at several heights: their mean and its standard error.

    Attributes
    ----------
    heights : numpy.ndarray
        (heights,) profile heights above the outlet (m).
    x : numpy.ndarray
        (nx,) node x positions of the first seed (m).
    v_z, v_z_error : numpy.ndarray
        (heights, nx) the seeds' mean v_z and its standard error between the seeds (m/s); the error is NaN for one
        seed.
    seeds : int
        Seeds averaged.
    """

    heights: np.ndarray
    x: np.ndarray
    v_z: np.ndarray
    v_z_error: np.ndarray
    seeds: int


def seed_profiles(depth_averaged: Sequence[Fields], heights: Sequence[float]) -> SeedProfiles:
    """v_z(x) at each of ``heights`` (m) of one configuration's seeds, as their mean and its standard error.

    Each seed's depth-averaged, time-averaged fields (one node layer in y, as the workflow writes them per run in
    ``fields/depth_averaged.npz``) give its profile at a height (:func:`velocity_profile`, linear in z), put on the
    first seed's nodes; the mean and error at each node are :func:`replicate_error`'s with no within-run error: the
    standard error of the seeds' mean.

    Raises
    ------
    ValueError
        Without fields, for fields of more than one node layer, no heights, or a height outside a seed's grid.
    """
    _one_layer(depth_averaged)
    heights = np.asarray(heights, dtype=float)
    if heights.size == 0:
        raise ValueError("heights must hold at least one profile height")
    for fields in depth_averaged:
        low, high = float(fields.grid.z[0]), float(fields.grid.z[-1])
        outside = [float(z) for z in heights if not low <= z <= high]
        if outside:
            raise ValueError(f"profile heights {outside} m lie outside a seed's fields ({low:g} to {high:g} m)")
    x = velocity_profile(depth_averaged[0], float(heights[0])).x
    by_seed = np.array([[np.interp(x, profile.x, profile.v_z)
                         for profile in (velocity_profile(fields, float(z)) for z in heights)]
                        for fields in depth_averaged])
    unknown = [math.nan] * len(depth_averaged)
    mean = np.empty(by_seed.shape[1:])
    error = np.empty(by_seed.shape[1:])
    for index in np.ndindex(*mean.shape):
        # one seed: replicate_error's error is its unknown within-run one, NaN
        mean[index], error[index], _ = replicate_error(list(by_seed[(slice(None), *index)]), unknown)
    return SeedProfiles(heights, x, mean, error, len(depth_averaged))


def _same_heights(tables: Sequence[Sequence[Mapping]], what: str) -> list[float]:
    """The heights ``z_m`` (m) every seed's table lists, in its order; ValueError without tables or when they
    differ."""
    if not tables:
        raise ValueError(f"tables must hold at least one seed's {what} table")
    heights = [[float(row["z_m"]) for row in table] for table in tables]
    if any(h != heights[0] for h in heights[1:]):
        raise ValueError(f"the seeds' {what} tables list different heights: {heights}")
    return heights[0]


@dataclass(frozen=True)
class SeedKinematic:
    """The kinematic constant B of one configuration's seeds at each height: their mean and its error.

    Attributes
    ----------
    heights : numpy.ndarray
        (heights,) heights above the outlet (m), those of the first seed's table.
    B, B_error : numpy.ndarray
        (heights,) the mean B over the seeds that fitted one at that height and its error (m)
        (:func:`replicate_error`: the larger of the seeds' standard error and the within-run errors); NaN where no
        seed fitted one.
    seeds : numpy.ndarray
        (heights,) seeds that fitted a B at each height.
    """

    heights: np.ndarray
    B: np.ndarray
    B_error: np.ndarray
    seeds: np.ndarray


def seed_kinematic(tables: Sequence[Sequence[Mapping]]) -> SeedKinematic:
    """B(z) of one configuration's seeds from each seed's ``metrics/kinematic.csv`` rows (``z_m``, ``B_m``,
    ``B_m_error`` in m, as :func:`siloflow.analysis.io.tables.read_table` gives them; a B that is None or NaN is a
    height where the fit failed).

    Raises
    ------
    ValueError
        Without tables, or when the seeds' tables do not list the same heights.
    """
    heights = _same_heights(tables, "kinematic")
    mean = np.full(len(heights), math.nan)
    error = np.full_like(mean, math.nan)
    seeds = np.zeros(mean.size, dtype=int)
    for i in range(mean.size):
        pairs = [(number_or_nan(table[i]["B_m"]), number_or_nan(table[i]["B_m_error"])) for table in tables]
        pairs = [(value, err) for value, err in pairs if math.isfinite(value)]
        seeds[i] = len(pairs)
        if pairs:
            mean[i], error[i], _ = replicate_error([value for value, _ in pairs], [err for _, err in pairs])
    return SeedKinematic(np.array(heights), mean, error, seeds)


def seed_janssen(tables: Sequence[Sequence[Mapping]]) -> JanssenComparison:
    """The vertical stress at the end of filling of one configuration's seeds, as the validation rows judge it: each
    seed's ``metrics/janssen.csv`` rows combined by :func:`~siloflow.analysis.numerics.reference_spread.combine_seeds`
    (row by row: the DEM and hydrostatic stresses as the seeds' mean with the larger of their standard error and the
    within-run errors, depth, height and Janssen's stress as the seeds' mean).

    Returns
    -------
    JanssenComparison
        In Pa and m; its surface height the mean of ``z + h`` over the rows, ``bin_pairs`` 0 (the error is the
        seeds', not one fill's mirror bins).

    Raises
    ------
    ValueError
        Without tables, or when the seeds' tables do not list the same heights.
    """
    _same_heights(tables, "Janssen")
    combined, _ = combine_seeds([[dict(row) for row in table] for table in tables])

    def column(key: str) -> np.ndarray:
        return np.array([number_or_nan(row.get(key)) for row in combined])

    depth, height = column("depth_below_surface_m"), column("z_m")
    return JanssenComparison(depth_below_surface=depth, simulated=column("sigma_v_dem_Pa"),
                             janssen=column("sigma_v_janssen_Pa"), surface_height=float(np.mean(depth + height)),
                             height=height, simulated_error=column("sigma_v_dem_Pa_error"),
                             hydrostatic=column("hydrostatic_pa"), hydrostatic_error=column("hydrostatic_pa_error"),
                             bin_pairs=0)


def parametric_rows(study: str, labels: Sequence[str], runs: Sequence[str], flows: Sequence[Mapping],
                    profiles: ParametricProfiles) -> list[dict]:
    """Rows of ``parametric/<study>.csv``: per run, its label, id, flow metrics (from its ``flow.json``) and
    centreline v_z (m/s) at the profile height.

    The flow metrics' standard errors (``<key>_error``) come along as the run's ``flow.json`` has them; a
    ``flow.json`` written before they existed gives NaN (unknown)."""
    return [
        {"study": study, "label": label, "run_id": run, "profile_height_m": profiles.height,
         "mass_flow_rate_kg_s": flow["mass_flow_rate_kg_s"],
         "mass_flow_rate_kg_s_error": _error(flow, "mass_flow_rate_kg_s"),
         "mass_flow_rate_stderr_kg_s": flow["mass_flow_rate_stderr_kg_s"],
         "beverloo_ratio": flow["beverloo_ratio"], "beverloo_ratio_error": _error(flow, "beverloo_ratio"),
         "filling_bulk_density_kg_m3": flow["filling_bulk_density_kg_m3"],
         "filling_bulk_density_kg_m3_error": _error(flow, "filling_bulk_density_kg_m3"),
         "centreline_v_z_m_s": float(np.interp(0.0, profiles.x, profile))}
        for label, run, flow, profile in zip(labels, runs, flows, profiles.v_z)
    ]


def _error(flow: Mapping, key: str) -> float:
    """``flow["<key>_error"]`` as a float; NaN when it is missing or null (JSON's NaN)."""
    return number_or_nan(flow.get(f"{key}_error"))
