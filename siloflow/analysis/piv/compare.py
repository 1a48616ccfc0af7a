"""DEM against measured PIV, the way the study compared them: the DEM's front-wall velocity on the PIV grid, averaged
over the same time window, profiles at the same heights, and the difference set against what PIV itself gets wrong
(the synthetic study's RMS error along the profile at the nearest pixel size, frame rate and height) and the DEM's
own noise over its frames.

The DEM's answer on the PIV grid is the mean velocity of the spheres within the band of the front wall in each
interrogation window (:func:`siloflow.analysis.piv.front_wall.window_mean_velocity`), the same truth the synthetic study
measures PIV against.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.analysis.piv.derived import field_quantities, planar_profile
from siloflow.analysis.piv.field import PlanarField, time_average
from siloflow.analysis.piv.front_wall import front_wall_spheres, window_mean_velocity

__all__ = ["DemWindow", "ProfilePair", "comparison_rows", "dem_front_wall", "error_band", "piv_comparison",
           "profile_pairs"]


@dataclass(frozen=True)
class DemWindow:
    """The DEM's front wall over a time window: the mean field, the standard error of its w over the frames [m/s]
    (NaN where fewer than two frames are valid) and how many frames it is over."""

    field: PlanarField
    w_standard_error: np.ndarray
    frames: int


def dem_front_wall(frames: Sequence, x: np.ndarray, z: np.ndarray, half_window: float, band: float, start: float,
                   end: float, min_count: int = 3, opened: float = 0.0) -> DemWindow:
    """The DEM front-wall field on the nodes (``x``, ``z``) [m] with windows of half width ``half_window`` [m],
    over the frames (each with its ``time`` [s], sphere ``position`` and ``velocity``) whose time after the outlet
    opened (at ``opened`` [s]) lies in ``start <= t <= end``; spheres within ``band`` [m] of the front wall.

    Raises
    ------
    ValueError
        When no frame lies in the window.
    """
    fields = []
    for frame in frames:
        time = frame.time - opened
        if start <= time <= end:
            position = np.asarray(frame.position, dtype=float).reshape(-1, 3)
            seen = front_wall_spheres(position, band)
            fields.append(window_mean_velocity(position[seen], np.asarray(frame.velocity, dtype=float)[seen], x, z,
                                               half_window, time, min_count))
    if not fields:
        raise ValueError(f"no DEM frame between {start:g} and {end:g} s after the outlet opened")
    mean = time_average(fields, start, end)
    stack = np.array([f.w for f in fields])  # NaN where a frame's node is not valid
    count = np.sum(np.isfinite(stack), axis=0)
    with warnings.catch_warnings():  # a node valid in fewer than two frames has no spread: NaN, as documented
        warnings.simplefilter("ignore", RuntimeWarning)
        error = np.nanstd(stack, axis=0, ddof=1) / np.sqrt(count)
    return DemWindow(mean, np.where(count >= 2, error, np.nan), len(fields))


def error_band(profiles: Sequence[dict], pixel_size: float | None, frame_rate: float | None,
               z: float) -> tuple[float, str]:
    """PIV's RMS error of v_z [m/s] along a profile at height ``z`` [m] for a camera of ``pixel_size`` [m/px] at
    ``frame_rate`` [1/s]: of the synthetic study's per-height rows (:func:`siloflow.analysis.piv.accuracy.profile_error_rows`
    with the combination columns), the image resolution nearest in pixel size, then the frame rate nearest (on a log
    scale), then the row nearest the height; and a note naming it. NaN with the reason when the pixel size is unknown
    or no row has a value."""
    rows = [r for r in profiles if math.isfinite(number_or_nan(r["rms_w_m_s"]))]
    if pixel_size is None:
        return math.nan, "pixel size unknown: no PIV error band"
    if not rows:
        return math.nan, "the synthetic PIV study has no valid row: no PIV error band"
    rate = frame_rate if frame_rate else float(rows[0]["frame_rate_hz"])
    nearest = min(rows, key=lambda r: (round(abs(math.log(1e-3 * float(r["mm_per_px"]) / pixel_size)), 9),
                                       abs(math.log(float(r["frame_rate_hz"]) / rate))))
    same = [r for r in rows if all(r[key] == nearest[key] for key in ("width_px", "height_px", "frame_rate_hz"))]
    row = min(same, key=lambda r: abs(float(r["z_m"]) - z))
    return float(row["rms_w_m_s"]), (f"PIV error from the synthetic study at {int(row['width_px'])} x "
                                     f"{int(row['height_px'])} px ({float(row['mm_per_px']):.3g} mm/px), "
                                     f"{float(row['frame_rate_hz']):g} frames/s, z = {1e3 * float(row['z_m']):.3g} mm")


@dataclass(frozen=True)
class ProfilePair:
    """DEM and measured v_z profiles at one height and window, on the nodes valid in both.

    Attributes
    ----------
    window : tuple of float
        Time window after the outlet opened [s].
    z : float
        Height of the node row [m].
    x, dem_w, measured_w, dem_error : numpy.ndarray
        Positions [m], the two profiles [m/s] and the DEM's standard error over its frames [m/s].
    band : float
        PIV's RMS error of v_z [m/s] (the error band; NaN when unknown).
    """

    window: tuple[float, float]
    z: float
    x: np.ndarray
    dem_w: np.ndarray
    measured_w: np.ndarray
    dem_error: np.ndarray
    band: float


def profile_pairs(dem: DemWindow, measured: PlanarField, heights: Sequence[float], window: tuple[float, float],
                  band: float) -> list[ProfilePair]:
    """The DEM and measured profiles at each height (the nearest node row of the common grid).

    Raises
    ------
    ValueError
        When the two fields are not on one grid, or a row has fewer than two nodes valid in both.
    """
    if not (np.allclose(dem.field.x, measured.x) and np.allclose(dem.field.z, measured.z)):
        raise ValueError("the DEM field is not on the PIV grid")
    both = PlanarField(measured.x, measured.z, measured.u, measured.w, measured.valid & dem.field.valid)
    pairs = []
    for height in heights:
        profile = planar_profile(both, height)
        row = int(np.argmin(np.abs(measured.z - profile.z)))
        columns = np.searchsorted(measured.x, profile.x)
        pairs.append(ProfilePair((float(window[0]), float(window[1])), profile.z, profile.x,
                                 dem.field.w[row, columns], profile.v_z, dem.w_standard_error[row, columns],
                                 float(band)))
    return pairs


def comparison_rows(dem: DemWindow, measured: PlanarField, pairs: Sequence[ProfilePair], fraction: float = 0.05,
                    note: str = "") -> list[dict]:
    """One row per profile: the mean and RMS of DEM minus measured v_z [m/s], the uncertainty they are judged
    against (RMS over the nodes of the PIV error band and the DEM's standard error combined in quadrature) [m/s],
    the RMS difference in units of it and whether it is larger than twice that (the project's threshold, as in the
    cross-engine table: an RMS difference equal to its expected error would be called larger half the time), and
    the centreline v_z, flow channel boundary (at ``fraction``) and kinematic constant B of each field
    (:func:`siloflow.analysis.piv.derived.field_quantities`)."""
    rows = []
    for pair in pairs:
        (dem_q,) = field_quantities(dem.field, [pair.z], fraction)
        (measured_q,) = field_quantities(measured, [pair.z], fraction)
        difference = pair.dem_w - pair.measured_w
        dem_error = np.where(np.isfinite(pair.dem_error), pair.dem_error, 0.0)
        band = pair.band if math.isfinite(pair.band) else 0.0
        uncertainty = float(np.sqrt(np.mean(band**2 + dem_error**2)))
        rms = float(np.sqrt(np.mean(difference**2)))
        rows.append({
            "window_start_s": pair.window[0], "window_end_s": pair.window[1], "z_m": pair.z, "nodes": int(pair.x.size),
            "dem_frames": dem.frames, "mean_difference_m_s": float(difference.mean()), "rms_difference_m_s": rms,
            "piv_error_m_s": pair.band, "dem_standard_error_m_s": float(np.sqrt(np.mean(dem_error**2))),
            "uncertainty_m_s": uncertainty,
            "difference_over_uncertainty": rms / uncertainty if uncertainty > 0 else math.inf,
            "larger_than_2_uncertainties": "yes" if rms > 2.0 * uncertainty else "no",
            "dem_centreline_w_m_s": dem_q.centreline_w, "measured_centreline_w_m_s": measured_q.centreline_w,
            "dem_fcb_left_m": dem_q.fcb_left, "measured_fcb_left_m": measured_q.fcb_left,
            "dem_fcb_right_m": dem_q.fcb_right, "measured_fcb_right_m": measured_q.fcb_right,
            "dem_kinematic_b_m": dem_q.kinematic_b, "measured_kinematic_b_m": measured_q.kinematic_b,
            "note": note,
        })
    return rows


def piv_comparison(dem_frames: Sequence, measured: Sequence[PlanarField], profiles: Sequence[dict], heights,
                   windows, band: float, pixel_size: float | None, frame_rate: float | None, fraction: float = 0.05,
                   min_valid_fraction: float = 0.5, opened: float = 0.0) -> tuple[list[dict], list[ProfilePair]]:
    """DEM against a measured sequence over each time window [s after the outlet opened] (all the fields' times when
    ``windows`` is empty): the measured fields' time average, the DEM front wall (spheres within ``band`` [m]) on its
    grid with interrogation windows of twice the node spacing (the study's 50 % overlap), the profiles at
    ``heights`` [m] and their rows (:func:`comparison_rows`), each judged against the PIV error band at its height
    from the synthetic study's per-height ``profiles`` rows for ``pixel_size`` [m/px] and ``frame_rate`` [1/s]
    (:func:`error_band`).

    Raises
    ------
    ValueError
        When a window holds no measured field or no DEM frame, or a height has no profile.
    """
    times = [f.time for f in measured]
    rows, pairs = [], []
    for start, end in (windows if len(windows) else [(min(times), max(times))]):
        average = time_average(measured, start, end, min_valid_fraction)
        spacing = min(float(np.min(np.diff(axis))) for axis in (average.x, average.z) if axis.size > 1)
        dem = dem_front_wall(dem_frames, average.x, average.z, spacing, band, start, end, opened=opened)
        for height in heights:
            piv_error, note = error_band(profiles, pixel_size, frame_rate, height)
            height_pairs = profile_pairs(dem, average, [height], (start, end), piv_error)
            rows.extend(comparison_rows(dem, average, height_pairs, fraction, note))
            pairs.extend(height_pairs)
    return rows, pairs
