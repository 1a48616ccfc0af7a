"""The edge where a measured PIV sequence comes in: the configured files (glob patterns expanded in sorted order) read
frame by frame with their format's reader and the section's reading options (:func:`siloflow.analysis.io.piv.read_options`),
then made into timed, filtered silo fields under the section's validity policy
(:func:`siloflow.analysis.piv.measured.measured_fields`). Used before any simulation starts, to stop on a bad file, and by
the comparison rule."""

from __future__ import annotations

import glob
from pathlib import Path

from siloflow.analysis.io.piv import read_options, read_piv_file
from siloflow.analysis.piv.field import PlanarField
from siloflow.analysis.piv.measured import MeasuredPiv, measured_fields

__all__ = ["load_measured_piv", "measured_piv_paths"]


def measured_piv_paths(patterns, base: str | Path = ".", where: str = "silo_flat.piv.measured.files") -> list[Path]:
    """The files of ``patterns`` (paths or glob patterns, relative to ``base``): each pattern's matches in sorted
    order, patterns in the given order.

    Raises
    ------
    ValueError
        Naming ``where`` and the pattern that matches no file, or that matches a folder (a DaVis set is named by its
        ``.set`` file), with the folder.
    """
    paths = []
    for pattern in patterns:
        full = Path(base) / pattern
        matches = sorted(glob.glob(str(full))) if glob.has_magic(pattern) else ([str(full)] if full.exists() else [])
        if not matches:
            raise ValueError(f"{where}: {pattern!r} matches no file (looked in {Path(base).resolve()})")
        folders = [m for m in matches if Path(m).is_dir()]
        if folders:
            more = f" (and {len(folders) - 1} more folder(s))" if len(folders) > 1 else ""
            which = f": {folders[0]}{more}" if glob.has_magic(pattern) else ""
            raise ValueError(f"{where}: {pattern!r} matches a folder, not a file{which}")
        paths.extend(Path(m) for m in matches)
    return paths


def load_measured_piv(measured: dict, settings: MeasuredPiv, paths) -> list[PlanarField]:
    """The fields of the files ``paths`` in the format of the validated ``silo_flat.piv.measured`` section, placed and
    timed by its ``settings`` (:func:`siloflow.analysis.piv.measured.measured_piv_settings`).

    Raises
    ------
    ValueError
        Naming the file and the problem (:class:`siloflow.analysis.io.piv.PivFormatError` is one).
    """
    frames, sources = [], []
    options = read_options(measured)
    for path in paths:
        for rows in read_piv_file(path, measured["format"], options):
            frames.append(rows)
            sources.append(str(path))
    return measured_fields(frames, settings, sources)
