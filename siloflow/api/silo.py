"""A silo run's dimensions, its fill surface and its discharge: the numbers the fields, profiles and Janssen's
comparison of a flat-bottom silo start from.

Coordinates as everywhere in siloflow: x across the width (0 on the axis), y front to back (0 at the front wall),
z up (0 at the outlet plane). SI units.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from siloflow.model.frames import ClumpFrame
from siloflow.analysis.studies.silo_flat.field_study import SiloDimensions, fill_surface_heights
from siloflow.analysis.studies.silo_flat.metrics import SiloFlowMetrics, silo_flow_metrics
from siloflow.api.runs import Run

__all__ = ["discharge", "fill_surface", "silo_dimensions"]


def silo_dimensions(run: Run) -> SiloDimensions:
    """The dimensions of a silo-type run (flat-bottom silo, recirculating silo, blender) from its case summary.

    Parameters
    ----------
    run : Run
        An open run (:func:`siloflow.open_run`).

    Returns
    -------
    SiloDimensions
        Width W, depth T and outlet width [m], the particle's volume-equivalent radius [m] and mass [kg].

    Raises
    ------
    KeyError
        For a run that is no silo (a Jenike cell).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> run = SimpleNamespace(case={"width_m": 0.15, "depth_m": 0.012, "outlet_width_m": 0.04,
    ...                             "equivalent_diameter_m": 0.004, "clump_mass_kg": 3e-5})
    >>> silo_dimensions(run)
    SiloDimensions(width=0.15, depth=0.012, outlet_width=0.04, particle_radius=0.002, clump_mass=3e-05)
    """
    return SiloDimensions.from_summary(run.case)


def fill_surface(settled: ClumpFrame, dimensions: SiloDimensions) -> np.ndarray:
    """Height of the fill surface [m] in columns across the width: the highest particle top ``z + r`` in each
    column of four particle diameters (NaN for an empty column).

    Parameters
    ----------
    settled : ClumpFrame
        The settled fill, e.g. the first of :meth:`Run.clumps` since the opening.
    dimensions : SiloDimensions
        The silo (its width [m] and particle radius [m]).

    Returns
    -------
    numpy.ndarray, shape (n_columns,)
        Surface heights [m], from the left wall (x = -W/2) to the right.

    Examples
    --------
    Two clumps of radius 2 mm, one in each half of a 32 mm wide silo:

    >>> from siloflow.model.frames import ClumpFrame
    >>> dimensions = SiloDimensions(width=0.032, depth=0.01, outlet_width=0.01, particle_radius=0.002,
    ...                             clump_mass=1e-5)
    >>> fill = ClumpFrame(time=0.0, step=0, clump_id=[1, 2], position=[[-0.008, 0.005, 0.05], [0.008, 0.005, 0.03]],
    ...                   velocity=[[0, 0, 0]] * 2, mass=[1e-5] * 2, n_spheres=[1, 1])
    >>> fill_surface(fill, dimensions).round(6).tolist()
    [0.052, 0.032]
    """
    return fill_surface_heights(settled, dimensions.particle_radius, dimensions.width)


def discharge(clumps: Sequence[ClumpFrame], dimensions: SiloDimensions, steady_window: tuple[float, float] = (0.2, 0.8),
              discharge_coefficient: float = 0.58, shape_coefficient: float = 1.5) -> SiloFlowMetrics:
    """Filling bulk density, discharged mass against time, the steady mass flow rate and Beverloo's prediction of a
    flat-bottom silo's discharge.

    Parameters
    ----------
    clumps : sequence of ClumpFrame
        The clumps of each frame from the outlet's opening on (:meth:`Run.clumps` with ``since_opening``); the
        first is the settled fill.
    dimensions : SiloDimensions
        The silo: width, depth and outlet width [m], particle radius [m].
    steady_window : tuple of float, optional
        Fractions of the finally discharged mass that bound the window the steady rate is fitted over (-); the
        study's (0.2, 0.8) by default.
    discharge_coefficient, shape_coefficient : float, optional
        Beverloo's C and k (-); the study's 0.58 and 1.5 by default.

    Returns
    -------
    SiloFlowMetrics
        ``bulk_density.density`` [kg/m3], ``history`` (discharged mass [kg] against time since the opening [s]),
        ``fit.mass_flow_rate`` [kg/s] over ``fit.t_start``-``fit.t_end`` [s], ``beverloo_rate`` [kg/s], and their
        standard errors.

    Raises
    ------
    siloflow.analysis.studies.silo_flat.metrics.EscapedParticles
        When clumps vanished from above the outlet plane (through a wall).
    ValueError
        With fewer than two frames, or when nothing was discharged.

    Examples
    --------
    A 40 mm wide silo holding 4 layers of 10 clumps of 20 mg, 4 mm apart; one clump leaves through the outlet
    every 10 ms, the lowest first, a steady 2 g/s:

    >>> import numpy as np
    >>> from siloflow.model.frames import ClumpFrame
    >>> dimensions = SiloDimensions(width=0.04, depth=0.012, outlet_width=0.012, particle_radius=0.002,
    ...                             clump_mass=2e-5)
    >>> x, z = np.meshgrid(-0.018 + 0.004 * np.arange(10), 0.002 + 0.004 * np.arange(4))
    >>> settled = np.column_stack([x.ravel(), np.full(40, 0.006), z.ravel()])
    >>> def frame(k):
    ...     position = settled.copy()
    ...     position[:k, 2] = -0.05  # below the outlet plane
    ...     return ClumpFrame(time=0.01 * k, step=k, clump_id=np.arange(40), position=position,
    ...                       velocity=np.zeros((40, 3)), mass=np.full(40, 2e-5), n_spheres=np.ones(40))
    >>> metrics = discharge([frame(k) for k in range(21)], dimensions)
    >>> round(metrics.fit.mass_flow_rate, 9), round(float(metrics.history.discharged_mass[-1]), 9)
    (0.002, 0.0004)
    """
    return silo_flow_metrics(list(clumps), dimensions.width, dimensions.depth, dimensions.outlet_width,
                             2.0 * dimensions.particle_radius, steady_window=tuple(steady_window),
                             discharge_coefficient=discharge_coefficient, shape_coefficient=shape_coefficient)
