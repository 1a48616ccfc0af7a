"""The edge where PIV velocity fields come in: one reader per program's format, each reading a file with the meaning
its program gives its flags, masks, units and axes, and the one writer (siloflow's CSV). The readers return
:class:`~siloflow.analysis.piv.field.PivRows` (one row per vector, in the file's units and axes, with the kind of each node:
:data:`~siloflow.analysis.piv.field.NODE_KINDS`); :mod:`siloflow.analysis.piv.measured` turns them into silo fields.

Formats (:data:`PIV_FORMATS`, the values of ``silo_flat.piv.measured.format``)
--------------------------------------------------------------------------------
``openpiv``
    OpenPIV's text output in every layout since 0.19 (:mod:`siloflow.analysis.io.piv_openpiv`).
``pivlab_txt``
    PIVlab's text export in every layout (4, 5, 11, 12, 13 and 14 columns) (:mod:`siloflow.analysis.io.piv_pivlab`).
``pivlab_mat``
    PIVlab's MATLAB files: GUI export, command-line workspace, session; MATLAB 5 to 7.3 (:mod:`siloflow.analysis.io.piv_pivlab`).
``davis``
    DaVis ``.vc7`` buffers and sets through LaVision's ``lvpyio`` (:mod:`siloflow.analysis.io.piv_davis`).
``csv``
    siloflow's own: a header ``x_m,z_m,u_m_s,w_m_s,valid`` and one row per node in silo coordinates (x across, z up;
    m, m/s; valid 1 or 0): what a user converts any other program's output to, and what :func:`write_piv_csv` writes.
    Its valid nodes are ``measured``, the others ``invalid``.

:func:`read_piv_file` reads any of them as a list of frames, with the choices a program's format leaves open
(:class:`PivReadOptions`, from the configuration by :func:`read_options`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from siloflow.analysis.io.piv_base import PivFormatError, finite_positions, header_names, numeric_table, text_lines
from siloflow.analysis.io.piv_davis import DAVIS_CHOICES, DAVIS_OUT_OF_PLANE, read_davis
from siloflow.analysis.io.piv_openpiv import OPENPIV_FIFTH_COLUMNS, read_openpiv
from siloflow.analysis.io.piv_pivlab import PIVLAB_FIELDS, read_pivlab_mat, read_pivlab_txt
from siloflow.analysis.io.tables import write_text
from siloflow.analysis.piv.field import PivRows, PlanarField, field_from_rows

__all__ = ["PIV_FORMATS", "PivFormatError", "PivReadOptions", "PivRows", "read_davis", "read_openpiv", "read_options",
           "read_piv_csv", "read_piv_file", "read_pivlab_mat", "read_pivlab_txt", "write_piv_csv"]

#: The formats :func:`read_piv_file` reads (the ``silo_flat.piv.measured.format`` values).
PIV_FORMATS = ("openpiv", "pivlab_txt", "pivlab_mat", "davis", "csv")

CSV_HEADER = "x_m,z_m,u_m_s,w_m_s,valid"
_CSV_NAMES = CSV_HEADER.split(",")


@dataclass(frozen=True)
class PivReadOptions:
    """The choices a format leaves to the user (``silo_flat.piv.measured``; the defaults are the schema's).

    Attributes
    ----------
    y_down : bool or None
        OpenPIV: whether v points down the image; None, the way the file's y points.
    openpiv_fifth_column : {"mask", "sig2noise"}
        OpenPIV without a header (0.19 to 0.22): what the fifth column holds.
    openpiv_sig2noise_threshold : float or None
        OpenPIV with a signal-to-noise ratio: vectors below it are invalid [-].
    pivlab_field : {"original", "filtered"}
        PIVlab MATLAB files: the correlation's field or the validated one.
    davis_choice : {"active", "first"}
        DaVis: each vector as validation left it, or its first correlation peak.
    davis_out_of_plane : {"refuse", "keep"}
        DaVis: a stereo file's third component.
    """

    y_down: bool | None = None
    openpiv_fifth_column: str = "mask"
    openpiv_sig2noise_threshold: float | None = None
    pivlab_field: str = "filtered"
    davis_choice: str = "active"
    davis_out_of_plane: str = "refuse"

    def __post_init__(self) -> None:
        for name, allowed in (("openpiv_fifth_column", OPENPIV_FIFTH_COLUMNS), ("pivlab_field", PIVLAB_FIELDS),
                              ("davis_choice", DAVIS_CHOICES), ("davis_out_of_plane", DAVIS_OUT_OF_PLANE)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} must be one of {', '.join(allowed)}, got {getattr(self, name)!r}")


def read_options(measured: dict) -> PivReadOptions:
    """The :class:`PivReadOptions` of a ``silo_flat.piv.measured`` section; a key it lacks takes the default."""
    default = PivReadOptions()
    openpiv, pivlab, davis = (measured.get(k) or {} for k in ("openpiv", "pivlab", "davis"))
    return PivReadOptions(
        measured.get("y_down", default.y_down),
        openpiv.get("fifth_column", default.openpiv_fifth_column),
        openpiv.get("sig2noise_threshold", default.openpiv_sig2noise_threshold),
        pivlab.get("field", default.pivlab_field),
        davis.get("choice", default.davis_choice),
        davis.get("out_of_plane", default.davis_out_of_plane))


def read_piv_csv(path: str | Path, time: float = 0.0) -> PlanarField:
    """A siloflow PIV CSV (module docstring) as a field at ``time`` [s].

    Raises
    ------
    PivFormatError
        Naming the file: a folder or a file that cannot be read, another header, a line and column that is not a
        number, not five columns, a position that is not finite, or nodes that do not fill a regular grid.
    """
    path = Path(path)
    lines = text_lines(path)
    names = lines[0].strip().split(",") if lines[0].strip() else []
    if names != _CSV_NAMES:
        raise PivFormatError(f"{path}: the header on line 1 {header_names(names, _CSV_NAMES, 'siloflow')}; siloflow's "
                             f"is {CSV_HEADER}")
    table, numbers = numeric_table(path, lines, start=1)
    if table.shape[1] != 5:
        raise PivFormatError(f"{path}: {table.shape[1]} columns, expected 5")
    x, z, u, w, valid = table.T
    finite_positions(path, x, z, numbers)
    try:
        # field_from_rows says what the nodes lack (counts and shapes), not their values
        return field_from_rows(x, z, u, w, (valid == 1) & np.isfinite(u) & np.isfinite(w), time)
    except ValueError as error:
        raise PivFormatError(f"{path}: {error}") from None


def write_piv_csv(path: str | Path, field: PlanarField) -> Path:
    """Write ``field`` as a siloflow PIV CSV (x fastest; invalid nodes with NaN velocities and valid 0)."""
    z, x = np.meshgrid(field.z, field.x, indexing="ij")
    # repr of a Python float is the shortest text that reads back to the same double
    lines = [CSV_HEADER] + [f"{float(a)!r},{float(b)!r},{float(c)!r},{float(d)!r},{int(e)}" for a, b, c, d, e in
                            zip(x.ravel(), z.ravel(), field.u.ravel(), field.w.ravel(), field.valid.ravel())]
    return write_text(path, "\n".join(lines) + "\n")


def read_piv_file(path: str | Path, file_format: str, options: PivReadOptions = PivReadOptions()) -> list[PivRows]:
    """The frames of one PIV file in ``file_format`` (one of :data:`PIV_FORMATS`), read with ``options``. A siloflow
    CSV gives one frame in metres with y up.

    Raises
    ------
    PivFormatError
        Naming the file: an unknown format, a missing file, or what the format's reader refuses (a folder, except a
        DaVis set's, or a file that cannot be read among them).
    """
    path = Path(path)
    if file_format not in PIV_FORMATS:
        raise PivFormatError(f"{path}: unknown PIV format {file_format!r}; expected one of {', '.join(PIV_FORMATS)}")
    if not path.exists():
        raise PivFormatError(f"{path}: no such file")
    if file_format == "openpiv":
        return [read_openpiv(path, options.y_down, options.openpiv_fifth_column, options.openpiv_sig2noise_threshold)]
    if file_format == "pivlab_txt":
        return [read_pivlab_txt(path)]
    if file_format == "pivlab_mat":
        return read_pivlab_mat(path, options.pivlab_field)
    if file_format == "davis":
        return read_davis(path, options.davis_choice, options.davis_out_of_plane)
    field = read_piv_csv(path)
    z, x = np.meshgrid(field.z, field.x, indexing="ij")
    return [PivRows(x.ravel(), z.ravel(), field.u.ravel(), field.w.ravel(), field.valid.ravel(), False, False)]
