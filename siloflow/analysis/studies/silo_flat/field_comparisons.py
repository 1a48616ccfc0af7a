"""Time-averaged silo fields compared: with measured profiles (e.g. PIV) and across the runs of a parametric study.

Pure computation on :class:`~siloflow.analysis.numerics.grid.Fields` (read from ``averaged.npz`` by
:func:`siloflow.analysis.io.fields.load_fields_npz`) and on plain data; the workflow scripts read the files, call these
functions and write their rows and plots.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.numerics.field_ops import depth_average, front_wall_slice
from siloflow.analysis.numerics.grid import Fields
from siloflow.analysis.numerics.profiles import velocity_profile
from siloflow.analysis.studies.silo_flat.measured import MeasuredProfile, ProfileComparison, compare_with_measurement

__all__ = [
    "MEASURED_PLANES",
    "comparison_plane",
    "compare_with_measurements",
    "measured_comparison_rows",
    "ParametricProfiles",
    "parametric_profiles",
    "parametric_rows",
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
    if not depth_averaged:
        raise ValueError("depth_averaged must hold at least one run's fields")
    layers = sorted({f.grid.shape[1] for f in depth_averaged} - {1})
    if layers:
        raise ValueError(f"depth_averaged fields must have one node layer in y (use depth_average), got {layers}")
    height = min([height] + [float(f.grid.z[-2]) for f in depth_averaged])
    profiles = [velocity_profile(f, height) for f in depth_averaged]
    x = profiles[0].x
    return ParametricProfiles(height, x, [np.interp(x, p.x, p.v_z) for p in profiles])


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
