"""Whether a run is at the study's scale for a finding, decided from its configuration alone.

*Scale*: every dimension a finding depends on (depth, width, fill height, outlet, bed above the blender's insert,
particle count, Jenike cell, particle size) is compared with the study's, as a ratio to the study's and, where a
floor applies, in the run's particle diameters; and the quantity must be defined and sampled as the study defines
it (a flag the row passes in: it knows how it computed its figure). A verdict never reads a row's value or any run's
result: :func:`scale_verdict` takes the validated configuration or the built case objects, and no value at all.

Thresholds (:class:`Thresholds`): a length is at the study's scale when its ratio to the study's lies in
[``min_dimension_ratio``, ``max_dimension_ratio``] and, for the depth, the outlet and tube widths and the Jenike cell,
it also spans at least ``min_depth_diameters``, ``min_outlet_diameters`` or ``min_cell_diameters`` volume-equivalent
particle diameters (the ``validation`` and ``validation.scale`` sections of the configuration). The particle count
has only the lower bound: more particles than the study's only lower the counting noise.

The study's dimensions (:data:`STUDY`) are from the thesis's methods, each with its section; lengths in m.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from siloflow.model.cases.blender import geometry_for
from siloflow.model.cases.blender_geometry import BlenderGeometry, blender_geometry
from siloflow.model.cases.kinds import kind_of_case
from siloflow.model.cases.particles import clump_volume, equivalent_diameter, particle_template

__all__ = ["STUDY", "STUDY_PARTICLE_DIAMETER", "FINDING_SCALES", "REASONS", "FLOORS", "Thresholds", "StudyDimension",
           "FindingScale", "DimensionDifference", "ScaleVerdict", "scale_verdict"]


@dataclass(frozen=True)
class StudyDimension:
    """One dimension of the study's set-up: ``value`` in ``unit`` (``m`` or ``clumps``), its thesis ``section``."""

    value: float
    section: str
    unit: str = "m"
    note: str = ""


#: The study's particle: the two-sphere clump (two 3 mm spheres 0.75 mm apart, §4.2) used in chapters 5-7 (§4.6,
#: §7.7); its volume-equivalent diameter, about 3.33 mm (m).
STUDY_PARTICLE_DIAMETER = equivalent_diameter(clump_volume(np.array([[-0.000375, 0.0, 0.0], [0.000375, 0.0, 0.0]]),
                                                           np.array([0.0015, 0.0015])))
#: The study's blender (§7.2): 450 mm wide, 40 mm deep, 30 degree hopper, 40 mm outlet and tube, the tube inlet 15 % of
#: the width above the transition, 5 mm internal walls. Its hopper and insert are rebuilt from these numbers (the
#: text's tube inlet at Z = 510 mm does not fit them; §7.2 and Fig. 7.3), as siloflow builds every blender.
_STUDY_BLENDER = dict(width=0.45, depth=0.04, vertical_height=1.5, hopper_half_angle=30.0, outlet_width=0.04,
                      wall_thickness=0.005, tube_width=0.04)
_STUDY_BLENDER_FILL = 1.125
_BLENDER_INSERTS = ("diverging", "straight", "converging")


def _top_of_internals(geometry: BlenderGeometry) -> float:
    """Height of the highest internal wall, the tube inlet or the insert's inlet (m)."""
    tops = [geometry.z_tube_inlet if geometry.has_tube else 0.0]
    return max(tops + ([geometry.insert_inlet[1]] if geometry.has_insert else []))


def _study_bed(insert: str) -> float:
    return _STUDY_BLENDER_FILL - _top_of_internals(blender_geometry(**_STUDY_BLENDER, insert=insert))


#: The study's particle stiffness: its material input 1e8 Pa is EDEM's shear modulus (its quoted Rayleigh time only
#: follows from G = 1e8 Pa), Young's modulus 2 (1 + 0.4) 1e8 = 2.8e8 Pa (§4.2, METHODS §1).
_STIFFNESS = StudyDimension(2.8e8, "§4.2", "Pa", "Young's modulus from the study's shear modulus 1e8 Pa")
_SILO = {"width": StudyDimension(0.15, "§5.2"), "depth": StudyDimension(0.04, "§5.2"),
         "fill_height": StudyDimension(0.27, "§6.2.2", note="the DEM fill (the experiment's 280-300 mm, §5.2)"),
         "outlet": StudyDimension(0.04, "§5.2"),
         "particle_diameter": StudyDimension(STUDY_PARTICLE_DIAMETER, "§4.2, §4.6"),
         "particle_count": StudyDimension(53492, "§5.3", "clumps", "at the end of filling"),
         "youngs_modulus": _STIFFNESS,
         "restitution": StudyDimension(1e-4, "§4.4.1, §5.6", "-",
                                       "particle-particle, chosen for the later chapters (§4.4.1)")}
#: The study's dimensions per case kind.
STUDY: Mapping[str, Mapping[str, StudyDimension]] = MappingProxyType({
    "jenike": MappingProxyType({
        "cell_diameter": StudyDimension(0.095, "§4.3, §4.3.1.1", note="13 mm bottom and 16 mm shear ring"),
        "particle_count": StudyDimension(6589, "§4.3.1.3", "clumps",
                                         "two-sphere clumps (sphere 4085, four-sphere 5513); not judged: it follows "
                                         "from the cell, its rings and the shape's packing"),
        "youngs_modulus": _STIFFNESS}),
    "silo_flat": MappingProxyType(dict(_SILO)),
    "silo_recirculation": MappingProxyType({
        **_SILO, "depth": StudyDimension(0.04, "§6.2.2", note="implied: the ch. 5 silo"),
        "fill_height": StudyDimension(0.27, "§6.2.2"), "outlet": StudyDimension(0.04, "§6.2.2"),
        "channel_length": StudyDimension(0.08, "§6.2.2"),
        "channel_width": StudyDimension(0.04, "§6.2.2", note="not stated, presumably the outlet's; siloflow's "
                                        "channel is the outlet's width, so the outlet's judgement is the channel's"),
        "particle_count": StudyDimension(53492, "§5.3, §6.2.2", "clumps", "the ch. 5 assembly")}),
    "blender": MappingProxyType({
        "width": StudyDimension(0.45, "§7.2"), "depth": StudyDimension(0.04, "§7.2"),
        "outlet": StudyDimension(0.04, "§7.2"), "tube_width": StudyDimension(0.04, "§7.2"),
        "fill_height": StudyDimension(_STUDY_BLENDER_FILL, "§7.2, §7.7", note="1125 +- 25 mm, the DEM at full scale"),
        "bed_above_insert": StudyDimension(_study_bed("diverging"), "§7.2",
                                           note="fill height above the tube inlet, rebuilt from §7.2"),
        "particle_diameter": StudyDimension(STUDY_PARTICLE_DIAMETER, "§4.6, §7.7"),
        "particle_count": StudyDimension(606652, "§7.7", "clumps", "at the end of filling"),
        "youngs_modulus": _STIFFNESS}),
})

#: Why a dimension bears on the findings that list it.
REASONS: Mapping[str, str] = MappingProxyType({
    "cell_diameter": "the cell's walls order the packing within a few particle diameters of them: a smaller cell "
                     "puts more of the shear zone in that layer",
    "width": "the side walls carry part of the weight (Janssen's z_c, eq. 5.4) and bound the flow channel",
    "depth": "the front and back walls carry part of the weight, loosen the packing next to them and hold the flow "
             "back: their share grows as the depth shrinks (§5.5)",
    "fill_height": "the stress saturates over a few z_c, and the head above the sampled heights sets the flow there",
    "outlet": "the outlet sets the discharge rate (Beverloo) and the flow channel above it",
    "channel_length": "the return channel holds part of the circulating material: its transit is part of every "
                      "residence time",
    "tube_width": "the tube is one of the insert's passages: its width sets its share of the flow, and a narrow one "
                  "arches",
    "bed_above_insert": "the head above the insert and the tube inlet sets the flow entering the passages",
    "particle_count": "the VRR and the RTD count particles in outlet samples and tracers: fewer, more counting noise",
    "particle_diameter": "B, Beverloo's empty annulus and every wall layer scale with the particle size",
    "youngs_modulus": "the contact stiffness sets the overlaps and the packing: E = 5e6 Pa against the study's "
                      "2.8e8 Pa moved the Jenike cell's bulk friction and the fills' densities beyond their errors "
                      "(docs/validation.md, Stiffness); the flow rates and the residence time it did not",
    "restitution": "a nearly plastic contact packs the pour denser: at the study's 1e-4 the tiny silo's filling "
                   "density rose by 23 standard errors over 0.1 on YADE (docs/validation.md, before and after); "
                   "LIGGGHTS refuses a restitution at or below 0.05",
})
#: The diameter floor (a key of the ``validation`` section) of each dimension that has one.
FLOORS: Mapping[str, str] = MappingProxyType({"depth": "min_depth_diameters", "outlet": "min_outlet_diameters",
                                              "tube_width": "min_outlet_diameters",
                                              "cell_diameter": "min_cell_diameters"})


@dataclass(frozen=True)
class FindingScale:
    """What a finding needs of a run: its case ``kind``, the ``dimensions`` that bear on it, the study's
    ``definition`` of its quantity (with sections) and, for the Jenike cell and the blender, the ``shapes`` or
    ``inserts`` it is about."""

    kind: str
    dimensions: tuple[str, ...]
    definition: str
    shapes: tuple[str, ...] = ()
    inserts: tuple[str, ...] = ()


_ALL_SHAPES, _CLUMP = ("sphere", "sphere2", "sphere4"), ("sphere2",)
_CELL = ("cell_diameter", "youngs_modulus")
_SILO_ALL = ("width", "depth", "fill_height", "outlet", "particle_diameter")
_VRR = _SILO_ALL + ("particle_count",)
_RTD = _VRR + ("channel_length",)
_BLENDER = ("width", "depth", "bed_above_insert", "tube_width", "particle_diameter")
_VRR_TEXT = "VRR, the input over the output variance of the blue concentration, Nr = time in the silo / t_rm"
_RTD_TEXT = ("a tracer of 10 % of the silo volume injected at the inlet of the steady flow, theta = t / t_rm with "
             "t_rm = hold-up volume / volumetric flow rate (§6.2.3.3, §6.5.1)")
#: Per finding id: its kind, the dimensions that bear on it and the study's definition of its quantity.
FINDING_SCALES: Mapping[str, FindingScale] = MappingProxyType({
    "C1": FindingScale("jenike", _CELL, "bulk internal friction F_t,avg / (F_N + W_solids) over the steady shear at "
                       "rolling friction 0, particle friction down to 0 (§4.3.3, §4.4.3.1)", _ALL_SHAPES),
    "C2": FindingScale("jenike", _CELL, "bulk internal friction at rolling friction 0 over particle friction 0-1, "
                       "sphere and two- and four-sphere clumps (§4.3.1.2, §4.4.3.1)", _ALL_SHAPES),
    "C3": FindingScale("jenike", _CELL, "bulk wall friction, the bottom ring replaced by a wall plate, "
                       "particle-wall friction 0-1 (§4.3, §4.4.3.2)", _ALL_SHAPES),
    "C4": FindingScale("jenike", _CELL, "bulk friction at restitution 1e-4, 0.1, 0.6 and 1 (§4.4.1)", _CLUMP),
    "C5": FindingScale("jenike", _CELL, "bulk friction with rotations blocked while shearing, at particle friction "
                       "0.1 and 0.5 (§4.5.2)", _CLUMP),
    "C6": FindingScale("jenike", _CELL, "bulk internal friction at rolling friction 0 and 0.1, particle friction 0.1 "
                       "and 0.5 (§4.5.3)", _CLUMP),
    "C7": FindingScale("jenike", _CELL, "bulk friction of the two-sphere clump at particle friction 0.35, rolling "
                       "0.1, walls 0.17 and 0.20, consolidated and sheared at 4 kPa (§4.3.1.3, §4.6)", _CLUMP),
    "S1": FindingScale("silo_flat", ("width", "depth", "fill_height", "particle_diameter"), "vertical stress at the "
                       "end of filling averaged over the cross-section against depth, against Janssen with the active "
                       "K and eq. 5.4's z_c (§5.4.1)"),
    "S2": FindingScale("silo_flat", ("depth", "particle_diameter", "youngs_modulus", "restitution"), "total particle "
                       "mass over the "
                       "filled volume of "
                       "the settled fill (§5.4.2)"),
    "S3": FindingScale("silo_flat", ("width", "depth", "outlet", "particle_diameter"), "time-averaged mass and "
                       "volumetric flow rates of the discharge (§5.4.2)"),
    "S4": FindingScale("silo_flat", _SILO_ALL, "centreline velocity over time, profiles at Z = 20, 40, 80 mm at "
                       "t = 0.1-1.1 s and steady profiles (t = 0.5-0.7 s) at Z = 20, 40, 80, 120 mm "
                       "(§5.4.3.2-§5.4.3.4)"),
    "S5": FindingScale("silo_flat", _SILO_ALL, "B from the fit of the steady (t = 0.5-0.7 s) vertical-velocity "
                       "profile at Z = 20, 40, 80 and 120 mm (§5.4.3.4)"),
    "S6": FindingScale("silo_flat", _SILO_ALL, "stress at the end of filling and Z = 120 mm profiles (t = 0.5-0.7 s) "
                       "at front/back wall friction 0 to 1 (§5.5)"),
    "B1": FindingScale("silo_recirculation", _SILO_ALL + ("youngs_modulus",), "bulk density of the fill while it "
                       "recirculates against the "
                       "settled fill's, per flow pattern (§6.3.1)"),
    "B2": FindingScale("silo_recirculation", _VRR, f"{_VRR_TEXT}, at Nr = 0 to 4 (§6.4.1, §6.4.2)"),
    "B3": FindingScale("silo_recirculation", _VRR, f"{_VRR_TEXT}, batches of 13, 25 and 50 % (§6.4, §6.4.2)"),
    "B4": FindingScale("silo_recirculation", _VRR, f"{_VRR_TEXT}, at Nr = 4, batches of 13, 25 and 50 % (§6.4.2)"),
    "B5": FindingScale("silo_recirculation", _VRR, f"{_VRR_TEXT}, at Nr = 0 (§6.4.2)"),
    "B6": FindingScale("silo_recirculation", _VRR, f"{_VRR_TEXT}, a 50 % batch in 1, 3 and 5 sub-layers (§6.4.2)"),
    "B7": FindingScale("silo_recirculation", _RTD, f"the peak of E(theta) of {_RTD_TEXT}"),
    "B8": FindingScale("silo_recirculation", _RTD, f"t_s (first tracer out) over t_d (all of it out), from the "
                       f"injection of {_RTD_TEXT}"),
    "M1": FindingScale("blender", _BLENDER, "diverging insert, steady continuous discharge: exterior annulus, interior "
                       "annulus and tube velocity at the insert outlet over the cross-section mean (§7.5.1.1)",
                       inserts=("diverging",)),
    "M2": FindingScale("blender", _BLENDER, "converging insert: velocities at the insert outlet and inlet and across "
                       "the vertical section (§7.5.3)", inserts=("converging",)),
    "M3": FindingScale("blender", _BLENDER, "RTD from path lines through the steady velocity field and the LTI "
                       "convolution, the three inserts compared (§7.6)", inserts=_BLENDER_INSERTS),
    "M4": FindingScale("blender", ("width", "depth", "outlet") + _BLENDER[2:] + ("youngs_modulus",),
                       "diverging insert at 1, 5 and 50 g, the same material at every factor: mass flow rate and "
                       "velocities against sqrt(g ratio) (§7.9)", inserts=("diverging",)),
})


@dataclass(frozen=True)
class Thresholds:
    """When a dimension is at the study's scale (the ``validation`` section's floors and its ``scale`` sub-object;
    all dimensionless): its ratio to the study's within [min_dimension_ratio, max_dimension_ratio] (the particle
    count: at least min_dimension_ratio), and the depth, outlet or tube width and Jenike cell at least their floor in
    particle diameters."""

    min_dimension_ratio: float = 0.9
    max_dimension_ratio: float = 1.11
    min_depth_diameters: float = 10.0
    min_outlet_diameters: float = 6.0
    min_cell_diameters: float = 20.0

    @classmethod
    def from_config(cls, validation: Mapping) -> "Thresholds":
        """From the validated ``validation`` configuration section."""
        scale = validation.get("scale") or {}
        return cls(**{key: float(scale[key] if key in scale else validation[key]) for key in cls.__dataclass_fields__
                      if key in scale or key in validation})


@dataclass(frozen=True)
class DimensionDifference:
    """A dimension of the run that is not at the study's scale.

    Attributes
    ----------
    name : str
        The dimension (a key of :data:`STUDY`).
    run_m, study_m : float
        The run's and the study's value, in m (the particle count: in clumps; Young's modulus: in Pa; the
        restitution: dimensionless).
    ratio : float
        run_m / study_m (-).
    run_diameters : float or None
        The run's value in its particle's volume-equivalent diameters (-); None for the particle count and size.
    threshold : str
        The bounds it fails, e.g. ``at least 0.9 of the study's``.
    reason : str
        Why this dimension bears on the finding.
    """

    name: str
    run_m: float
    study_m: float
    ratio: float
    run_diameters: float | None
    threshold: str
    reason: str

    @property
    def label(self) -> str:
        """The dimension as a reader names it (``fill height``, ``Young's modulus``)."""
        return "Young's modulus" if self.name == "youngs_modulus" else self.name.replace("_", " ")

    @property
    def text(self) -> str:
        """E.g. ``depth 12.5 mm = 0.31 of the study's 40 mm (3.8 particle diameters; at least 0.9 of the study's)``."""
        label = self.label
        if self.name == "particle_count":
            run, study = f"{self.run_m:.0f}", f"{self.study_m:.0f}"
        elif self.name == "youngs_modulus":
            run, study = f"{self.run_m:.3g} Pa", f"{self.study_m:.3g} Pa"
        elif self.name == "restitution":
            run, study = f"{self.run_m:g}", f"{self.study_m:g}"
        else:
            run, study = f"{self.run_m * 1000:.4g} mm", f"{self.study_m * 1000:.4g} mm"
        diameters = "" if self.run_diameters is None else f"{self.run_diameters:.1f} particle diameters; "
        return f"{label} {run} = {self.ratio:.2g} of the study's {study} ({diameters}{self.threshold})"


@dataclass(frozen=True)
class ScaleVerdict:
    """Whether a run is at the study's scale for a finding, and what differs.

    Attributes
    ----------
    finding_id, kind : str
        The finding and the case kind judged.
    at_study_scale : bool
        Every bearing dimension at the study's scale and the quantity defined as the study's.
    differences : tuple of DimensionDifference
        Each bearing dimension that fails, in the finding's order.
    definition_as_study : bool
        The flag the row passed in.
    definition : str
        The study's definition of the quantity (with sections).
    text : str
        One line: what fails and by how much, or that the run is at scale.
    """

    finding_id: str
    kind: str
    at_study_scale: bool
    differences: tuple[DimensionDifference, ...]
    definition_as_study: bool
    definition: str
    text: str


def _particle(config: Mapping, section: Mapping, model: str | None = None):
    name = model or section["particle_model"]
    return particle_template(name, config["particle_models"][name],
                             config["materials"][section["particle_material"]]["density"])


def _modulus(config: Mapping, section: Mapping) -> float:
    """The particle material's Young's modulus (Pa) as configured."""
    return float(config["materials"][section["particle_material"]]["youngs_modulus"])


def _restitution(config: Mapping, section: Mapping) -> float:
    """The particle-particle restitution (-) as configured (``contacts``)."""
    material = section["particle_material"]
    return next(float(contact["restitution"]) for contact in config["contacts"]
                if list(contact["materials"]) == [material, material])


def _silo_values(width, depth, fill_height, outlet, particle, count) -> dict[str, float]:
    return {"width": width, "depth": depth, "fill_height": fill_height, "outlet": outlet,
            "particle_diameter": particle.equivalent_diameter, "particle_count": float(count)}


def _run_values(kind: str, source, finding: FindingScale) -> tuple[dict[str, float], float]:
    """The run's dimensions (m; the count in clumps) and its particle's volume-equivalent diameter (m; for a Jenike
    config, the largest of the finding's shapes its sweep runs: the one the cell's floor is hardest on)."""
    if isinstance(source, Mapping):
        if kind == "jenike":
            jenike = source["jenike"]
            swept = jenike["sweep"]["shapes"]
            shapes = [shape for shape in finding.shapes if shape in swept] or list(swept)
            diameter = max(_particle(source, jenike, shape).equivalent_diameter for shape in shapes)
            return {"cell_diameter": float(jenike["cell"]["inner_diameter"]),
                    "youngs_modulus": _modulus(source, jenike)}, diameter
        section = source[kind]
        particle = _particle(source, section)
        width, depth, fill = section["width"], section["depth"], section["fill_height"]
        count = round(section["fill"]["bulk_density_estimate"] * width * depth * fill / particle.mass)
        values = _silo_values(width, depth, fill, section["outlet_width"], particle, count)
        values["youngs_modulus"] = _modulus(source, section)
        values["restitution"] = _restitution(source, section)
        if kind == "silo_recirculation":
            values["channel_length"] = section["channel_length"]
        elif kind == "blender":
            tops = [_top_of_internals(geometry_for(source, insert)) for insert in finding.inserts]
            values.update(tube_width=section["tube_width"], bed_above_insert=fill - max(tops))
        return values, particle.equivalent_diameter
    if kind == "jenike":
        return ({"cell_diameter": 2.0 * source.geometry.inner_radius,
                 "youngs_modulus": float(source.materials.youngs_modulus[0])}, source.particle.equivalent_diameter)
    silo = source if kind == "silo_flat" else source.silo
    values = _silo_values(silo.width, silo.depth, silo.fill_height, silo.outlet_width, silo.particle,
                          silo.fill.n_clumps)
    values["youngs_modulus"] = float(silo.materials.youngs_modulus[0])
    values["restitution"] = float(silo.materials.restitution[0][0])
    if kind == "silo_recirculation":
        values["channel_length"] = source.channel_length
    elif kind == "blender":
        geometry = source.geometry
        values.update(width=geometry.width, depth=geometry.depth, outlet=geometry.outlet_width,
                      tube_width=geometry.tube_width, bed_above_insert=source.fill_height - _top_of_internals(geometry))
    return values, silo.particle.equivalent_diameter


def _study_value(kind: str, name: str, finding: FindingScale) -> float:
    if name == "bed_above_insert":
        return min(_study_bed(insert) for insert in finding.inserts)
    return float(STUDY[kind][name].value)


def _difference(name: str, run: float, study: float, diameter: float,
                thresholds: Thresholds) -> DimensionDifference | None:
    ratio = run / study
    failed = []
    if ratio < thresholds.min_dimension_ratio:
        failed.append(f"at least {thresholds.min_dimension_ratio:g} of the study's")
    if ratio > thresholds.max_dimension_ratio and name != "particle_count":
        failed.append(f"at most {thresholds.max_dimension_ratio:g} of the study's")
    length = name not in ("particle_count", "particle_diameter", "youngs_modulus", "restitution")
    diameters = run / diameter if length else None
    floor = getattr(thresholds, FLOORS[name]) if name in FLOORS else None
    if floor is not None and diameters < floor:
        failed.append(f"at least {floor:g} particle diameters")
    if not failed:
        return None
    return DimensionDifference(name, float(run), study, ratio, diameters, " and ".join(failed), REASONS[name])


def scale_verdict(finding_id: str, kind: str, config_or_case, definition_as_study: bool, *,
                  thresholds: Thresholds | None = None) -> ScaleVerdict:
    """Whether a run of case ``kind`` is at the study's scale for finding ``finding_id``, from its configuration.

    Parameters
    ----------
    finding_id : str
        A key of :data:`FINDING_SCALES` (C1-C7, S1-S6, B1-B8, M1-M4).
    kind : str
        The case kind of the run: the finding's (``jenike``, ``silo_flat``, ``silo_recirculation``, ``blender``).
    config_or_case : Mapping or case object
        The validated configuration (:func:`siloflow.engines.config.load_config`), or the built case of the run
        (``SiloCase``, ``RecirculationCase``, ``BlenderCase``, ``JenikeCase``). Never a result.
    definition_as_study : bool
        Whether the row computed its quantity as the study defines and samples it (``FINDING_SCALES[id].definition``).
    thresholds : Thresholds, optional
        The bounds; by default the configuration's (``validation``), or the schema's defaults for a case.

    Returns
    -------
    ScaleVerdict
        At scale when every dimension in ``FINDING_SCALES[finding_id].dimensions`` is and the definition is the study's.

    Raises
    ------
    KeyError
        For an unknown finding id.
    ValueError
        When ``kind`` is not the finding's, or a case is not of ``kind``.
    """
    if finding_id not in FINDING_SCALES:
        raise KeyError(f"unknown finding {finding_id!r}; the findings are {', '.join(FINDING_SCALES)}")
    finding = FINDING_SCALES[finding_id]
    if kind != finding.kind:
        raise ValueError(f"finding {finding_id} is about the {finding.kind} case, not {kind}")
    if isinstance(config_or_case, Mapping):
        thresholds = thresholds or Thresholds.from_config(config_or_case.get("validation") or {})
    else:
        if kind_of_case(config_or_case).name != kind:
            raise ValueError(f"a {type(config_or_case).__name__} is not a {kind} case")
        thresholds = thresholds or Thresholds()
    values, diameter = _run_values(kind, config_or_case, finding)
    differences = tuple(difference for name in finding.dimensions
                        if (difference := _difference(name, values[name], _study_value(kind, name, finding),
                                                      diameter, thresholds)) is not None)
    definition_ok = bool(definition_as_study)
    parts = [difference.text for difference in differences]
    if not definition_ok:
        parts.append(f"the quantity is not defined or sampled as the study's: {finding.definition}")
    at_scale = not parts
    text = "; ".join(parts) if parts else (
        f"at the study's scale for {finding_id} ({', '.join(n.replace('_', ' ') for n in finding.dimensions)}); "
        f"the quantity as the study defines it")
    return ScaleVerdict(finding_id, kind, at_scale, differences, definition_ok, finding.definition, text)
