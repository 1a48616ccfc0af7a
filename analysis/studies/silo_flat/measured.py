"""Measured velocity profiles (e.g. PIV behind the front wall) and their comparison with a simulation.

File format (CSV, header required, SI units, one row per measured point; ``#`` starts a comment line)::

    # silo: planar flat-bottom, PIV at the front wall, averaged 0.5-0.7 s
    z_m,x_m,window,v_z_m_s,v_x_m_s,uncertainty_m_s
    0.12,-0.06,0.5-0.7,-0.0012,0.0004,0.0005
    0.12,-0.054,0.5-0.7,-0.0019,0.0006,0.0005

- ``z_m``: height above the outlet plane (m); ``x_m``: position across the width, 0 on the axis (m);
- ``window``: a label of the time or time window the row belongs to (free text without commas; rows with
  the same z and window form one profile);
- ``v_z_m_s``, ``v_x_m_s``: measured velocity components (m/s, z up);
- ``uncertainty_m_s``: measurement uncertainty of v_z (m/s); may be empty.

Parsing is pure (text in, records out); comparison works on arrays.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.numerics.profiles import ProfileErrors, profile_errors

COLUMNS = ("z_m", "x_m", "window", "v_z_m_s", "v_x_m_s", "uncertainty_m_s")


class MeasurementFormatError(ValueError):
    """A measured-profile file does not follow the documented format; the message names file and line."""


@dataclass(frozen=True)
class MeasuredProfile:
    """One measured profile: points across the width at one height and window.

    Attributes
    ----------
    z : float
        Height above the outlet (m).
    window : str
        Time or window label.
    x, v_z, v_x : numpy.ndarray
        Positions (m) and velocities (m/s), sorted by x.
    uncertainty : numpy.ndarray or None
        Uncertainty of v_z (m/s) per point, or None when the file gives none.
    """

    z: float
    window: str
    x: np.ndarray
    v_z: np.ndarray
    v_x: np.ndarray
    uncertainty: np.ndarray | None


def parse_measured_profiles(text: str, source: str = "<text>") -> list[MeasuredProfile]:
    """Parse the measured-profile CSV format (see the module docstring) into profiles.

    Raises
    ------
    MeasurementFormatError
        Naming ``source`` and the line for a missing column, a non-numeric or non-finite value.
    """
    lines = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise MeasurementFormatError(f"{source}: missing column(s) {', '.join(missing)}; expected {','.join(COLUMNS)}")
    groups: dict[tuple[float, str], list[tuple[float, float, float, float]]] = {}
    for number, row in enumerate(reader, start=2):
        try:
            values = [float(row[c]) for c in ("z_m", "x_m", "v_z_m_s", "v_x_m_s")]
            raw = (row["uncertainty_m_s"] or "").strip()
            uncertainty = float(raw) if raw else math.nan
        except (TypeError, ValueError):
            raise MeasurementFormatError(f"{source}: data line {number}: a value is not a number") from None
        if not all(math.isfinite(v) for v in values):
            raise MeasurementFormatError(f"{source}: data line {number}: non-finite value")
        z, x, v_z, v_x = values
        groups.setdefault((z, row["window"].strip()), []).append((x, v_z, v_x, uncertainty))
    profiles = []
    for (z, window), points in sorted(groups.items()):
        points.sort()
        array = np.array(points)
        has_uncertainty = not np.all(np.isnan(array[:, 3]))
        profiles.append(MeasuredProfile(z, window, array[:, 0], array[:, 1], array[:, 2],
                                        array[:, 3] if has_uncertainty else None))
    if not profiles:
        raise MeasurementFormatError(f"{source}: no measured points")
    return profiles


def read_measured_profiles(path: str | Path) -> list[MeasuredProfile]:
    """Read a measured-profile CSV file."""
    path = Path(path)
    return parse_measured_profiles(path.read_text(encoding="utf-8"), str(path))


@dataclass(frozen=True)
class ProfileComparison:
    """A measured profile, the simulated one interpolated onto its points, and the error metrics."""

    measured: MeasuredProfile
    simulated_v_z: np.ndarray
    errors: ProfileErrors


def compare_with_measurement(simulated_x, simulated_v_z, measured: MeasuredProfile) -> ProfileComparison:
    """Interpolate a simulated v_z(x) at the measured points and compute the error metrics.

    Measured points outside the simulated x range are not extrapolated: they raise a ValueError.
    """
    simulated_x = np.asarray(simulated_x, dtype=float)
    if measured.x.min() < simulated_x.min() - 1e-12 or measured.x.max() > simulated_x.max() + 1e-12:
        raise ValueError(
            f"measured points at z = {measured.z} m span x = [{measured.x.min()}, {measured.x.max()}] m, beyond "
            f"the simulated profile [{simulated_x.min()}, {simulated_x.max()}] m"
        )
    interpolated = np.interp(measured.x, simulated_x, np.asarray(simulated_v_z, dtype=float))
    return ProfileComparison(measured, interpolated, profile_errors(interpolated, measured.v_z, measured.uncertainty))
