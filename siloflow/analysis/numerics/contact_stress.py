"""Contact stress field from pair forces and branch vectors, coarse-grained with the kernels of
:mod:`siloflow.analysis.numerics.coarse_graining`.

``sigma_c(n) = -sum_c f_ij (x) r_ij  int_0^1 phi(x_n - x_i - s r_ij) ds / V_cell`` [Pa], compression
positive, so it adds to the kinetic stress of :func:`siloflow.analysis.numerics.coarse_graining.coarse_grain`.
The line integral along each branch is a Gauss-Legendre rule (:func:`numpy.polynomial.legendre.leggauss`)
whose points are deposited by :func:`siloflow.analysis.numerics.coarse_graining.deposit`.
"""

from __future__ import annotations

import numpy as np

from siloflow.model.checks import points3
from siloflow.analysis.numerics.coarse_graining import DEFAULT_CUTOFF, deposit
from siloflow.analysis.numerics.grid import Grid

__all__ = ["contact_stress"]


def _gauss_legendre_unit(n: int) -> tuple[np.ndarray, np.ndarray]:
    nodes, weights = np.polynomial.legendre.leggauss(n)
    return 0.5 * (nodes + 1.0), 0.5 * weights


def contact_stress(
    grid: Grid,
    contact_positions_i,
    contact_positions_j,
    forces_ij,
    width: float,
    cutoff: float = DEFAULT_CUTOFF,
    kernel: str = "gaussian",
    n_quadrature: int = 3,
    backend: str = "auto",
) -> np.ndarray:
    """Contact stress field from pair forces and branch vectors, compression positive.

    ``sigma_c(n) = -sum_c f_ij (x) r_ij  int_0^1 phi(x_n - x_i - s r_ij) ds / V_cell``

    with ``r_ij = x_j - x_i`` the branch vector from particle i to particle j and ``f_ij``
    the force **on i exerted by j**. A repulsive (compressive) contact has ``f_ij`` pointing
    away from j towards i, against ``r_ij``, so ``-f_ij (x) r_ij`` has a positive trace: compression is
    positive. (Goldhirsch's tension-positive form is ``+1/2 sum_ij f_ij (x) r_ij ...`` over
    ordered pairs with ``r_ij = x_i - x_j``; here each contact is listed once.)

    Parameters
    ----------
    grid : Grid
        Target grid.
    contact_positions_i, contact_positions_j : array_like, shape (c, 3)
        Centres of the two particles of each contact [m] (for clumps: the centres of the
        touching spheres, or the clump centres for a clump-level branch).
    forces_ij : array_like, shape (c, 3)
        Force on particle i by particle j [N].
    width : float
        Kernel standard deviation w [m].
    cutoff : float, optional
        Gaussian cut-off in units of w (default 3).
    kernel : {"gaussian", "gaussian_shifted", "lucy"}, optional
        Kernel.
    n_quadrature : int, optional
        Gauss-Legendre points along each branch (default 3, exact for the part of the
        kernel that is a polynomial of degree 5 along the branch; branches are about one
        particle diameter, shorter than the kernel support, so 3 points are ample).
    backend : {"auto", "numba", "numpy"}, optional
        Compiled loop or numpy fallback.

    Returns
    -------
    numpy.ndarray, shape (nx, ny, nz, 3, 3)
        Contact stress [Pa]; ``[..., a, b] = -sum f_a r_b ...``. Not symmetric in general
        (tangential forces); symmetrise if needed.

    Notes
    -----
    The line integral is evaluated with ``n_quadrature`` points ``x_i + s_q r_ij`` and weights
    ``omega_q`` (summing to 1); each point is deposited with the discretely normalised kernel,
    so ``sum(sigma_c) * V_cell = -sum_c f_ij (x) r_ij`` exactly for contacts inside the box.
    Quadrature points outside the grid box are dropped (their share of the branch is lost),
    e.g. contacts across the outlet plane.
    """
    if not isinstance(grid, Grid):
        raise ValueError(f"grid must be a Grid, got {type(grid).__name__}")
    first = points3("contact_positions_i", contact_positions_i)
    second = points3("contact_positions_j", contact_positions_j)
    forces = points3("forces_ij", forces_ij)
    if second.shape != first.shape or forces.shape != first.shape:
        raise ValueError(
            "contact_positions_i, contact_positions_j and forces_ij must have the same shape, got "
            f"{first.shape}, {second.shape} and {forces.shape}"
        )
    if isinstance(n_quadrature, bool) or int(n_quadrature) != n_quadrature or n_quadrature < 1:
        raise ValueError(f"n_quadrature must be an integer >= 1, got {n_quadrature!r}")
    n_quadrature = int(n_quadrature)

    branch = second - first
    tensor = -(forces[:, :, None] * branch[:, None, :]).reshape(-1, 9)
    s, omega = _gauss_legendre_unit(n_quadrature)
    points = (first[None, :, :] + s[:, None, None] * branch[None, :, :]).reshape(-1, 3)
    values = (omega[:, None, None] * tensor[None, :, :]).reshape(-1, 9)
    sums = deposit(points, values, grid, width, cutoff, kernel, backend)
    return sums.reshape(grid.shape + (3, 3)) / grid.cell_volume
