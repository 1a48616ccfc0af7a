"""Discharge metrics of a flat-bottom silo run from a sequence of clump frames.

Pure computation: the frames come in as :class:`analysis.data.frames.ClumpFrame` objects (or anything with
``time``, ``clump_id``, ``position`` and ``mass``), the results go out as dataclasses.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from analysis.data.constants import GRAVITY
from analysis.numerics.flow import (
    BulkDensity,
    DischargeHistory,
    FlowRateFit,
    beverloo_mass_flow_rate,
    discharged_mass_history,
    filling_bulk_density,
    mass_in_silo,
    steady_flow_rate,
    volumetric_flow_rate,
)


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
    """

    bulk_density: BulkDensity
    history: DischargeHistory
    fit: FlowRateFit
    volumetric_flow_rate: float
    beverloo_rate: float
    particle_diameter: float
    initial_mass: float

    @property
    def beverloo_ratio(self) -> float:
        """Measured over predicted steady mass flow rate (-)."""
        return self.fit.mass_flow_rate / self.beverloo_rate


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

    Raises
    ------
    EscapedParticles
        If clumps vanished from above the outlet plane.
    ValueError
        If there are fewer than two frames or nothing was discharged.
    """
    if len(frames) < 2:
        raise ValueError(f"need at least two frames of the discharge, got {len(frames)}")
    for previous, current in zip(frames[:-1], frames[1:]):
        escaped = vanished_above_outlet(previous.clump_id, previous.position[:, 2], current.clump_id)
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
    return SiloFlowMetrics(
        bulk_density=bulk,
        history=history,
        fit=fit,
        volumetric_flow_rate=volumetric_flow_rate(fit.mass_flow_rate, bulk.density),
        beverloo_rate=beverloo,
        particle_diameter=particle_diameter,
        initial_mass=float(masses[0]),
    )


def flow_table_row(run_id: str, particle_model: str, n_clumps: int, metrics: SiloFlowMetrics) -> dict:
    """One row of ``metrics/flow.csv`` (column names carry their units)."""
    return {
        "run_id": run_id,
        "particle_model": particle_model,
        "n_clumps": n_clumps,
        "initial_mass_kg": metrics.initial_mass,
        "filling_bulk_density_kg_m3": metrics.bulk_density.density,
        "mass_flow_rate_kg_s": metrics.fit.mass_flow_rate,
        "mass_flow_rate_stderr_kg_s": metrics.fit.standard_error,
        "volumetric_flow_rate_m3_s": metrics.volumetric_flow_rate,
        "steady_window_start_s": metrics.fit.t_start,
        "steady_window_end_s": metrics.fit.t_end,
        "beverloo_mass_flow_rate_kg_s": metrics.beverloo_rate,
        "beverloo_ratio": metrics.beverloo_ratio,
        "particle_diameter_m": metrics.particle_diameter,
        "discharged_mass_kg": float(metrics.history.discharged_mass[-1]),
    }
