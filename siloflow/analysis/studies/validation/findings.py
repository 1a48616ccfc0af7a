"""The study's findings as data: what each states, and of what kind, for the validation record to judge against.

The study is the PhD thesis whose method siloflow reproduces (EDEM 2.7 DEM and PIV of HDPE pellets in planar
silos). It reports 27 findings: the Jenike calibration (ch. 4, C1-C7), the flat-bottom silo (ch. 5, S1-S6),
blending in the recirculating silo (ch. 6, B1-B8) and the multi-flow blender (ch. 7, M1-M4). Each
:class:`Finding` has one or more :class:`Part`: one quantity of one kind, judged by the rule of that kind in
:mod:`siloflow.analysis.studies.validation.agreement` (one record row per part; a part stated "at each height" or
"for each shape" takes one row per height or shape).

Kinds of a part
---------------
:data:`VALUE`
    A number with a band: the band the study gives, or the number widened by a configured tolerance.
:data:`SIGN`
    The sign of a change (e.g. B decreases with height).
:data:`ORDER`
    An order of several figures, largest first (e.g. tube > interior > exterior annulus).
:data:`NEGLIGIBLE`
    A change within a configured fraction of a reference value ("no visible effect", "uniform").
:data:`RATIO`
    A ratio of two figures with a band (e.g. "about doubled"); the error is propagated from both.
:data:`POWER_LAW`
    An exponent of a scaling (e.g. with the square root of gravity), or a deviation from it.

A finding whose parts are of one kind has that kind; one whose parts differ is :data:`COMPOUND`.

Tolerances are not chosen here. Where the study says "about", "nearly", "negligible", "levels off", "uniform",
or states a number with no band, the part names the key of the configuration's ``validation.agreement`` section
that gives the band (:class:`~siloflow.analysis.studies.validation.agreement.AgreementTolerances`).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

__all__ = ["VALUE", "SIGN", "ORDER", "NEGLIGIBLE", "RATIO", "POWER_LAW", "COMPOUND", "PART_KINDS", "DEM",
           "EXPERIMENT", "BOTH", "SOURCES", "Part", "Finding", "FINDINGS", "BY_ID", "PARTS", "finding", "part"]

VALUE, SIGN, ORDER, NEGLIGIBLE, RATIO, POWER_LAW = "value", "sign", "order", "negligible", "ratio", "power law"
COMPOUND = "compound"
#: The kinds a part may have (a finding's kind is one of these or COMPOUND).
PART_KINDS = (VALUE, SIGN, ORDER, NEGLIGIBLE, RATIO, POWER_LAW)
#: Where a finding comes from: the study's DEM (EDEM), its experiment (PIV, weighing), or a comparison of both.
DEM, EXPERIMENT, BOTH = "DEM", "experiment", "DEM and experiment"
SOURCES = (DEM, EXPERIMENT, BOTH)


@dataclass(frozen=True)
class Part:
    """One quantity a finding states, judged by one record row (per height, shape, ... where it says so).

    Attributes
    ----------
    id : str
        The finding's id, with a suffix when the finding states several quantities (``"B8.internal"``).
    kind : str
        One of :data:`PART_KINDS`.
    quantity : str
        What to measure, and under which conditions.
    unit : str
        Unit of the measured figure (``"-"`` for a dimensionless one).
    value : float or None
        The stated number: a value or ratio, the exponent of a power law; None for the other kinds.
    band : tuple of float or None
        ``(low, high)`` the study gives (e.g. VRR 4-6), in ``unit``; None when it gives none.
    tolerance : str or None
        The ``validation.agreement`` key that widens ``value`` (or ``band``) into the band judged against, or
        bounds a negligible change.
    sign : int
        SIGN: +1 when the study's change is an increase, -1 a decrease; 0 for the other kinds.
    order : tuple of str
        ORDER: the figures' names, largest first.
    deviates : bool
        POWER_LAW: True when the study states that the figure deviates from the scaling.
    configured : str or None
        The configuration key holding the number the study measured, where the finding quotes none (the caller
        passes its band).
    """

    id: str
    kind: str
    quantity: str
    unit: str = "-"
    value: float | None = None
    band: tuple[float, float] | None = None
    tolerance: str | None = None
    sign: int = 0
    order: tuple[str, ...] = ()
    deviates: bool = False
    configured: str | None = None

    def __post_init__(self):
        if self.kind not in PART_KINDS:
            raise ValueError(f"{self.id}: kind must be one of {PART_KINDS}, got {self.kind!r}")
        if self.band is not None and not self.band[0] <= self.band[1]:
            raise ValueError(f"{self.id}: band must be (low, high) with low <= high, got {self.band!r}")
        stated = self.value is not None or self.band is not None
        problems = {
            VALUE: not (self.configured or (stated and (self.band or self.tolerance))),
            RATIO: not (stated and (self.band or self.tolerance)),
            SIGN: self.sign not in (1, -1),
            ORDER: len(self.order) < 2,
            NEGLIGIBLE: self.tolerance is None,
            POWER_LAW: self.value is None or self.tolerance is None,
        }
        if problems[self.kind]:
            raise ValueError(f"{self.id}: a {self.kind} part needs " + {
                VALUE: "a band, or a value with a tolerance key, or a configured key",
                RATIO: "a band, or a value with a tolerance key", SIGN: "sign +1 or -1",
                ORDER: "at least two names, largest first", NEGLIGIBLE: "a tolerance key",
                POWER_LAW: "an exponent and a tolerance key"}[self.kind])

    def stated(self) -> str:
        """What the study states, for the record's study column (e.g. ``"about 0.42"``, ``"4 to 6"``)."""
        if self.kind == SIGN:
            return "increases" if self.sign > 0 else "decreases"
        if self.kind == ORDER:
            return " > ".join(self.order)
        if self.kind == NEGLIGIBLE:
            return f"negligible ({self.tolerance})"
        if self.kind == POWER_LAW:
            return f"{'deviates from' if self.deviates else 'scales with'} exponent {self.value:g} ({self.tolerance})"
        prefix = "ratio " if self.kind == RATIO else ""
        if self.band is not None:
            point = f"{self.value:.4g}, " if self.value is not None else ""
            return f"{prefix}{point}{self.band[0]:.4g} to {self.band[1]:.4g}"
        if self.value is None:
            return f"the measured value ({self.configured})"
        return f"{prefix}{'' if self.tolerance == 'no_band_relative' else 'about '}{self.value:g} ({self.tolerance})"


@dataclass(frozen=True)
class Finding:
    """One finding of the study.

    Attributes
    ----------
    id : str
        ``C1``-``C7``, ``S1``-``S6``, ``B1``-``B8`` or ``M1``-``M4``.
    chapter : int
        The thesis chapter (4 calibration, 5 flat-bottom silo, 6 recirculating silo, 7 multi-flow blender).
    section : str
        The thesis section(s), e.g. ``"§4.4.3.1"``.
    source : str
        One of :data:`SOURCES`.
    statement : str
        The finding in one sentence.
    parts : tuple of Part
        The quantities it states, each judged by one row.
    """

    id: str
    chapter: int
    section: str
    source: str
    statement: str
    parts: tuple[Part, ...]

    def __post_init__(self):
        if self.source not in SOURCES:
            raise ValueError(f"{self.id}: source must be one of {SOURCES}, got {self.source!r}")
        if f"§{self.chapter}." not in self.section:
            raise ValueError(f"{self.id}: section {self.section!r} is not in chapter {self.chapter}")
        single = len(self.parts) == 1 and self.parts[0].id == self.id
        if not self.parts or not (single or all(p.id.startswith(self.id + ".") for p in self.parts)):
            raise ValueError(f"{self.id}: one part with the finding's id, or parts named '{self.id}.<suffix>'")

    @property
    def kind(self) -> str:
        """The parts' kind when they share one, else :data:`COMPOUND`."""
        kinds = {p.kind for p in self.parts}
        return kinds.pop() if len(kinds) == 1 else COMPOUND


def _value(id, quantity, unit="-", value=None, band=None, tolerance=None, configured=None) -> Part:
    return Part(id, VALUE, quantity, unit, value=value, band=band, tolerance=tolerance, configured=configured)


def _ratio(id, quantity, value=None, band=None, tolerance=None) -> Part:
    return Part(id, RATIO, quantity, value=value, band=band, tolerance=tolerance)


def _sign(id, quantity, sign, unit="-") -> Part:
    return Part(id, SIGN, quantity, unit, sign=sign)


def _order(id, quantity, *names, unit="-") -> Part:
    return Part(id, ORDER, quantity, unit, order=names)


def _negligible(id, quantity, tolerance, unit="-") -> Part:
    return Part(id, NEGLIGIBLE, quantity, unit, tolerance=tolerance)


def _power(id, quantity, exponent, deviates=False) -> Part:
    return Part(id, POWER_LAW, quantity, value=exponent, tolerance="exponent_absolute", deviates=deviates)


_ABOUT, _NO_BAND, _SMALL = "about_relative", "no_band_relative", "negligible_relative"
_PLATEAU, _UNIFORM = "plateau_relative", "uniform_relative"
_PER_SHAPE = "; one row per shape"
# The drop quoted by S2 is taken relative to the ch. 3 rig's 40 mm deep silo (666.7 +- 5 kg/m3, §3.10), the
# experiment the finding names: the ch. 5 table with both densities is not legible. The +- 5 is scaled by the same
# 0.934; the 6.6 % comes from one DEM fill and has no band of its own.
_S2_SCALE = 1.0 - 0.066

FINDINGS: tuple[Finding, ...] = (
    Finding("C1", 4, "§4.4.3.1", DEM, "At zero rolling friction the bulk internal friction exceeds the particle "
            "friction at low particle friction and is finite at zero particle friction (interlocking).", (
        # "low particle friction" has no value in the text: read as the sweep's first step, 0.1.
        _sign("C1.above_particle_friction", "bulk internal friction minus particle friction, particle friction 0.1, "
              "rolling friction 0" + _PER_SHAPE, +1),
        _sign("C1.finite_at_zero", "bulk internal friction (its change from zero), particle friction 0, rolling "
              "friction 0" + _PER_SHAPE, +1))),
    Finding("C2", 4, "§4.4.3.1", DEM, "At zero rolling friction the bulk internal friction rises with particle "
            "friction up to about 0.4, then levels off at about 0.42 (sphere) and 0.54 (both clumps).", (
        # The knee "about 0.4" is read as the sweep step 0.4; the plateau is the curve from there to 1.
        _sign("C2.rises", "change of bulk internal friction from particle friction 0 to 0.4, rolling friction 0"
              + _PER_SHAPE, +1),
        _negligible("C2.levels_off", "change of bulk internal friction from particle friction 0.4 to 1, relative "
                    "to its value at 0.4, rolling friction 0" + _PER_SHAPE, _PLATEAU),
        _value("C2.sphere", "plateau bulk internal friction (particle friction >= 0.4), sphere", value=0.42,
               tolerance=_ABOUT),
        _value("C2.sphere2", "plateau bulk internal friction, two-sphere clump", value=0.54, tolerance=_ABOUT),
        _value("C2.sphere4", "plateau bulk internal friction, four-sphere clump", value=0.54, tolerance=_ABOUT),
        # "nearly identical" is read as "about the same".
        _ratio("C2.clumps_alike", "plateau bulk internal friction, four-sphere over two-sphere clump", 1.0,
               tolerance=_ABOUT))),
    Finding("C3", 4, "§4.4.3.2", DEM, "Bulk wall friction equals the particle-wall friction at low values (fully "
            "mobilised at 0.1) and levels off at about 0.17 (sphere) and 0.35 (clumps).", (
        _ratio("C3.mobilised", "bulk wall friction over particle-wall friction 0.1, rolling friction 0" + _PER_SHAPE,
               1.0, tolerance=_ABOUT),
        # The text gives no knee for the wall: 0.5 is the first sweep step clearly above both plateau values.
        _negligible("C3.levels_off", "change of bulk wall friction from particle-wall friction 0.5 to 1, relative "
                    "to its value at 0.5" + _PER_SHAPE, _PLATEAU),
        _value("C3.sphere", "plateau bulk wall friction, sphere", value=0.17, tolerance=_ABOUT),
        _value("C3.sphere2", "plateau bulk wall friction, two-sphere clump", value=0.35, tolerance=_ABOUT),
        _value("C3.sphere4", "plateau bulk wall friction, four-sphere clump", value=0.35, tolerance=_ABOUT))),
    Finding("C4", 4, "§4.4.1", DEM, "The coefficient of restitution (1e-4 to 1) has no visible effect on the bulk "
            "friction.", (
        _negligible("C4", "change of bulk internal friction from restitution 1e-4 to 1, relative to its value at "
                    "1e-4", _SMALL),)),
    Finding("C5", 4, "§4.5.2", DEM, "Blocking particle rotations hardly changes the bulk friction at particle "
            "friction 0.1 and about doubles it at 0.5.", (
        _negligible("C5.friction_0_1", "change of bulk internal friction when rotations are blocked, relative to "
                    "its value with free rotations, particle friction 0.1", _SMALL),
        _ratio("C5.friction_0_5", "bulk internal friction with rotations blocked over free, particle friction 0.5",
               2.0, tolerance=_ABOUT))),
    Finding("C6", 4, "§4.5.3", DEM, "Raising rolling friction from 0 to 0.1 leaves the bulk internal friction "
            "nearly unchanged at particle friction 0.1 and raises it by nearly 20 % at 0.5.", (
        _negligible("C6.friction_0_1", "change of bulk internal friction from rolling friction 0 to 0.1, relative "
                    "to its value at 0, particle friction 0.1, two-sphere clump", _SMALL),
        # "nearly +20 %" is read as a ratio of about 1.2 (the tolerance widens the ratio, not the change).
        _ratio("C6.friction_0_5", "bulk internal friction at rolling friction 0.1 over 0, particle friction 0.5, "
               "two-sphere clump", 1.2, tolerance=_ABOUT))),
    Finding("C7", 4, "§4.6", DEM, "The two-sphere clump with particle friction 0.35 and rolling friction 0.1 "
            "reproduces the measured bulk internal friction (about 30 deg), particle-wall 0.17 (aluminium) and 0.20 "
            "(Perspex) the measured wall friction angles.", (
        _value("C7.internal", "bulk internal friction angle, two-sphere clump, particle friction 0.35, rolling "
               "friction 0.1", "deg", value=30.0, tolerance=_ABOUT),
        # The finding quotes no wall angle: the measured ones are the configured calibration targets, whose band
        # is +- calibration.tolerance_deg.
        _value("C7.aluminium", "bulk wall friction angle on aluminium, particle-wall friction 0.17", "deg",
               configured="calibration.targets_deg.aluminium"),
        _value("C7.perspex", "bulk wall friction angle on Perspex, particle-wall friction 0.20", "deg",
               configured="calibration.targets_deg.perspex"))),
    Finding("S1", 5, "§5.4.1", DEM, "The vertical stress at the end of filling rises linearly, then saturates, in "
            "good agreement with Janssen.", (
        # "good agreement" is read as "about".
        _ratio("S1.linear_near_surface", "gradient of the mean vertical stress below the free surface over the "
               "bulk unit weight (hydrostatic)", 1.0, tolerance=_ABOUT),
        _sign("S1.saturates", "change of the vertical stress gradient from the top to the bottom of the fill", -1,
              "Pa/m"),
        _ratio("S1.janssen", "mean vertical stress at the base over Janssen's at that depth (active K, the "
               "calibration chart's bulk frictions)", 1.0, tolerance=_ABOUT))),
    Finding("S2", 5, "§5.4.2, §3.10", BOTH, "The DEM filling bulk density is 6.6 % below the experiment's "
            "(666.7 +- 5 kg/m3).", (
        _value("S2", "filling bulk density, total particle mass over filled volume", "kg/m3",
               value=666.7 * _S2_SCALE, band=(661.7 * _S2_SCALE, 671.7 * _S2_SCALE)),)),
    Finding("S3", 5, "§5.4.2", BOTH, "With rolling friction the DEM mass flow rate is within 3.7 % and the "
            "volumetric flow rate within 3.2 % of the experiment's.", (
        # "within" gives no sign: a symmetric band. The experiment's rates are the denominators.
        _ratio("S3.mass_flow", "mass flow rate over the experiment's", band=(1.0 - 0.037, 1.0 + 0.037)),
        _ratio("S3.volumetric_flow", "volumetric flow rate over the experiment's", band=(1.0 - 0.032, 1.0 + 0.032)))),
    Finding("S4", 5, "§5.4.3.2-§5.4.3.4", BOTH, "The flow starts faster in the DEM than in the experiment, and the "
            "steady velocity profiles agree.", (
        # "starts faster" is read at the first instantaneous profiles (t = 0.1 s, Z = 20, 40 and 80 mm, §5.4.3.3).
        _sign("S4.faster_start", "centreline vertical velocity minus the experiment's at t = 0.1 s; one row per "
              "height Z = 20, 40, 80 mm", +1, "m/s"),
        _ratio("S4.steady_profiles", "steady (0.5-0.7 s) centreline vertical velocity over the experiment's; one "
               "row per height Z = 20, 40, 80, 120 mm", 1.0, tolerance=_ABOUT))),
    Finding("S5", 5, "§5.4.3.4", BOTH, "The kinematic constant B decreases with the height above the outlet, in "
            "the DEM and in the experiment.", (
        _sign("S5.dem", "change of B from the lowest to the highest fitted height, DEM", -1, "m"),
        _sign("S5.experiment", "change of B from the lowest to the highest fitted height, experiment (PIV)", -1,
              "m"))),
    Finding("S6", 5, "§5.5", DEM, "Frictionless front and back walls give a near-hydrostatic stress and a "
            "near-uniform velocity (semi-mass flow); more front/back friction turns the flow towards internal flow.", (
        # "close to hydrostatic" is read as "about"; the side walls keep their friction, so not equal.
        _ratio("S6.hydrostatic", "mean vertical stress at the base over the hydrostatic one, front/back wall "
               "friction 0", 1.0, tolerance=_ABOUT),
        _negligible("S6.uniform_velocity", "largest deviation of the steady vertical velocity across the width at "
                    "Z = 120 mm from its mean, relative to the mean, front/back wall friction 0", _UNIFORM),
        _sign("S6.towards_internal_flow", "change of the near-side-wall over the centreline vertical velocity at "
              "Z = 120 mm from front/back wall friction 0 to 1", -1))),
    Finding("B1", 6, "§6.3.1", DEM, "During recirculation the bulk density falls to a flowing bulk density, 4.5 % "
            "lower in semi-mass flow and 13 % lower in internal flow.", (
        _value("B1.semi_mass", "drop of bulk density while recirculating, 1 - flowing / filling, semi-mass flow",
               value=0.045, tolerance=_NO_BAND),
        _value("B1.internal", "drop of bulk density while recirculating, 1 - flowing / filling, internal flow",
               value=0.13, tolerance=_NO_BAND))),
    # B2-B6: the study's VRR "at the end of Nr recirculations" is read from the outflow of the discharge after Nr
    # recirculations (Fig. 6.9, §6.4.2); whether that discharge had a falling head is not stated (§6.6.2). The rows
    # take the discharge after the recirculations where a run has one (silo_recirculation.final_discharge) and say
    # so in ``differs`` where they fall back on a pass at constant head.
    Finding("B2", 6, "§6.4.2", DEM, "The VRR grows with the number of recirculations, more slowly after 2.", (
        _sign("B2.grows", "change of VRR from Nr = 0 to 4; one row per flow pattern and batch", +1),
        _sign("B2.slower_after_2", "VRR gain from Nr = 2 to 4 minus the gain from Nr = 0 to 2; one row per flow "
              "pattern and batch", -1))),
    Finding("B3", 6, "§6.4.2", DEM, "In internal flow the smaller the batch, the higher the VRR (a strong effect); "
            "in semi-mass flow the batch has a minor effect.", (
        _sign("B3.internal", "change of VRR at Nr = 4 from the 13 % to the 50 % batch, internal flow", -1),
        # "minor" is read as smaller than in internal flow, not as negligible: the study gives it no size.
        _order("B3.stronger_in_internal", "batch effect VRR(13 % batch) / VRR(50 % batch) - 1 at Nr = 4",
               "internal flow", "semi-mass flow"))),
    Finding("B4", 6, "§6.4.2", DEM, "The VRR at the end of 4 recirculations is 4-6 in semi-mass flow and 8-13 in "
            "internal flow, depending on the batch size.", (
        _value("B4.semi_mass", "VRR at Nr = 4, semi-mass flow; one row per batch (13, 25, 50 %)", band=(4.0, 6.0)),
        _value("B4.internal", "VRR at Nr = 4, internal flow; one row per batch (13, 25, 50 %)", band=(8.0, 13.0)))),
    Finding("B5", 6, "§6.4.2", DEM, "Without recirculation the VRR is about the same for both flow patterns.", (
        _ratio("B5", "VRR at Nr = 0, internal over semi-mass flow; one row per batch", 1.0, tolerance=_ABOUT),)),
    Finding("B6", 6, "§6.4.2", DEM, "More sub-layers of the same batch give a higher VRR.", (
        _order("B6", "VRR at Nr = 4 of the 50 % batch; one row per flow pattern", "5 sub-layers", "3 sub-layers",
               "1 layer"),)),
    # B7, B8: t_rm is the silo volume over the volumetric flow rate (§6.2.3.3); whether the RTD's first moment
    # was used instead, and whether t_s and t_d count from the injection, is not stated.
    Finding("B7", 6, "§6.5.1", DEM, "The RTD peaks at theta about 1 in semi-mass flow and about 0.75 in internal "
            "flow, theta = t / t_rm.", (
        _value("B7.semi_mass", "theta of the RTD's peak, semi-mass flow", value=1.0, tolerance=_ABOUT),
        _value("B7.internal", "theta of the RTD's peak, internal flow", value=0.75, tolerance=_ABOUT))),
    Finding("B8", 6, "§6.5.1", DEM, "The first appearance over the total discharge time of the tracer, t_s / t_d, "
            "is 0.39 in internal flow and 0.46 in semi-mass flow.", (
        _value("B8.internal", "t_s / t_d of the RTD, internal flow", value=0.39, tolerance=_NO_BAND),
        _value("B8.semi_mass", "t_s / t_d of the RTD, semi-mass flow", value=0.46, tolerance=_NO_BAND))),
    # M1: measured by PIV in continuous (constant-head) discharge; the study's DEM ran batch discharge only (§7.7).
    Finding("M1", 7, "§7.5.1.1", EXPERIMENT, "At the outlet of the diverging insert the steady velocity is about "
            "0.16 (exterior annulus), 1.49 (interior annulus) and 1.79 (tube) of the cross-section mean.", (
        _value("M1.exterior", "steady exterior annulus velocity at the insert outlet over the cross-section mean, "
               "diverging insert", value=0.16, tolerance=_ABOUT),
        _value("M1.interior", "steady interior annulus velocity at the insert outlet over the cross-section mean, "
               "diverging insert", value=1.49, tolerance=_ABOUT),
        _value("M1.tube", "steady tube velocity at the insert outlet over the cross-section mean, diverging insert",
               value=1.79, tolerance=_ABOUT))),
    Finding("M2", 7, "§7.5.3", EXPERIMENT, "With the converging insert the tube is fastest, then the interior and "
            "the exterior annulus at the insert outlet, while the velocity is uniform across both annuli at the "
            "insert inlet and across the width of the vertical section away from the tube.", (
        _order("M2.outlet_order", "vertical velocity at the insert outlet, converging insert", "tube",
               "interior annulus", "exterior annulus", unit="m/s"),
        _negligible("M2.inlet_uniform", "interior minus exterior annulus velocity at the insert inlet, relative to "
                    "the cross-section mean, converging insert", _UNIFORM),
        _negligible("M2.vertical_uniform", "largest deviation of the vertical velocity across the width of the "
                    "vertical section, away from the tube, from its mean, relative to the mean; one row per height",
                    _UNIFORM))),
    # M3: source "experiment + LTI". "Blends best" is judged in §7.6 both by the recirculations to homogenise and
    # by the VRR of the continuous mode; the VRR, a figure with an error, is taken. Straight vs diverging: unstated.
    Finding("M3", 7, "§7.6", EXPERIMENT, "The converging insert blends best of the three.", (
        _order("M3.over_straight", "VRR of the continuous mode at one input period (LTI of the RTD)", "converging",
               "straight"),
        _order("M3.over_diverging", "VRR of the continuous mode at one input period (LTI of the RTD)", "converging",
               "diverging"))),
    # M4: the gravity runs used the insert the study's table calls "Inward", taken as the diverging one (inferred,
    # not stated); the annuli's deviation is stated without its direction.
    Finding("M4", 7, "§7.9", DEM, "The mass flow rate and the cross-section mean velocity scale with the square root "
            "of gravity (1, 5, 50 g), while the annuli's velocities at the insert outlet deviate from it and the "
            "velocity differential across the annuli at the insert inlet decreases.", (
        _power("M4.mass_flow", "mass flow rate against the gravity factor", 0.5),
        _power("M4.mean_velocity", "cross-section mean vertical velocity against the gravity factor; one row per "
               "height", 0.5),
        _power("M4.exterior_deviates", "exterior annulus velocity at the insert outlet against the gravity factor",
               0.5, deviates=True),
        _power("M4.interior_deviates", "interior annulus velocity at the insert outlet against the gravity factor",
               0.5, deviates=True),
        _sign("M4.inlet_differential_decreases", "change of the velocity differential across the annuli at the "
              "insert inlet, over sqrt(g / g0), from 1 g to 50 g", -1, "m/s"))),
)

#: The findings by id, and their parts by part id.
BY_ID = MappingProxyType({f.id: f for f in FINDINGS})
PARTS = MappingProxyType({p.id: p for f in FINDINGS for p in f.parts})


def finding(id: str) -> Finding:
    """The finding of that id (``"S5"``); KeyError naming the known ids otherwise."""
    if id not in BY_ID:
        raise KeyError(f"no finding {id!r}; the findings are {', '.join(BY_ID)}")
    return BY_ID[id]


def part(id: str) -> Part:
    """The finding part of that id (``"B8.internal"``, or ``"C4"`` for a single-part finding)."""
    if id not in PARTS:
        raise KeyError(f"no finding part {id!r}; see siloflow.analysis.studies.validation.findings.PARTS")
    return PARTS[id]
