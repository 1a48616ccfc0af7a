"""Calibration charts and their inversion: particle friction for a measured bulk friction.

Pure functions; no file I/O. A calibration chart is bulk friction (from simulated
Jenike shear tests, see :mod:`siloflow.calibration.friction`) against the particle sliding
friction coefficient, one curve per particle shape, test and rolling friction:

* ``test="internal"``: bulk internal friction against particle-particle friction;
* ``test="wall"``: bulk wall friction against particle-wall friction, for one
  ``wall_material`` (e.g. "aluminium", "perspex").

Bulk and particle friction are coefficients [-]; angles are in degrees. The
inverse problem reads a chart backwards: the particle friction whose bulk friction
angle equals a measured one (30 deg internal, 9.5 deg aluminium, 11 deg perspex),
with the band of particle friction that the measurement uncertainty (+-1 deg)
allows.

Error of the calibrated friction. Besides that band, the inverted particle friction carries the simulations'
own noise: each chart point's bulk friction has a standard error (batch means of its steady shear window,
:mod:`siloflow.calibration.friction`). Propagated to first order through the piecewise linear inversion, the points
``i``, ``i + 1`` of the segment that holds the target (at fraction ``t`` of its angle span) give

    ``se(p) = sqrt(((1 - t) se_i)^2 + (t se_{i+1})^2) / s``,

``se_i`` the points' angle errors [deg] and ``s = (theta_{i+1} - theta_i) / (p_{i+1} - p_i)`` the local slope of
the chart [deg per unit particle friction]: a shift of the chart by ``d theta`` moves the inverted friction by
``d theta / s``. The points are independent runs, so their errors add in quadrature.

The straight-line reading has a second error where the chart bends (bulk friction saturates): with three or more
points it is estimated as the difference between the straight line and the parabola through the segment and its
nearest third point (:func:`interpolation_error`), and added in quadrature (``Inversion.total_error``, written as
``sliding_friction_error``). A chart of two points cannot show its bend: its error is unknown (YAML null), and a
shear test at the chosen friction may miss the target by far more than the band (measured on a two-point chart
from 0.1 to 0.5: the chosen 0.228 gave 28.3 deg against a 24 deg target).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from siloflow.analysis.numerics.uncertainty import combine_independent
from siloflow.calibration.friction import friction_angle_error
from siloflow.calibration.inversion_errors import interpolation_error, inversion_error

__all__ = [
    "CalibrationCurve",
    "Inversion",
    "UnreachableTarget",
    "invert_curve",
    "invert_calibration",
    "curves_from_table",
]

_TESTS = ("internal", "wall")


class UnreachableTarget(ValueError):
    """A target bulk friction angle lies outside what a calibration chart reaches."""


# --------------------------------------------------------------------------- data


def _finite_number(name: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return number


def _material(value) -> str | None:
    """Normalise an empty wall material ('' / None / NaN from a table) to None."""
    if value is None:
        return None
    if isinstance(value, float) and math.isnan(value):
        return None
    text = str(value).strip()
    return text or None


@dataclass(frozen=True, eq=False)
class CalibrationCurve:
    """One curve of a calibration chart: bulk friction against particle friction.

    Attributes
    ----------
    shape : str
        Particle model, e.g. "sphere", "sphere2", "sphere4".
    test : {"internal", "wall"}
        Internal friction (particle-particle) or wall friction (particle-wall).
    rolling_friction : float
        Rolling friction coefficient mu_r of the curve [-], >= 0.
    particle_friction : numpy.ndarray, shape (n,)
        Particle sliding friction coefficients, strictly increasing [-].
    bulk_friction : numpy.ndarray, shape (n,)
        Bulk friction coefficients measured at those points [-].
    bulk_standard_error : numpy.ndarray, shape (n,), or None
        Standard errors of ``bulk_friction`` [-]; NaN where unknown.
    wall_material : str or None
        Wall material of a wall-friction curve (None for internal friction;
        an empty string is stored as None).
    """

    shape: str
    test: str
    rolling_friction: float
    particle_friction: np.ndarray
    bulk_friction: np.ndarray
    bulk_standard_error: np.ndarray | None = None
    wall_material: str | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.shape, str) or not self.shape:
            raise ValueError(f"shape must be a non-empty string, got {self.shape!r}")
        if self.test not in _TESTS:
            raise ValueError(f"test must be 'internal' or 'wall', got {self.test!r}")
        rolling = _finite_number("rolling_friction", self.rolling_friction)
        if rolling < 0.0:
            raise ValueError(f"rolling_friction must be >= 0, got {rolling!r}")
        particle = np.asarray(self.particle_friction, dtype=float)
        if particle.ndim != 1 or particle.size == 0 or not np.all(np.isfinite(particle)):
            raise ValueError("particle_friction must be a non-empty 1-D array of finite numbers")
        if np.any(np.diff(particle) <= 0.0):
            raise ValueError("particle_friction must be strictly increasing")
        bulk = np.asarray(self.bulk_friction, dtype=float)
        if bulk.shape != particle.shape or not np.all(np.isfinite(bulk)):
            raise ValueError(
                f"bulk_friction must hold {particle.size} finite numbers like particle_friction, got shape {bulk.shape}"
            )
        error = self.bulk_standard_error
        if error is not None:
            error = np.asarray(error, dtype=float)
            if error.shape != particle.shape:
                raise ValueError(
                    f"bulk_standard_error must have shape {particle.shape} like particle_friction, got {error.shape}"
                )
            if np.any(error[~np.isnan(error)] < 0.0) or np.any(np.isinf(error)):
                raise ValueError("bulk_standard_error must be finite and >= 0 (NaN where unknown)")
        material = _material(self.wall_material)
        if self.test == "internal" and material is not None:
            raise ValueError(f"wall_material must be empty for an internal friction curve, got {material!r}")
        object.__setattr__(self, "rolling_friction", rolling)
        object.__setattr__(self, "particle_friction", particle)
        object.__setattr__(self, "bulk_friction", bulk)
        object.__setattr__(self, "bulk_standard_error", error)
        object.__setattr__(self, "wall_material", material)

    @property
    def bulk_angle_deg(self) -> np.ndarray:
        """Bulk friction angles ``degrees(atan(bulk_friction))`` [deg]."""
        return np.degrees(np.arctan(self.bulk_friction))

    @property
    def bulk_angle_standard_error_deg(self) -> np.ndarray | None:
        """Standard errors of :attr:`bulk_angle_deg` [deg] (:func:`siloflow.calibration.friction.friction_angle_error`);
        None without ``bulk_standard_error``, NaN where it is NaN."""
        if self.bulk_standard_error is None:
            return None
        return friction_angle_error(self.bulk_friction, self.bulk_standard_error)


@dataclass(frozen=True)
class Inversion:
    """Particle friction that reproduces a target bulk friction angle.

    Attributes
    ----------
    particle_friction : float
        Particle sliding friction at the target angle [-].
    lower, upper : float
        Particle friction at ``target - tolerance`` and ``target + tolerance`` [-]
        (clipped to the ends of the usable chart if ``band_clipped``).
    target_angle_deg, tolerance_deg : float
        Target bulk friction angle and its uncertainty [deg].
    reachable_range_deg : tuple of float
        ``(min, max)`` bulk friction angle of the usable (monotone) chart [deg].
    shape, test : str
        Curve identification (see :class:`CalibrationCurve`).
    rolling_friction : float
        Rolling friction of the curve [-].
    wall_material : str or None
        Wall material of a wall-friction curve.
    band_clipped : bool
        True if ``target - tolerance`` or ``target + tolerance`` lies outside the
        reachable range, so ``lower`` or ``upper`` is the end of the chart.
    plateau_particle_friction : float or None
        Particle friction above which bulk friction stops growing (the end of
        the monotone part used), or None if the whole curve increases.
    standard_error : float
        Standard error of ``particle_friction`` from the chart points' bulk
        friction errors (module docstring) [-]; NaN when those are unknown.
    interpolation_error : float
        How far the straight-line reading may miss the chart's bend at the target
        (:func:`interpolation_error`) [-]; NaN for a chart of two points, which cannot
        show its bend.
    """

    particle_friction: float
    lower: float
    upper: float
    target_angle_deg: float
    tolerance_deg: float
    reachable_range_deg: tuple[float, float]
    shape: str
    test: str
    rolling_friction: float
    wall_material: str | None
    band_clipped: bool
    plateau_particle_friction: float | None
    standard_error: float
    interpolation_error: float = math.nan

    @property
    def total_error(self) -> float:
        """The chart points' error and the interpolation error in quadrature [-]; NaN when either is unknown."""
        return combine_independent([self.standard_error, self.interpolation_error])


# --------------------------------------------------------------------------- inversion


def _monotone_part(curve: CalibrationCurve) -> tuple[np.ndarray, np.ndarray, float | None]:
    """Angles and particle friction up to the first maximum; the plateau start or None."""
    angles = curve.bulk_angle_deg
    not_growing = np.flatnonzero(np.diff(angles) <= 0.0)
    if not_growing.size == 0:
        return angles, curve.particle_friction, None
    last = int(not_growing[0])
    return angles[: last + 1], curve.particle_friction[: last + 1], float(curve.particle_friction[last])


def _describe(curve: CalibrationCurve) -> str:
    if curve.test == "internal":
        return "internal friction angle"
    if curve.wall_material:
        return f"{curve.wall_material} wall friction angle"
    return "wall friction angle"


def invert_curve(curve: CalibrationCurve, target_angle_deg: float, tolerance_deg: float = 1.0) -> Inversion:
    """Particle friction that gives a target bulk friction angle on one chart curve.

    The chart points are converted to bulk friction angles
    ``degrees(atan(bulk_friction))`` and the particle friction is interpolated
    piecewise linearly as a function of that angle (so chart points are
    reproduced exactly). The inversion needs a curve that increases; when bulk
    friction stops growing with particle friction (a plateau, common at high
    rolling friction, or a dip from noise), only the monotone part up to the
    *first* maximum is used: the points up to the first one that is not
    followed by a larger angle. Targets above that maximum are reported as
    unreachable, naming the particle friction where growth stops.

    Error. ``standard_error`` propagates the chart points' bulk friction errors
    through the local slope of the chart (:func:`inversion_error`).

    Band. ``lower`` and ``upper`` are the particle friction at
    ``target - tolerance`` and ``target + tolerance``. If the target itself is
    reachable but a band edge is not, that edge is clipped to the end of the
    usable chart (its smallest or largest particle friction) and
    ``band_clipped`` is set, rather than failing: the band is then only a lower
    bound of the uncertainty.

    Parameters
    ----------
    curve : CalibrationCurve
        The chart curve.
    target_angle_deg : float
        Measured bulk friction angle [deg], in ``(-90, 90)``.
    tolerance_deg : float, optional
        Measurement uncertainty [deg], >= 0 (default 1).

    Returns
    -------
    Inversion
        Particle friction, band, reachable range and curve identification.

    Raises
    ------
    UnreachableTarget
        If the target angle lies outside the reachable range of the monotone
        part of the curve.
    ValueError
        On malformed arguments.
    """
    if not isinstance(curve, CalibrationCurve):
        raise ValueError(f"curve must be a CalibrationCurve, got {type(curve).__name__}")
    target = _finite_number("target_angle_deg", target_angle_deg)
    if not -90.0 < target < 90.0:
        raise ValueError(f"target_angle_deg must lie in (-90, 90) deg, got {target!r}")
    tolerance = _finite_number("tolerance_deg", tolerance_deg)
    if tolerance < 0.0:
        raise ValueError(f"tolerance_deg must be >= 0, got {tolerance!r}")

    angles, particle, plateau = _monotone_part(curve)
    angle_errors = curve.bulk_angle_standard_error_deg
    if angle_errors is not None:
        angle_errors = angle_errors[: angles.size]
    low, high = float(angles[0]), float(angles[-1])
    if not low <= target <= high:
        reason = (
            f" (bulk friction stops growing above particle friction {plateau:g})" if plateau is not None else ""
        )
        raise UnreachableTarget(
            f"{_describe(curve)} {target:.1f} deg is unreachable for {curve.shape} with rolling friction "
            f"{curve.rolling_friction:g}: the chart reaches {low:.1f}-{high:.1f} deg{reason}"
        )

    def interpolate(angle: float) -> float:
        return float(np.interp(angle, angles, particle))

    band_low, band_high = target - tolerance, target + tolerance
    band_clipped = band_low < low or band_high > high
    return Inversion(
        particle_friction=interpolate(target),
        lower=interpolate(max(band_low, low)),
        upper=interpolate(min(band_high, high)),
        target_angle_deg=target,
        tolerance_deg=tolerance,
        reachable_range_deg=(low, high),
        shape=curve.shape,
        test=curve.test,
        rolling_friction=curve.rolling_friction,
        wall_material=curve.wall_material,
        band_clipped=bool(band_clipped),
        plateau_particle_friction=plateau,
        standard_error=float(inversion_error(angles, particle, angle_errors, target)),
        interpolation_error=interpolation_error(angles, particle, target),
    )


def _find_curve(
    curves: list[CalibrationCurve], test: str, material: str | None, shape: str, rolling_friction: float
) -> CalibrationCurve:
    matches = [
        curve
        for curve in curves
        if curve.shape == shape
        and curve.test == test
        and curve.wall_material == material
        and math.isclose(curve.rolling_friction, rolling_friction, rel_tol=1e-9, abs_tol=1e-12)
    ]
    what = "internal friction" if test == "internal" else f"wall friction on {material}"
    if not matches:
        available = sorted(
            {
                f"{c.shape}/{c.test}{'/' + c.wall_material if c.wall_material else ''}/mu_r={c.rolling_friction:g}"
                for c in curves
            }
        )
        raise ValueError(
            f"curves: no {what} curve for shape {shape} with rolling friction {rolling_friction:g} "
            f"(available: {', '.join(available) if available else 'none'})"
        )
    if len(matches) > 1:
        raise ValueError(
            f"curves: {len(matches)} {what} curves for shape {shape} with rolling friction "
            f"{rolling_friction:g}; expected one"
        )
    return matches[0]


def invert_calibration(
    curves: list[CalibrationCurve],
    targets: dict[str, float],
    tolerance_deg: float = 1.0,
    *,
    shape: str,
    rolling_friction: float,
    record_unreachable: bool = False,
) -> dict:
    """Particle-scale friction parameters that reproduce measured bulk friction angles.

    For each target, the curve of the given shape and rolling friction is
    inverted with :func:`invert_curve`: the key ``"internal"`` uses the
    ``test="internal"`` curve (particle-particle friction), any other key is a
    wall material and uses the ``test="wall"`` curve of that ``wall_material``
    (particle-wall friction).

    Parameters
    ----------
    curves : list of CalibrationCurve
        All chart curves (any shapes, rolling frictions, tests).
    targets : dict of str to float
        Target bulk friction angles [deg], e.g.
        ``{"internal": 30.0, "aluminium": 9.5, "perspex": 11.0}``.
    tolerance_deg : float, optional
        Measurement uncertainty of every target [deg] (default 1).
    shape : str
        Particle shape to calibrate (keyword only).
    rolling_friction : float
        Rolling friction of the curves to use [-] (keyword only).
    record_unreachable : bool, optional
        Instead of raising :class:`UnreachableTarget`, leave the target out of the parameters and record
        its message under ``"unreachable"`` (keyword only; default False). A calibration stage uses this
        so that one unreachable target does not hide the others.

    Returns
    -------
    dict
        Plain Python values, ready for YAML::

            {"shape": "sphere2", "rolling_friction": 0.1, "tolerance_deg": 1.0,
             "particle_particle": {"sliding_friction": x, "sliding_friction_error": se, "lower": ..,
                                   "upper": .., "band_clipped": False},
             "particle_wall": {"aluminium": {...}, "perspex": {...}},
             "targets_deg": {"internal": 30.0, "aluminium": 9.5, "perspex": 11.0}}

        ``particle_particle`` is present only with an ``"internal"`` target;
        ``particle_wall`` holds one entry per wall material (possibly none).
        ``sliding_friction_error`` is :attr:`Inversion.total_error` [-] (the chart points' errors and the
        interpolation error), None (YAML null) when either is unknown (no bulk friction errors, or a chart of
        two points).

    Raises
    ------
    ValueError
        If a needed curve is missing (the message names the test, material,
        shape and rolling friction) or is ambiguous, or on malformed arguments.
    UnreachableTarget
        If a target is outside the reach of its curve.
    """
    curves = list(curves)
    if not all(isinstance(curve, CalibrationCurve) for curve in curves):
        raise ValueError("curves must be a list of CalibrationCurve")
    if not isinstance(targets, dict) or not targets:
        raise ValueError(f"targets must be a non-empty dict of name to angle [deg], got {targets!r}")
    if not isinstance(shape, str) or not shape:
        raise ValueError(f"shape must be a non-empty string, got {shape!r}")
    rolling_friction = _finite_number("rolling_friction", rolling_friction)
    tolerance = _finite_number("tolerance_deg", tolerance_deg)

    result: dict = {"shape": shape, "rolling_friction": rolling_friction, "tolerance_deg": tolerance}
    walls: dict[str, dict] = {}
    targets_deg: dict[str, float] = {}
    unreachable: dict[str, str] = {}
    for name, angle in targets.items():
        material = _material(name)
        if material is None:
            raise ValueError(f"targets: empty target name {name!r}")
        angle = _finite_number(f"targets[{name!r}]", angle)
        targets_deg[material] = angle
        if material == "internal":
            curve = _find_curve(curves, "internal", None, shape, rolling_friction)
        else:
            curve = _find_curve(curves, "wall", material, shape, rolling_friction)
        try:
            inversion = invert_curve(curve, angle, tolerance)
        except UnreachableTarget as error:
            if not record_unreachable:
                raise
            unreachable[material] = str(error)
            continue
        entry = {
            "sliding_friction": inversion.particle_friction,
            # YAML null, not .nan, for an unknown error: plain data that round-trips
            "sliding_friction_error": None if math.isnan(inversion.total_error) else inversion.total_error,
            "lower": inversion.lower,
            "upper": inversion.upper,
            "band_clipped": inversion.band_clipped,
        }
        if material == "internal":
            result["particle_particle"] = entry
        else:
            walls[material] = entry
    result["particle_wall"] = walls
    result["targets_deg"] = targets_deg
    if record_unreachable:
        result["unreachable"] = unreachable
    return result


# --------------------------------------------------------------------------- table


def _optional_number(value) -> float:
    if value is None or (isinstance(value, str) and not value.strip()):
        return math.nan
    return float(value)


def curves_from_table(rows: list[dict]) -> list[CalibrationCurve]:
    """Group the rows of a calibration table into chart curves.

    Each row is one simulated shear test with the keys ``shape``, ``test``
    ("internal" or "wall"), ``wall_material`` (empty, None or NaN for internal
    friction), ``rolling_friction``, ``particle_friction``, ``bulk_friction``
    and, optionally, ``bulk_friction_error`` (or ``bulk_friction_stderr``). Values may be strings (as
    read from CSV). Rows are grouped by (shape, test, wall material, rolling
    friction); each curve is sorted by particle friction. The bulk friction's
    standard error is read from ``bulk_friction_error``, or, when a row lacks
    that key, from ``bulk_friction_stderr``.

    Parameters
    ----------
    rows : list of dict
        Table rows.

    Returns
    -------
    list of CalibrationCurve
        Sorted by shape, test, wall material and rolling friction. A curve's
        ``bulk_standard_error`` is None if none of its rows has one, otherwise an
        array with NaN where a row has none.

    Raises
    ------
    ValueError
        If a key is missing or a value malformed (naming the row), or if a
        curve has two rows with the same particle friction.
    """
    groups: dict[tuple, list[tuple[float, float, float]]] = {}
    for index, row in enumerate(rows):
        if not isinstance(row, dict):
            raise ValueError(f"rows[{index}] must be a dict, got {type(row).__name__}")
        try:
            shape = str(row["shape"]).strip()
            test = str(row["test"]).strip()
            material = _material(row.get("wall_material"))
            rolling = _finite_number("rolling_friction", row["rolling_friction"])
            particle = _finite_number("particle_friction", row["particle_friction"])
            bulk = _finite_number("bulk_friction", row["bulk_friction"])
            # the error under its current name, else under the name tables written before it had
            error = _optional_number(row.get("bulk_friction_error", row.get("bulk_friction_stderr")))
        except KeyError as missing:
            raise ValueError(f"rows[{index}] lacks the key {missing.args[0]!r}") from None
        except ValueError as problem:
            raise ValueError(f"rows[{index}]: {problem}") from None
        if test not in _TESTS:
            raise ValueError(f"rows[{index}]: test must be 'internal' or 'wall', got {test!r}")
        if test == "internal":
            material = None
        groups.setdefault((shape, test, material, rolling), []).append((particle, bulk, error))

    curves = []
    for (shape, test, material, rolling), points in sorted(
        groups.items(), key=lambda item: (item[0][0], item[0][1], item[0][2] or "", item[0][3])
    ):
        points.sort(key=lambda point: point[0])
        particle = np.array([point[0] for point in points])
        duplicates = particle[1:][np.diff(particle) == 0.0]
        if duplicates.size:
            raise ValueError(
                f"rows: curve {shape}/{test}{'/' + material if material else ''}/mu_r={rolling:g} has "
                f"several rows with particle friction {duplicates[0]:g}"
            )
        errors = np.array([point[2] for point in points])
        curves.append(
            CalibrationCurve(
                shape=shape,
                test=test,
                rolling_friction=rolling,
                particle_friction=particle,
                bulk_friction=np.array([point[1] for point in points]),
                bulk_standard_error=None if np.all(np.isnan(errors)) else errors,
                wall_material=material,
            )
        )
    return curves
