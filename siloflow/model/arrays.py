"""Read-only array fields of the neutral data types, checked for shape on construction."""

from __future__ import annotations

import numpy as np

__all__ = ["frozen_array"]


def frozen_array(value, dtype, shape_tail: tuple[int, ...], name: str, n: int | None) -> np.ndarray:
    """A read-only copy of ``value`` as ``dtype`` with shape ``(n, *shape_tail)`` (any n when ``n`` is None).

    Raises
    ------
    ValueError
        Naming the field ``name`` and the shapes, when the shape differs.
    """
    array = np.array(value, dtype=dtype)  # a copy the object owns
    expected_ndim = 1 + len(shape_tail)
    if array.ndim != expected_ndim or array.shape[1:] != shape_tail or (n is not None and array.shape[0] != n):
        expected = ("n" if n is None else str(n),) + tuple(str(s) for s in shape_tail)
        raise ValueError(f"{name} must have shape ({', '.join(expected)}), got {array.shape}")
    array.setflags(write=False)
    return array
