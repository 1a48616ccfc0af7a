"""What the PIV readers share: the error that names a file and its problem, and what a program's row order says about
its axes.

PIV programs write their vector grid in a fixed order: OpenPIV row by row from the image's top row, x fastest
(``numpy.ravel`` of its 2-D arrays), PIVlab column by column from the image's left column, y fastest (MATLAB's
``reshape`` of its 2-D arrays). Each program computes its grid in image order (columns to the right, rows down), so
the step of y from the first grid line to the second says whether the file's y points down the image or up, and the
step of x whether x points right or left, whatever units and offsets the program applied.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["PivFormatError", "axis_steps", "finite_positions"]


class PivFormatError(ValueError):
    """A PIV file does not follow its documented layout, or says something siloflow cannot use; the message names the
    file and the problem."""


def finite_positions(path: Path, x: np.ndarray, y: np.ndarray) -> None:
    """Refuse vectors without a finite position.

    Raises
    ------
    PivFormatError
        Naming ``path``, the number of such vectors and the first one's row (from 1).
    """
    bad = ~(np.isfinite(x) & np.isfinite(y))
    if bad.any():
        raise PivFormatError(f"{path}: {int(bad.sum())} vector(s) without a finite position (first at row "
                             f"{int(np.argmax(bad)) + 1})")


def axis_steps(x: np.ndarray, y: np.ndarray, x_fastest: bool) -> tuple[float | None, float | None]:
    """The steps (dx, dy) [file units] from the first grid line to the next, along the image's columns (x) and rows
    (y), of vectors written in grid order; None along an axis with a single grid line.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (n,)
        Positions in the order of the file.
    x_fastest : bool
        True when x changes fastest (OpenPIV: a grid row after the other), False when y does (PIVlab: a grid column
        after the other).

    Examples
    --------
    >>> axis_steps(np.array([16.0, 48.0, 16.0, 48.0]), np.array([16.0, 16.0, 48.0, 48.0]), x_fastest=True)
    (32.0, 32.0)
    """
    fast, slow = (x, y) if x_fastest else (y, x)
    run = int(np.argmax(slow != slow[0])) if np.any(slow != slow[0]) else slow.size
    fast_step = float(fast[1] - fast[0]) if run > 1 else None
    slow_step = float(slow[run] - slow[0]) if run < slow.size else None
    return (fast_step, slow_step) if x_fastest else (slow_step, fast_step)
