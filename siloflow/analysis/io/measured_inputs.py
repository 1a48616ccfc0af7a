"""The measured data a configuration names, read once when the workflow starts, before any step runs: the measured
PIV files (``silo_flat.piv.measured``) and the measured velocity profiles (``silo_flat.fields.measured_profiles``).

A missing, unreadable or malformed file stops the workflow first with one :class:`MeasuredInputError`, naming the key
and the file's line or row, never the text found there (the readers' messages, :mod:`siloflow.analysis.io.piv_base`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from siloflow.analysis.io.measured_piv import load_measured_piv, measured_piv_paths
from siloflow.analysis.piv.measured import check_windows, measured_piv_settings
from siloflow.analysis.studies.silo_flat.measured import read_measured_profiles

__all__ = ["MEASURED_PROFILES_KEY", "MeasuredInputError", "check_measured_inputs"]

#: The key that names the measured velocity profiles.
MEASURED_PROFILES_KEY = "silo_flat.fields.measured_profiles"


class MeasuredInputError(ValueError):
    """A measured file the configuration names cannot be used; the message names the key."""


def _measured_piv(measured: Mapping) -> list[Path]:
    """The measured PIV files, read, scaled and filtered once, so that a bad file or marker set stops the workflow
    first, naming it."""
    if not measured["files"]:
        return []
    try:
        paths = measured_piv_paths(measured["files"])
        check_windows(load_measured_piv(measured, measured_piv_settings(measured), paths), measured["windows"])
    except ValueError as error:
        raise MeasuredInputError(f"Invalid measured PIV (silo_flat.piv.measured): {error}") from None
    return paths


def _measured_profiles(path: str | None) -> None:
    if path is None:
        return
    where = f"Invalid configuration: config key '{MEASURED_PROFILES_KEY}'"
    if not Path(path).is_file():
        kind = "a folder" if Path(path).is_dir() else "no regular file" if Path(path).exists() else "no file"
        raise MeasuredInputError(f"{where}: {path!r} is {kind} (looked in {Path.cwd()})")
    try:
        read_measured_profiles(path)
    except OSError as error:
        raise MeasuredInputError(f"{where}: {path!r} cannot be read ({error.strerror})") from None
    except ValueError as error:
        raise MeasuredInputError(f"{where}: {error}") from None


def check_measured_inputs(silo_flat: Mapping) -> list[Path]:
    """Read every measured file the validated ``silo_flat`` section names, once.

    Parameters
    ----------
    silo_flat : mapping
        The validated ``silo_flat`` section; relative paths are relative to the working directory.

    Returns
    -------
    list of pathlib.Path
        The measured PIV files, in time order; empty for no PIV comparison.

    Raises
    ------
    MeasuredInputError
        Naming the key and the file's fault.
    """
    paths = _measured_piv(silo_flat["piv"]["measured"])
    _measured_profiles(silo_flat["fields"]["measured_profiles"])
    return paths
