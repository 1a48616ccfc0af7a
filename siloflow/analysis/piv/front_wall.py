"""What a camera behind the front wall sees of a DEM run, and how PIV of it compares with the particles' own
velocities: the spheres next to the wall, their image, their mean velocity in each PIV window, and the bias and RMS
error of a PIV field against it.

Coordinates and the image are those of :mod:`siloflow.analysis.piv.calibration` (x across, z up, y into the silo from the
front wall at y = 0; image columns right, rows down).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from siloflow.analysis.piv.calibration import ImageScale
from siloflow.analysis.piv.field import PlanarField
from siloflow.analysis.piv.synthetic import render_particle_image

__all__ = ["FieldErrors", "field_errors", "front_wall_image", "front_wall_spheres", "window_mean_velocity"]


def front_wall_spheres(position: np.ndarray, band: float, wall_y: float = 0.0) -> np.ndarray:
    """Which spheres (bool) have their centre within ``band`` [m] of the front wall (the study: one particle
    diameter), the ones a camera sees through it."""
    position = np.asarray(position, dtype=float).reshape(-1, 3)
    if not band > 0:
        raise ValueError(f"band must be > 0, got {band!r}")
    return (position[:, 1] - wall_y) <= band


def front_wall_image(position: np.ndarray, radius: np.ndarray, scale: ImageScale, shape: tuple[int, int],
                     **rendering) -> np.ndarray:
    """The image (rows x columns) of spheres at ``position`` [m] with ``radius`` [m] seen through the front wall,
    through ``scale`` (``rendering``: the levels, blur and noise of
    :func:`siloflow.analysis.piv.synthetic.render_particle_image`)."""
    position = np.asarray(position, dtype=float).reshape(-1, 3)
    columns = (position[:, 0] - scale.x0) / scale.scale
    rows = (scale.z0 - position[:, 2]) / scale.scale
    return render_particle_image(np.column_stack([columns, rows]), np.asarray(radius, dtype=float) / scale.scale,
                                 shape, **rendering)


def window_mean_velocity(position: np.ndarray, velocity: np.ndarray, x: np.ndarray, z: np.ndarray,
                         half_window: float, time: float = 0.0, min_count: int = 1) -> PlanarField:
    """The mean in-plane velocity of the spheres whose centres lie in the square window of half width
    ``half_window`` [m] about each node (x, z) [m] (windows may overlap, as PIV's do): the DEM's answer on a PIV
    grid. A node with fewer than ``min_count`` spheres is not valid."""
    position = np.asarray(position, dtype=float).reshape(-1, 3)
    velocity = np.asarray(velocity, dtype=float).reshape(-1, 3)
    x, z = np.asarray(x, dtype=float), np.asarray(z, dtype=float)
    inside_x = np.abs(position[None, :, 0] - x[:, None]) <= half_window  # (nx, n)
    inside_z = np.abs(position[None, :, 2] - z[:, None]) <= half_window  # (nz, n)
    count = inside_z.astype(float) @ inside_x.T.astype(float)  # (nz, nx)
    sums = [(inside_z * velocity[None, :, axis]) @ inside_x.T.astype(float) for axis in (0, 2)]
    valid = count >= max(1, min_count)
    with np.errstate(invalid="ignore", divide="ignore"):
        u, w = (np.where(valid, s / count, np.nan) for s in sums)
    return PlanarField(x, z, u, w, valid, time)


@dataclass(frozen=True)
class FieldErrors:
    """PIV against the truth over the nodes valid in both [m/s]: bias (mean of PIV minus truth) and RMS error of
    each component, and how many nodes they are over."""

    bias_u: float
    rms_u: float
    bias_w: float
    rms_w: float
    nodes: int


def field_errors(measured: PlanarField, truth: PlanarField) -> FieldErrors:
    """Bias and RMS error of ``measured`` against ``truth`` on the same grid.

    Raises
    ------
    ValueError
        When the grids differ or no node is valid in both.
    """
    if measured.u.shape != truth.u.shape or not (np.allclose(measured.x, truth.x) and np.allclose(measured.z, truth.z)):
        raise ValueError("the PIV field and the truth are not on the same grid")
    both = measured.valid & truth.valid
    if not both.any():
        raise ValueError("no node is valid in both the PIV field and the truth")
    du, dw = (measured.u - truth.u)[both], (measured.w - truth.w)[both]
    return FieldErrors(float(du.mean()), float(np.sqrt(np.mean(du**2))), float(dw.mean()),
                       float(np.sqrt(np.mean(dw**2))), int(both.sum()))
