"""The verification table: each problem's measured quantities against their closed forms
(:mod:`siloflow.analysis.numerics.verification`), with the relative error and whether it is within tolerance.

Input per run: the sphere trajectories as arrays (times ``(n,)``; positions, velocities and angular velocities
``(n, k, 3)`` for ``k`` spheres in a fixed order) and the problem's parameters (a plain dict, the case summary).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from siloflow.analysis.numerics.verification import (
    axis_precession_angle,
    contact_interval,
    hertz_contact_time,
    incline_acceleration,
    linear_slope,
    moment_about_axis,
    precession_rate,
    rolling_deceleration_cdt,
    hertz_normal_force,
    sliding_to_rolling,
    sphere_contacts,
    spin_deceleration,
    zero_crossings,
)

__all__ = ["TOLERANCES", "Trajectories", "VerificationRow", "measure_problem", "trajectories_from_frames",
           "verification_table"]

#: Relative tolerance of each measured quantity (the time step resolves a contact in 100 steps; frames of the
#: impacts are every step).
TOLERANCES = {"restitution": 0.02, "contact_time": 0.03, "rolling_time": 0.02, "rolling_speed": 0.01,
              "rolling_deceleration": 0.03, "precession_rate": 0.01, "incline_acceleration": 0.02,
              "spin_deceleration": 0.02, "torque_ratio": 0.02}


@dataclass(frozen=True)
class Trajectories:
    """Sphere trajectories of one run: times [s] ``(n,)``; positions [m], velocities [m/s], angular velocities
    [rad/s] ``(n, k, 3)``."""

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray


@dataclass(frozen=True)
class VerificationRow:
    """One measured quantity of one problem on one engine."""

    problem: str
    quantity: str
    closed_form: float
    measured: float
    tolerance: float
    #: what the error is relative to: the closed form, or (where that is 0) the scale of the quantity
    scale: float = 0.0

    @property
    def error(self) -> float:
        """Error of the measurement relative to the closed form (or to ``scale`` when given)."""
        return (self.measured - self.closed_form) / (self.scale or abs(self.closed_form))

    @property
    def passes(self) -> bool:
        return abs(self.error) <= self.tolerance


def trajectories_from_frames(frames) -> Trajectories:
    """The trajectories of a run's frames (:class:`siloflow.model.frames.ParticleFrame`, oldest first), spheres in
    the order of their ids.

    Raises
    ------
    ValueError
        When the frames hold different spheres or no angular velocity.
    """
    if not frames:
        raise ValueError("no frames")
    ids = np.sort(frames[0].id)
    columns = {"position": [], "velocity": [], "angular_velocity": []}
    for frame in frames:
        order = np.argsort(frame.id)
        if not np.array_equal(frame.id[order], ids):
            raise ValueError(f"the frame of step {frame.step} holds spheres {frame.id.tolist()}, not {ids.tolist()}")
        if frame.angular_velocity is None:
            raise ValueError(f"the frame of step {frame.step} has no angular velocity")
        for name in columns:
            columns[name].append(getattr(frame, name)[order])
    return Trajectories(np.array([frame.time for frame in frames]), *(np.array(columns[n]) for n in columns))


def _row(problem: str, quantity: str, closed: float, measured: float, scale: float = 0.0) -> VerificationRow:
    return VerificationRow(problem, quantity, float(closed), float(measured), TOLERANCES[quantity], float(scale))


def _flat_modulus(p: dict) -> float:
    # sphere and flat of the same material: 1/E* = 2 (1 - nu^2) / E
    return p["youngs_modulus"] / (2.0 * (1.0 - p["poisson_ratio"] ** 2))


def measure_problem(problem: str, p: dict, run: Trajectories) -> list[VerificationRow]:
    """The rows of problem ``problem`` (``wall_impact``, ``pair_impact``, their ``_damped`` variants,
    ``slide_to_roll``, ``rolling``, ``incline_slide``, ``incline_stick``, ``clump_rotation``, ``pair_spin``,
    ``wall_spin``, ``clump_pair_spin``) from its parameters ``p`` (``radius``, ``mass_kg``, ``youngs_modulus``,
    ``poisson_ratio``, ``restitution``, ``sliding_friction``, ``rolling_friction``, ``gravity``; a clump problem's
    ``clump_spheres`` and ``clump_inertia``; ``rolling_lever_arm_m``) and the run's trajectories.

    ``clump_pair_spin`` has two rows: the spin's deceleration against the study's torque, and the engine's torque
    over the study's (the measured deceleration over the study's closed form) against the ratio the engines' rolling
    law gives it, the clump's mean lever arm over each contact's own (:mod:`siloflow.model.rolling`).

    Raises
    ------
    ValueError
        For an unknown problem, or trajectories that do not show what the problem needs (no contact, a contact that
        has not ended, a sphere that never rolls).
    """
    t, x, v, w = run.time, run.position, run.velocity, run.angular_velocity
    r, m = p["radius"], p["mass_kg"]
    # the Hertz time is the closed form of an elastic impact only (damping lengthens the contact)
    elastic = p["restitution"] == 1.0
    if problem in ("wall_impact", "wall_impact_damped"):
        start, end = contact_interval(t, x[:, 0, 2] - r)
        speed = -v[0, 0, 2]
        rows = [_row(problem, "restitution", p["restitution"], v[-1, 0, 2] / speed)]
        if elastic:
            rows.append(_row(problem, "contact_time", hertz_contact_time(m, r, _flat_modulus(p), speed), end - start))
        return rows
    if problem in ("pair_impact", "pair_impact_damped"):
        gap = np.linalg.norm(x[:, 1] - x[:, 0], axis=1) - 2.0 * r
        start, end = contact_interval(t, gap)
        before = v[0, 0, 0] - v[0, 1, 0]
        after = v[-1, 1, 0] - v[-1, 0, 0]
        rows = [_row(problem, "restitution", p["restitution"], after / before)]
        if elastic:
            rows.append(_row(problem, "contact_time",
                             hertz_contact_time(m / 2.0, r / 2.0, _flat_modulus(p), before), end - start))
        return rows
    if problem == "clump_rotation":
        axis = x[:, 1] - x[:, 0]
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        inertia, spin = np.asarray(p["clump_inertia"]), np.asarray(p["initial_angular_velocity"])
        slope, _ = linear_slope(t, axis_precession_angle(axis, inertia * spin))
        return [_row(problem, "precession_rate", precession_rate(inertia, spin), abs(slope))]
    if problem in ("pair_spin", "wall_spin"):
        # the held sphere is the last; its overlap with the fixed sphere (or the floor) at the start sets |Fn|
        gap = (np.linalg.norm(x[0, -1] - x[0, 0]) - 2.0 * r) if problem == "pair_spin" else x[0, -1, 2] - r
        force = hertz_normal_force(_flat_modulus(p), r / 2.0 if problem == "pair_spin" else r, -gap)
        spin = w[:, -1, 0]
        # while it still spins at more than a fifth of its start (the elastic start of an EPSD moment, a few steps,
        # left out with the first twentieth)
        spinning = (t > 0.05 * t[-1]) & (spin > 0.2 * spin[0])
        if spinning.sum() < 3:
            raise ValueError("too few frames of the spinning phase")
        slope, _ = linear_slope(t[spinning], spin[spinning])
        closed = spin_deceleration(p["rolling_friction"], force, r, 0.4 * m * r * r)
        return [_row(problem, "spin_deceleration", closed, -slope)]
    if problem == "clump_pair_spin":
        # the held clump's spheres are the last of its frames; its contacts with the fixed clump's, the overlaps and
        # the lever arms at the start, set the closed form (the spin about the clump's long axis moves neither)
        k = len(p["clump_spheres"])
        held, fixed = x[0, -k:], x[0, :-k]
        # the clump starts at its template's orientation
        centre = held.mean(axis=0) - np.mean(p["clump_spheres"], axis=0)
        overlaps, points = sphere_contacts(held, fixed, r)
        if not len(overlaps):
            raise ValueError("the held clump does not touch the fixed one")
        forces = [hertz_normal_force(_flat_modulus(p), r / 2.0, overlap) for overlap in overlaps]
        arms = np.linalg.norm(points - centre, axis=1)
        spin = w[:, -1]
        inertia = moment_about_axis(p["clump_inertia"], spin[0])
        speed = spin @ (spin[0] / np.linalg.norm(spin[0]))
        # while it still spins at more than a fifth of its start, the first twentieth left out (as pair_spin)
        spinning = (t > 0.05 * t[-1]) & (speed > 0.2 * speed[0])
        if spinning.sum() < 3:
            raise ValueError("too few frames of the spinning phase")
        slope, _ = linear_slope(t[spinning], speed[spinning])
        study = sum(spin_deceleration(p["rolling_friction"], f, arm, inertia) for f, arm in zip(forces, arms))
        mapped = sum(spin_deceleration(p["rolling_friction"], f, p["rolling_lever_arm_m"], inertia) for f in forces)
        return [_row(problem, "spin_deceleration", study, -slope),
                _row(problem, "torque_ratio", mapped / study, -slope / study)]
    if problem in ("incline_slide", "incline_stick"):
        # the block's centre of mass along the slope, after it has settled on the floor (two fifths of the run)
        along = v[:, :, 0].mean(axis=1)
        settled = t > 0.4 * t[-1]
        slope, _ = linear_slope(t[settled], along[settled])
        g = float(np.linalg.norm(p["gravity"]))
        angle = math.degrees(math.atan2(p["gravity"][0], -p["gravity"][2]))
        closed = incline_acceleration(angle, p["sliding_friction"], g)
        # a block that sticks has no acceleration to be relative to: its error is relative to g sin(theta)
        return [_row(problem, "incline_acceleration", closed, slope,
                     0.0 if closed > 0 else g * math.sin(math.radians(angle)))]
    gravity = abs(p["gravity"][2])
    if problem == "slide_to_roll":
        slip = v[:, 0, 0] - w[:, 0, 1] * r
        rolls_at = zero_crossings(t, slip)
        if not len(rolls_at):
            raise ValueError("the sphere never stopped slipping: run longer")
        closed_time, closed_speed = sliding_to_rolling(v[0, 0, 0], p["sliding_friction"], gravity)
        return [_row(problem, "rolling_time", closed_time, rolls_at[0]),
                _row(problem, "rolling_speed", closed_speed, v[-1, 0, 0])]
    if problem == "rolling":
        speed = v[:, 0, 0]
        # the rolling phase: after the sphere has settled on the floor (a tenth of the run), while it still moves
        # at more than a fifth of its start speed
        rolling = (t > 0.1 * t[-1]) & (speed > 0.2 * speed[0])
        if rolling.sum() < 3:
            raise ValueError("too few frames of the rolling phase")
        slope, _ = linear_slope(t[rolling], speed[rolling])
        return [_row(problem, "rolling_deceleration", rolling_deceleration_cdt(p["rolling_friction"], gravity),
                     -slope)]
    raise ValueError(f"unknown verification problem {problem!r}")


def verification_table(rows_by_engine: dict[str, list[VerificationRow]]) -> pd.DataFrame:
    """One row per problem, quantity and engine: closed form, measured, relative error, tolerance, pass."""
    records = []
    for engine, rows in rows_by_engine.items():
        for row in rows:
            records.append({"engine": engine, **asdict(row), "error": row.error, "passes": row.passes})
    columns = ["problem", "quantity", "engine", "closed_form", "measured", "error", "tolerance", "passes"]
    if not records:
        raise ValueError("no verification rows")
    table = pd.DataFrame.from_records(records, columns=columns)
    return table.sort_values(["problem", "quantity", "engine"], kind="stable").reset_index(drop=True)

