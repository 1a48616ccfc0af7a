"""Planar multi-flow blender geometry: silo, hopper, cone-in-cone insert and blending tube (thesis ch. 7).

Coordinates (SI units, m): x across the width with the silo centred on x = 0, y through the depth (front wall
y = 0, back wall y = T), z up with the outlet plane at z = 0. Every wall is a 2-D shape in the x-z plane
extruded over y in [0, T], and the silo is mirror-symmetric about x = 0: everything is described on the right
half (x > 0) and mirrored.

Walls
    The hopper (half-angle alpha from the vertical, slot outlet B0 = 2 b) runs from the outlet to the transition
    at z_t = (W/2 - b) / tan(alpha), the vertical section of inner width W from there to z_top = z_t + Hv. Their
    inner surface is ``wall_x(z)``; they are thickened outward, so the inner dimensions are the nominal ones.
    Internal walls (insert and tube plates) are centred on their nominal mid-line, t/2 each side.

Insert (two inclined plates; the right plate runs from its outlet (x_o, z_o) up to its inlet (x_i, z_i))
    Planar "areas" are widths on the right half, measured from the mid-line of internal walls (the tube's
    mid-line at x = tw, or the centre plane without a tube) to the inner surface of the outer wall:
    interior annulus x_plate(z) - tw, exterior annulus wall_x(z) - x_plate(z). The area ratios compare the
    insert inlet with its outlet: Ai = (x_i - tw) / (x_o - tw), Ae = (W/2 - x_i) / (X - x_o) with X = wall_x(z_o),
    Ar = Ae / Ai. The inlet lies on the circle through the transition points (+-W/2, z_t) centred at the hopper
    apex z_apex = -b / tan(alpha), of radius R = (W/2) / sin(alpha), so it sits at or above z_t where the wall is
    vertical. The outlet level is shared by every configuration: the level where a reference insert (the
    study's diverging one, Ai 0.5, Ae 2.6) occupies the fraction phi = 0.63 of the hopper cross-section,
    x_o = phi X; the two conditions are linear in X and give X = (W/2 - tw (1 - Ai_ref)) /
    (phi Ai_ref + (1 - phi) Ae_ref) and z_o = (X - b) / tan(alpha). Given (Ai, Ae) at that level,
    x_i - tw = Ai (x_o - tw) and W/2 - x_i = Ae (X - x_o) are linear in (x_o, x_i).

Tube
    Two plates centred on x = +-tw from the insert outlet level z_o (the tube outlet; the reference level when
    there is no insert) up to z_t + ``tube_inlet_above_transition`` (the tube inlet).

The wall solids (closed meshes with outward normals) are built by :mod:`siloflow.model.cases.blender_meshes`; the clear
passages between the walls and the plain-data summary by :mod:`siloflow.model.cases.blender_passages`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

#: Insert presets by name: the study's area ratios, or None for "no insert and no tube".
INSERT_PRESETS: Mapping[str, Mapping[str, float] | None] = MappingProxyType(
    {
        "diverging": MappingProxyType({"interior_ratio": 0.5, "exterior_ratio": 2.6}),
        "straight": MappingProxyType({"interior_ratio": 1.0, "exterior_ratio": 1.72}),
        "converging": MappingProxyType({"interior_ratio": 2.0, "exterior_ratio": 1.18}),
        "none": None,
    }
)
#: The study's insert outlet level: the reference (diverging) insert occupies this fraction of the hopper width.
STUDY_OCCUPANCY = 0.63
#: Area ratios Ai, Ae of the reference insert that fixes the shared insert outlet level.
STUDY_REFERENCE_INTERIOR_RATIO = 0.5
STUDY_REFERENCE_EXTERIOR_RATIO = 2.6
#: The study's tube inlet: this fraction of the silo width above the hopper transition.
STUDY_TUBE_INLET_FRACTION = 0.15

_RATIO_KEYS = frozenset({"interior_ratio", "exterior_ratio"})
_POINT_KEYS = frozenset({"inlet", "outlet"})


def finite_number(name: str, value) -> float:
    """``value`` as a float; ValueError naming ``name`` when it is not a finite number."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return number


def positive_number(name: str, value) -> float:
    """``value`` as a float; ValueError naming ``name`` unless it is a finite number > 0."""
    number = finite_number(name, value)
    if not number > 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return number


def _point(name: str, value) -> tuple[float, float]:
    """A 2-D point (x, z) in m; ValueError naming ``name`` unless it is two finite numbers."""
    try:
        x, z = value
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a point [x, z], got {value!r}") from None
    return (finite_number(f"{name} x", x), finite_number(f"{name} z", z))


@dataclass(frozen=True)
class BlenderGeometry:
    """Walls, insert and tube of the planar blender (build it with :func:`blender_geometry`).

    Attributes
    ----------
    width : float
        Inner width W of the vertical section (m).
    depth : float
        Inner depth T between the front and back walls (m).
    vertical_height : float
        Height Hv of the vertical section above the hopper transition (m).
    hopper_half_angle : float
        Hopper half-angle alpha from the vertical (degrees), 0 < alpha < 90.
    outlet_width : float
        Slot outlet width B0 (m), smaller than W.
    wall_thickness : float
        Thickness t of every wall (m). Outer walls grow outward from their inner surface, internal walls are
        centred on their mid-line.
    tube_width : float
        Tube width between the mid-surfaces of its plates (m); 0 for no tube.
    tube_inlet_above_transition : float
        Height of the tube inlet above the hopper transition (m); unused without a tube.
    insert_name : str or None
        Preset name, ``"custom"`` for user ratios or end points, None for no insert.
    insert_inlet, insert_outlet : tuple of float or None
        Upper and lower end (x, z) of the right plate's mid-line (m); None for no insert.
    occupancy : float
        Fraction phi of the hopper width the reference insert occupies at its outlet (-).
    reference_interior_ratio, reference_exterior_ratio : float
        Ai_ref, Ae_ref of the reference insert that fixes the shared insert outlet level (-).
    """

    width: float
    depth: float
    vertical_height: float
    hopper_half_angle: float
    outlet_width: float
    wall_thickness: float
    tube_width: float = 0.0
    tube_inlet_above_transition: float = 0.0
    insert_name: str | None = None
    insert_inlet: tuple[float, float] | None = None
    insert_outlet: tuple[float, float] | None = None
    occupancy: float = STUDY_OCCUPANCY
    reference_interior_ratio: float = STUDY_REFERENCE_INTERIOR_RATIO
    reference_exterior_ratio: float = STUDY_REFERENCE_EXTERIOR_RATIO

    def __post_init__(self) -> None:
        self._validate_silo()
        self._validate_reference_level()
        if (self.insert_inlet is None) != (self.insert_outlet is None):
            raise ValueError(
                f"insert needs both end points: insert_inlet={self.insert_inlet!r}, insert_outlet={self.insert_outlet!r}"
            )
        if self.has_insert:
            self._validate_insert()
        if self.has_tube:
            self._validate_tube()

    # ----------------------------------------------------------------------------------------------- validation
    def _validate_silo(self) -> None:
        for name in ("width", "depth", "vertical_height", "outlet_width", "wall_thickness"):
            positive_number(name, getattr(self, name))
        alpha = finite_number("hopper_half_angle", self.hopper_half_angle)
        if not 0.0 < alpha < 90.0:
            raise ValueError(f"hopper_half_angle must lie in (0, 90) degrees, got {self.hopper_half_angle!r}")
        tube_width = finite_number("tube_width", self.tube_width)
        if tube_width < 0:
            raise ValueError(f"tube_width must be >= 0 (0 for no tube), got {self.tube_width!r}")
        # The outer wall bends at z_t - t tan(alpha/2): a wall that thick would reach below the outlet plane.
        if not self.wall_thickness * math.tan(math.radians(alpha) / 2.0) < self.z_transition:
            raise ValueError(
                f"wall_thickness={self.wall_thickness!r} is too thick for a hopper {self.z_transition:.4g} m tall"
            )
        for name in ("occupancy", "reference_interior_ratio", "reference_exterior_ratio"):
            positive_number(name, getattr(self, name))
        if not self.occupancy < 1.0:
            raise ValueError(f"occupancy must lie in (0, 1), got {self.occupancy!r}")

    def _validate_reference_level(self) -> None:
        wall = self.reference_outlet_wall_x
        if not self.half_outlet < wall < 0.5 * self.width:
            raise ValueError(
                f"the reference insert (occupancy={self.occupancy!r}, reference_interior_ratio="
                f"{self.reference_interior_ratio!r}, reference_exterior_ratio={self.reference_exterior_ratio!r}) "
                f"puts the insert outlet level outside the hopper: hopper half-width {wall:.4g} m there, "
                f"not within ({self.half_outlet:.4g}, {0.5 * self.width:.4g}) m"
            )

    def _validate_insert(self) -> None:
        (x_i, z_i), (x_o, z_o) = _point("insert inlet", self.insert_inlet), _point("insert outlet", self.insert_outlet)
        t, tw = self.wall_thickness, self.tube_half_width
        where = f"insert inlet ({x_i:.6g}, {z_i:.6g}) m, outlet ({x_o:.6g}, {z_o:.6g}) m"
        if not z_o < z_i:
            raise ValueError(f"insert outlet must lie below the insert inlet: {where}")
        if not 0.0 < z_o:
            raise ValueError(f"insert outlet lies below the outlet plane z = 0: {where}")
        if not z_i <= self.z_top:
            raise ValueError(f"insert inlet lies above the top of the silo (z_top {self.z_top:.6g} m): {where}")
        # The annuli are linear (interior) and concave (exterior) in z: their narrowest point is at a plate end.
        for end, (x, z) in (("inlet", (x_i, z_i)), ("outlet", (x_o, z_o))):
            inner = "the tube mid-line" if self.has_tube else "the centre plane"
            if not x - tw > t:
                raise ValueError(
                    f"insert {end} is outside the silo or not clear of {inner} by more than the wall thickness "
                    f"({t:.4g} m): {where}"
                )
            if not float(self.wall_x(z)) - x > t:
                raise ValueError(
                    f"insert {end} is outside the silo or not clear of the silo wall (at x = {float(self.wall_x(z)):.6g} m) "
                    f"by more than the wall thickness ({t:.4g} m): {where}"
                )

    def _validate_tube(self) -> None:
        t, tw = self.wall_thickness, self.tube_half_width
        if not self.tube_width > t:
            raise ValueError(
                f"tube_width={self.tube_width!r} leaves no clear passage inside walls of thickness {t!r} (wall_thickness)"
            )
        rise = finite_number("tube_inlet_above_transition", self.tube_inlet_above_transition)
        if not self.z_tube_inlet > self.z_tube_outlet:
            raise ValueError(
                f"tube_inlet_above_transition={rise!r} puts the tube inlet (z = {self.z_tube_inlet:.6g} m) "
                f"at or below the tube outlet (z = {self.z_tube_outlet:.6g} m)"
            )
        if not self.z_tube_inlet <= self.z_top:
            raise ValueError(
                f"tube_inlet_above_transition={rise!r} puts the tube inlet (z = {self.z_tube_inlet:.6g} m) above the "
                f"top of the silo (z = {self.z_top:.6g} m)"
            )
        if not tw + 0.5 * t < float(self.wall_x(self.z_tube_outlet)):
            raise ValueError(
                f"tube_width={self.tube_width!r} does not fit inside the hopper at the tube outlet "
                f"(half-width {float(self.wall_x(self.z_tube_outlet)):.4g} m)"
            )

    # ------------------------------------------------------------------------------------------ silo and hopper
    @property
    def _tan_alpha(self) -> float:
        return math.tan(math.radians(self.hopper_half_angle))

    @property
    def half_outlet(self) -> float:
        """Half the outlet width, b = B0/2 (m)."""
        return 0.5 * self.outlet_width

    @property
    def z_transition(self) -> float:
        """Height z_t of the hopper transition, (W/2 - b) / tan(alpha) (m)."""
        return (0.5 * self.width - self.half_outlet) / self._tan_alpha

    @property
    def z_apex(self) -> float:
        """Height of the (virtual) hopper apex, -b / tan(alpha), below the outlet (m)."""
        return -self.half_outlet / self._tan_alpha

    @property
    def circle_radius(self) -> float:
        """Radius R = (W/2) / sin(alpha) of the circle about the apex through the transition points (m)."""
        return 0.5 * self.width / math.sin(math.radians(self.hopper_half_angle))

    @property
    def z_top(self) -> float:
        """Height of the top of the silo, z_t + Hv (m)."""
        return self.z_transition + self.vertical_height

    def wall_x(self, z):
        """Inner surface of the right outer wall at height ``z`` (m): b + z tan(alpha) in the hopper, W/2 above.

        Parameters
        ----------
        z : float or array_like
            Heights (m) within [0, z_top].

        Returns
        -------
        float or numpy.ndarray
            x of the inner wall surface (m), a float for a scalar ``z``.
        """
        heights = np.asarray(z, dtype=float)
        if np.any(~np.isfinite(heights)) or np.any(heights < 0.0) or np.any(heights > self.z_top):
            raise ValueError(f"z must lie within [0, z_top = {self.z_top:.6g}] m, got {z!r}")
        x = np.where(heights <= self.z_transition, self.half_outlet + heights * self._tan_alpha, 0.5 * self.width)
        return float(x) if x.ndim == 0 else x

    # ------------------------------------------------------------------------------------------ insert and tube
    @property
    def has_tube(self) -> bool:
        """Whether the geometry has a blending tube."""
        return self.tube_width > 0

    @property
    def has_insert(self) -> bool:
        """Whether the geometry has an insert."""
        return self.insert_inlet is not None

    @property
    def tube_half_width(self) -> float:
        """tw = tube_width / 2, the x of the right tube plate's mid-line (m); 0 without a tube."""
        return 0.5 * self.tube_width if self.has_tube else 0.0

    @property
    def reference_outlet_wall_x(self) -> float:
        """Hopper half-width X at the shared insert outlet level (m), from the reference insert's occupancy:
        (W/2 - tw (1 - Ai_ref)) / (phi Ai_ref + (1 - phi) Ae_ref)."""
        phi, a_i, a_e = self.occupancy, self.reference_interior_ratio, self.reference_exterior_ratio
        return (0.5 * self.width - self.tube_half_width * (1.0 - a_i)) / (phi * a_i + (1.0 - phi) * a_e)

    @property
    def z_reference_outlet(self) -> float:
        """Shared insert outlet level, (X - b) / tan(alpha) (m)."""
        return (self.reference_outlet_wall_x - self.half_outlet) / self._tan_alpha

    @property
    def z_insert_outlet(self) -> float:
        """Height of the insert outlet (m): the plate's lower end, or the shared level without an insert."""
        return self.insert_outlet[1] if self.has_insert else self.z_reference_outlet

    @property
    def z_tube_outlet(self) -> float:
        """Height of the tube outlet: the insert outlet level (m)."""
        return self.z_insert_outlet

    @property
    def z_tube_inlet(self) -> float:
        """Height of the tube inlet, z_t + tube_inlet_above_transition (m)."""
        return self.z_transition + self.tube_inlet_above_transition

    def solve_plate(self, interior_ratio: float, exterior_ratio: float) -> tuple[tuple[float, float], tuple[float, float]]:
        """End points of the right insert plate with area ratios (Ai, Ae) at the shared outlet level.

        Parameters
        ----------
        interior_ratio : float
            Ai, interior annulus width at the insert inlet over that at its outlet (-).
        exterior_ratio : float
            Ae, exterior annulus width at the insert inlet over that at its outlet (-).

        Returns
        -------
        inlet, outlet : tuple of float
            (x_i, z_i) on the circle about the apex, and (x_o, z_o) at the shared level (m).

        Raises
        ------
        ValueError
            When Ae == Ai (parallel conditions, no solution) or the plate falls outside the silo or the tube.
        """
        a_i = positive_number("interior_ratio", interior_ratio)
        a_e = positive_number("exterior_ratio", exterior_ratio)
        if math.isclose(a_e, a_i, rel_tol=1e-12, abs_tol=0.0):
            raise ValueError(
                f"insert exterior_ratio={exterior_ratio!r} equals interior_ratio={interior_ratio!r}: no plate has both"
            )
        half_width, tw = 0.5 * self.width, self.tube_half_width
        wall, z_o = self.reference_outlet_wall_x, self.z_reference_outlet
        # x_i - tw = Ai (x_o - tw) and W/2 - x_i = Ae (X - x_o), solved for x_o and x_i.
        x_o = (a_e * wall - half_width + tw * (1.0 - a_i)) / (a_e - a_i)
        x_i = tw + a_i * (x_o - tw)
        ratios = f"interior_ratio={interior_ratio!r}, exterior_ratio={exterior_ratio!r}"
        if not tw < x_o < wall:
            raise ValueError(
                f"insert {ratios} puts the plate outlet at x = {x_o:.6g} m, outside ({tw:.6g}, {wall:.6g}) m "
                "(between the tube or centre plane and the hopper wall)"
            )
        if not tw < x_i < half_width:
            raise ValueError(
                f"insert {ratios} puts the plate inlet at x = {x_i:.6g} m, outside ({tw:.6g}, {half_width:.6g}) m "
                "(between the tube or centre plane and the silo wall)"
            )
        z_i = self.z_apex + math.sqrt(self.circle_radius**2 - x_i**2)
        return (x_i, z_i), (x_o, z_o)

    def _require_insert(self) -> None:
        if not self.has_insert:
            raise ValueError(f"the geometry has no insert (insert_name={self.insert_name!r})")

    def plate_x(self, z):
        """Mid-line x of the right insert plate at height ``z`` (m), linear between its end points.

        Parameters
        ----------
        z : float or array_like
            Heights (m) within [z_o, z_i].
        """
        self._require_insert()
        (x_i, z_i), (x_o, z_o) = self.insert_inlet, self.insert_outlet
        heights = np.asarray(z, dtype=float)
        if np.any(~np.isfinite(heights)) or np.any(heights < z_o) or np.any(heights > z_i):
            raise ValueError(f"z must lie within the insert [{z_o:.6g}, {z_i:.6g}] m, got {z!r}")
        x = x_o + (heights - z_o) * (x_i - x_o) / (z_i - z_o)
        return float(x) if x.ndim == 0 else x

    @property
    def plate_length(self) -> float:
        """Length of the insert plate's mid-line (m)."""
        self._require_insert()
        (x_i, z_i), (x_o, z_o) = self.insert_inlet, self.insert_outlet
        return math.hypot(x_i - x_o, z_i - z_o)

    @property
    def plate_half_thickness_x(self) -> float:
        """Half the horizontal thickness of the inclined insert plate, (t/2) / cos(plate angle from vertical) (m).

        A horizontal cut through a plate of thickness t inclined at beta from the vertical is t / cos(beta) wide.
        """
        self._require_insert()
        (_, z_i), (_, z_o) = self.insert_inlet, self.insert_outlet
        return 0.5 * self.wall_thickness * self.plate_length / (z_i - z_o)

    @property
    def interior_ratio(self) -> float:
        """Achieved Ai = (x_i - tw) / (x_o - tw) (-)."""
        self._require_insert()
        tw = self.tube_half_width
        return (self.insert_inlet[0] - tw) / (self.insert_outlet[0] - tw)

    @property
    def exterior_ratio(self) -> float:
        """Achieved Ae = (wall_x(z_i) - x_i) / (wall_x(z_o) - x_o) (-)."""
        self._require_insert()
        (x_i, z_i), (x_o, z_o) = self.insert_inlet, self.insert_outlet
        return (self.wall_x(z_i) - x_i) / (self.wall_x(z_o) - x_o)

    @property
    def area_ratio(self) -> float:
        """Achieved Ar = Ae / Ai (-)."""
        return self.exterior_ratio / self.interior_ratio

    @property
    def insert_occupancy(self) -> float:
        """Fraction of the hopper half-width the insert takes at its outlet, x_o / wall_x(z_o) (-)."""
        self._require_insert()
        x_o, z_o = self.insert_outlet
        return x_o / self.wall_x(z_o)

    @property
    def included_angle(self) -> float:
        """Angle between the insert plate and the hopper wall, both taken upward (degrees)."""
        self._require_insert()
        (x_i, z_i), (x_o, z_o) = self.insert_inlet, self.insert_outlet
        alpha = math.radians(self.hopper_half_angle)
        cosine = ((x_i - x_o) * math.sin(alpha) + (z_i - z_o) * math.cos(alpha)) / self.plate_length
        return math.degrees(math.acos(min(1.0, max(-1.0, cosine))))

    def internal_wall_spans(self) -> list[tuple[tuple[float, float], tuple[float, float]]]:
        """Mid-lines of the right half's internal walls (insert plate, tube plate), lower end first.

        Returns
        -------
        list of ((x, z), (x, z))
            Lower and upper end of each mid-line (m); mirror for the left half.
        """
        spans = []
        if self.has_insert:
            spans.append((tuple(self.insert_outlet), tuple(self.insert_inlet)))
        if self.has_tube:
            tw = self.tube_half_width
            spans.append(((tw, self.z_tube_outlet), (tw, self.z_tube_inlet)))
        return spans


def blender_geometry(
    width: float,
    depth: float,
    vertical_height: float,
    hopper_half_angle: float,
    outlet_width: float,
    wall_thickness: float,
    tube_width: float | None = None,
    tube_inlet_above_transition: float | None = None,
    insert=None,
    *,
    occupancy: float = STUDY_OCCUPANCY,
    reference_interior_ratio: float = STUDY_REFERENCE_INTERIOR_RATIO,
    reference_exterior_ratio: float = STUDY_REFERENCE_EXTERIOR_RATIO,
) -> BlenderGeometry:
    """Build and validate the blender geometry from plain numbers.

    Parameters
    ----------
    width, depth, vertical_height : float
        Inner width W, depth T and height of the vertical section above the transition (m).
    hopper_half_angle : float
        Hopper half-angle from the vertical (degrees).
    outlet_width : float
        Slot outlet width B0 (m).
    wall_thickness : float
        Thickness t of every wall (m).
    tube_width : float or None
        Tube width between its plates' mid-surfaces (m); 0 or None for no tube.
    tube_inlet_above_transition : float or None
        Tube inlet height above the hopper transition (m); None for the study's 15 % of W.
    insert : str, dict or None
        A name of :data:`INSERT_PRESETS` (``"none"`` means no insert and no tube, whatever ``tube_width``),
        ``{"interior_ratio": Ai, "exterior_ratio": Ae}`` solved at the shared outlet level, or
        ``{"inlet": [x_i, z_i], "outlet": [x_o, z_o]}`` (the right plate's mid-line ends, m); None for no
        insert (the tube is kept).
    occupancy, reference_interior_ratio, reference_exterior_ratio : float
        phi, Ai_ref, Ae_ref of the reference insert that fixes the shared insert outlet level (-).

    Raises
    ------
    ValueError
        Naming the offending parameter and value.
    """
    name, ratios, points = None, None, None
    if isinstance(insert, str):
        if insert not in INSERT_PRESETS:
            raise ValueError(f"insert must be one of {', '.join(INSERT_PRESETS)} or a dict, got {insert!r}")
        ratios = INSERT_PRESETS[insert]
        if ratios is None:
            tube_width = 0.0
        else:
            name = insert
    elif isinstance(insert, Mapping):
        keys = frozenset(insert)
        if keys == _RATIO_KEYS:
            name, ratios = "custom", insert
        elif keys == _POINT_KEYS:
            name = "custom"
            points = (_point("insert inlet", insert["inlet"]), _point("insert outlet", insert["outlet"]))
        else:
            raise ValueError(
                f"insert dict needs the keys interior_ratio and exterior_ratio, or inlet and outlet; got {sorted(keys)}"
            )
    elif insert is not None:
        raise ValueError(f"insert must be a preset name, a dict or None, got {insert!r}")

    tube = 0.0 if tube_width is None else finite_number("tube_width", tube_width)
    if tube_inlet_above_transition is None:
        rise = STUDY_TUBE_INLET_FRACTION * finite_number("width", width)
    else:
        rise = finite_number("tube_inlet_above_transition", tube_inlet_above_transition)
    common = {
        "width": width,
        "depth": depth,
        "vertical_height": vertical_height,
        "hopper_half_angle": hopper_half_angle,
        "outlet_width": outlet_width,
        "wall_thickness": wall_thickness,
        "tube_width": tube,
        "tube_inlet_above_transition": rise,
        "occupancy": occupancy,
        "reference_interior_ratio": reference_interior_ratio,
        "reference_exterior_ratio": reference_exterior_ratio,
    }
    for key in ("width", "depth", "vertical_height", "hopper_half_angle", "outlet_width", "wall_thickness",
                "occupancy", "reference_interior_ratio", "reference_exterior_ratio"):
        common[key] = finite_number(key, common[key])
    if ratios is not None:
        # The plate is solved at the shared outlet level, which the insert-free geometry already defines.
        points = BlenderGeometry(**common).solve_plate(ratios["interior_ratio"], ratios["exterior_ratio"])
    if points is None:
        return BlenderGeometry(**common)
    inlet, outlet = points
    return BlenderGeometry(**common, insert_name=name, insert_inlet=inlet, insert_outlet=outlet)
