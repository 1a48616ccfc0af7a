"""The DEM verification suite: single-sphere problems with closed-form answers, run on every engine.

In the style of the MFiX DEM verification problems (which LAMMPS' granular tests also use), each problem is one or
two free spheres of the study's HDPE, a flat floor (or none) and gravity (or none), set moving and let go:

- ``wall_impact``: a sphere hits the floor normally without gravity, elastically (e = 1): it rebounds at its
  impact speed after the Hertz contact time of a sphere on a flat.
- ``pair_impact``: two spheres meet head-on without gravity, elastically: restitution 1 and the Hertz time of the
  pair.
- ``wall_impact_damped``, ``pair_impact_damped``: the same at e = 0.5: the rebound speed over the impact speed is
  the configured restitution (damping lengthens the contact, by 9 % at e = 0.5, so its time is not checked).
- ``slide_to_roll``: a sphere slides on the floor without spin: friction slows it at mu g and spins it up until it
  rolls at 5/7 of its speed, at t = 2 v0 / (7 mu g) (no rolling resistance).
- ``rolling``: a sphere rolls on the floor without slip: rolling resistance slows it; for a constant directional
  torque (CDT) at (5/7) mu_r g.
- ``pair_spin``, ``wall_spin``: a sphere held in place (its translation blocked, its rotation free) presses on a fixed
  sphere, or on the floor, at a set overlap, without gravity or sliding friction, and spins about an axis across the
  contact normal: the study's rolling torque ``mu_r |Fn| R`` (R = r for a sphere, :mod:`siloflow.model.rolling`)
  decelerates its spin at ``mu_r |Fn| r / I``, ``|Fn|`` Hertz's force at the overlap. The pair contact is the one the
  clumps of every case make; the wall contact shows the engines' mapping keeps the wall's torque.
- ``clump_pair_spin``: the study's two-sphere clump, held in place, lies on a fixed one, the two side by side and
  parallel, so that each sphere of the one presses on the sphere below it at the set overlap; it spins about its own
  long axis, across the two contact normals. Spinning leaves the contacts where they are (the clump is symmetric about
  that axis), and the normal forces, through the sphere centres, have no moment about it: the study's torque
  ``mu_r |Fn| R_i`` at each contact, R_i the distance from the contact point to the clump's centre of mass (1.545 mm,
  neither a tip nor the waist), decelerates its spin at ``sum mu_r |Fn| R_i / I``, I its moment of inertia about the
  long axis. The engines' mapping gives each contact the torque at the clump's mean lever arm R instead (1.673 mm,
  :mod:`siloflow.engines.liggghts.rolling`): their spin slows at R / R_i = 1.083 times the study's.
- ``incline_slide``, ``incline_stick``: a block (four spheres in a square, 3 r apart) on the floor under gravity
  tilted by 30 and 15 degrees: above the friction angle (tan 30 deg > mu) it slides at g (sin theta - mu cos theta),
  below it stays put.
- ``clump_rotation``: the study's two-sphere clump (3 mm spheres 0.75 mm apart) spins freely about an axis that is
  not a principal one: its axis precesses about the angular momentum L at |L| / I_perp, which tests the clump's
  inertia (the union of the spheres, overlap counted once).

Every problem is a :class:`VerificationCase`: engine-neutral data, written and run by an engine like any other case;
its frames (every sphere's position, velocity and spin) are what :mod:`siloflow.analysis.numerics.verification` measures.
A clump problem's ``spheres`` are its clumps (each one's centre of mass, velocity, spin and motion), and its frames
hold their spheres clump by clump, in that order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.model.cases.common import run_id
from siloflow.model.cases.particles import clump_inertia, clump_volume
from siloflow.model.cases.stages import Stage
from siloflow.model.rolling import RollingGeometry, rolling_geometry

__all__ = ["MATERIAL", "PROBLEMS", "FREE", "HELD", "FIXED", "SPIN_OVERLAP", "VerificationCase", "VerificationSphere",
           "verification_cases"]

#: The study's HDPE pellet material and its contacts (E [Pa], nu, density [kg/m3], mu, mu_r, e), one sphere size.
MATERIAL = {"youngs_modulus": 5.0e6, "poisson_ratio": 0.4, "density": 950.0, "radius": 1.5e-3}
GRAVITY = 9.81


#: How a sphere moves: freely, with its translation blocked (it still turns), or not at all.
FREE, HELD, FIXED = "free", "held", "fixed"


@dataclass(frozen=True)
class VerificationSphere:
    """A sphere: centre [m], velocity [m/s], angular velocity [rad/s] and how it moves (:data:`FREE`,
    :data:`HELD`: translation blocked, or :data:`FIXED`)."""

    position: tuple[float, float, float]
    velocity: tuple[float, float, float]
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    motion: str = FREE

    def __post_init__(self):
        if self.motion not in (FREE, HELD, FIXED):
            raise ValueError(f"motion must be {FREE!r}, {HELD!r} or {FIXED!r}, got {self.motion!r}")


@dataclass(frozen=True)
class VerificationCase:
    """One verification problem: spheres (or clumps), the floor (the plane z = 0, or none), gravity, contact law,
    duration."""

    name: str
    spheres: tuple[VerificationSphere, ...]
    floor: bool
    gravity: tuple[float, float, float]
    radius: float
    density: float
    youngs_modulus: float
    poisson_ratio: float
    sliding_friction: float
    rolling_friction: float
    restitution: float
    timestep: float
    steps: int
    output_every: int
    domain: tuple[float, float, float, float, float, float]
    #: clumps instead of spheres, one at each of ``spheres`` (its centre of mass) with the orientation of the template:
    #: the sphere centres relative to the centre of mass [m] (principal axes along x, y, z), the principal moments of
    #: inertia [kg m2] and mass [kg] (the exact union of the spheres)
    clump_spheres: tuple[tuple[float, float, float], ...] = ()
    clump_inertia: tuple[float, float, float] = (0.0, 0.0, 0.0)
    clump_mass: float = 0.0

    @property
    def n_spheres(self) -> int:
        """Spheres in the problem (those of its clumps, or the free ones)."""
        return len(self.spheres) * (len(self.clump_spheres) or 1)

    @property
    def run_id(self) -> str:
        """Directory name: the problem's name plus a hash of everything that defines it."""
        parameters = {key: value for key, value in self.__dict__.items() if key != "name"}
        return run_id(self.name, {key: repr(value) for key, value in parameters.items()})

    @property
    def rolling(self) -> RollingGeometry:
        """The rolling geometry of the problem's particle, its clump or one sphere (:mod:`siloflow.model.rolling`)."""
        centres = self.clump_spheres or ((0.0, 0.0, 0.0),)
        return rolling_geometry(centres, [self.radius] * len(centres))

    @property
    def mass(self) -> float:
        """Mass of one sphere [kg], or of the clump."""
        return self.clump_mass if self.clump_spheres else self.density * 4.0 / 3.0 * math.pi * self.radius**3

    def stages(self) -> tuple[Stage, ...]:
        return (Stage("release", {"duration_s": self.steps * self.timestep,
                              "frame_interval_s": self.output_every * self.timestep}, ("frames",)),)

    def summary(self) -> dict:
        """Plain-data summary (``case.json``)."""
        return {"case": "verification", "run_id": self.run_id, "problem": self.name, "timestep_s": self.timestep,
                "steps": self.steps, "frame_interval_s": self.output_every * self.timestep,
                "mass_kg": self.mass, "initial_angular_velocity": self.spheres[0].angular_velocity,
                # the lever arm the engines' rolling law is given (siloflow.model.rolling), the radius for a sphere
                "rolling_lever_arm_m": self.rolling.lever_arm,
                **{key: value for key, value in self.__dict__.items() if key not in ("spheres", "name")}}


def _hertz_time(radius_eff: float, mass_eff: float, modulus_eff: float, speed: float) -> float:
    # the undamped Hertz contact time, to size the time step and the run (siloflow.analysis.numerics.verification has the
    # closed form the results are checked against)
    overlap = (15.0 * mass_eff * speed**2 / (16.0 * modulus_eff * math.sqrt(radius_eff))) ** 0.4
    return 2.94 * overlap / speed


#: Problem name -> (impact speed [m/s] or sliding speed, restitution, sliding friction, rolling friction).
PROBLEMS = {
    "wall_impact": {"speed": 1.0, "restitution": 1.0, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "pair_impact": {"speed": 0.5, "restitution": 1.0, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "wall_impact_damped": {"speed": 1.0, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "pair_impact_damped": {"speed": 0.5, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "slide_to_roll": {"speed": 0.2, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "rolling": {"speed": 0.05, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.1},
    "incline_slide": {"angle_deg": 30.0, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "incline_stick": {"angle_deg": 15.0, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.0},
    "clump_rotation": {"speed": 100.0, "restitution": 0.5, "sliding_friction": 0.35, "rolling_friction": 0.0},
    # spin [rad/s]; no sliding friction, so that the rolling torque alone acts on the spin
    "pair_spin": {"speed": 50.0, "restitution": 0.5, "sliding_friction": 0.0, "rolling_friction": 0.1},
    "wall_spin": {"speed": 50.0, "restitution": 0.5, "sliding_friction": 0.0, "rolling_friction": 0.1},
    "clump_pair_spin": {"speed": 50.0, "restitution": 0.5, "sliding_friction": 0.0, "rolling_friction": 0.1},
}
#: The overlap of the spin problems' contact, as a fraction of the radius: about four times the weight's (-).
SPIN_OVERLAP = 0.002
#: The study's two-sphere clump: centres along x, 0.75 mm apart.
CLUMP_HALF_SPACING = 0.375e-3


def verification_cases(steps_per_contact: int = 100) -> dict[str, VerificationCase]:
    """The suite, keyed by problem name; the time step resolves each contact in ``steps_per_contact`` steps."""
    r, rho, e_mod, nu = (MATERIAL[key] for key in ("radius", "density", "youngs_modulus", "poisson_ratio"))
    mass = rho * 4.0 / 3.0 * math.pi * r**3
    # sphere on a flat of the same material: E* = E / (2 (1 - nu^2)), R* = r, m* = m
    flat = _hertz_time(r, mass, e_mod / (2.0 * (1.0 - nu**2)), PROBLEMS["wall_impact"]["speed"])
    pair = _hertz_time(r / 2.0, mass / 2.0, e_mod / (2.0 * (1.0 - nu**2)), 2.0 * PROBLEMS["pair_impact"]["speed"])
    # resting contact under gravity: the Hertz time at a small speed bounds the stiffest contact
    resting = _hertz_time(r, mass, e_mod / (2.0 * (1.0 - nu**2)), 1.0)
    box = 0.02
    cases = {}

    def case(name, spheres, floor, gravity, contact_time, duration):
        problem = PROBLEMS[name]
        timestep = contact_time / steps_per_contact
        steps = int(math.ceil(duration / timestep))
        cases[name] = VerificationCase(
            name=name, spheres=tuple(spheres), floor=floor, gravity=gravity, radius=r, density=rho,
            youngs_modulus=e_mod, poisson_ratio=nu, sliding_friction=problem["sliding_friction"],
            rolling_friction=problem["rolling_friction"], restitution=problem["restitution"], timestep=timestep,
            steps=steps, output_every=1 if duration < 20 * contact_time else max(1, steps // 400),
            domain=(-box, box + 0.05, -box, box, -box, box))

    gap = 0.1 * r
    for name in ("wall_impact", "wall_impact_damped"):
        v = PROBLEMS[name]["speed"]
        case(name, [VerificationSphere((0.0, 0.0, r + gap), (0.0, 0.0, -v))], True, (0.0, 0.0, 0.0),
             flat, 2.0 * gap / v + 3.0 * flat)
    for name in ("pair_impact", "pair_impact_damped"):
        v = PROBLEMS[name]["speed"]
        case(name, [VerificationSphere((-r - gap, 0.0, 0.0), (v, 0.0, 0.0)),
                    VerificationSphere((r + gap, 0.0, 0.0), (-v, 0.0, 0.0))], False, (0.0, 0.0, 0.0),
             pair, gap / v + 3.0 * pair)
    # the sphere sits on the floor at its static overlap (none: it settles in a few contact times, which the
    # analysis leaves out)
    v = PROBLEMS["slide_to_roll"]["speed"]
    mu = PROBLEMS["slide_to_roll"]["sliding_friction"]
    case("slide_to_roll", [VerificationSphere((0.0, 0.0, r), (v, 0.0, 0.0))], True, (0.0, 0.0, -GRAVITY),
         resting, 2.0 * (2.0 * v / (7.0 * mu * GRAVITY)))
    v = PROBLEMS["rolling"]["speed"]
    mu_r = PROBLEMS["rolling"]["rolling_friction"]
    case("rolling", [VerificationSphere((0.0, 0.0, r), (v, 0.0, 0.0), (0.0, v / r, 0.0))], True,
         (0.0, 0.0, -GRAVITY), resting, 0.8 * v / (5.0 / 7.0 * mu_r * GRAVITY))
    # a sphere held above a fixed one (or the floor) at the set overlap, spinning about x across the normal z; the run
    # lasts 0.8 of the time the closed form stops it in
    inertia = 0.4 * mass * r * r
    for name, floor, reduced in (("pair_spin", False, r / 2.0), ("wall_spin", True, r)):
        spin = PROBLEMS[name]["speed"]
        overlap = SPIN_OVERLAP * r
        force = 4.0 / 3.0 * e_mod / (2.0 * (1.0 - nu**2)) * math.sqrt(reduced) * overlap**1.5
        stop = spin * inertia / (PROBLEMS[name]["rolling_friction"] * force * r)
        held = VerificationSphere((0.0, 0.0, (2.0 * r if not floor else r) - overlap), (0.0, 0.0, 0.0),
                                  (spin, 0.0, 0.0), HELD)
        spheres = [held] if floor else [VerificationSphere((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), motion=FIXED), held]
        case(name, spheres, floor, (0.0, 0.0, 0.0), resting, 0.8 * stop)
    centres = np.array([[-CLUMP_HALF_SPACING, 0.0, 0.0], [CLUMP_HALF_SPACING, 0.0, 0.0]])
    tensor = clump_inertia(centres, [r, r], rho)
    clump = {"clump_spheres": tuple(tuple(map(float, c)) for c in centres),
             "clump_inertia": tuple(float(v) for v in np.diag(tensor)),
             "clump_mass": rho * clump_volume(centres, [r, r])}
    # the clump held above a fixed one, both along x, at the set overlap of each sphere with the one below it,
    # spinning about its long axis x (across the normals z), a turn that moves no sphere of it. Neither a tip nor the
    # waist would do: spun across the normal, a clump standing on its tip tilts away from it, the tip's normal force
    # gaining a moment about the centre of mass, and a sphere at the waist touches both spheres, along normals not
    # across the spin. The run lasts 0.8 of the time the study's torque stops it in.
    problem = PROBLEMS["clump_pair_spin"]
    spin, overlap = problem["speed"], SPIN_OVERLAP * r
    force = 4.0 / 3.0 * e_mod / (2.0 * (1.0 - nu**2)) * math.sqrt(r / 2.0) * overlap**1.5
    arm = math.hypot(CLUMP_HALF_SPACING, r - overlap / 2.0)
    stop = spin * clump["clump_inertia"][0] / (2.0 * problem["rolling_friction"] * force * arm)
    timestep = resting / steps_per_contact
    steps = int(math.ceil(0.8 * stop / timestep))
    cases["clump_pair_spin"] = VerificationCase(
        name="clump_pair_spin", spheres=(VerificationSphere((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), motion=FIXED),
                                         VerificationSphere((0.0, 0.0, 2.0 * r - overlap), (0.0, 0.0, 0.0),
                                                            (spin, 0.0, 0.0), HELD)),
        floor=False, gravity=(0.0, 0.0, 0.0), radius=r, density=rho, youngs_modulus=e_mod, poisson_ratio=nu,
        sliding_friction=problem["sliding_friction"], rolling_friction=problem["rolling_friction"],
        restitution=problem["restitution"], timestep=timestep, steps=steps,
        output_every=1 if 0.8 * stop < 20 * resting else max(1, steps // 400),
        domain=(-box, box, -box, box, -box, box), **clump)
    # a free clump spinning at 100 rad/s about an axis 30 degrees off its long axis (no contacts: the time step only
    # resolves the rotation, 2000 steps a turn)
    spin = PROBLEMS["clump_rotation"]["speed"]
    omega = (spin * math.cos(math.radians(30.0)), spin * math.sin(math.radians(30.0)), 0.0)
    turn = 2.0 * math.pi / spin
    problem = PROBLEMS["clump_rotation"]
    steps = 4000 * 3
    cases["clump_rotation"] = VerificationCase(
        name="clump_rotation", spheres=(VerificationSphere((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), omega),), floor=False,
        gravity=(0.0, 0.0, 0.0), radius=r, density=rho, youngs_modulus=e_mod, poisson_ratio=nu,
        sliding_friction=problem["sliding_friction"], rolling_friction=0.0, restitution=problem["restitution"],
        timestep=turn / 2000.0, steps=steps, output_every=20, domain=(-box, box, -box, box, -box, box), **clump)
    # a block of four spheres on the floor, gravity tilted about y: it slides along +x or sticks
    block = np.array([[sx * 1.5 * r, sy * 1.5 * r, 0.0] for sx in (-1, 1) for sy in (-1, 1)])
    block_tensor = clump_inertia(block, [r] * 4, rho)
    for name in ("incline_slide", "incline_stick"):
        problem = PROBLEMS[name]
        angle = math.radians(problem["angle_deg"])
        timestep = resting / steps_per_contact
        steps = int(math.ceil(0.1 / timestep))
        cases[name] = VerificationCase(
            name=name, spheres=(VerificationSphere((0.0, 0.0, 1.05 * r), (0.0, 0.0, 0.0)),), floor=True,
            gravity=(GRAVITY * math.sin(angle), 0.0, -GRAVITY * math.cos(angle)), radius=r, density=rho,
            youngs_modulus=e_mod, poisson_ratio=nu, sliding_friction=problem["sliding_friction"], rolling_friction=0.0,
            restitution=problem["restitution"], timestep=timestep, steps=steps, output_every=max(1, steps // 400),
            domain=(-box, box + 0.05, -box, box, -box, box), clump_spheres=tuple(tuple(map(float, c)) for c in block),
            clump_inertia=tuple(float(v) for v in np.diag(block_tensor)), clump_mass=4 * mass)
    return cases
