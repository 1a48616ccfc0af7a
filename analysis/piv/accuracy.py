"""How accurate PIV of the front wall is, measured where the truth is known: synthetic PIV of DEM frames.

For one particle frame, one image resolution and one camera frame rate f: the spheres within the band of the front
wall are rendered (image A), then rendered again moved by their velocity over one camera frame, ``x + v / f``
(image B), so that the true displacement of every sphere is known exactly; OpenPIV's multipass gives a field, and the
truth on the same grid is the spheres' mean velocity in each interrogation window
(:func:`analysis.piv.front_wall.window_mean_velocity`). The image spans the silo's full width W (scale W / width px)
from the outlet plane z = 0 up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.piv.calibration import ImageScale, piv_field
from analysis.piv.field import PlanarField
from analysis.piv.front_wall import field_errors, front_wall_image, front_wall_spheres, window_mean_velocity
from analysis.piv.synthetic import piv_displacements

__all__ = ["PivSettings", "accuracy_row", "accuracy_table", "silo_image_scale", "synthetic_piv"]


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


def synthetic_piv(position: np.ndarray, velocity: np.ndarray, radius: np.ndarray, scale: ImageScale,
                  resolution: tuple[int, int], frame_rate: float, settings: PivSettings,
                  rng: np.random.Generator | None = None) -> tuple[PlanarField, PlanarField]:
    """PIV of one frame's front wall and the truth on the same grid (module docstring): (PIV field, truth)."""
    position = np.asarray(position, dtype=float).reshape(-1, 3)
    velocity = np.asarray(velocity, dtype=float).reshape(-1, 3)
    seen = front_wall_spheres(position, settings.band)
    shape = (int(resolution[1]), int(resolution[0]))
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


def accuracy_row(pairs: list[tuple[PlanarField, PlanarField]]) -> dict:
    """Bias and RMS error of u and w [m/s] over every node of every pair (valid in both), with the spread of the
    per-pair RMS of w over the pairs [m/s], and the error of the centreline w (the node column nearest x = 0, mean
    over its nodes) [m/s]."""
    measured = np.concatenate([(m.u - t.u)[m.valid & t.valid] for m, t in pairs])
    vertical = np.concatenate([(m.w - t.w)[m.valid & t.valid] for m, t in pairs])
    per_pair = [field_errors(m, t).rms_w for m, t in pairs]
    centre = []
    for m, t in pairs:
        column = int(np.argmin(np.abs(m.x)))
        both = m.valid[:, column] & t.valid[:, column]
        centre.extend((m.w[both, column] - t.w[both, column]).tolist())
    return {
        "nodes": int(measured.size), "pairs": len(pairs),
        "bias_u_m_s": float(measured.mean()), "rms_u_m_s": float(np.sqrt(np.mean(measured**2))),
        "bias_w_m_s": float(vertical.mean()), "rms_w_m_s": float(np.sqrt(np.mean(vertical**2))),
        "rms_w_spread_m_s": float(np.std(per_pair, ddof=1)) if len(per_pair) > 1 else float("nan"),
        "centreline_w_error_m_s": float(np.mean(centre)) if centre else float("nan"),
    }


def accuracy_table(frames: list, width: float, resolutions, frame_rates, settings: PivSettings) -> list[dict]:
    """One row per image resolution and frame rate (:func:`accuracy_row` over ``frames``, each with ``position``,
    ``velocity`` and ``radius`` of its spheres), with ``width_px``, ``height_px``, ``frame_rate_hz`` and the scale
    [mm/px]. A combination where OpenPIV finds no valid vector gets NaN errors and its reason in ``note``."""
    rows = []
    for resolution in resolutions:
        scale = silo_image_scale(width, resolution)
        for frame_rate in frame_rates:
            row = {"width_px": int(resolution[0]), "height_px": int(resolution[1]), "frame_rate_hz": float(frame_rate),
                   "mm_per_px": 1e3 * scale.scale}
            try:
                pairs = [synthetic_piv(f.position, f.velocity, f.radius, scale, resolution, frame_rate, settings)
                         for f in frames]
                row.update(accuracy_row(pairs), note="")
            except ValueError as error:
                row.update({key: float("nan") for key in ("bias_u_m_s", "rms_u_m_s", "bias_w_m_s", "rms_w_m_s",
                                                          "rms_w_spread_m_s", "centreline_w_error_m_s")},
                           nodes=0, pairs=0, note=str(error))
            rows.append(row)
    return rows
