"""Engine-neutral physics helpers: time step, seeds.

All quantities in SI units.
"""

from __future__ import annotations

import math


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


def steps_for(duration: float, timestep: float) -> int:
    """Whole number of time steps (at least one) that covers ``duration`` (s) at ``timestep`` (s)."""
    if duration <= 0 or timestep <= 0:
        raise ValueError(f"duration and timestep must be positive, got {duration!r}, {timestep!r}")
    return max(1, int(math.ceil(duration / timestep - 1e-9)))
