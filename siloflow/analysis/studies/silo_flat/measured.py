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
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from siloflow.model.file_messages import unreadable
from siloflow.analysis.numerics.profiles import ProfileErrors, profile_errors

COLUMNS = ("z_m", "x_m", "window", "v_z_m_s", "v_x_m_s", "uncertainty_m_s")
#: The columns that must hold a finite number on every row.
_NUMBERS = ("z_m", "x_m", "v_z_m_s", "v_x_m_s")


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


def _number(row: dict, column: str, source: str, line: int) -> float:
    """The value of ``column`` in ``row`` (from the file's ``line``), refused without quoting it: the file may be any
    file a configuration names."""
    try:
        return float(row[column])
    except (TypeError, ValueError):
        raise MeasurementFormatError(f"{source}: line {line}, column {column} is not a number") from None


def _line(reader: csv.DictReader, numbers: list[int]) -> int:
    """The line in the file (``numbers``: the line number of each line given to ``reader``) of the record ``reader``
    read last or failed on: its last line, as a quoted field may span lines. The csv reader's own count, as
    DictReader's lags behind a line it fails on."""
    return numbers[max(reader.reader.line_num, 1) - 1]


def parse_measured_profiles(text: str, source: str = "<text>") -> list[MeasuredProfile]:
    """Parse the measured-profile CSV format (see the module docstring) into profiles.

    Raises
    ------
    MeasurementFormatError
        Naming ``source`` and, for a value, its line in the text (from 1, comment and blank lines counted) and its
        column: a missing column, text that is not CSV, a value that is not a number or not finite. No message
        quotes the text.
    """
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    numbered = [(number, line) for number, line in enumerate(lines, start=1)
                if line.strip() and not line.lstrip().startswith("#")]
    numbers = [number for number, _ in numbered]
    reader = csv.DictReader(line for _, line in numbered)
    groups: dict[tuple[float, str], list[tuple[float, float, float, float]]] = {}
    try:
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise MeasurementFormatError(f"{source}: missing column(s) {', '.join(missing)}; expected "
                                         f"{','.join(COLUMNS)}")
        for row in reader:
            line = _line(reader, numbers)
            values = [_number(row, c, source, line) for c in _NUMBERS]
            raw = (row["uncertainty_m_s"] or "").strip()
            uncertainty = _number(row, "uncertainty_m_s", source, line) if raw else math.nan
            infinite = [c for c, v in zip(_NUMBERS, values) if not math.isfinite(v)]
            if infinite:
                raise MeasurementFormatError(f"{source}: line {line}, column {infinite[0]} is not finite")
            z, x, v_z, v_x = values
            groups.setdefault((z, row["window"].strip()), []).append((x, v_z, v_x, uncertainty))
    except csv.Error:
        # the csv module's messages describe the text it met; the line is enough
        raise MeasurementFormatError(f"{source}: line {_line(reader, numbers)} is not CSV") from None
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
    """Read a measured-profile CSV file (UTF-8).

    Raises
    ------
    MeasurementFormatError
        Naming the file: a folder, a file that cannot be read, a line that is not UTF-8, or what
        :func:`parse_measured_profiles` refuses.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise MeasurementFormatError(f"{path}: {unreadable(error)}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        raise MeasurementFormatError(f"{path}: line {line} is not UTF-8 text") from None
    return parse_measured_profiles(text, str(path))


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
