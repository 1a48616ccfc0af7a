"""The registry of the study's findings: exactly its ids, chapters and sections, each part of a kind the rules judge,
with the numbers the study states and a configured tolerance wherever it states no band."""

from __future__ import annotations

import dataclasses

import pytest

from siloflow.analysis.studies.validation import findings as registry
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.findings import (BOTH, COMPOUND, DEM, EXPERIMENT, FINDINGS, NEGLIGIBLE,
                                                           ORDER, PART_KINDS, POWER_LAW, RATIO, SIGN, VALUE, Part,
                                                           finding, part)
from siloflow.engines.config import validate_config

#: The study's findings: id, chapter, thesis section(s), source.
EXPECTED = [
    ("C1", 4, "§4.4.3.1", DEM), ("C2", 4, "§4.4.3.1", DEM), ("C3", 4, "§4.4.3.2", DEM), ("C4", 4, "§4.4.1", DEM),
    ("C5", 4, "§4.5.2", DEM), ("C6", 4, "§4.5.3", DEM), ("C7", 4, "§4.6", DEM),
    ("S1", 5, "§5.4.1", DEM), ("S2", 5, "§5.4.2, §3.10", BOTH), ("S3", 5, "§5.4.2", BOTH),
    ("S4", 5, "§5.4.3.2-§5.4.3.4", BOTH), ("S5", 5, "§5.4.3.4", BOTH), ("S6", 5, "§5.5", DEM),
    ("B1", 6, "§6.3.1", DEM), ("B2", 6, "§6.4.2", DEM), ("B3", 6, "§6.4.2", DEM), ("B4", 6, "§6.4.2", DEM),
    ("B5", 6, "§6.4.2", DEM), ("B6", 6, "§6.4.2", DEM), ("B7", 6, "§6.5.1", DEM), ("B8", 6, "§6.5.1", DEM),
    ("M1", 7, "§7.5.1.1", EXPERIMENT), ("M2", 7, "§7.5.3", EXPERIMENT), ("M3", 7, "§7.6", EXPERIMENT),
    ("M4", 7, "§7.9", DEM),
]


def test_the_registry_holds_exactly_the_studys_findings_with_chapter_section_and_source():
    assert [(f.id, f.chapter, f.section, f.source) for f in FINDINGS] == EXPECTED
    assert all(f.statement.endswith(".") and f.statement.count(". ") == 0 for f in FINDINGS)  # one sentence


def test_parts_are_named_after_their_finding_and_unique():
    ids = [p.id for f in FINDINGS for p in f.parts]
    assert len(ids) == len(set(ids)) == len(registry.PARTS)
    for f in FINDINGS:
        assert f.parts[0].id == f.id if len(f.parts) == 1 else all(p.id.startswith(f.id + ".") for p in f.parts)


def test_every_kind_is_used_and_mixed_findings_are_compound():
    assert {p.kind for p in registry.PARTS.values()} == set(PART_KINDS)
    kinds = {f.id: f.kind for f in FINDINGS}
    assert {i for i, k in kinds.items() if k == COMPOUND} == {"C2", "C3", "C5", "C6", "S1", "S4", "S6", "B3", "M2",
                                                              "M4"}
    assert (kinds["C4"], kinds["S5"], kinds["B4"], kinds["B6"], kinds["B8"]) == (NEGLIGIBLE, SIGN, VALUE, ORDER, VALUE)


def test_tolerances_named_by_parts_are_configured_keys():
    named = {p.tolerance for p in registry.PARTS.values()} - {None}
    configured = set(validate_config({})["validation"]["agreement"])
    assert named == configured
    assert configured == {f.name for f in dataclasses.fields(AgreementTolerances)} - {"max_relative_error"}


def test_the_numbers_the_study_states():
    s2 = part("S2")
    assert s2.value == pytest.approx(622.70, abs=0.01) and s2.unit == "kg/m3"
    assert s2.band == pytest.approx((618.03, 627.37), abs=0.01)
    assert (part("B4.semi_mass").band, part("B4.internal").band) == ((4.0, 6.0), (8.0, 13.0))
    assert (part("B8.internal").value, part("B8.semi_mass").value) == (0.39, 0.46)
    assert {p.tolerance for p in finding("B8").parts} == {"no_band_relative"}
    assert [part(f"M1.{a}").value for a in ("exterior", "interior", "tube")] == [0.16, 1.49, 1.79]
    assert {p.tolerance for p in finding("M1").parts} == {"about_relative"}
    assert part("M2.outlet_order").order == ("tube", "interior annulus", "exterior annulus")
    assert (part("C5.friction_0_5").kind, part("C5.friction_0_5").value) == (RATIO, 2.0)
    assert (part("C6.friction_0_5").kind, part("C6.friction_0_5").value) == (RATIO, 1.2)
    assert [part(i).kind for i in ("C4", "C5.friction_0_1", "C6.friction_0_1")] == [NEGLIGIBLE] * 3
    assert (part("S5.dem").sign, part("S5.experiment").sign, part("B2.grows").sign) == (-1, -1, 1)
    assert part("S3.mass_flow").band == pytest.approx((0.963, 1.037))
    assert (part("B7.semi_mass").value, part("B7.internal").value) == (1.0, 0.75)
    scaling = [part(f"M4.{name}") for name in ("mass_flow", "mean_velocity", "exterior_deviates")]
    assert [(p.kind, p.value, p.deviates) for p in scaling] == [(POWER_LAW, 0.5, False), (POWER_LAW, 0.5, False),
                                                                (POWER_LAW, 0.5, True)]
    assert part("C7.aluminium").configured == "calibration.targets_deg.aluminium"


def test_stated_text_for_the_record():
    assert part("C2.sphere").stated() == "about 0.42 (about_relative)"
    assert part("B8.internal").stated() == "0.39 (no_band_relative)"
    assert part("B4.internal").stated() == "8 to 13"
    assert part("S2").stated() == "622.7, 618 to 627.4"
    assert part("C5.friction_0_5").stated() == "ratio about 2 (about_relative)"
    assert part("S5.dem").stated() == "decreases"
    assert part("B6").stated() == "5 sub-layers > 3 sub-layers > 1 layer"
    assert part("M4.exterior_deviates").stated() == "deviates from exponent 0.5 (exponent_absolute)"


@pytest.mark.parametrize("fields, message", [
    ({"kind": VALUE, "value": 0.4}, "a value with a tolerance key"),  # "about" with no configured tolerance
    ({"kind": RATIO}, "a band, or a value"),
    ({"kind": SIGN, "sign": 2}, r"sign \+1 or -1"),
    ({"kind": ORDER, "order": ("tube",)}, "at least two names"),
    ({"kind": NEGLIGIBLE}, "a tolerance key"),
    ({"kind": POWER_LAW, "value": 0.5}, "an exponent and a tolerance key"),
    ({"kind": "trend"}, "kind must be one of"),
    ({"kind": VALUE, "band": (6.0, 4.0)}, "low <= high"),
])
def test_a_part_that_cannot_be_judged_is_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        Part("X1", quantity="q", **fields)


def test_lookups_name_what_is_known():
    assert finding("S5").parts == (part("S5.dem"), part("S5.experiment"))
    with pytest.raises(KeyError, match="C1, C2"):
        finding("C8")
    with pytest.raises(KeyError, match="no finding part 'B8'"):
        part("B8")
    with pytest.raises(ValueError, match="not in chapter"):
        registry.Finding("C9", 5, "§4.4", DEM, "x.", (Part("C9", SIGN, "q", sign=1),))
