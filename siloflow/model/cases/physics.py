"""Engine-neutral physics helpers: time step, seeds.

All quantities in SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


def rayleigh_time(radius: float, density: float, youngs_modulus: float, poisson_ratio: float) -> float:
    """Rayleigh time of a sphere, the period of a Rayleigh surface wave across it.

    t_R = pi R sqrt(rho / G) / (0.1631 nu + 0.8766), with shear modulus G = E / (2 (1 + nu)).

    Parameters
    ----------
    radius : float
        Sphere radius R (m).
    density : float
        Solid density rho (kg/m^3).
    youngs_modulus : float
        Young's modulus E (Pa).
    poisson_ratio : float
        Poisson ratio nu (-).

    Returns
    -------
    float
        Rayleigh time (s).
    """
    for name, value in (("radius", radius), ("density", density), ("youngs_modulus", youngs_modulus)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    if not 0 < poisson_ratio < 0.5:
        raise ValueError(f"poisson_ratio must lie in (0, 0.5), got {poisson_ratio!r}")
    shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson_ratio))
    return math.pi * radius * math.sqrt(density / shear_modulus) / (0.1631 * poisson_ratio + 0.8766)


def hertz_contact_time(
    radius: float, density: float, youngs_modulus: float, poisson_ratio: float, impact_velocity: float
) -> float:
    """Duration of a head-on Hertz impact of two identical spheres.

    t_H = 2.87 (m*^2 / (R* E*^2 v))^(1/5), with the effective mass m* = m/2, radius R* = R/2 and modulus
    E* = E / (2 (1 - nu^2)) of two equal spheres (Johnson, Contact Mechanics, section 11.4; the form
    LIGGGHTS' ``fix check/timestep/gran`` uses). A sphere of a clump is given its own mass, not the clump's:
    the lighter body makes the shorter contact, so the bound holds for every contact the sphere takes part in.

    Parameters
    ----------
    radius : float
        Sphere radius R (m).
    density : float
        Solid density rho (kg/m^3).
    youngs_modulus : float
        Young's modulus E (Pa).
    poisson_ratio : float
        Poisson ratio nu (-).
    impact_velocity : float
        Relative normal velocity of the impact v (m/s); faster impacts are shorter.

    Returns
    -------
    float
        Contact duration (s).
    """
    rayleigh_time(radius, density, youngs_modulus, poisson_ratio)  # the same checks of the material
    if not (math.isfinite(impact_velocity) and impact_velocity > 0):
        raise ValueError(f"impact_velocity must be a positive finite number, got {impact_velocity!r}")
    mass = density * 4.0 / 3.0 * math.pi * radius**3
    effective_modulus = youngs_modulus / (2.0 * (1.0 - poisson_ratio**2))
    return 2.87 * ((0.5 * mass) ** 2 / (0.5 * radius * effective_modulus**2 * impact_velocity)) ** 0.2


@dataclass(frozen=True)
class TimestepChoice:
    """A time step and the two stability limits it was chosen from.

    Attributes
    ----------
    timestep : float
        The time step: the smaller of the two limits (s).
    rayleigh_time : float
        Rayleigh time of the smallest sphere (s).
    hertz_time : float
        Hertz contact duration of two smallest spheres at the largest expected impact velocity (s).
    impact_velocity : float
        The largest relative velocity the case expects at an impact (m/s).
    limited_by : str
        ``"rayleigh"`` or ``"hertz"``: the criterion that set the time step.
    scale : float
        The particle model's factor on the smaller limit (-).
    """

    timestep: float
    rayleigh_time: float
    hertz_time: float
    impact_velocity: float
    limited_by: str
    scale: float = 1.0


class ChosenTimestep:
    """Mixin for a case that holds a ``timestep_choice``: its time step and Rayleigh time as attributes."""

    timestep_choice: TimestepChoice

    @property
    def timestep(self) -> float:
        """Time step (s)."""
        return self.timestep_choice.timestep

    @property
    def rayleigh_time(self) -> float:
        """Rayleigh time of the smallest sphere (s)."""
        return self.timestep_choice.rayleigh_time

    def timestep_summary(self) -> dict:
        """The time step and the limits it was chosen from, for ``case.json``."""
        choice = self.timestep_choice
        return {"rayleigh_time_s": choice.rayleigh_time, "hertz_time_s": choice.hertz_time,
                "impact_velocity_m_s": choice.impact_velocity, "timestep_limited_by": choice.limited_by,
                "timestep_scale": choice.scale, "timestep_s": choice.timestep}


def stable_timestep(
    radius: float,
    density: float,
    youngs_modulus: float,
    poisson_ratio: float,
    impact_velocity: float,
    rayleigh_fraction: float,
    hertz_fraction: float,
    scale: float = 1.0,
) -> TimestepChoice:
    """The time step of a run from two explicit stability criteria.

    dt = s min(f_R t_R, f_H t_H(v_max)): a fraction of the Rayleigh time (a surface wave must not cross a sphere
    within one step) and a fraction of the Hertz contact duration at the largest impact velocity the case
    expects (an impact must span enough steps to integrate its force). These are the two limits LIGGGHTS'
    ``fix check/timestep/gran`` checks, both for one pair of spheres. The particle model's scale ``s`` accounts
    for a clump whose spheres overlap so much that two clumps touch with many sphere pairs at once: their contact
    is that many times stiffer than one pair's.

    Parameters
    ----------
    radius, density, youngs_modulus, poisson_ratio : float
        The smallest sphere's radius (m), solid density (kg/m^3), Young's modulus (Pa) and Poisson ratio (-).
    impact_velocity : float
        Largest expected relative impact velocity v_max (m/s).
    rayleigh_fraction, hertz_fraction : float
        f_R and f_H (-), each in (0, 1].
    scale : float, optional
        s (-), in (0, 1] (default 1).

    Returns
    -------
    TimestepChoice
    """
    for name, value in (("rayleigh_fraction", rayleigh_fraction), ("hertz_fraction", hertz_fraction),
                        ("scale", scale)):
        if not (math.isfinite(value) and 0 < value <= 1):
            raise ValueError(f"{name} must lie in (0, 1], got {value!r}")
    t_rayleigh = rayleigh_time(radius, density, youngs_modulus, poisson_ratio)
    t_hertz = hertz_contact_time(radius, density, youngs_modulus, poisson_ratio, impact_velocity)
    by_rayleigh, by_hertz = rayleigh_fraction * t_rayleigh, hertz_fraction * t_hertz
    return TimestepChoice(
        timestep=scale * min(by_rayleigh, by_hertz),
        rayleigh_time=t_rayleigh,
        hertz_time=t_hertz,
        impact_velocity=impact_velocity,
        limited_by="rayleigh" if by_rayleigh <= by_hertz else "hertz",
        scale=scale,
    )


def free_fall_velocity(start_velocity: float, height: float, gravity: float) -> float:
    """Speed after a free fall of ``height`` (m) that starts downwards at ``start_velocity`` (m/s)."""
    return math.sqrt(start_velocity**2 + 2.0 * gravity * max(height, 0.0))


def free_fall_time(start_velocity: float, height: float, gravity: float) -> float:
    """Time (s) of a free fall of ``height`` (m) that starts downwards at ``start_velocity`` (m/s):
    the root of v t + g t^2 / 2 = h, as 2 h / (v + sqrt(v^2 + 2 g h)). The textbook (sqrt(v^2 + 2 g h) - v) / g
    subtracts two nearly equal numbers when the start is fast or the fall short, down to 0 for a fall that takes
    time (1e-15 m at 100 m/s)."""
    if not (height >= 0 and gravity > 0 and start_velocity >= 0):
        raise ValueError(f"need height >= 0, gravity > 0 and start_velocity >= 0, got {height!r}, {gravity!r}, "
                         f"{start_velocity!r}")
    if height == 0:
        return 0.0
    return 2.0 * height / (start_velocity + math.sqrt(start_velocity**2 + 2.0 * gravity * height))


def is_prime(number: int) -> bool:
    """Whether an integer is prime (trial division; seeds are small)."""
    if number < 2:
        return False
    if number % 2 == 0:
        return number == 2
    divisor = 3
    while divisor * divisor <= number:
        if number % divisor == 0:
            return False
        divisor += 2
    return True


def engine_seeds(seed: int, count: int) -> list[int]:
    """Distinct primes above 10000 derived from one user seed.

    LIGGGHTS wants each random generator seeded with a prime larger than 10000. Seed ``s`` maps to the
    primes that follow ``10000 + 1000 s``, so different user seeds give disjoint seed sets for
    ``count`` up to about 100.
    """
    if seed < 1:
        raise ValueError(f"seed must be a positive integer, got {seed!r}")
    primes: list[int] = []
    candidate = 10000 + 1000 * seed
    while len(primes) < count:
        candidate += 1
        if is_prime(candidate):
            primes.append(candidate)
    return primes


#: The most time steps one stage may take: 2^31 - 1, the largest N of LIGGGHTS' ``run N`` (a 32-bit int; a larger
#: one fails only when the deck reaches it, hours into the run), and on any engine half a year of one core for the
#: default config's silo (10,000 spheres at 0.7 microseconds a sphere-step).
MAX_STEPS = 2**31 - 1


def check_steps(steps: float, what: str = "a stage") -> float:
    """``steps`` if it is at most :data:`MAX_STEPS`.

    Raises
    ------
    ValueError
        Naming ``what`` and the count, when the plan would take more steps than one engine run command (or an
        infinite or NaN count).
    """
    if not steps <= MAX_STEPS:
        raise ValueError(f"{what} would take {steps:.3g} time steps, more than the {MAX_STEPS} (2^31 - 1) one engine "
                         "run command takes: raise the time step fractions or shorten the stage")
    return steps


def steps_for(duration: float, timestep: float) -> int:
    """Whole number of time steps (at least one) that covers ``duration`` (s) at ``timestep`` (s).

    Raises
    ------
    ValueError
        For a duration or time step that is not positive, or a count beyond :data:`MAX_STEPS` (also one too large
        for a float, which ``int`` would refuse with an OverflowError the workflow does not report as a
        configuration error).
    """
    if duration <= 0 or timestep <= 0:
        raise ValueError(f"duration and timestep must be positive, got {duration!r}, {timestep!r}")
    ratio = check_steps(duration / timestep, f"{duration!r} s at a time step of {timestep!r} s")
    return max(1, int(math.ceil(ratio - 1e-9)))
