"""Closed forms of the DEM verification problems and what is measured on a run's sphere trajectories.

Closed forms (SI units):

- Hertz contact time of an elastic impact at speed v (effective mass m*, radius R*, modulus E*):
  ``t_c = C delta_max / v`` with ``delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5)`` and
  ``C = 2 int_0^1 (1 - x^(5/2))^(-1/2) dx = (4/5) sqrt(pi) Gamma(2/5) / Gamma(9/10) = 2.9432...``.
- A sphere sliding without spin on a flat with friction mu: it rolls from ``t* = 2 v0 / (7 mu g)`` on, at
  ``5/7 v0`` (solid sphere, I = 2/5 m r^2, no rolling resistance).
- A sphere rolling without slip against a constant directional torque ``mu_r r |Fn|``: it decelerates at
  ``(5/7) mu_r g``.
- A sphere held in place against a fixed sphere or a flat at overlap delta, spinning across the contact normal: the
  study's rolling torque ``mu_r |Fn| r`` (:mod:`siloflow.model.rolling`) decelerates its spin at
  ``mu_r |Fn| r / I``, with Hertz's ``|Fn| = (4/3) E* sqrt(R*) delta^(3/2)`` and ``I = (2/5) m r^2``.
- A clump held in place against a fixed one, spinning about a principal axis across its contact normals without
  moving its contacts: the study's torques decelerate it at ``sum_k mu_r |Fn_k| R_k / I``, R_k the distance from
  contact k's point (the middle of the overlap, :func:`sphere_contacts`) to the clump's centre of mass and I its
  moment of inertia about the spin axis (:func:`moment_about_axis`).
- A block on a flat under gravity tilted by theta, friction mu: it slides at ``g (sin theta - mu cos theta)`` when
  ``tan theta > mu`` and stays put otherwise.
- A free symmetric top (principal moments ``I_axis, I_perp, I_perp``) spinning at ``omega`` (body axes = space axes
  at t = 0): its symmetry axis precesses about the angular momentum ``L = I omega`` at ``|L| / I_perp``.

Measurements take arrays (times, gaps, velocities), never files.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special, stats

from siloflow.model.checks import finite_array

__all__ = [
    "HERTZ_TIME_CONSTANT",
    "contact_interval",
    "hertz_contact_time",
    "axis_precession_angle",
    "incline_acceleration",
    "linear_slope",
    "precession_rate",
    "rolling_deceleration_cdt",
    "hertz_normal_force",
    "moment_about_axis",
    "spin_deceleration",
    "sliding_to_rolling",
    "sphere_contacts",
    "zero_crossings",
]

#: ``2 int_0^1 (1 - x^(5/2))^(-1/2) dx``: the Hertz contact time in units of delta_max / v.
HERTZ_TIME_CONSTANT = 0.8 * math.sqrt(math.pi) * float(special.gamma(0.4) / special.gamma(0.9))


def _positive(name: str, value: float) -> float:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def hertz_contact_time(mass: float, radius: float, modulus: float, speed: float) -> float:
    """Duration [s] of an undamped Hertz impact.

    Parameters
    ----------
    mass, radius, modulus : float
        Effective mass m* [kg], radius R* [m] and modulus E* [Pa] of the contact (sphere on a rigid flat of the
        same material: m, r, E / (2 (1 - nu^2)); two equal spheres: m / 2, r / 2, the same E*).
    speed : float
        Normal approach speed [m/s].
    """
    mass, radius, modulus, speed = (_positive(n, v) for n, v in
                                    (("mass", mass), ("radius", radius), ("modulus", modulus), ("speed", speed)))
    overlap = (15.0 * mass * speed**2 / (16.0 * modulus * math.sqrt(radius))) ** 0.4
    return HERTZ_TIME_CONSTANT * overlap / speed


def sliding_to_rolling(speed: float, friction: float, gravity: float) -> tuple[float, float]:
    """(time [s] at which a sphere sliding at ``speed`` without spin starts to roll, its rolling speed [m/s])."""
    speed, friction, gravity = (_positive(n, v) for n, v in
                                (("speed", speed), ("friction", friction), ("gravity", gravity)))
    return 2.0 * speed / (7.0 * friction * gravity), 5.0 / 7.0 * speed


def rolling_deceleration_cdt(rolling_friction: float, gravity: float) -> float:
    """Deceleration [m/s^2] of a solid sphere rolling without slip against a constant directional torque."""
    return 5.0 / 7.0 * _positive("rolling_friction", rolling_friction) * _positive("gravity", gravity)


def hertz_normal_force(modulus: float, radius: float, overlap: float) -> float:
    """Hertz's elastic normal force [N], ``(4/3) E* sqrt(R*) delta^(3/2)``, from the effective modulus E* [Pa] and
    radius R* [m] of the contact (see :func:`hertz_contact_time`) and its overlap delta [m]."""
    return 4.0 / 3.0 * _positive("modulus", modulus) * math.sqrt(_positive("radius", radius)) * _positive(
        "overlap", overlap) ** 1.5


def spin_deceleration(rolling_friction: float, normal_force: float, lever_arm: float, inertia: float) -> float:
    """Angular deceleration [rad/s^2] of a particle spinning against the study's rolling torque, ``mu_r |Fn| R / I``:
    coefficient (-), normal force [N], distance from the contact point to the centre of mass [m], moment of inertia
    about the spin axis [kg m^2]."""
    return (_positive("rolling_friction", rolling_friction) * _positive("normal_force", normal_force)
            * _positive("lever_arm", lever_arm) / _positive("inertia", inertia))


def sphere_contacts(first, second, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """The contacts between two sets of spheres of one radius.

    Parameters
    ----------
    first, second : array_like, shape (k, 3) and (l, 3)
        Sphere centres [m].
    radius : float
        The spheres' radius [m].

    Returns
    -------
    overlaps : numpy.ndarray, shape (m,)
        ``2 radius`` less the distance between the centres [m], of every pair (a sphere of ``first``, one of
        ``second``) that overlaps, pairs in the order of ``first`` then ``second``.
    points : numpy.ndarray, shape (m, 3)
        Each contact's point [m]: the middle of the overlap, on the line of centres (halfway between the centres).
    """
    a = finite_array("first", first, ndim=2)
    b = finite_array("second", second, ndim=2)
    radius = _positive("radius", radius)
    if a.shape[1] != 3 or b.shape[1] != 3:
        raise ValueError(f"centres must be (k, 3), got {a.shape} and {b.shape}")
    pairs = [(i, j) for i in range(len(a)) for j in range(len(b))
             if np.linalg.norm(a[i] - b[j]) < 2.0 * radius]
    overlaps = np.array([2.0 * radius - np.linalg.norm(a[i] - b[j]) for i, j in pairs]).reshape(-1)
    points = np.array([(a[i] + b[j]) / 2.0 for i, j in pairs]).reshape(-1, 3)
    return overlaps, points


def moment_about_axis(inertia, axis) -> float:
    """Moment of inertia [kg m2] of a body about an axis through its centre of mass: the principal moments ``inertia``
    (3,) [kg m2] along the principal axes, and the axis's direction ``axis`` (3,) in those axes, of any length > 0."""
    moments = finite_array("inertia", inertia)
    direction = finite_array("axis", axis)
    if moments.shape != (3,) or direction.shape != (3,) or np.any(moments <= 0) or not np.any(direction):
        raise ValueError(f"inertia (3 moments > 0) and a non-zero axis (3,) expected, got {moments} and {direction}")
    direction = direction / np.linalg.norm(direction)
    return float(moments @ direction**2)


def incline_acceleration(angle_deg: float, friction: float, gravity: float) -> float:
    """Acceleration [m/s^2] of a block on an incline of ``angle_deg`` with sliding friction ``friction``: zero when
    friction holds it (``tan(angle) <= friction``)."""
    angle = math.radians(_positive("angle_deg", angle_deg))
    gravity = _positive("gravity", gravity)
    if not (isinstance(friction, (int, float)) and math.isfinite(friction) and friction >= 0):
        raise ValueError(f"friction must be a finite number >= 0, got {friction!r}")
    return max(0.0, gravity * (math.sin(angle) - friction * math.cos(angle)))


def precession_rate(inertia, angular_velocity) -> float:
    """Rate [rad/s] at which the symmetry axis (the first principal axis) of a free symmetric top precesses about
    its angular momentum.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments [kg m2]: the symmetry axis first, then the two equal ones (their mean is used).
    angular_velocity : array_like, shape (3,)
        Angular velocity [rad/s] in the principal frame.
    """
    moments = finite_array("inertia", inertia)
    omega = finite_array("angular_velocity", angular_velocity)
    if moments.shape != (3,) or omega.shape != (3,) or np.any(moments <= 0):
        raise ValueError(f"inertia (3 moments > 0) and angular_velocity (3,) expected, got {moments} and {omega}")
    return float(np.linalg.norm(moments * omega) / moments[1:].mean())


def axis_precession_angle(axis, momentum) -> np.ndarray:
    """Unwrapped angle [rad] of the unit vectors ``axis`` ``(n, 3)`` about the direction of ``momentum`` (3,):
    the angle of each vector's part perpendicular to it, in a fixed basis of that plane."""
    vectors = finite_array("axis", axis, ndim=2)
    direction = finite_array("momentum", momentum)
    direction = direction / np.linalg.norm(direction)
    helper = np.eye(3)[int(np.argmin(np.abs(direction)))]
    first = np.cross(direction, helper)
    first /= np.linalg.norm(first)
    second = np.cross(direction, first)
    return np.unwrap(np.arctan2(vectors @ second, vectors @ first))


def zero_crossings(times, values) -> np.ndarray:
    """Times [s] at which ``values`` changes sign, by linear interpolation between the samples around each change
    (a sample at exactly zero counts once, at its own time)."""
    t = finite_array("times", times)
    y = finite_array("values", values)
    if t.shape != y.shape or t.ndim != 1:
        raise ValueError(f"times and values must be 1-d of one length, got {t.shape} and {y.shape}")
    sign = np.sign(y)
    found = []
    for i in range(len(y) - 1):
        if sign[i] == 0 and (i == 0 or sign[i - 1] != 0):
            found.append(t[i])
        elif sign[i] * sign[i + 1] < 0:
            found.append(t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i]))
    if len(y) and sign[-1] == 0 and (len(y) == 1 or sign[-2] != 0):
        found.append(t[-1])
    return np.asarray(found, dtype=float)


def contact_interval(times, gaps) -> tuple[float, float]:
    """(start, end) [s] of the first contact: the first interval in which the surface gap [m] is negative.

    Raises
    ------
    ValueError
        When the gap never turns negative, or the contact has not ended by the last sample.
    """
    crossings = zero_crossings(times, gaps)
    gap = np.asarray(gaps, dtype=float)
    if not np.any(gap < 0):
        raise ValueError("the spheres never touch: the gap is never negative")
    if gap[0] < 0:
        raise ValueError("the spheres touch at the first sample: start them apart")
    if len(crossings) < 2:
        raise ValueError("the contact has not ended by the last sample: run longer")
    return float(crossings[0]), float(crossings[1])


def linear_slope(times, values) -> tuple[float, float]:
    """Least-squares slope of ``values`` over ``times`` and its standard error (``scipy.stats.linregress``)."""
    t = finite_array("times", times)
    y = finite_array("values", values)
    if t.shape != y.shape or t.size < 3:
        raise ValueError(f"need at least 3 samples of one length, got {t.shape} and {y.shape}")
    fit = stats.linregress(t, y)
    return float(fit.slope), float(fit.stderr)
