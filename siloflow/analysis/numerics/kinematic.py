"""The kinematic model of silo flow (Nedderman and Tuzun 1979) fitted to a velocity profile.

In the kinematic model the vertical velocity obeys the diffusion equation
``d v_z / d z = B d^2 v_z / d x^2`` with the height above the outlet playing the role of time; for a
point outlet the solution is the Gaussian ``v_z(x) = A exp(-x^2 / (4 B z))`` across the width, and the
horizontal velocity is ``u = -B d v_z / d x``. Pure functions on numpy arrays; SI units (m, m/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import curve_fit

from siloflow.model.checks import non_negative_number, positive_number
from siloflow.analysis.numerics.profiles import checked_profile

__all__ = ["KinematicFit", "kinematic_velocity", "fit_kinematic_constant", "kinematic_horizontal_velocity"]


@dataclass(frozen=True)
class KinematicFit:
    """Least-squares fit of ``v_z(x) = A exp(-x^2 / (4 B z))`` at one height.

    Attributes
    ----------
    B : float
        Kinematic constant (diffusion length) [m], corrected for the kernel width if asked.
    A : float
        Centreline velocity of the fit [m/s] (negative for downward flow).
    z : float
        Height above the outlet used in the model [m].
    B_standard_error : float
        Standard error of B from the fit covariance [m].
    rms_residual : float
        Root-mean-square residual of the fit [m/s].
    """

    B: float
    A: float
    z: float
    B_standard_error: float
    rms_residual: float


def kinematic_velocity(x, z: float, A: float, B: float) -> np.ndarray:
    """Kinematic-model profile ``v_z(x) = A exp(-x^2 / (4 B z))`` [m/s].

    Parameters
    ----------
    x : array_like
        Horizontal position from the axis [m].
    z : float
        Height above the outlet plane [m], > 0 (the model's virtual origin is the outlet).
    A : float
        Centreline velocity [m/s].
    B : float
        Kinematic constant [m], > 0.
    """
    x = np.asarray(x, dtype=float)
    z = positive_number("z", z)
    B = positive_number("B", B)
    return float(A) * np.exp(-(x**2) / (4.0 * B * z))


def fit_kinematic_constant(x, v_z, z: float, kernel_width: float = 0.0) -> KinematicFit:
    """Fit the kinematic model ``v_z(x) = A exp(-x^2 / (4 B z))`` to a profile.

    In the kinematic model (Nedderman and Tuzun 1979) the vertical velocity obeys the
    diffusion equation ``d v_z / d z = B d^2 v_z / d x^2`` with the height above the outlet
    playing the role of time; for a point outlet the solution is a Gaussian of variance
    ``2 B z`` across the width. Here ``z`` is the distance above the outlet plane (z = 0,
    the virtual origin placed at the outlet; a finite slot shifts the true origin a little
    below it, which the fitted B absorbs).

    Parameters
    ----------
    x : array_like, shape (n,)
        Node x coordinates, strictly increasing [m]; the profile is centred on x = 0.
    v_z : array_like, shape (n,)
        Vertical velocity [m/s].
    z : float
        Height of the profile above the outlet plane [m], > 0.
    kernel_width : float, optional
        Standard deviation w of a Gaussian coarse-graining kernel the profile was smoothed
        with [m] (default 0: no correction). Smoothing convolves the Gaussian profile, so
        its variance becomes ``2 B z + w^2``; with ``kernel_width`` given the fitted variance
        is corrected, ``B = (sigma_fit^2 - w^2) / (2 z)``.

    Returns
    -------
    KinematicFit

    Notes
    -----
    Nonlinear least squares on ``v_z`` itself (scipy ``curve_fit``, unweighted), started
    at the moments of ``|v_z|``. The fit is over all given points; pass a slice of the
    profile to restrict it (e.g. to leave out wall slip).
    """
    x, v = checked_profile(x, v_z, min_points=3)
    z = positive_number("z", z)
    kernel_width = non_negative_number("kernel_width", kernel_width)
    speed = np.abs(v)
    if not np.any(speed > 0.0):
        raise ValueError("v_z is zero everywhere; nothing to fit")

    peak = int(np.argmax(speed))
    amplitude0 = float(v[peak])
    variance0 = float(np.sum(x**2 * speed) / np.sum(speed))
    if variance0 <= 0.0:
        variance0 = float(np.min(np.diff(x))) ** 2
    scale = float(np.max(speed))

    def model(xs, a, log_variance):
        return a * np.exp(-(xs**2) / (2.0 * np.exp(log_variance)))

    try:
        parameters, covariance = curve_fit(
            model, x, v / scale, p0=(amplitude0 / scale, math.log(variance0)), maxfev=10_000
        )
    except RuntimeError as error:  # no convergence
        raise ValueError(f"v_z: the Gaussian fit did not converge ({error})") from None
    a_scaled, log_variance = (float(p) for p in parameters)
    variance = math.exp(log_variance)
    corrected = variance - kernel_width**2
    if corrected <= 0.0:
        raise ValueError(
            f"kernel_width = {kernel_width!r} m: the fitted profile variance {variance:.6g} m2 is not larger "
            "than the kernel variance; the profile is no wider than the smoothing"
        )
    B = corrected / (2.0 * z)
    log_variance_error = math.sqrt(max(float(covariance[1, 1]), 0.0)) if np.all(np.isfinite(covariance)) else math.inf
    B_error = variance * log_variance_error / (2.0 * z)
    residual = v - scale * model(x, a_scaled, log_variance)
    return KinematicFit(
        B=B,
        A=a_scaled * scale,
        z=z,
        B_standard_error=B_error,
        rms_residual=float(np.sqrt(np.mean(residual**2))),
    )


def kinematic_horizontal_velocity(x, v_z, B: float) -> np.ndarray:
    """Horizontal velocity of the kinematic model, ``u = -B d v_z / d x``.

    With ``v_z`` signed (negative downward) and z up, ``u = -B dv_z/dx`` points toward the
    axis above an outlet: it is the relation that, with continuity
    ``du/dx + dv_z/dz = 0``, gives the diffusion equation ``dv_z/dz = B d^2 v_z/dx^2``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Node x coordinates, strictly increasing [m] (uniform or not).
    v_z : array_like, shape (n,)
        Vertical velocity [m/s].
    B : float
        Kinematic constant [m], > 0.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Horizontal velocity [m/s]. ``dv_z/dx`` is the second-order central difference at
        interior nodes (``numpy.gradient``; ``(v[i+1] - v[i-1]) / (2 dx)`` on a uniform grid)
        and one-sided first-order differences at the two end nodes.
    """
    x, v = checked_profile(x, v_z)
    B = positive_number("B", B)
    return -B * np.gradient(v, x, edge_order=1)
