"""Virtual tracers seeded on a regular lattice filling a box region (the start points of pathlines).

Pure computation on numpy arrays; SI units (m). The seeds feed
:func:`siloflow.analysis.numerics.pathlines.integrate_pathlines`.
"""

from __future__ import annotations

import numpy as np

from siloflow.model.checks import vector3

__all__ = ["lattice_seeds"]


def lattice_seeds(region_lower, region_upper, count=None, spacing=None) -> np.ndarray:
    """Virtual tracers on a regular lattice filling a box region (e.g. an inlet bin).

    The region is split into ``n_x x n_y x n_z`` equal cells and a tracer is put at each cell
    centre ``lower + (i + 0.5) (upper - lower) / n`` per axis. A flat axis (``upper == lower``)
    gets one tracer at that coordinate.

    Parameters
    ----------
    region_lower, region_upper : array_like, shape (3,)
        Opposite corners of the region, ``upper >= lower`` per axis [m].
    count : int or array_like of 3 int, optional
        Three ints: tracers per axis (exact). One int ``N``: an approximately cubic lattice with
        about ``N`` tracers, ``n_a = max(1, round(L_a / h))`` with ``h = (prod L / N)^(1/d)`` over the
        ``d`` non-flat axes (the product is close to ``N`` but not always equal; pass three ints
        for an exact count, e.g. from bulk density and tracer volume).
    spacing : float or array_like of 3 float, optional
        Wanted lattice spacing [m]: ``n_a = max(1, round(L_a / spacing_a))``. Give exactly one of
        ``count`` and ``spacing``.

    Returns
    -------
    numpy.ndarray, shape (n_x n_y n_z, 3)
        Positions [m], x index slowest and z fastest.
    """
    lower = vector3("region_lower", region_lower, positive=False, scalar_to_all=True)
    upper = vector3("region_upper", region_upper, positive=False, scalar_to_all=True)
    if np.any(upper < lower):
        raise ValueError(f"region_upper must be >= region_lower per axis, got {lower.tolist()} and {upper.tolist()}")
    if (count is None) == (spacing is None):
        raise ValueError("give exactly one of count and spacing")
    lengths = upper - lower
    flat = lengths == 0.0
    if count is not None:
        counts = np.asarray(count)
        if counts.ndim == 0:
            if isinstance(count, (bool, np.bool_)) or not np.issubdtype(counts.dtype, np.number) or int(count) != count or int(count) < 1:
                raise ValueError(f"count must be an integer >= 1 or 3 integers >= 1, got {count!r}")
            total = int(count)
            dims = int(np.count_nonzero(~flat))
            per_axis = np.ones(3, dtype=np.int64)
            if dims:
                h = (float(np.prod(lengths[~flat])) / total) ** (1.0 / dims)
                per_axis[~flat] = np.maximum(1, np.round(lengths[~flat] / h)).astype(np.int64)
        else:
            if counts.shape != (3,) or counts.dtype == bool or not np.issubdtype(counts.dtype, np.number) or np.any(counts != np.round(counts)) or np.any(counts < 1):
                raise ValueError(f"count must be an integer >= 1 or 3 integers >= 1, got {count!r}")
            per_axis = counts.astype(np.int64)
            if np.any(per_axis[flat] != 1):
                raise ValueError("count must be 1 along a flat axis of the region (upper == lower)")
    else:
        step = vector3("spacing", spacing, positive=True, scalar_to_all=True)
        per_axis = np.maximum(1, np.round(lengths / step)).astype(np.int64)
    axes = [lower[a] + (np.arange(per_axis[a]) + 0.5) * lengths[a] / per_axis[a] for a in range(3)]
    grids = np.meshgrid(*axes, indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1)
