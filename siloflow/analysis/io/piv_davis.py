"""The reader of DaVis vector fields (``.vc7`` buffers and sets) through LaVision's ``lvpyio`` (the optional extra
``siloflow[davis]``: LaVision's licence restricts its use).

What a DaVis vector frame holds (``lvpyio.types.frame.VectorFrame``, lvpyio 1.x; DaVis 7 to 11 write it alike)
-------------------------------------------------------------------------------------------------------------
Up to four correlation peaks per vector (``U0``, ``V0`` to ``U3``, ``V3``; ``W0`` to ``W3`` in a stereo, three-component
field), ``ACTIVE_CHOICE`` (0 to 3: the peak DaVis' validation kept; 4 and 5: a vector DaVis filled in or smoothed,
stored in the last peak's slot), ``ENABLED`` (0 where validation rejected every peak and filled nothing in) and
``MASK`` (0 outside the image mask); a file without one of the last three has every vector on its first peak,
enabled and inside the mask (lvpyio's reading). Vector (i, j) sits at ``(i + 0.5) grid slope + offset`` of the
frame's x and y scales; velocities are the intensity scale of the stored values, along the scaled axes (lvpyio turns
a component whose axis slope is negative). A calibrated frame (lengths in mm or m, velocities in m/s or mm/s) gives
metres with y up or down as its y slope says (up when negative, DaVis' usual calibration); an uncalibrated one
(unit ``pixel``) gives pixels and displacements per frame with y down.

Vector choice (``choice``)
    ``active``: each vector as DaVis' validation left it (``lvpyio``'s ``as_masked_array``): ``measured`` on the
    first peak, ``second_peak`` on a later one, ``interpolated`` where DaVis filled in or smoothed (active choice 4
    or 5). ``first``: the first peak everywhere, ``measured`` where DaVis kept it and ``invalid`` where it did not
    (a vector DaVis smoothed or filled no longer says whether its first peak passed, so it is ``invalid`` too).
    Either way a vector DaVis disabled is ``invalid`` and one outside its mask ``masked``.
Stereo files (``out_of_plane``)
    ``refuse`` (a three-component field is not read), or ``keep``: the third component is read into
    :attr:`~siloflow.analysis.piv.field.PivRows.out_of_plane`, in the unit of u and v; the silo's planar field has the
    in-plane components only.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from siloflow.analysis.io.piv_base import PivFormatError, first_at, readable_file
from siloflow.analysis.piv.field import INTERPOLATED, INVALID, MASKED, MEASURED, SECOND_PEAK, PivRows

try:
    import lvpyio
except ImportError:  # LaVision's reader is the optional extra siloflow[davis] (its licence restricts its use)
    lvpyio = None

__all__ = ["DAVIS_CHOICES", "DAVIS_OUT_OF_PLANE", "read_davis"]

#: Which vector of each node ``read_davis`` takes (module docstring).
DAVIS_CHOICES = ("active", "first")
#: What ``read_davis`` does with a stereo file's third component.
DAVIS_OUT_OF_PLANE = ("refuse", "keep")

#: Metres per unit of a DaVis length scale, and m/s per unit of its velocity (intensity) scale.
_DAVIS_LENGTHS = {"m": 1.0, "mm": 1e-3}
_DAVIS_VELOCITIES = {"m/s": 1.0, "mm/s": 1e-3}


def _units(frame, path: Path) -> tuple[float, float, bool]:
    length, speed = frame.scales.x.unit.strip().lower(), frame.scales.i.unit.strip().lower()
    if length == "pixel":
        return 1.0, 1.0, True
    if length in _DAVIS_LENGTHS and speed in _DAVIS_VELOCITIES:
        return _DAVIS_LENGTHS[length], _DAVIS_VELOCITIES[speed], False
    # the units are the file's text: quoted only when they are units this reader knows
    units = (f"units {length} and {speed}" if {length, speed} <= {"pixel", *_DAVIS_LENGTHS, *_DAVIS_VELOCITIES}
             else "a length or velocity unit this reader does not know")
    raise PivFormatError(f"{path}: {units}; expected pixel, or mm or m with m/s or mm/s")


def _kinds(frame, path: Path, choice: str) -> np.ndarray:
    active = np.asarray(frame.active_choice[0])
    odd = (active < 0) | (active > 5)
    if np.any(odd):
        raise PivFormatError(f"{path}: {first_at(odd.ravel())} (row by row) has an active choice DaVis does not "
                             "write; DaVis writes 0 to 3 (a correlation peak), 4 or 5 (filled in or smoothed)")
    kind = np.full(active.shape, INVALID, dtype=np.int8)
    kind[active == 0] = MEASURED
    if choice == "active":
        kind[(active >= 1) & (active <= 3)] = SECOND_PEAK
        kind[active >= 4] = INTERPOLATED
    kind[np.asarray(frame.enabled[0]) == 0] = INVALID
    kind[np.asarray(frame.masks[0]) == 0] = MASKED
    return kind


def _first_choice(frame):
    """The frame as if DaVis had kept every vector's first peak, for lvpyio to scale."""
    first = copy.copy(frame)
    components = type(frame.components)(frame.components)
    scale = frame.components["ACTIVE_CHOICE"].scale if "ACTIVE_CHOICE" in frame.components else frame.scales.i
    components["ACTIVE_CHOICE"] = lvpyio.Component(scale, [np.zeros(frame.shape, dtype=np.int32)])
    first.components = components
    return first


def _davis_rows(frame, path: Path, choice: str, out_of_plane: str) -> PivRows:
    if not hasattr(frame, "grid"):
        raise PivFormatError(f"{path}: an image frame, not vectors")
    if len(frame) != 1:
        raise PivFormatError(f"{path}: a volume of {len(frame)} planes; siloflow reads planar fields")
    if frame.is_3c and out_of_plane == "refuse":
        raise PivFormatError(f"{path}: a stereo field of three velocity components; the silo's field is planar: set "
                             "silo_flat.piv.measured.davis.out_of_plane: keep to read u and v and keep the third apart")
    factor, velocity_factor, pixels = _units(frame, path)
    scales, grid = frame.scales, frame.grid
    vectors = (frame if choice == "active" else _first_choice(frame)).as_masked_array()
    rows, columns = vectors.shape
    j, i = np.meshgrid(np.arange(rows), np.arange(columns), indexing="ij")
    x = factor * ((i + 0.5) * grid.x * scales.x.slope + scales.x.offset)
    y = factor * ((j + 0.5) * grid.y * scales.y.slope + scales.y.offset)
    u, v = (velocity_factor * np.asarray(vectors[name].filled(np.nan), dtype=float) for name in ("u", "v"))
    kind = _kinds(frame, path, choice)
    kind[~(np.isfinite(u) & np.isfinite(v)) & (kind != MASKED)] = INVALID
    w = velocity_factor * np.asarray(vectors["w"].filled(np.nan), dtype=float).ravel() if frame.is_3c else None
    return PivRows(x.ravel(), y.ravel(), u.ravel(), v.ravel(), kind.ravel(), bool(scales.y.slope > 0), pixels, w)


def read_davis(path: str | Path, choice: str = "active", out_of_plane: str = "refuse") -> list[PivRows]:
    """The vector frames of a DaVis buffer (``.vc7``) or set (a ``.set`` file or its folder) (module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        The buffer or set.
    choice : {"active", "first"}
        Each vector as DaVis' validation left it, or its first correlation peak.
    out_of_plane : {"refuse", "keep"}
        What to do with a stereo file's third component.

    Returns
    -------
    list of PivRows
        One per vector frame: positions [m or px], velocities [m/s or px/frame], ``y_down`` and ``pixels`` from the
        frame's scales, the kind of each vector.

    Raises
    ------
    PivFormatError
        Naming the file: ``lvpyio`` not installed, a file that cannot be read or that lvpyio cannot read, an image
        instead of vectors, a volume, a stereo field with ``out_of_plane`` "refuse", an active choice DaVis does not
        write (and the first vector that has one), or units other than pixels, or mm or m with m/s or mm/s. No
        message quotes the file's contents.
    """
    path = Path(path)
    if choice not in DAVIS_CHOICES or out_of_plane not in DAVIS_OUT_OF_PLANE:
        raise ValueError(f"choice must be one of {', '.join(DAVIS_CHOICES)} and out_of_plane one of "
                         f"{', '.join(DAVIS_OUT_OF_PLANE)}, got {choice!r} and {out_of_plane!r}")
    if lvpyio is None:
        raise PivFormatError(f"{path}: reading DaVis files needs LaVision's lvpyio: pip install 'siloflow[davis]'")
    if not path.is_dir():  # a set may be named by its folder
        readable_file(path)
    try:
        buffers = [lvpyio.read_buffer(str(path))] if path.suffix.lower() in (".vc7", ".im7") \
            else list(lvpyio.read_set(str(path)))
    except (RuntimeError, ValueError, OSError):
        # lvpyio's messages may quote what it found in the file's header, so they are not passed on
        raise PivFormatError(f"{path}: not a DaVis buffer or set that lvpyio can read (a set is a .set file next to "
                             "its folder of the same name)") from None
    frames = [_davis_rows(frame, path, choice, out_of_plane) for buffer in buffers for frame in buffer]
    if not frames:
        raise PivFormatError(f"{path}: no vector frame")
    return frames
