"""From image pixels to silo coordinates: the scale and origin fixed by wall markers.

An image has its column c to the right and its row r downwards (pixels); the silo has x to the right and z up
(metres, :mod:`siloflow.analysis.piv.field`). With the camera square to the front wall, ``x = x0 + s c`` and ``z = z0 - s r``:
one scale s [m/px] and an origin. Two or more markers (image position and known silo position) fix them by least
squares (exact for two); the residuals say how well the camera was square.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.analysis.piv.field import PlanarField, field_from_rows

__all__ = ["ImageScale", "piv_field", "scale_from_markers"]


@dataclass(frozen=True)
class ImageScale:
    """``x = x0 + scale c``, ``z = z0 - scale r`` (image rows point down).

    Attributes
    ----------
    scale : float
        Metres per pixel [m/px].
    x0, z0 : float
        Silo coordinates of pixel (0, 0) [m].
    residual : float
        Largest distance between a marker's known position and where the scale puts it [m].
    """

    scale: float
    x0: float
    z0: float
    residual: float = 0.0

    def to_silo(self, column, row) -> tuple[np.ndarray, np.ndarray]:
        """Silo (x, z) [m] of image positions (column, row) [px]."""
        return self.x0 + self.scale * np.asarray(column, dtype=float), self.z0 - self.scale * np.asarray(row, dtype=float)

    def velocity(self, u_px, v_px, frame_rate: float) -> tuple[np.ndarray, np.ndarray]:
        """Silo velocity (u, w) [m/s] of image displacements per frame (u to the right, v down) [px/frame] at
        ``frame_rate`` [1/s]."""
        if not frame_rate > 0:
            raise ValueError(f"frame_rate must be > 0, got {frame_rate!r}")
        factor = self.scale * frame_rate
        return factor * np.asarray(u_px, dtype=float), -factor * np.asarray(v_px, dtype=float)


def scale_from_markers(image_points, silo_points, where: str = "markers") -> ImageScale:
    """The :class:`ImageScale` that best maps ``image_points`` (n x 2, column and row, px) onto ``silo_points``
    (n x 2, x and z, m).

    Raises
    ------
    ValueError
        Naming ``where``: fewer than two markers, non-finite values, or markers that do not fix a scale (all at one
        image position, or a scale that is not positive).
    """
    image = np.asarray(image_points, dtype=float)
    silo = np.asarray(silo_points, dtype=float)
    if image.ndim != 2 or image.shape[1] != 2 or silo.shape != image.shape:
        raise ValueError(f"{where}: give n x 2 image positions (column, row) and n x 2 silo positions (x, z)")
    if image.shape[0] < 2:
        raise ValueError(f"{where}: {image.shape[0]} marker(s) do not fix a scale; give two or more")
    if not (np.all(np.isfinite(image)) and np.all(np.isfinite(silo))):
        raise ValueError(f"{where}: marker positions must be finite")
    # unknowns (s, x0, z0): x = x0 + s c and z = z0 - s r, stacked into one linear least-squares problem
    n = image.shape[0]
    matrix = np.zeros((2 * n, 3))
    matrix[:n, 0], matrix[:n, 1] = image[:, 0], 1.0
    matrix[n:, 0], matrix[n:, 2] = -image[:, 1], 1.0
    rhs = np.concatenate([silo[:, 0], silo[:, 1]])
    if np.ptp(image[:, 0]) == 0.0 and np.ptp(image[:, 1]) == 0.0:
        raise ValueError(f"{where}: all markers are at one image position; they do not fix a scale")
    (scale, x0, z0), *_ = np.linalg.lstsq(matrix, rhs, rcond=None)
    if not scale > 0:
        raise ValueError(f"{where}: the markers give a scale of {scale:.4g} m/px; check that image rows point down and "
                         "that each marker's image and silo positions belong together")
    fitted = ImageScale(float(scale), float(x0), float(z0))
    x, z = fitted.to_silo(image[:, 0], image[:, 1])
    residual = float(np.max(np.hypot(x - silo[:, 0], z - silo[:, 1])))
    return ImageScale(float(scale), float(x0), float(z0), residual)


def piv_field(x, y, u, v, valid, y_down: bool, scale: ImageScale | None, frame_rate: float | None,
              time: float = 0.0) -> PlanarField:
    """The neutral field of PIV vectors (one per row; positions x, y and displacements u, v).

    With ``scale``, positions are image pixels with rows pointing down (``y_down`` must be True: rows a PIV program
    already turned up cannot be placed without the image height) and (u, v) pixels per frame at ``frame_rate``
    [1/s]; both go through the scale. Without ``scale``, positions are metres with y up (``y_down`` must be False)
    and (u, v) m/s.

    Raises
    ------
    ValueError
        For pixels without a frame rate, pixel rows pointing up, metres with y down, or nodes that do not fill a
        regular grid.
    """
    x, y, u, v = (np.asarray(a, dtype=float) for a in (x, y, u, v))
    if scale is None:
        if y_down:
            raise ValueError("PIV positions in metres must have y up (z); give the image scale for pixel files")
        return field_from_rows(x, y, u, v, valid, time)
    if frame_rate is None:
        raise ValueError("PIV displacements in pixels need the frame rate")
    if not y_down:
        raise ValueError("a pixel file with y up cannot be placed in the image; write it with image rows (y down)")
    silo_x, silo_z = scale.to_silo(x, y)
    velocity_u, velocity_w = scale.velocity(u, v, frame_rate)
    return field_from_rows(silo_x, silo_z, velocity_u, velocity_w, valid, time)
