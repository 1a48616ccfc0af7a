"""Contact diagnostics of a shear cell: mobilised friction of contacts and directions of vectors.

Pure functions on numpy arrays; no file I/O. Contact forces come already split into their normal and
tangential parts, as the engine reads them back (:class:`siloflow.model.contacts.ContactFrame`). SI units:
forces in N, lengths in m, angles in rad.
"""

from __future__ import annotations

import math

import numpy as np

from siloflow.model.checks import finite_array

__all__ = ["mobilised_friction_histogram", "angular_histogram", "mobilised_friction_by_azimuth"]


def _vectors(name: str, values) -> np.ndarray:
    array = finite_array(name, values, ndim=None)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {array.shape}")
    return array


def mobilised_friction_histogram(
    normal_force_vectors,
    tangential_force_vectors,
    bins=20,
    range: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Histogram of the mobilised friction ``|F_t| / |F_n|`` of contacts.

    The contact force is given already split into its normal and tangential
    parts, as the engine reports them for particle-particle and particle-wall
    contacts. A ratio equal to the sliding friction coefficient means a sliding
    contact.
    Contacts with ``|F_n| = 0`` (no load, ratio undefined) are left out.

    Parameters
    ----------
    normal_force_vectors : array_like, shape (n, 3)
        Normal contact forces [N].
    tangential_force_vectors : array_like, shape (n, 3)
        Tangential contact forces [N].
    bins : int or array_like, optional
        Number of equal bins (default 20) or the bin edges (increasing).
    range : tuple of float, optional
        ``(low, high)`` for integer ``bins``; default ``(0, max ratio)``
        (``(0, 1)`` if there is no loaded contact or every ratio is 0).
        Ratios outside the range are not counted; ``high`` is included in the
        last bin.

    Returns
    -------
    tuple of numpy.ndarray
        ``(bin_edges, counts)``: the edges [-] and the integer number of
        contacts per bin.
    """
    normal = _vectors("normal_force_vectors", normal_force_vectors)
    tangential = _vectors("tangential_force_vectors", tangential_force_vectors)
    if normal.shape != tangential.shape:
        raise ValueError(
            f"normal_force_vectors and tangential_force_vectors must have the same shape, "
            f"got {normal.shape} and {tangential.shape}"
        )
    normal_magnitude = np.linalg.norm(normal, axis=1)
    loaded = normal_magnitude > 0.0
    ratio = np.linalg.norm(tangential[loaded], axis=1) / normal_magnitude[loaded]

    if np.ndim(bins) == 0:
        if isinstance(bins, bool) or int(bins) != bins or bins < 1:
            raise ValueError(f"bins must be an integer >= 1 or an array of edges, got {bins!r}")
        if range is None:
            high = float(ratio.max()) if ratio.size else 0.0
            range = (0.0, high if high > 0.0 else 1.0)
        low, high = float(range[0]), float(range[1])
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise ValueError(f"range must be finite with low < high, got {range!r}")
        counts, edges = np.histogram(ratio, bins=int(bins), range=(low, high))
    else:
        edges = finite_array("bins", bins)
        if edges.size < 2 or np.any(np.diff(edges) <= 0.0):
            raise ValueError("bins must hold at least 2 strictly increasing edges")
        counts, edges = np.histogram(ratio, bins=edges)
    return edges, counts


_PLANE_AXES = {"x": (1, 2), "y": (0, 2), "z": (0, 1)}


def angular_histogram(vectors, axis: str = "y", bins: int = 36, weights=None) -> tuple[np.ndarray, np.ndarray]:
    """Histogram of the direction of vectors projected on a coordinate plane.

    Each vector is projected on the plane perpendicular to ``axis`` and the
    angle of the projection ``(u, v)`` is ``atan2(v, u)`` in ``[0, 2 pi)``, with

    * ``axis="y"``: ``(u, v) = (x, z)``: 0 along +x, pi/2 along +z, i.e.
      counter-clockwise as seen from the front (looking along +y, x to the
      right, z up), the usual view of a planar silo or a shear cell;
    * ``axis="x"``: ``(u, v) = (y, z)``;
    * ``axis="z"``: ``(u, v) = (x, y)`` (seen from above).

    Vectors whose projection is zero (parallel to ``axis``, or zero) have no
    direction and are left out. Sector ``i`` holds the angles
    ``2 pi i / bins <= angle < 2 pi (i + 1) / bins``, so a direction on an edge
    (e.g. exactly along +z) belongs to the sector that starts there. Used for polar plots of, e.g., particle angular
    velocity directions or the direction of the mobilised tangential force.

    Parameters
    ----------
    vectors : array_like, shape (n, 3)
        Vectors (any unit).
    axis : {"x", "y", "z"}, optional
        Normal of the projection plane (default "y").
    bins : int, optional
        Number of equal angular sectors over ``[0, 2 pi]`` (default 36, 10 deg).
    weights : array_like, shape (n,), optional
        Weight per vector (e.g. its magnitude); default 1 (counts).

    Returns
    -------
    tuple of numpy.ndarray
        ``(edges_rad, counts)``: ``bins + 1`` edges from 0 to 2 pi [rad] and the
        (weighted) counts per sector (integers without weights).
    """
    vectors = _vectors("vectors", vectors)
    if axis not in _PLANE_AXES:
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    if isinstance(bins, bool) or int(bins) != bins or bins < 1:
        raise ValueError(f"bins must be an integer >= 1, got {bins!r}")
    if weights is not None:
        weights = finite_array("weights", weights)
        if weights.shape != (vectors.shape[0],):
            raise ValueError(f"weights must have shape ({vectors.shape[0]},), got {weights.shape}")

    first, second = _PLANE_AXES[axis]
    u = vectors[:, first]
    v = vectors[:, second]
    has_direction = (u != 0.0) | (v != 0.0)
    bins = int(bins)
    angle = np.mod(np.arctan2(v[has_direction], u[has_direction]), 2.0 * math.pi)
    # Sector index from the fraction of a full turn: exact for the axis directions
    # (pi/2 / 2pi = 0.25 exactly), so a direction on an edge starts the next sector.
    sector = np.minimum(np.floor(angle / (2.0 * math.pi) * bins).astype(np.intp), bins - 1)
    if weights is None:
        counts = np.bincount(sector, minlength=bins)
    else:
        counts = np.bincount(sector, weights=weights[has_direction], minlength=bins)
    edges = np.linspace(0.0, 2.0 * math.pi, bins + 1)
    return edges, counts


def mobilised_friction_by_azimuth(
    contact_points, normal_force_vectors, tangential_force_vectors, bins: int = 36
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean mobilised friction |F_t| / |F_n| of wall contacts per azimuthal sector around the cell axis.

    The azimuth of a contact is the angle of its contact point about the z axis (the cell axis through
    the origin), measured from +x, the shear direction. Contacts with zero normal force are left out.

    Parameters
    ----------
    contact_points : array_like, shape (n, 3)
        Contact points on the wall (m).
    normal_force_vectors, tangential_force_vectors : array_like, shape (n, 3)
        Normal and tangential contact forces (N).
    bins : int
        Number of equal sectors over [-pi, pi).

    Returns
    -------
    edges_rad : numpy.ndarray
        (bins + 1,) sector edges (rad).
    mean_ratio : numpy.ndarray
        (bins,) mean |F_t| / |F_n| per sector (0 where a sector has no contact).
    counts : numpy.ndarray
        (bins,) contacts per sector.
    """
    points = finite_array("contact_points", contact_points, ndim=2)
    normal = np.linalg.norm(finite_array("normal_force_vectors", normal_force_vectors, ndim=2), axis=1)
    tangential = np.linalg.norm(finite_array("tangential_force_vectors", tangential_force_vectors, ndim=2), axis=1)
    if not (points.shape[0] == normal.shape[0] == tangential.shape[0]) or points.shape[1] != 3:
        raise ValueError("contact_points and the force vectors must all have shape (n, 3)")
    if int(bins) < 1:
        raise ValueError(f"bins must be a positive integer, got {bins!r}")
    loaded = normal > 0.0
    azimuth = np.arctan2(points[loaded, 1], points[loaded, 0])
    ratio = tangential[loaded] / normal[loaded]
    edges = np.linspace(-np.pi, np.pi, int(bins) + 1)
    sector = np.clip(np.digitize(azimuth, edges) - 1, 0, int(bins) - 1)
    counts = np.bincount(sector, minlength=int(bins))
    sums = np.bincount(sector, weights=ratio, minlength=int(bins))
    mean_ratio = np.divide(sums, counts, out=np.zeros(int(bins)), where=counts > 0)
    return edges, mean_ratio, counts
