"""Synthetic PIV: images of the particles at the front wall rendered from DEM, and PIV run on them with OpenPIV.

Rendering follows the study (thesis ch. 3): the particles seen through the front wall in one colour on grey
voids. Each particle is a disc, its edge anti-aliased by the fraction of a pixel it covers (``radius + 0.5 - d``,
clipped to [0, 1], with d the pixel centre's distance from the disc centre), then optionally blurred (Gaussian,
``scipy.ndimage``) and given Gaussian noise. Image axes: column c to the right, row r down, pixel (c, r) covers
[c - 0.5, c + 0.5] x [r - 0.5, r + 0.5].

PIV is OpenPIV's multipass with window deformation (``openpiv.windef``): each pass halves the window of the one
before it, ending at ``window_px`` with ``overlap_px``; :func:`piv_displacements` returns its vectors in image axes
(rows down, v positive down), undoing the flip OpenPIV's ``simple_multipass`` applies.
"""

from __future__ import annotations

import numpy as np
from openpiv import windef
from scipy.ndimage import gaussian_filter

__all__ = ["piv_displacements", "render_particle_image"]


def render_particle_image(centres_px, radii_px, shape: tuple[int, int], void_level: float = 0.5,
                          particle_level: float = 1.0, blur_px: float = 0.0, noise: float = 0.0,
                          rng: np.random.Generator | None = None) -> np.ndarray:
    """A grey image (float, rows x columns) of discs at ``centres_px`` (n x 2: column, row) with ``radii_px``.

    Raises
    ------
    ValueError
        For a shape that is not two positive sizes, centres that are not n x 2 and finite, or radii not positive.
    """
    rows, columns = (int(v) for v in shape)
    if rows < 1 or columns < 1:
        raise ValueError(f"image shape must be two positive sizes, got {shape!r}")
    centres = np.asarray(centres_px, dtype=float).reshape(-1, 2)
    radii = np.broadcast_to(np.asarray(radii_px, dtype=float), (centres.shape[0],))
    if not np.all(np.isfinite(centres)) or np.any(~(radii > 0)):
        raise ValueError("particle centres must be finite and radii positive")
    coverage = np.zeros((rows, columns))
    for (c, r), radius in zip(centres, radii):
        c0, c1 = max(0, int(np.floor(c - radius - 1))), min(columns, int(np.ceil(c + radius + 2)))
        r0, r1 = max(0, int(np.floor(r - radius - 1))), min(rows, int(np.ceil(r + radius + 2)))
        if c0 >= c1 or r0 >= r1:
            continue
        cc, rr = np.meshgrid(np.arange(c0, c1), np.arange(r0, r1))
        patch = np.clip(radius + 0.5 - np.hypot(cc - c, rr - r), 0.0, 1.0)
        np.maximum(coverage[r0:r1, c0:c1], patch, out=coverage[r0:r1, c0:c1])
    image = void_level + (particle_level - void_level) * coverage
    if blur_px > 0:
        image = gaussian_filter(image, blur_px)
    if noise > 0:
        image = image + (rng or np.random.default_rng(0)).normal(0.0, noise, image.shape)
    return image


def piv_displacements(frame_a: np.ndarray, frame_b: np.ndarray, window_px: int = 40, overlap_px: int = 20,
                      passes: int = 2) -> tuple[np.ndarray, ...]:
    """Displacements from ``frame_a`` to ``frame_b`` by OpenPIV's multipass (module docstring).

    Returns
    -------
    x, y, u, v : numpy.ndarray, shape (rows, columns) of the vector grid
        Window centres (column, row) [px] and displacements (right, down) [px per frame pair].
    valid : numpy.ndarray of bool
        False where OpenPIV's validation replaced the vector.

    Raises
    ------
    ValueError
        For frames of different shapes, a window or overlap that does not fit, fewer than one pass, or when OpenPIV
        finds no valid vector.
    """
    if frame_a.shape != frame_b.shape or frame_a.ndim != 2:
        raise ValueError(f"frames must be two 2-D images of one shape, got {frame_a.shape} and {frame_b.shape}")
    first_window, first_overlap = window_px * 2 ** max(passes - 1, 0), overlap_px * 2 ** max(passes - 1, 0)
    # window deformation interpolates the first pass's vectors with cubic splines: at least 4 vectors per axis
    vectors = min((size - first_window) // max(first_window - first_overlap, 1) + 1 for size in frame_a.shape)
    if passes < 1 or not 0 <= overlap_px < window_px or vectors < (4 if passes > 1 else 1):
        raise ValueError(f"window {window_px} px, overlap {overlap_px} px and {passes} passes do not fit images of "
                         f"{frame_a.shape[1]} x {frame_a.shape[0]} px (the first pass needs 4 windows per axis)")
    settings = windef.PIVSettings()
    settings.windowsizes = tuple(window_px * 2 ** k for k in range(passes - 1, -1, -1))
    settings.overlap = tuple(overlap_px * 2 ** k for k in range(passes - 1, -1, -1))
    settings.num_iterations = passes  # OpenPIV runs 3 passes unless told, whatever windowsizes says
    settings.show_plot = settings.save_plot = False
    # OpenPIV 0.26's vectorised correlation raises "too many values to unpack" on some frames of a silo's front wall
    # (pyprocess.vectorized_correlation_to_displacements, first pass); the loop over windows does not
    settings.use_vectorized = False
    try:
        x, y, u, v, flags = windef.simple_multipass(np.asarray(frame_a, dtype=float),
                                                    np.asarray(frame_b, dtype=float), settings)
    except ValueError as error:
        # OpenPIV raises "Something happened in the validation" when every vector of a pass failed it
        raise ValueError(f"OpenPIV found no valid vector ({error}): the {window_px} px windows hold too little "
                         "texture (too few particle edges) or the displacement exceeds them") from None
    # simple_multipass turned rows up and negated v (transform_coordinates); turn them back to image axes
    x, y, u, v = windef.transform_coordinates(x, y, u, v)
    valid = np.asarray(flags, dtype=int) == 0
    return x, y, u, v, valid
