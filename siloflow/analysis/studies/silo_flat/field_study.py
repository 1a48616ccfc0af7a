"""The continuum study of one flat-bottom silo run, from the frames after opening to the rows of its tables.

:func:`analyse_silo_fields` takes the clump frames since the outlet opened, the contacts of the settled fill
(None for a run that saved none: what needs them is then left out), the silo's dimensions
(:class:`SiloDimensions`, from the run's silo case) and the ``silo_flat.fields`` settings (:class:`SiloFieldOptions`)
and returns a :class:`SiloFieldStudy`: the coarse-grained fields and their time
average, the velocity profiles, flow channel boundaries and kinematic constant, the centreline velocity, the
profile flow rates, the Janssen comparison and the force-chain segments, with the standard errors of B(z), of
the flow channel boundary (batch means over :data:`FIELD_BATCHES` time windows,
:func:`siloflow.analysis.studies.silo_flat.fields.profile_uncertainty`) and of the DEM vertical stress (differences of
mirror bins, as wide as the kernel's support, across the axis,
:func:`siloflow.analysis.studies.silo_flat.fields.compare_janssen`). The
small functions after it lay the results out as table rows (each error as ``<column>_error`` beside its column)
and the summary. Nothing here reads or writes files; the building blocks are in
:mod:`siloflow.analysis.studies.silo_flat.fields`. Coordinates as everywhere in siloflow: x across the width (0 on the
axis), y front to back (0 at the front wall), z up (0 at the outlet).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from siloflow.model.checks import number_or_nan
from siloflow.model.contacts import ContactFrame
from siloflow.model.frames import ClumpFrame
from siloflow.model.cases.silo_flat import SiloCase
from siloflow.model.constants import GRAVITY
from siloflow.analysis.numerics.field_ops import depth_average, front_wall_slice
from siloflow.analysis.numerics.flow import column_surface_heights
from siloflow.analysis.numerics.force_chains import ForceChainSegments, force_chain_segments
from siloflow.analysis.numerics.grid import Fields, Grid
from siloflow.analysis.numerics.profiles import profile_flow_rate, velocity_profile
from siloflow.analysis.studies.silo_flat.field_clock import averaging_window
from siloflow.analysis.studies.silo_flat.fields import (
    FieldSettings,
    JanssenComparison,
    ProfileAnalysis,
    ProfileUncertainty,
    analyse_profiles,
    centreline_velocity,
    clump_fields,
    janssen_from_contacts,
    profile_mass_flow_rate,
    profile_uncertainty,
    silo_grid,
    time_average,
)

__all__ = [
    "COVERED_DENSITY_FRACTION",
    "FIELD_BATCHES",
    "FORCE_CHAIN_CAP_WEIGHTS",
    "SURFACE_COLUMN_DIAMETERS",
    "SiloDimensions",
    "SiloFieldOptions",
    "SiloFieldStudy",
    "analyse_silo_fields",
    "fill_surface_heights",
    "profile_heights_inside",
    "force_chain_cap",
    "vtk_series",
    "profile_rows",
    "boundary_rows",
    "kinematic_rows",
    "instantaneous_profile_rows",
    "centreline_rows",
    "janssen_rows",
    "field_summary",
]

SURFACE_COLUMN_DIAMETERS = 4
"""Width of the columns in which the fill surface is found, in particle diameters (-)."""

FORCE_CHAIN_CAP_WEIGHTS = 50
"""Force-chain colours are capped at this many particle weights (-), as in the study's pictures."""

FIELD_BATCHES = 10
"""Time windows of the averaging window whose spread gives the errors of B(z) and of the flow channel boundary
(-): 10 to 20 batches is the usual compromise between the batches' independence and the error's own scatter."""

COVERED_DENSITY_FRACTION = 0.5
"""A profile height counts as covered by the fill while the density on the axis there is at least this fraction
of the filling bulk density (-); a flowing fill dilates by far less, the free surface's kernel-smeared edge
falls through it."""


# --------------------------------------------------------------------------- inputs


@dataclass(frozen=True)
class SiloDimensions:
    """The numbers of a silo case the field study uses.

    Attributes
    ----------
    width, depth : float
        Silo width W (x) and depth T (y) (m).
    outlet_width : float
        Slot outlet width (m).
    particle_radius : float
        Volume-equivalent particle radius (m).
    clump_mass : float
        Mass of one particle (clump) (kg).
    """

    width: float
    depth: float
    outlet_width: float
    particle_radius: float
    clump_mass: float

    @classmethod
    def from_case(cls, case: SiloCase) -> "SiloDimensions":
        """From the silo case the run was made of (the same numbers its ``case.json`` holds as ``width_m``,
        ``depth_m``, ``outlet_width_m``, ``equivalent_diameter_m`` and ``clump_mass_kg``).

        Parameters
        ----------
        case : siloflow.model.cases.silo_flat.SiloCase
            The run's silo: ``width``, ``depth``, ``outlet_width`` [m] and its particle's ``equivalent_diameter``
            [m] and ``mass`` [kg].

        Returns
        -------
        SiloDimensions
        """
        return cls(
            width=case.width,
            depth=case.depth,
            outlet_width=case.outlet_width,
            particle_radius=0.5 * case.particle.equivalent_diameter,
            clump_mass=case.particle.mass,
        )

    @classmethod
    def from_summary(cls, summary: Mapping) -> "SiloDimensions":
        """From a run's case summary (``deck/case.json``), which every silo-type case writes: the flat-bottom
        silo, the recirculating silo and the blender.

        Parameters
        ----------
        summary : mapping
            ``width_m``, ``depth_m``, ``outlet_width_m``, ``equivalent_diameter_m`` [m] and ``clump_mass_kg`` [kg].

        Returns
        -------
        SiloDimensions

        Raises
        ------
        KeyError
            Naming the missing key, for the summary of a case that is no silo (a Jenike cell).
        """
        missing = [key for key in ("width_m", "depth_m", "outlet_width_m", "equivalent_diameter_m", "clump_mass_kg")
                   if key not in summary]
        if missing:
            raise KeyError(f"the case summary has no {', '.join(missing)}: it is no silo's")
        return cls(
            width=float(summary["width_m"]),
            depth=float(summary["depth_m"]),
            outlet_width=float(summary["outlet_width_m"]),
            particle_radius=0.5 * float(summary["equivalent_diameter_m"]),
            clump_mass=float(summary["clump_mass_kg"]),
        )


@dataclass(frozen=True)
class SiloFieldOptions:
    """The ``silo_flat.fields`` settings (see the configuration schema for each key's meaning).

    Attributes
    ----------
    spacing : tuple of float
        Requested grid spacing (dx, dy, dz) (m).
    kernel : str
        Coarse-graining kernel.
    width_radii : float
        Kernel width in particle radii (-).
    cutoff : float
        Kernel cut-off in kernel widths (-).
    profile_heights : tuple of float
        Heights of the velocity profiles (m); those outside the fill are skipped.
    fcb_fractions : tuple of float
        Fractions of the centreline velocity that define the flow channel boundary (-).
    subtract_wall_velocity : bool
        Subtract the near-wall velocity before locating the boundary.
    average_window : tuple of float or None
        Time window since opening of the time average (s); None: the steady flow window.
    vtk_every : int
        Every n-th frame is written as .vti (-).
    internal_friction_angle_deg, side_wall_friction_angle_deg, front_wall_friction_angle_deg : float
        Bulk friction angles of Janssen's formula (degrees).
    force_chain_slice : float
        Thickness of the mid-depth slice of the force-chain picture (m).
    """

    spacing: tuple[float, float, float]
    kernel: str
    width_radii: float
    cutoff: float
    profile_heights: tuple[float, ...]
    fcb_fractions: tuple[float, ...]
    subtract_wall_velocity: bool
    average_window: tuple[float, float] | None
    vtk_every: int
    internal_friction_angle_deg: float
    side_wall_friction_angle_deg: float
    front_wall_friction_angle_deg: float
    force_chain_slice: float

    @classmethod
    def from_config(cls, section: Mapping) -> "SiloFieldOptions":
        """From the validated ``silo_flat.fields`` section (defaults filled in by the schema)."""
        janssen = section["janssen"]
        window = section["average_window"]
        return cls(
            spacing=tuple(section["spacing"]),
            kernel=section["kernel"],
            width_radii=section["width_radii"],
            cutoff=section["cutoff"],
            profile_heights=tuple(section["profile_heights"]),
            fcb_fractions=tuple(section["fcb_fractions"]),
            subtract_wall_velocity=section["subtract_wall_velocity"],
            average_window=tuple(window) if window else None,
            vtk_every=section["vtk_every"],
            internal_friction_angle_deg=janssen["internal_friction_angle_deg"],
            side_wall_friction_angle_deg=janssen["side_wall_friction_angle_deg"],
            front_wall_friction_angle_deg=janssen["front_wall_friction_angle_deg"],
            force_chain_slice=section["force_chain_slice"],
        )

    def field_settings(self, particle_radius: float) -> FieldSettings:
        """How particles of radius ``particle_radius`` (m) become fields: the kernel width is
        ``width_radii`` radii."""
        return FieldSettings(self.spacing, self.kernel, self.width_radii * particle_radius, self.cutoff)


# --------------------------------------------------------------------------- small steps


def fill_surface_heights(settled: ClumpFrame, particle_radius: float, width: float) -> np.ndarray:
    """Fill surface height (m) in columns of :data:`SURFACE_COLUMN_DIAMETERS` particle diameters across the width.

    The highest particle top ``z + r`` per column (NaN for an empty column); at least one column.
    """
    n_columns = max(1, int(width / (SURFACE_COLUMN_DIAMETERS * 2 * particle_radius)))
    return column_surface_heights(settled.position[:, 0], settled.position[:, 2], particle_radius, width, n_columns)


def profile_heights_inside(requested: Sequence[float], grid: Grid, top: float, dz: float) -> list[float]:
    """The requested profile heights (m) that lie inside the fill, away from its top row.

    A height is kept when ``grid.z[0] <= z <= min(top, grid.z[-1]) - dz``, ``top`` the fill surface (m) and
    ``dz`` the requested vertical spacing (m); the order is kept.

    Raises
    ------
    ValueError
        If no height is left.
    """
    heights = [z for z in requested if grid.z[0] <= z <= min(top, grid.z[-1]) - dz]
    if not heights:
        raise ValueError(
            f"no profile height lies inside the fill (surface at {top:.3f} m): lower fields.profile_heights")
    return heights


def force_chain_cap(clump_mass: float, gravity: float = GRAVITY) -> float:
    """The cap of the force-chain colours: :data:`FORCE_CHAIN_CAP_WEIGHTS` particle weights m g (N)."""
    return FORCE_CHAIN_CAP_WEIGHTS * (clump_mass * gravity)


def vtk_series(steps: Sequence[int], times: Sequence[float], every: int) -> list[tuple[int, float, str]]:
    """Which frames go into the ParaView time series: ``(frame index, time (s), file name)`` of every
    ``every``-th frame from the first, named ``fields_<step>.vti``."""
    return [(index, float(times[index]), f"fields_{steps[index]}.vti") for index in range(0, len(steps), every)]


# --------------------------------------------------------------------------- the study


@dataclass(frozen=True)
class SiloFieldStudy:
    """The continuum view of one silo run (see :func:`analyse_silo_fields`).

    Attributes
    ----------
    settings : FieldSettings
        How the particles became fields.
    grid : Grid
        Grid of the fields, tiling the silo up to the fill surface.
    steps : tuple of int
        Time steps of the frames (-).
    times : numpy.ndarray
        Time of each frame since the first frame after opening (s).
    fields : list of Fields
        Fields of each frame.
    window : tuple of float
        Time window of the average, since the first frame after opening (s).
    window_source : str
        Where ``window`` came from (:func:`~siloflow.analysis.studies.silo_flat.field_clock.averaging_window`):
        ``"silo_flat.fields.average_window"`` (``options.average_window``) or ``"silo_flat.steady_window"`` (the
        steady flow window).
    averaged : Fields
        Time average over ``window``.
    averaged_depth : Fields
        Its depth average.
    surface : numpy.ndarray
        Fill surface height per column of the settled frame (m).
    top : float
        Highest surface point (m).
    heights : list of float
        Profile heights inside the fill (m).
    profiles : ProfileAnalysis
        Depth-averaged profiles, boundaries and kinematic constant.
    front : ProfileAnalysis
        The same at the front wall (what a camera sees).
    depth_series : list of Fields
        Depth average of each frame.
    centreline : numpy.ndarray
        (frames, heights) v_z on the axis (m/s).
    profile_rate : float
        Mass flow rate through the lowest profile height from the momentum density (kg/s).
    bulk_rate : float
        The same from ``rho_b T integral(v_z dx)`` at the filling bulk density (kg/s).
    stress : numpy.ndarray or None
        Contact stress of the settled fill on the grid (Pa, compression positive); None without contacts.
    janssen : JanssenComparison or None
        Mean vertical contact stress against Janssen's formula and hydrostatic, with its error; None without
        contacts.
    uncertainty : ProfileUncertainty
        Standard errors of the depth-averaged B(z) and flow channel boundary.
    segments : ForceChainSegments or None
        Force chains in the mid-depth slice; None without contacts.
    n_contacts : int or None
        Contacts of the settled fill (-); None when none were given (a run that saved none).
    """

    settings: FieldSettings
    grid: Grid
    steps: tuple[int, ...]
    times: np.ndarray
    fields: list[Fields]
    window: tuple[float, float]
    window_source: str
    averaged: Fields
    averaged_depth: Fields
    surface: np.ndarray
    top: float
    heights: list[float]
    profiles: ProfileAnalysis
    front: ProfileAnalysis
    depth_series: list[Fields]
    centreline: np.ndarray
    profile_rate: float
    bulk_rate: float
    stress: np.ndarray | None
    janssen: JanssenComparison | None
    segments: ForceChainSegments | None
    n_contacts: int | None
    uncertainty: ProfileUncertainty


def analyse_silo_fields(
    frames: Sequence[ClumpFrame],
    contacts: ContactFrame | None,
    silo: SiloDimensions,
    options: SiloFieldOptions,
    steady_window: tuple[float, float],
    bulk_density: float,
    bulk_density_error: float | None = math.nan,
) -> SiloFieldStudy:
    """Coarse-grained fields, profiles, flow channel boundary, kinematic constant, Janssen and force chains.

    Parameters
    ----------
    frames : sequence of ClumpFrame
        The clumps of each frame from the opening of the outlet on; the first is the settled fill.
    contacts : ContactFrame or None
        Contacts of the settled fill; None for a run that saved none (its contact stress, Janssen comparison and
        force chains are then None, never made up).
    silo : SiloDimensions
        The silo's dimensions and particle.
    options : SiloFieldOptions
        The study's settings.
    steady_window : tuple of float
        Steady flow window since opening (s), the time average's window when ``options.average_window``
        is None.
    bulk_density : float
        Filling bulk density (kg/m3), for the profile flow rate, Janssen's formula and the hydrostatic stress.
    bulk_density_error : float or None, optional
        Its standard error (kg/m3), for the hydrostatic stress's error; NaN or None (null in a flow.json written
        before the error existed): unknown.

    Returns
    -------
    SiloFieldStudy
    """
    frames = list(frames)
    if not frames:
        raise ValueError("frames must hold at least the settled frame at the opening")
    settings = options.field_settings(silo.particle_radius)
    surface = fill_surface_heights(frames[0], silo.particle_radius, silo.width)
    top = float(np.nanmax(surface))
    grid = silo_grid(silo.width, silo.depth, top, settings.spacing)
    times = np.array([frame.time for frame in frames]) - frames[0].time
    fields = [clump_fields(frame, grid, settings) for frame in frames]
    window, window_source = averaging_window(options.average_window, steady_window)
    averaged = time_average(fields, times, window)
    averaged_depth = depth_average(averaged)

    heights = profile_heights_inside(options.profile_heights, grid, top, settings.spacing[2])
    profiles = analyse_profiles(averaged_depth, heights, options.fcb_fractions, options.subtract_wall_velocity,
                                kernel_width=settings.width)
    # What a camera behind the front wall sees, next to the depth average.
    front = analyse_profiles(front_wall_slice(averaged), heights, options.fcb_fractions)
    depth_series = [depth_average(f) for f in fields]
    centre = centreline_velocity(depth_series, heights)
    uncertainty = profile_uncertainty(depth_series, times, window, heights, options.fcb_fractions,
                                      COVERED_DENSITY_FRACTION * bulk_density, FIELD_BATCHES,
                                      options.subtract_wall_velocity, kernel_width=settings.width)

    # Mass flow rate through the lowest profile height, from the averaged momentum density, and the same with
    # the study's formula W = rho_b T integral(v_z dx) at the filling bulk density.
    profile_rate = profile_mass_flow_rate(averaged_depth, heights[0], silo.depth)
    bulk_rate = profile_flow_rate(profiles.x, profiles.v_z[0], bulk_density, silo.depth)

    stress, janssen, segments = (None, None, None) if contacts is None else _contact_analyses(
        contacts, grid, settings, surface, bulk_density, bulk_density_error, silo, options)
    return SiloFieldStudy(
        settings=settings, grid=grid, steps=tuple(frame.step for frame in frames), times=times, fields=fields,
        window=window, window_source=window_source, averaged=averaged, averaged_depth=averaged_depth,
        surface=surface, top=top, heights=heights, profiles=profiles, front=front, depth_series=depth_series,
        centreline=centre, profile_rate=profile_rate, bulk_rate=bulk_rate, stress=stress, janssen=janssen, segments=segments,
        n_contacts=None if contacts is None else len(contacts), uncertainty=uncertainty,
    )


def _contact_analyses(contacts: ContactFrame, grid: Grid, settings: FieldSettings, surface: np.ndarray,
                      bulk_density: float, bulk_density_error: float | None, silo: SiloDimensions,
                      options: SiloFieldOptions) -> tuple[np.ndarray, JanssenComparison, ForceChainSegments]:
    """The settled fill's contact stress on the grid (Pa), its Janssen comparison and its force chains."""
    # Janssen: mean vertical contact stress of the settled fill against the formula, below the lowest point of
    # the surface.
    stress, janssen = janssen_from_contacts(
        contacts, grid, settings, float(np.nanmin(surface)), bulk_density, silo.width, silo.depth,
        options.internal_friction_angle_deg, options.side_wall_friction_angle_deg,
        options.front_wall_friction_angle_deg, bulk_density_error=number_or_nan(bulk_density_error))
    segments = force_chain_segments(contacts, 0.5 * silo.depth, options.force_chain_slice,
                                    cap=force_chain_cap(silo.clump_mass))
    return stress, janssen, segments


# --------------------------------------------------------------------------- table rows


def profile_rows(profiles: ProfileAnalysis, front: ProfileAnalysis) -> list[dict]:
    """Rows of ``profiles.csv``: per height and node, v_z, v_x and the kinematic u (m/s), with the front-wall
    v_z and v_x next to them."""
    return [
        {"z_m": z, "x_m": x, "v_z_m_s": vz, "v_x_m_s": vx, "u_kinematic_m_s": u,
         "v_z_front_wall_m_s": fz, "v_x_front_wall_m_s": fx}
        for i, z in enumerate(profiles.heights)
        for x, vz, vx, u, fz, fx in zip(profiles.x, profiles.v_z[i], profiles.v_x[i], profiles.kinematic_u[i],
                                        front.v_z[i], front.v_x[i])
    ]


def boundary_rows(profiles: ProfileAnalysis, uncertainty: ProfileUncertainty) -> list[dict]:
    """Rows of ``flow_channel_boundary.csv``: per height and fraction, the left and right boundary (m) with their
    standard errors (m) and the time windows behind them (``batches``)."""
    return [
        {"z_m": z, "fraction": f,
         "x_left_m": profiles.fcb_left[i, j], "x_left_m_error": uncertainty.fcb_left_error[i, j],
         "x_right_m": profiles.fcb_right[i, j], "x_right_m_error": uncertainty.fcb_right_error[i, j],
         "batches": int(uncertainty.batches[i])}
        for i, z in enumerate(profiles.heights) for j, f in enumerate(profiles.fcb_fractions)
    ]


def kinematic_rows(profiles: ProfileAnalysis, uncertainty: ProfileUncertainty) -> list[dict]:
    """Rows of ``kinematic.csv``: the kinematic constant B (m) per height with its standard error (m) and the time
    windows behind it (``batches``)."""
    return [{"z_m": z, "B_m": b, "B_m_error": e, "batches": int(n)}
            for z, b, e, n in zip(profiles.heights, profiles.kinematic_B, uncertainty.kinematic_B_error,
                                  uncertainty.batches)]


def instantaneous_profile_rows(times: Sequence[float], depth_series: Sequence[Fields],
                               heights: Sequence[float]) -> list[dict]:
    """Rows of ``profiles_instantaneous.csv``: per frame, height and node, v_z and v_x (m/s) of the depth
    average."""
    rows = []
    for t, frame_fields in zip(times, depth_series):
        for z in heights:
            profile = velocity_profile(frame_fields, z)
            rows.extend(
                {"time_s": t, "z_m": z, "x_m": x, "v_z_m_s": vz, "v_x_m_s": vx}
                for x, vz, vx in zip(profile.x, profile.v_z, profile.v_x))
    return rows


def centreline_rows(times: Sequence[float], heights: Sequence[float], centreline: np.ndarray) -> list[dict]:
    """Rows of ``centreline_velocity.csv``: per frame, v_z on the axis (m/s) in one column per height
    (``v_z_at_<mm>mm_m_s``)."""
    return [
        {"time_s": t, **{f"v_z_at_{1e3 * z:g}mm_m_s": centreline[i, j] for j, z in enumerate(heights)}}
        for i, t in enumerate(times)
    ]


def janssen_rows(comparison: JanssenComparison) -> list[dict]:
    """Rows of ``janssen.csv``: per depth below the surface (m) and height above the floor (m), the DEM vertical
    stress with its standard error, Janssen's and the hydrostatic ``rho_b g h`` with its error (Pa)."""
    return [
        {"depth_below_surface_m": h, "z_m": z, "sigma_v_dem_Pa": s, "sigma_v_dem_Pa_error": se,
         "sigma_v_janssen_Pa": j, "hydrostatic_pa": p, "hydrostatic_pa_error": pe}
        for h, z, s, se, j, p, pe in zip(comparison.depth_below_surface, comparison.height, comparison.simulated,
                                         comparison.simulated_error, comparison.janssen, comparison.hydrostatic,
                                         comparison.hydrostatic_error)
    ]


def field_summary(study: SiloFieldStudy, outflow_rate: float) -> dict:
    """The contents of ``fields.json``: grid, kernel, the averaging window (its start and end in seconds after the
    outlet opened, ``average_window_s``, and the key it came from, ``average_window_source``:
    :func:`~siloflow.analysis.studies.silo_flat.field_clock.averaging_window`), heights, the profile flow rates
    against the measured outflow ``outflow_rate`` (kg/s), B and the flow-pattern index (wall over centreline v_z) per
    height with their errors, surface height and number of contacts (the Janssen bins and the contacts null for a
    study made without contacts)."""
    return {
        "grid_shape": list(study.grid.shape),
        "grid_spacing_m": list(study.grid.spacing),
        "kernel": study.settings.kernel,
        "kernel_width_m": study.settings.width,
        "average_window_s": list(study.window),
        "average_window_source": study.window_source,
        "profile_heights_m": study.heights,
        "profile_flow_height_m": study.heights[0],
        "profile_mass_flow_rate_kg_s": study.profile_rate,
        "outflow_mass_flow_rate_kg_s": outflow_rate,
        "profile_over_outflow": study.profile_rate / outflow_rate,
        "profile_bulk_density_mass_flow_rate_kg_s": study.bulk_rate,
        "kinematic_B_m": {f"{z:g}": b for z, b in zip(study.profiles.heights, study.profiles.kinematic_B)},
        "kinematic_B_m_error": {f"{z:g}": e for z, e in
                                zip(study.profiles.heights, study.uncertainty.kinematic_B_error)},
        "flow_pattern_index": {f"{z:g}": i for z, i in zip(study.profiles.heights, study.profiles.flow_pattern_index)},
        "flow_pattern_index_error": {f"{z:g}": float(e) for z, e in
                                     zip(study.profiles.heights, _index_errors(study))},
        "error_batches": study.uncertainty.n_batches,
        "janssen_error_bin_pairs": None if study.janssen is None else study.janssen.bin_pairs,
        "surface_height_m": study.top,
        "contacts": study.n_contacts,
    }


def _index_errors(study: SiloFieldStudy) -> np.ndarray:
    errors = study.uncertainty.flow_pattern_index_error
    return np.full(len(study.profiles.heights), np.nan) if errors is None else errors
