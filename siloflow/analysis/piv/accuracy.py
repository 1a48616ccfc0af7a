"""How accurate PIV of the front wall is, measured where the truth is known: synthetic PIV of DEM frames.

For one particle frame, one image resolution and one camera frame rate f: the spheres within the band of the front
wall are rendered (image A), then rendered again moved by their velocity over one camera frame, ``x + v / f``
(image B), so that the true displacement of every sphere is known exactly; OpenPIV's multipass gives a field, and the
truth on the same grid is the spheres' mean velocity in each interrogation window
(:func:`siloflow.analysis.piv.front_wall.window_mean_velocity`). The image spans the silo's full width W (scale W / width px)
from the outlet plane z = 0 up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.analysis.piv.calibration import ImageScale, piv_field
from siloflow.analysis.piv.derived import field_quantities
from siloflow.analysis.piv.field import PlanarField, time_average
from siloflow.analysis.piv.front_wall import field_errors, front_wall_image, front_wall_spheres, window_mean_velocity
from siloflow.analysis.piv.synthetic import piv_displacements

__all__ = ["COMBINATION", "ERROR_COLUMNS", "PivSettings", "accuracy_row", "accuracy_table", "derived_errors",
           "profile_error_rows", "silo_image_scale", "synthetic_piv", "visible_top"]

#: The columns that name a combination of image resolution and frame rate.
COMBINATION = ("width_px", "height_px", "frame_rate_hz", "mm_per_px")
#: The error columns of an accuracy row (m/s unless the name says otherwise).
ERROR_COLUMNS = ("bias_u_m_s", "rms_u_m_s", "bias_w_m_s", "rms_w_m_s", "rms_w_spread_m_s", "centreline_w_error_m_s",
                 "fcb_error_m", "kinematic_b_error_percent")


@dataclass(frozen=True)
class PivSettings:
    """Rendering and PIV settings (``silo_flat.piv``): window and overlap [px], passes, the visible band [m], blur
    [px] and noise (of the particle-void contrast)."""

    window_px: int = 40
    overlap_px: int = 20
    passes: int = 2
    band: float = 0.00375
    blur_px: float = 0.7
    noise: float = 0.0


def silo_image_scale(width: float, resolution: tuple[int, int]) -> ImageScale:
    """The scale of an image ``resolution`` = (width, height) px spanning the silo's width ``width`` [m] from
    x = -W/2, its bottom row at the outlet plane z = 0."""
    columns, rows = (int(v) for v in resolution)
    scale = width / columns
    return ImageScale(scale, -0.5 * width + 0.5 * scale, (rows - 0.5) * scale)


def visible_top(frames, band: float) -> float | None:
    """The highest point [m] of the spheres within ``band`` [m] of the front wall over ``frames`` (each with
    ``position`` and ``radius``), or None when none is visible."""
    tops = []
    for frame in frames:
        position = np.asarray(frame.position, dtype=float).reshape(-1, 3)
        seen = front_wall_spheres(position, band)
        if seen.any():
            tops.append(float(np.max(position[seen, 2] + np.asarray(frame.radius, dtype=float)[seen])))
    return max(tops) if tops else None


def synthetic_piv(position: np.ndarray, velocity: np.ndarray, radius: np.ndarray, scale: ImageScale,
                  resolution: tuple[int, int], frame_rate: float, settings: PivSettings,
                  rng: np.random.Generator | None = None, image_top: float | None = None) -> tuple[PlanarField, PlanarField]:
    """PIV of one frame's front wall and the truth on the same grid (module docstring): (PIV field, truth).

    With ``image_top`` [m] the image ends one first-pass window above it (but keeps at least the four first-pass
    windows multipass needs): a camera aims at the fill, and a head space of blank image above it (windows without
    texture, most of a tall image over a low fill) makes OpenPIV's multipass fail everywhere, because its window
    deformation cannot interpolate across the hole. Pairs to be averaged need one ``image_top``, so that they share
    a grid (:func:`visible_top` of all their frames)."""
    position = np.asarray(position, dtype=float).reshape(-1, 3)
    velocity = np.asarray(velocity, dtype=float).reshape(-1, 3)
    seen = front_wall_spheres(position, settings.band)
    rows = int(resolution[1])
    if image_top is not None:
        first_window = settings.window_px * 2 ** max(settings.passes - 1, 0)
        first_step = first_window - settings.overlap_px * 2 ** max(settings.passes - 1, 0)
        bottom = scale.z0 - (rows - 1) * scale.scale  # the bottom row's z stays where it is
        needed = int(np.ceil((image_top - bottom) / scale.scale)) + 1 + first_window
        rows = min(rows, max(needed, first_window + 3 * first_step))
        scale = ImageScale(scale.scale, scale.x0, bottom + (rows - 1) * scale.scale)
    shape = (rows, int(resolution[0]))
    # one generator for both images: their noise must be independent, or it correlates to zero displacement
    rendering = {"void_level": 0.5, "particle_level": 1.0, "blur_px": settings.blur_px, "noise": 0.5 * settings.noise,
                 "rng": rng if rng is not None else np.random.default_rng(0)}
    image_a = front_wall_image(position[seen], radius[seen], scale, shape, **rendering)
    image_b = front_wall_image(position[seen] + velocity[seen] / frame_rate, radius[seen], scale, shape, **rendering)
    x, y, u, v, valid = piv_displacements(image_a, image_b, settings.window_px, settings.overlap_px, settings.passes)
    measured = piv_field(x.ravel(), y.ravel(), u.ravel(), v.ravel(), valid.ravel(), True, scale, frame_rate)
    truth = window_mean_velocity(position[seen], velocity[seen], measured.x, measured.z,
                                 0.5 * settings.window_px * scale.scale, min_count=3)
    return measured, truth


def derived_errors(pairs: list[tuple[PlanarField, PlanarField]], heights, fraction: float = 0.05) -> dict:
    """PIV's error of the derived quantities (:func:`siloflow.analysis.piv.derived.field_quantities`) of the mean field over
    the pairs, against the truth's, averaged over ``heights`` [m]: the centreline v_z [m/s], the flow channel boundary
    at ``fraction`` of it (mean absolute error over both sides) [m] and the kinematic constant B [% of the truth's].
    A quantity that one of the two fields does not give is left out of its mean (NaN when none is left)."""
    measured = field_quantities(time_average([m for m, _ in pairs], -np.inf, np.inf), heights, fraction)
    truth = field_quantities(time_average([t for _, t in pairs], -np.inf, np.inf), heights, fraction)

    def mean(values) -> float:
        values = np.asarray(values, dtype=float)
        return float(np.mean(values[np.isfinite(values)])) if np.isfinite(values).any() else float("nan")

    return {
        "centreline_w_error_m_s": mean([m.centreline_w - t.centreline_w for m, t in zip(measured, truth)]),
        "fcb_error_m": mean([abs(getattr(m, side) - getattr(t, side)) for m, t in zip(measured, truth)
                             for side in ("fcb_left", "fcb_right")]),
        "kinematic_b_error_percent": mean([100.0 * (m.kinematic_b - t.kinematic_b) / t.kinematic_b
                                           for m, t in zip(measured, truth)]),
    }


def accuracy_row(pairs: list[tuple[PlanarField, PlanarField]], heights=(), fraction: float = 0.05) -> dict:
    """Bias and RMS error of u and w [m/s] over every node of every pair (valid in both), with the spread of the
    per-pair RMS of w over the pairs [m/s], and the error of the derived quantities at ``heights`` [m]
    (:func:`derived_errors`; without heights, only the centreline w: the node column nearest x = 0, mean over its
    nodes) [m/s]."""
    measured = np.concatenate([(m.u - t.u)[m.valid & t.valid] for m, t in pairs])
    vertical = np.concatenate([(m.w - t.w)[m.valid & t.valid] for m, t in pairs])
    per_pair = [field_errors(m, t).rms_w for m, t in pairs]
    centre = []
    for m, t in pairs:
        column = int(np.argmin(np.abs(m.x)))
        both = m.valid[:, column] & t.valid[:, column]
        centre.extend((m.w[both, column] - t.w[both, column]).tolist())
    row = {
        "nodes": int(measured.size), "pairs": len(pairs),
        "bias_u_m_s": float(measured.mean()), "rms_u_m_s": float(np.sqrt(np.mean(measured**2))),
        "bias_w_m_s": float(vertical.mean()), "rms_w_m_s": float(np.sqrt(np.mean(vertical**2))),
        "rms_w_spread_m_s": float(np.std(per_pair, ddof=1)) if len(per_pair) > 1 else float("nan"),
        "centreline_w_error_m_s": float(np.mean(centre)) if centre else float("nan"),
        "fcb_error_m": float("nan"), "kinematic_b_error_percent": float("nan"),
    }
    if len(heights):
        row.update(derived_errors(pairs, heights, fraction))
    return row


def profile_error_rows(pairs: list[tuple[PlanarField, PlanarField]], heights) -> list[dict]:
    """PIV's error of v_z along the profile at each height: bias and RMS [m/s] over the nodes of the node row nearest
    the height (``z_m``, m) valid in both, over every pair. PIV's error is not uniform over a silo: it is largest in
    the narrow, sheared flow channel, so a profile is judged against its own row's error."""
    rows = []
    for height in heights:
        k = int(np.argmin(np.abs(pairs[0][0].z - height)))
        errors = np.concatenate([(m.w[k] - t.w[k])[m.valid[k] & t.valid[k]] for m, t in pairs])
        rows.append({"z_m": float(pairs[0][0].z[k]), "nodes": int(errors.size),
                     "bias_w_m_s": float(errors.mean()) if errors.size else float("nan"),
                     "rms_w_m_s": float(np.sqrt(np.mean(errors**2))) if errors.size else float("nan")})
    return rows


def accuracy_table(frames: list, width: float, resolutions, frame_rates, settings: PivSettings, heights=(),
                   fraction: float = 0.05) -> tuple[list[dict], list[dict]]:
    """One row per image resolution and frame rate (:func:`accuracy_row` over ``frames``, each with ``position``,
    ``velocity`` and ``radius`` of its spheres, derived quantities at ``heights`` [m]), with ``width_px``,
    ``height_px``, ``frame_rate_hz`` and the scale [mm/px]. A combination where OpenPIV finds no valid vector, or
    whose fields give no profile at a height, gets NaN errors and its reason in ``note``. Second, the same
    combinations' rows of :func:`profile_error_rows` per height."""
    rows, profiles = [], []
    top = visible_top(frames, settings.band)
    for resolution in resolutions:
        scale = silo_image_scale(width, resolution)
        for frame_rate in frame_rates:
            row = {"width_px": int(resolution[0]), "height_px": int(resolution[1]), "frame_rate_hz": float(frame_rate),
                   "mm_per_px": 1e3 * scale.scale}
            try:
                pairs = [synthetic_piv(f.position, f.velocity, f.radius, scale, resolution, frame_rate, settings,
                                       image_top=top) for f in frames]
                row.update(accuracy_row(pairs, heights, fraction), note="")
                profiles.extend({key: row[key] for key in COMBINATION} | r for r in profile_error_rows(pairs, heights))
            except ValueError as error:
                row.update({key: float("nan") for key in ERROR_COLUMNS}, nodes=0, pairs=0, note=str(error))
                profiles.extend({key: row[key] for key in COMBINATION} | {"z_m": float(height), "nodes": 0,
                                "bias_w_m_s": float("nan"), "rms_w_m_s": float("nan")} for height in heights)
            rows.append(row)
    return rows, profiles
