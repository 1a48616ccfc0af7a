"""Measured PIV frames made into silo velocity fields: each frame checked against the configuration, through the image
scale and frame rate, with the validity policy applied, stamped with its time and cleaned by the Hampel filter.

A PIV sequence gives one field per image pair; field n (from 0) is at ``start_time + n field_interval`` after the
outlet opened, where ``field_interval`` defaults to one camera frame (pairs of consecutive images). Pixel files need
the scale from wall markers and the camera frame rate (a displacement per frame times the frame rate is a velocity);
files in metres and m/s need neither, but must be in silo coordinates: y up (z), from the silo's axis and outlet.

Validity policy: every node is of one kind (:data:`siloflow.analysis.piv.field.NODE_KINDS`: measured, second peak,
interpolated, unflagged, masked, invalid), as its program says; the configuration (``silo_flat.piv.measured.valid``)
names the kinds that count as valid, by default measured and second peak, whatever program wrote the file. A frame
whose vectors carry no flag at all (``unflagged``: PIVlab's text export before 2.44, OpenPIV with only a
signal-to-noise ratio) is refused unless ``unflagged`` is counted, so that a file's silence is never read as
"measured". Each field records the kind of each node (:attr:`~siloflow.analysis.piv.field.PlanarField.kind`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from siloflow.analysis.piv.calibration import ImageScale, piv_field, scale_from_markers
from siloflow.analysis.piv.field import DEFAULT_VALID_KINDS, SELECTABLE_KINDS, UNFLAGGED, PivRows, PlanarField
from siloflow.analysis.piv.hampel import hampel_filter

__all__ = ["MeasuredPiv", "check_windows", "measured_fields", "measured_piv_settings"]


@dataclass(frozen=True)
class MeasuredPiv:
    """How to read a measured sequence (``silo_flat.piv.measured``).

    Attributes
    ----------
    pixels : bool
        True when positions are pixels and vectors displacements per frame; False for metres and m/s.
    scale : ImageScale or None
        The image scale (from the wall markers); needed for pixels.
    frame_rate : float or None
        Camera frame rate [1/s]; needed for pixels and for the default field interval.
    start_time : float
        Time of the first field after the outlet opened [s].
    field_interval : float or None
        Time between successive fields [s]; None: one camera frame.
    hampel_half_window, hampel_threshold, hampel_noise_floor : int, float, float
        The Hampel filter (:func:`siloflow.analysis.piv.hampel.hampel_filter`; noise floor in m/s).
    valid_kinds : tuple of str
        The node kinds that count as valid (module docstring; some of
        :data:`siloflow.analysis.piv.field.SELECTABLE_KINDS`).
    """

    pixels: bool
    scale: ImageScale | None
    frame_rate: float | None
    start_time: float = 0.0
    field_interval: float | None = None
    hampel_half_window: int = 1
    hampel_threshold: float = 3.0
    hampel_noise_floor: float = 0.0
    valid_kinds: tuple[str, ...] = DEFAULT_VALID_KINDS

    def __post_init__(self) -> None:
        object.__setattr__(self, "valid_kinds", tuple(self.valid_kinds))
        wrong = [k for k in self.valid_kinds if k not in SELECTABLE_KINDS]
        if wrong or not self.valid_kinds:
            raise ValueError(f"valid kinds {list(self.valid_kinds)}: give one or more of {', '.join(SELECTABLE_KINDS)}")
        if self.pixels and (self.scale is None or self.frame_rate is None):
            raise ValueError("PIV in pixels needs the image scale (two or more wall markers) and the frame rate")
        if self.field_interval is None and self.frame_rate is None:
            raise ValueError("give the frame rate or the interval between fields, to time the fields")
        for name in ("frame_rate", "field_interval"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ValueError(f"{name} must be > 0, got {value!r}")

    @property
    def interval(self) -> float:
        """Time between successive fields [s]."""
        return self.field_interval if self.field_interval is not None else 1.0 / self.frame_rate


def _kind_grid(field: PlanarField, rows: PivRows, scale: ImageScale | None) -> np.ndarray:
    """Each row's kind at its node of ``field`` (placed as :func:`siloflow.analysis.piv.calibration.piv_field` places it)."""
    x, z = scale.to_silo(rows.x, rows.y) if scale is not None else (rows.x, rows.y)
    # field_from_rows rounds coordinates to 9 decimals before it matches them to grid lines; so does this
    i = np.searchsorted(field.x, np.round(x, 9))
    k = np.searchsorted(field.z, np.round(z, 9))
    kind = np.empty(field.u.shape, dtype=np.int8)
    kind[k, i] = rows.kind
    return kind


def measured_fields(frames: Sequence[PivRows], settings: MeasuredPiv,
                    sources: str | Sequence[str] = "measured PIV") -> list[PlanarField]:
    """The fields of ``frames`` (in time order) in silo coordinates, timed, valid as ``settings.valid_kinds`` say
    (module docstring) and Hampel-filtered; each field records its nodes' kinds. ``sources`` names where the frames
    come from (one name for all, or one per frame).

    Raises
    ------
    ValueError
        Naming the frame's source and number: a frame whose file says other units than ``settings`` (both named),
        positions in metres with y down the image, vectors without flags that the policy does not count, or a frame
        that does not fit the scale (:func:`siloflow.analysis.piv.calibration.piv_field`).
    """
    fields = []
    for number, rows in enumerate(frames):
        source = sources if isinstance(sources, str) else sources[number]
        where = f"{source}, frame {number}"
        if rows.pixels is not None and rows.pixels != settings.pixels:
            raise ValueError(f"{where}: the file is in {'pixels' if rows.pixels else 'metres'}, the "
                             f"configuration says {'pixels' if settings.pixels else 'metres'} (silo_flat.piv.measured."
                             "units)")
        if not settings.pixels and rows.y_down:
            raise ValueError(f"{where}: positions in metres with y pointing down the image are not silo coordinates "
                             "(z up, from the outlet); calibrate with y increasing upwards and the origin on the "
                             "silo's axis at the outlet, or give pixel files and wall markers")
        unflagged = rows.kind == UNFLAGGED
        if unflagged.any() and "unflagged" not in settings.valid_kinds:
            raise ValueError(f"{where}: {int(unflagged.sum())} vector(s) without a flag (the file does not say "
                             "whether they are measured or interpolated); list unflagged in silo_flat.piv.measured."
                             "valid to count them")
        scale = settings.scale if settings.pixels else None
        try:
            field = piv_field(rows.x, rows.y, rows.u, rows.v, rows.counted(settings.valid_kinds), rows.y_down,
                              scale, settings.frame_rate, settings.start_time + number * settings.interval)
        except ValueError as error:
            raise ValueError(f"{where}: {error}") from None
        filtered = hampel_filter(field, settings.hampel_half_window, settings.hampel_threshold,
                                 settings.hampel_noise_floor)
        fields.append(replace(filtered, kind=_kind_grid(field, rows, scale)))
    if not fields:
        raise ValueError(f"{sources if isinstance(sources, str) else 'measured PIV'}: no PIV frame")
    return fields


def measured_piv_settings(measured: dict, where: str = "silo_flat.piv.measured") -> MeasuredPiv:
    """The :class:`MeasuredPiv` of a validated ``silo_flat.piv.measured`` section: the scale from its markers for
    pixel files.

    Raises
    ------
    ValueError
        Naming ``where``: pixel files without two or more markers that fix a scale, or without a frame rate; fields
        that cannot be timed; valid kinds that are not node kinds a policy may count.
    """
    pixels = measured["units"] == "pixels"
    scale = None
    if pixels:
        markers = measured["markers"]
        if len(markers) < 2:
            raise ValueError(f"{where}.markers: {len(markers)} marker(s) do not fix the image scale of pixel files; "
                             "give two or more, each its image [column, row] (px) and silo [x, z] (m) position")
        scale = scale_from_markers([m["image"] for m in markers], [m["silo"] for m in markers], f"{where}.markers")
        if measured["frame_rate"] is None:
            raise ValueError(f"{where}.frame_rate: pixel files need the camera frame rate")
    hampel = measured["hampel"]
    try:
        return MeasuredPiv(pixels, scale, measured["frame_rate"], measured["start_time"], measured["field_interval"],
                           hampel["half_window"], hampel["threshold"], hampel["noise_floor"],
                           tuple(measured.get("valid", DEFAULT_VALID_KINDS)))
    except ValueError as error:
        raise ValueError(f"{where}: {error}") from None


def check_windows(fields: Sequence[PlanarField], windows, where: str = "silo_flat.piv.measured.windows") -> None:
    """Refuse time windows [s] that are empty or hold none of the measured fields.

    Raises
    ------
    ValueError
        Naming ``where``, the window and the fields' time span.
    """
    times = [f.time for f in fields]
    for index, (start, end) in enumerate(windows):
        if not start < end:
            raise ValueError(f"{where}[{index}]: the window [{start:g}, {end:g}] s does not end after it starts")
        if not any(start <= t <= end for t in times):
            raise ValueError(f"{where}[{index}]: no measured field between {start:g} and {end:g} s; the fields span "
                             f"{min(times):g} to {max(times):g} s after the outlet opened")
