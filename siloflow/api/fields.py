"""Continuum fields of a silo run: its particles coarse-grained onto a grid, averaged over time and depth, and the
velocity profiles across the width at chosen heights.

Coordinates as everywhere in siloflow: x across the width (0 on the axis), y front to back (0 at the front wall),
z up (0 at the outlet plane); a vertical velocity is negative downwards. SI units.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from siloflow.model.frames import ClumpFrame, ParticleFrame, clumps_from_frame
from siloflow.analysis.numerics.coarse_graining import DEFAULT_CUTOFF
from siloflow.analysis.numerics.coarse_graining import coarse_grain as coarse_grain_particles
from siloflow.analysis.numerics.field_ops import average_fields, depth_average
from siloflow.analysis.numerics.grid import DEFAULT_SPACING, Fields, Grid
from siloflow.analysis.numerics.profiles import VelocityProfile, velocity_profile
from siloflow.analysis.studies.silo_flat.field_study import SiloDimensions
from siloflow.analysis.studies.silo_flat.fields import silo_grid as grid_of_silo
from siloflow.analysis.studies.silo_flat.fields import time_average as average_in_window

__all__ = ["coarse_grain", "silo_grid", "time_average", "velocity_profiles"]


def silo_grid(dimensions: SiloDimensions, top: float, spacing=DEFAULT_SPACING) -> Grid:
    """A grid whose cells tile the silo's interior ``[-W/2, W/2] x [0, T] x [0, top]``.

    Parameters
    ----------
    dimensions : SiloDimensions
        The silo: its width W and depth T [m].
    top : float
        Height the grid reaches at least [m] (e.g. the highest point of the fill surface); rounded up to whole
        cells.
    spacing : sequence of 3 float, optional
        Cell size (dx, dy, dz) [m], the study's (6, 4, 6) mm by default; dx and dy are stretched slightly where W or
        T is not a whole number of cells.

    Returns
    -------
    Grid

    Examples
    --------
    >>> dimensions = SiloDimensions(width=0.06, depth=0.012, outlet_width=0.02, particle_radius=0.0015,
    ...                             clump_mass=2e-5)
    >>> grid = silo_grid(dimensions, top=0.04)
    >>> grid.shape, round(float(grid.x[0]), 6), round(float(grid.z[-1]), 6)
    ((10, 3, 7), -0.027, 0.039)
    """
    return grid_of_silo(dimensions.width, dimensions.depth, top, spacing)


def coarse_grain(frames: Sequence[ParticleFrame | ClumpFrame], grid: Grid, width: float,
                 cutoff: float = DEFAULT_CUTOFF, kernel: str = "gaussian") -> list[Fields]:
    """Density [kg/m3], velocity [m/s] and kinetic stress [Pa] of each frame's clumps on a grid.

    Each frame's spheres are grouped into clumps (their centre of mass and velocity, their mass once per clump,
    :func:`siloflow.model.frames.clumps_from_frame`) and deposited with a kernel
    (:func:`siloflow.analysis.numerics.coarse_graining.coarse_grain`); clumps outside the grid's box (below the outlet
    plane, discharged) are left out.

    Parameters
    ----------
    frames : sequence of ParticleFrame or ClumpFrame
        The frames, e.g. :meth:`Run.frames` or :meth:`Run.clumps` since the opening.
    grid : Grid
        The grid (:func:`silo_grid`).
    width : float
        Kernel width, its standard deviation w [m]; the study's is 3 particle radii
        (:func:`siloflow.analysis.numerics.coarse_graining.default_width`).
    cutoff : float, optional
        Gaussian cut-off in kernel widths [-] (default 3).
    kernel : {"gaussian", "gaussian_shifted", "lucy"}, optional
        The kernel.

    Returns
    -------
    list of Fields
        One per frame, in order.

    Examples
    --------
    A 4 mm lattice of 1 g clumps filling a 24 x 8 x 24 mm box, all falling at 0.1 m/s: the coarse-grained
    velocity is theirs at every node, and the mass is conserved on the grid.

    >>> import numpy as np
    >>> from siloflow.model.frames import ClumpFrame
    >>> from siloflow.analysis.numerics.grid import Grid
    >>> grid = Grid(origin=(-0.012, 0.0, 0.0), spacing=(0.006, 0.004, 0.006), shape=(4, 2, 4))
    >>> lattice = np.stack(np.meshgrid(-0.01 + 0.004 * np.arange(6), [0.002, 0.006], 0.002 + 0.004 * np.arange(6),
    ...                                indexing="ij"), axis=-1).reshape(-1, 3)
    >>> n = len(lattice)
    >>> frame = ClumpFrame(time=0.0, step=0, clump_id=np.arange(n), position=lattice,
    ...                    velocity=np.tile([0.0, 0.0, -0.1], (n, 1)), mass=np.full(n, 1e-3), n_spheres=np.ones(n))
    >>> (fields,) = coarse_grain([frame], grid, width=0.003)
    >>> bool(np.allclose(fields.velocity[..., 2], -0.1)), round(fields.total_mass, 12), round(n * 1e-3, 12)
    (True, 0.072, 0.072)
    """
    fields = []
    for frame in frames:
        clumps = frame if isinstance(frame, ClumpFrame) else clumps_from_frame(frame)
        fields.append(coarse_grain_particles(clumps.position, clumps.mass, clumps.velocity, grid, width,
                                             cutoff=cutoff, kernel=kernel))
    return fields


def time_average(fields: Sequence[Fields], times=None, window: tuple[float, float] | None = None) -> Fields:
    """The mass-weighted time average of a series of fields (momentum averaged, velocity = momentum / density).

    Parameters
    ----------
    fields : sequence of Fields
        The fields, on one grid.
    times : array_like, shape (n,), optional
        The time of each field [s]; with ``window``, only the fields with ``window[0] <= t <= window[1]`` are
        averaged.
    window : tuple of float, optional
        The averaging window [s], e.g. the steady discharge's ``(fit.t_start, fit.t_end)`` of :func:`discharge`
        (times since the opening); default every field.

    Returns
    -------
    Fields

    Raises
    ------
    ValueError
        When no field lies in the window, or ``window`` is given without ``times``.

    Examples
    --------
    >>> import numpy as np
    >>> from siloflow.analysis.numerics.grid import Fields, Grid
    >>> grid = Grid(origin=(0, 0, 0), spacing=(0.01, 0.01, 0.01), shape=(1, 1, 1))
    >>> def field(rho, v):
    ...     return Fields.from_moments(grid, [[[rho]]], [[[[0, 0, rho * v]]]], np.zeros((1, 1, 1, 3, 3)))
    >>> series = [field(500.0, -0.1), field(600.0, -0.2), field(700.0, -0.5)]
    >>> averaged = time_average(series, times=[0.0, 0.1, 0.2], window=(0.0, 0.1))
    >>> float(averaged.density[0, 0, 0]), round(float(averaged.velocity[0, 0, 0, 2]), 12)
    (550.0, -0.154545454545)
    """
    if window is None:
        return average_fields(list(fields))
    if times is None:
        raise ValueError("an averaging window needs the fields' times")
    return average_in_window(list(fields), np.asarray(times, dtype=float), tuple(window))


def velocity_profiles(fields: Fields, heights: Sequence[float], method: str = "linear") -> list[VelocityProfile]:
    """Profiles of the depth-averaged velocity across the width, ``v_z(x)`` and ``v_x(x)`` [m/s], at each height.

    Parameters
    ----------
    fields : Fields
        Fields on a grid (e.g. a :func:`time_average`); averaged over the depth first when they have more than one
        node layer in y.
    heights : sequence of float
        Heights above the outlet plane [m], within the grid's node rows.
    method : {"linear", "nearest"}, optional
        Interpolate linearly between the node rows that bracket a height (default), or take the nearest row.

    Returns
    -------
    list of VelocityProfile
        One per height: ``z`` [m], node positions ``x`` [m], ``v_x`` and ``v_z`` [m/s] (negative downwards).

    Examples
    --------
    A velocity field falling fastest on the axis, ``v_z = -0.1 (1 - (x / 0.03)^2)`` m/s:

    >>> import numpy as np
    >>> from siloflow.analysis.numerics.grid import Fields, Grid
    >>> grid = Grid(origin=(-0.03, 0.0, 0.0), spacing=(0.01, 0.01, 0.01), shape=(6, 2, 3))
    >>> v_z = -0.1 * (1.0 - (grid.x / 0.03) ** 2)
    >>> momentum = np.zeros(grid.shape + (3,))
    >>> momentum[..., 2] = 600.0 * v_z[:, None, None]
    >>> fields = Fields.from_moments(grid, np.full(grid.shape, 600.0), momentum, np.zeros(grid.shape + (3, 3)))
    >>> (profile,) = velocity_profiles(fields, [0.02])
    >>> profile.x.round(3).tolist()
    [-0.025, -0.015, -0.005, 0.005, 0.015, 0.025]
    >>> profile.v_z.round(6).tolist()
    [-0.030556, -0.075, -0.097222, -0.097222, -0.075, -0.030556]
    """
    plane = depth_average(fields) if fields.grid.shape[1] > 1 else fields
    return [velocity_profile(plane, height, method=method) for height in heights]
