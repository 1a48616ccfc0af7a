"""Discharge metrics of a flat-bottom silo run from a sequence of clump frames.

Pure computation: the frames come in as :class:`siloflow.model.frames.ClumpFrame` objects (or anything with
``time``, ``clump_id``, ``position`` and ``mass``), the results go out as dataclasses.

Uncertainties (standard errors, in the unit of their figure; :mod:`siloflow.analysis.numerics.uncertainty`):

* filling bulk density: the spread of the density over horizontal slabs of :data:`SLAB_DIAMETERS` particle
  diameters of the control volume (:func:`siloflow.analysis.numerics.flow.slab_bulk_density`);
* steady mass flow rate: batch means of the rate, the least-squares slopes of the discharged mass in
  :data:`FLOW_RATE_BATCHES` contiguous batches of the steady window
  (:func:`siloflow.analysis.numerics.uncertainty.batch_rate`). The least-squares standard error of the one slope over the
  window (``FlowRateFit.standard_error``) assumes independent residuals, but the residuals of a cumulative
  mass about its line are strongly correlated (a random walk), so it is several times too small; it is kept
  under its old name only;
* volumetric flow rate, Beverloo's prediction and their ratio: first-order propagation of these two, which are
  independent (the settled fill and the discharge); Beverloo's coefficients C and k are taken as exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from siloflow.model.constants import GRAVITY
from siloflow.analysis.numerics.flow import (
    BulkDensity,
    DischargeHistory,
    FlowRateFit,
    beverloo_mass_flow_rate,
    discharged_mass_history,
    filling_bulk_density,
    mass_in_silo,
    slab_bulk_density,
    steady_flow_rate,
    volumetric_flow_rate,
)
from siloflow.analysis.numerics.uncertainty import Estimate, batch_rate, combine_independent

SLAB_DIAMETERS = 4
"""Thickness of the slabs whose spread gives the bulk density's error, in particle diameters (-)."""

FLOW_RATE_BATCHES = 10
"""Batches of the steady window whose slopes give the flow rate's error (-)."""


class EscapedParticles(ValueError):
    """Clumps vanished from the domain somewhere other than through the outlet."""


@dataclass(frozen=True)
class SiloFlowMetrics:
    """Flow metrics of one batch discharge.

    Attributes
    ----------
    bulk_density : BulkDensity
        Filling bulk density of the settled fill (kg/m^3) and its control volume.
    history : DischargeHistory
        Discharged mass (kg) against time since the outlet opened (s).
    fit : FlowRateFit
        Steady mass flow rate (kg/s) fitted over the steady window.
    volumetric_flow_rate : float
        Steady volumetric flow rate at the filling bulk density (m^3/s).
    beverloo_rate : float
        Beverloo's prediction for the slot at the measured bulk density (kg/s).
    particle_diameter : float
        Particle diameter used in Beverloo's correlation (m).
    initial_mass : float
        Mass in the silo when the outlet opened (kg).
    density_estimate : Estimate
        The bulk density's spread over horizontal slabs (kg/m^3): its ``std_error`` is the density's error.
    rate_estimate : Estimate
        Batch rate of the steady window (kg/s): its ``std_error`` is the flow rate's error.
    """

    bulk_density: BulkDensity
    history: DischargeHistory
    fit: FlowRateFit
    volumetric_flow_rate: float
    beverloo_rate: float
    particle_diameter: float
    initial_mass: float
    density_estimate: Estimate
    rate_estimate: Estimate

    @property
    def beverloo_ratio(self) -> float:
        """Measured over predicted steady mass flow rate (-)."""
        return self.fit.mass_flow_rate / self.beverloo_rate

    @property
    def bulk_density_error(self) -> float:
        """Standard error of the filling bulk density (kg/m^3); NaN when unknown."""
        return self.density_estimate.std_error

    @property
    def mass_flow_rate_error(self) -> float:
        """Standard error of the steady mass flow rate from batch means of the rate (kg/s); NaN when unknown."""
        return self.rate_estimate.std_error

    def _relative_density_error(self) -> float:
        return self.bulk_density_error / self.bulk_density.density

    def _relative_rate_error(self) -> float:
        rate = self.fit.mass_flow_rate
        return self.mass_flow_rate_error / abs(rate) if rate != 0.0 else math.nan

    def _relative_rate_and_density_error(self) -> float:
        """The relative errors of W and rho_b in quadrature: that of W / rho_b, and of W / W_B (W_B ~ rho_b)."""
        return combine_independent([self._relative_rate_error(), self._relative_density_error()])

    @property
    def volumetric_flow_rate_error(self) -> float:
        """Standard error of ``W / rho_b`` (m^3/s): the relative errors of W and rho_b in quadrature."""
        return abs(self.volumetric_flow_rate) * self._relative_rate_and_density_error()

    @property
    def beverloo_rate_error(self) -> float:
        """Standard error of Beverloo's prediction (kg/s) through the measured bulk density it is proportional
        to (C and k exact)."""
        return self.beverloo_rate * self._relative_density_error()

    @property
    def beverloo_ratio_error(self) -> float:
        """Standard error of the measured over predicted flow rate (-): ``W / W_B`` with ``W_B`` proportional to
        rho_b, so the relative errors of W and rho_b in quadrature."""
        return abs(self.beverloo_ratio) * self._relative_rate_and_density_error()


def steady_rate_estimate(history: DischargeHistory, fit: FlowRateFit, n_batches: int = FLOW_RATE_BATCHES) -> Estimate:
    """Batch rate of the discharged mass over the fit's steady window, for the flow rate's standard error (kg/s).

    The samples with ``fit.t_start <= t <= fit.t_end`` are cut into ``min(n_batches, n // 2)`` batches
    (:func:`siloflow.analysis.numerics.uncertainty.batch_rate`, two samples per slope at least). The value is the
    least-squares slope of the whole window (``fit.mass_flow_rate``, the flow rate reported), the error that of
    the mean of the batch slopes. A window of fewer than 4 samples (fewer than 2 batches) gives a NaN error.

    Parameters
    ----------
    history : DischargeHistory
        Discharged mass (kg) against time since opening (s).
    fit : FlowRateFit
        The steady flow rate fit and its window (s).
    n_batches : int, optional
        Batches wanted, >= 2.

    Returns
    -------
    Estimate
        ``method="batch rate"``, ``n`` the batches used (1 when there are too few samples).
    """
    time = np.asarray(history.time, dtype=float)
    inside = (time >= fit.t_start) & (time <= fit.t_end)
    batches = min(int(n_batches), int(np.count_nonzero(inside)) // 2)
    if batches < 2:
        return Estimate(value=fit.mass_flow_rate, std_error=math.nan, n=1, method="batch rate")
    rate = batch_rate(time[inside], np.asarray(history.discharged_mass, dtype=float)[inside], n_batches=batches)
    return Estimate(value=fit.mass_flow_rate, std_error=rate.std_error, n=rate.n, method=rate.method, dof=rate.dof)


def vanished_above_outlet(previous_ids, previous_z, current_ids, outlet_plane: float = 0.0) -> np.ndarray:
    """Ids of clumps that disappeared between two frames while last seen at or above the outlet plane.

    Discharged clumps leave the domain only after falling below the outlet plane, and between two frames
    none can travel from the silo to the bottom of the domain, so a clump that vanishes from above the
    outlet plane has escaped through a wall (lost atoms).
    """
    previous_ids = np.asarray(previous_ids)
    previous_z = np.asarray(previous_z, dtype=float)
    gone = ~np.isin(previous_ids, np.asarray(current_ids))
    return previous_ids[gone & (previous_z >= outlet_plane)]


def could_reach_outlet(position, velocity, interval: float, outlet_width: float,
                       gravity: float = GRAVITY) -> np.ndarray:
    """Whether clumps last seen at ``position`` moving at ``velocity`` could have passed the slot outlet within
    ``interval``.

    A clump can reach the outlet when it is over the slot, or no farther beside it than it travels sideways in the
    interval (``|x| <= B0 / 2 + |v_x| dt``), and no higher above the outlet plane than it falls in the interval from
    its vertical velocity under gravity (``z <= max(0, -v_z) dt + g dt^2 / 2``). Lateral deflection by contacts and
    any downward acceleration beyond gravity are not counted, so the test errs towards calling a clump escaped.

    Parameters
    ----------
    position, velocity : array_like, shape (n, 3)
        Clump centres (m, silo coordinates: x = 0 on the axis, z = 0 at the outlet plane) and velocities (m/s).
    interval : float
        Time until the next frame (s), > 0.
    outlet_width : float
        Slot width B0 (m).
    gravity : float, optional
        Gravitational acceleration (m/s^2).

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
    """
    position = np.asarray(position, dtype=float).reshape(-1, 3)
    velocity = np.asarray(velocity, dtype=float).reshape(-1, 3)
    interval = float(interval)
    if not (math.isfinite(interval) and interval > 0.0):
        raise ValueError(f"interval must be a finite positive time (s), got {interval!r}")
    sideways = np.abs(position[:, 0]) <= 0.5 * outlet_width + np.abs(velocity[:, 0]) * interval
    fall = np.maximum(0.0, -velocity[:, 2]) * interval + 0.5 * gravity * interval**2
    return sideways & (position[:, 2] <= fall)


def escaped_clumps(previous, current, outlet_width: float, removed_at_outlet: bool = False,
                   gravity: float = GRAVITY) -> np.ndarray:
    """Ids of the clumps that vanished between two frames other than through the outlet.

    Parameters
    ----------
    previous, current : ClumpFrame
        Two consecutive frames (silo coordinates).
    outlet_width : float
        Slot width B0 (m).
    removed_at_outlet : bool, optional
        Whether the run removes clumps as they cross the outlet plane (a run siloflow did not make may): a clump
        that vanished above the plane then counts as discharged when it could have reached the outlet by the
        next frame (:func:`could_reach_outlet`). False (siloflow's decks, which remove clumps only far below the
        outlet): every clump that vanished above the plane escaped.
    gravity : float, optional
        Gravitational acceleration (m/s^2).

    Returns
    -------
    numpy.ndarray of int64
        The escaped clumps' ids.
    """
    escaped = vanished_above_outlet(previous.clump_id, previous.position[:, 2], current.clump_id)
    if escaped.size and removed_at_outlet:
        rows = np.isin(previous.clump_id, escaped)
        reached = could_reach_outlet(previous.position[rows], previous.velocity[rows], current.time - previous.time,
                                     outlet_width, gravity)
        escaped = previous.clump_id[rows][~reached]
    return escaped


def silo_flow_metrics(
    frames: Sequence,
    width: float,
    depth: float,
    outlet_width: float,
    particle_diameter: float,
    steady_window: tuple[float, float] = (0.2, 0.8),
    discharge_coefficient: float = 0.58,
    shape_coefficient: float = 1.5,
    gravity: float = GRAVITY,
    removed_at_outlet: bool = False,
) -> SiloFlowMetrics:
    """Filling bulk density, discharge history, steady flow rate and Beverloo's prediction.

    Parameters
    ----------
    frames : sequence of ClumpFrame
        Clump frames in time order; the first is the settled fill at the moment the outlet opens.
    width, depth, outlet_width : float
        Silo width W, depth T and slot width B0 (m); the slot spans the depth, so L = T.
    particle_diameter : float
        Particle diameter d for Beverloo's correlation (m).
    steady_window : tuple of float
        Fractions of the final discharged mass that bound the fitted steady window.
    discharge_coefficient, shape_coefficient : float
        Beverloo's C and k (-).
    gravity : float
        Gravitational acceleration (m/s^2).
    removed_at_outlet : bool, optional
        Whether the run may remove clumps as they cross the outlet plane (:func:`escaped_clumps`).

    Raises
    ------
    EscapedParticles
        If clumps vanished from above the outlet plane (other than through the outlet, with
        ``removed_at_outlet``).
    ValueError
        If there are fewer than two frames or nothing was discharged.
    """
    if len(frames) < 2:
        raise ValueError(f"need at least two frames of the discharge, got {len(frames)}")
    for previous, current in zip(frames[:-1], frames[1:]):
        escaped = escaped_clumps(previous, current, outlet_width, removed_at_outlet, gravity)
        if escaped.size:
            raise EscapedParticles(
                f"{escaped.size} clumps vanished above the outlet plane between t = {previous.time:.4g} s "
                f"and t = {current.time:.4g} s (ids {escaped[:5].tolist()}...): particles escaped through a wall"
            )
    settled = frames[0]
    bulk = filling_bulk_density(
        settled.position,
        settled.mass,
        width,
        depth,
        surface_margin=2.0 * particle_diameter,
        n_columns=max(1, int(width / (4.0 * particle_diameter))),
    )
    times = np.array([frame.time for frame in frames])
    masses = np.array([mass_in_silo(frame.position[:, 2], frame.mass) for frame in frames])
    history = discharged_mass_history(times, masses)
    fit = steady_flow_rate(history.time, history.discharged_mass, fraction_window=tuple(steady_window))
    beverloo = beverloo_mass_flow_rate(
        bulk.density,
        outlet_width,
        depth,
        particle_diameter,
        discharge_coefficient=discharge_coefficient,
        shape_coefficient=shape_coefficient,
        gravity=gravity,
    )
    slabs = slab_bulk_density(settled.position[:, 2], settled.mass, width * depth, bulk.measured_height,
                              SLAB_DIAMETERS * particle_diameter)
    return SiloFlowMetrics(
        bulk_density=bulk,
        history=history,
        fit=fit,
        volumetric_flow_rate=volumetric_flow_rate(fit.mass_flow_rate, bulk.density),
        beverloo_rate=beverloo,
        particle_diameter=particle_diameter,
        initial_mass=float(masses[0]),
        density_estimate=slabs,
        rate_estimate=steady_rate_estimate(history, fit),
    )


def flow_table_row(run_id: str, particle_model: str, n_clumps: int, metrics: SiloFlowMetrics) -> dict:
    """One row of ``metrics/flow.csv`` and ``metrics/flow.json`` (column names carry their units).

    Each ``<key>_error`` is the standard error of ``<key>`` in its unit (NaN when unknown), as the module
    docstring derives it; ``filling_bulk_density_slabs`` and ``mass_flow_rate_batches`` count the independent
    samples behind the two measured errors. ``mass_flow_rate_stderr_kg_s`` is the least-squares error of the
    slope, kept for the readers of the old key; it is not the flow rate's error.
    """
    return {
        "run_id": run_id,
        "particle_model": particle_model,
        "n_clumps": n_clumps,
        "initial_mass_kg": metrics.initial_mass,
        "filling_bulk_density_kg_m3": metrics.bulk_density.density,
        "filling_bulk_density_kg_m3_error": metrics.bulk_density_error,
        "filling_bulk_density_slabs": metrics.density_estimate.n,
        "mass_flow_rate_kg_s": metrics.fit.mass_flow_rate,
        "mass_flow_rate_kg_s_error": metrics.mass_flow_rate_error,
        "mass_flow_rate_batches": metrics.rate_estimate.n,
        "mass_flow_rate_stderr_kg_s": metrics.fit.standard_error,
        "volumetric_flow_rate_m3_s": metrics.volumetric_flow_rate,
        "volumetric_flow_rate_m3_s_error": metrics.volumetric_flow_rate_error,
        "steady_window_start_s": metrics.fit.t_start,
        "steady_window_end_s": metrics.fit.t_end,
        "beverloo_mass_flow_rate_kg_s": metrics.beverloo_rate,
        "beverloo_mass_flow_rate_kg_s_error": metrics.beverloo_rate_error,
        "beverloo_ratio": metrics.beverloo_ratio,
        "beverloo_ratio_error": metrics.beverloo_ratio_error,
        "particle_diameter_m": metrics.particle_diameter,
        "discharged_mass_kg": float(metrics.history.discharged_mass[-1]),
    }
