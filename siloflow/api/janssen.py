"""Janssen's comparison of a silo run: the mean vertical contact stress of its settled fill against depth, beside
Janssen's formula and the hydrostatic stress.

SI units: m, kg/m3, Pa; friction angles in degrees. Stress is compression positive.
"""

from __future__ import annotations

import math

from siloflow.model.contacts import ContactFrame
from siloflow.analysis.numerics.coarse_graining import DEFAULT_CUTOFF
from siloflow.analysis.numerics.grid import Grid
from siloflow.analysis.studies.silo_flat.field_study import SiloDimensions
from siloflow.analysis.studies.silo_flat.fields import FieldSettings, JanssenComparison, janssen_from_contacts

__all__ = ["janssen_comparison"]


def janssen_comparison(contacts: ContactFrame, grid: Grid, dimensions: SiloDimensions, surface_height: float,
                       bulk_density: float, kernel_width: float, internal_friction_angle_deg: float,
                       side_wall_friction_angle_deg: float, front_wall_friction_angle_deg: float,
                       cutoff: float = DEFAULT_CUTOFF, kernel: str = "gaussian",
                       bulk_density_error: float = math.nan) -> JanssenComparison:
    """The settled fill's mean vertical contact stress per grid row against Janssen's formula and hydrostatic.

    The contacts are coarse-grained into a stress field on the grid with the kernel of the velocity fields, and
    averaged over each row's cross-section (:func:`siloflow.analysis.studies.silo_flat.fields.janssen_from_contacts`); rows
    within the kernel's reach (``cutoff`` widths) of the floor or the surface are left out. Janssen's stress is
    ``sigma_v(h) = rho_b g z_c (1 - exp(-h / z_c))`` with ``z_c = W T / (2 K (T mu_side + W mu_front))``,
    ``K = (1 - sin phi) / (1 + sin phi)`` and ``mu = tan`` of the wall friction angles
    (:func:`siloflow.analysis.numerics.janssen.janssen_vertical_stress`).

    Parameters
    ----------
    contacts : ContactFrame
        Pair contacts of the settled fill (:meth:`Run.contacts`: the last before the opening).
    grid : Grid
        Grid tiling the silo (:func:`siloflow.silo_grid`).
    dimensions : SiloDimensions
        The silo's width W and depth T [m].
    surface_height : float
        Height H of the fill surface the depths ``h = H - z`` are measured from [m]; the study takes the lowest
        point of :func:`siloflow.fill_surface`.
    bulk_density : float
        Bulk density of the fill rho_b [kg/m3] (:func:`siloflow.discharge`'s ``bulk_density.density``).
    kernel_width : float
        Kernel width w [m] (that of :func:`siloflow.coarse_grain`).
    internal_friction_angle_deg : float
        Bulk internal friction angle phi [deg].
    side_wall_friction_angle_deg, front_wall_friction_angle_deg : float
        Bulk wall friction angles of the side walls and of the front and back walls [deg] (the calibration's bulk
        values, not the particle-wall ones).
    cutoff : float, optional
        Gaussian cut-off in kernel widths [-] (default 3).
    kernel : {"gaussian", "gaussian_shifted", "lucy"}, optional
        The kernel.
    bulk_density_error : float, optional
        Standard error of ``bulk_density`` [kg/m3], for the hydrostatic stress's error; NaN (default): unknown.

    Returns
    -------
    JanssenComparison
        Per row: ``depth_below_surface`` h and ``height`` z [m], the DEM's ``simulated`` stress with its
        ``simulated_error``, ``janssen`` and ``hydrostatic`` (``rho_b g h``) [Pa].

    Raises
    ------
    ValueError
        When no grid row lies inside the fill beyond the kernel's reach of the floor and of the surface.

    Examples
    --------
    Janssen's curve does not depend on the contacts; here a single unloaded contact in a 60 x 12 mm silo filled
    to 60 mm, at rho_b = 600 kg/m3, phi = 30 deg and both wall friction angles 10 deg:

    >>> import numpy as np
    >>> from siloflow.model.contacts import ContactFrame
    >>> from siloflow.analysis.numerics.grid import Grid
    >>> from siloflow.analysis.numerics.janssen import janssen_vertical_stress
    >>> dimensions = SiloDimensions(width=0.06, depth=0.012, outlet_width=0.02, particle_radius=0.0015,
    ...                             clump_mass=2e-5)
    >>> grid = Grid.covering((-0.03, 0.0, 0.0), (0.03, 0.012, 0.06), spacing=(0.006, 0.004, 0.006))
    >>> contact = ContactFrame(step=0, position_i=np.array([[0.0, 0.006, 0.03]]),
    ...                        position_j=np.array([[0.0, 0.006, 0.033]]), id_i=np.array([1]), id_j=np.array([2]),
    ...                        force=np.zeros((1, 3)))
    >>> comparison = janssen_comparison(contact, grid, dimensions, surface_height=0.06, bulk_density=600.0,
    ...                                 kernel_width=0.002, internal_friction_angle_deg=30.0,
    ...                                 side_wall_friction_angle_deg=10.0, front_wall_friction_angle_deg=10.0)
    >>> comparison.height.round(3).tolist()
    [0.009, 0.015, 0.021, 0.027, 0.033, 0.039, 0.045, 0.051]
    >>> expected = janssen_vertical_stress(comparison.depth_below_surface, 600.0, 0.06, 0.012,
    ...                                    np.tan(np.radians(10.0)), np.tan(np.radians(10.0)), 30.0)
    >>> bool(np.allclose(comparison.janssen, expected)), float(comparison.simulated.max())
    (True, 0.0)
    """
    settings = FieldSettings(spacing=grid.spacing, kernel=kernel, width=kernel_width, cutoff=cutoff)
    _, comparison = janssen_from_contacts(
        contacts, grid, settings, surface_height, bulk_density, dimensions.width, dimensions.depth,
        internal_friction_angle_deg, side_wall_friction_angle_deg, front_wall_friction_angle_deg,
        bulk_density_error=bulk_density_error)
    return comparison
