"""A row's scale verdict, decided from the configuration alone (siloflow.analysis.studies.validation.scale)."""

from __future__ import annotations

import copy
import inspect
import math

import numpy as np
import pytest

from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED, Agreement
from siloflow.analysis.studies.validation.findings import FINDINGS
from siloflow.analysis.studies.validation.rows import AT_SCALE, NOT_AT_SCALE, row, with_scale
from siloflow.analysis.studies.validation.scale import (FINDING_SCALES, STUDY, STUDY_PARTICLE_DIAMETER, Thresholds,
                                                        scale_verdict)
from siloflow.engines.config import load_config, validate_config
from siloflow.model.cases.blender import build_blender_case
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.model.cases.silo_recirculation import build_recirculation_case
from tests.repo import REPO_ROOT

#: The study's dimensions as a configuration (thesis §4.3, §5.2, §6.2.2, §7.2).
AT_STUDY_SCALE = {
    "silo_flat": {"width": 0.15, "depth": 0.04, "fill_height": 0.27, "outlet_width": 0.04},
    "silo_recirculation": {"width": 0.15, "depth": 0.04, "fill_height": 0.27, "outlet_width": 0.04,
                           "channel_length": 0.08},
    "blender": {"width": 0.45, "depth": 0.04, "vertical_height": 1.5, "hopper_half_angle": 30.0, "outlet_width": 0.04,
                "tube_width": 0.04, "fill_height": 1.125, "wall_thickness": 0.005},
    "jenike": {"cell": {"inner_diameter": 0.095}, "sweep": {"shapes": ["sphere", "sphere2", "sphere4"]}},
    # the study's G = 1e8 Pa as Young's modulus (§4.2)
    "materials": {**validate_config({})["materials"],
                  "hdpe": {"youngs_modulus": 2.8e8, "poisson_ratio": 0.4, "density": 950.0}},
    # the study's particle-particle restitution (§4.4.1)
    "contacts": [{**contact, "restitution": 1e-4} if contact["materials"] == ["hdpe", "hdpe"] else contact
                 for contact in validate_config({})["contacts"]],
}
SHRINK = 0.85
D = STUDY_PARTICLE_DIAMETER
SPHERE = 0.0038   # the one-sphere model's diameter, the largest of the Jenike shapes


def _config(change=None) -> dict:
    raw = copy.deepcopy(AT_STUDY_SCALE)
    if change:
        change(raw)
    return validate_config(raw)


def _shrink(section, *keys):
    def change(raw):
        node = raw[section]
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] *= SHRINK
    return change


def _smaller_clump(raw):
    """The study's two-sphere clump shrunk by SHRINK, as a particle model of its own."""
    spheres = [{"position": [sign * 0.000375 * SHRINK, 0.0, 0.0], "radius": 0.0015 * SHRINK} for sign in (-1, 1)]
    raw["particle_models"] = {**validate_config({})["particle_models"], "small2": {"spheres": spheres}}
    raw["silo_flat"]["particle_model"] = "small2"


def _lower_blender_fill(raw):
    raw["blender"]["fill_height"] *= SHRINK
    raw["blender"]["pathlines"] = {"release_height": 0.9}   # tracers start below the fill


def _looser_fill(raw):
    raw["silo_recirculation"]["fill"] = {"bulk_density_estimate": 400.0}


def test_at_the_study_s_dimensions_every_finding_is_at_scale():
    config = _config()
    for finding, entry in FINDING_SCALES.items():
        verdict = scale_verdict(finding, entry.kind, config, True)
        assert verdict.at_study_scale and verdict.differences == (), (finding, verdict.text)
        assert verdict.text.startswith(f"at the study's scale for {finding} (")


BED = STUDY["blender"]["bed_above_insert"].value
TOP = 1.125 - BED   # the study's tube inlet, rebuilt from §7.2

# (change, kind, finding it bears on, dimension named, run value, ratio, run diameters, a finding it does not bear on)
SHRUNK = [
    (_shrink("silo_flat", "depth"), "silo_flat", "S2", "depth", 0.034, SHRINK, 0.034 / D, None),
    (_shrink("silo_flat", "width"), "silo_flat", "S1", "width", 0.1275, SHRINK, 0.1275 / D, "S2"),
    (_shrink("silo_flat", "fill_height"), "silo_flat", "S5", "fill_height", 0.2295, SHRINK, 0.2295 / D, "S3"),
    (_shrink("silo_flat", "outlet_width"), "silo_flat", "S3", "outlet", 0.034, SHRINK, 0.034 / D, "S1"),
    (_smaller_clump, "silo_flat", "S2", "particle_diameter", SHRINK * D, SHRINK, None, None),
    (_shrink("silo_recirculation", "channel_length"), "silo_recirculation", "B7", "channel_length", 0.068, SHRINK,
     0.068 / D, "B4"),
    (_shrink("silo_recirculation", "outlet_width"), "silo_recirculation", "B4", "outlet", 0.034, SHRINK, 0.034 / D,
     None),
    (_looser_fill, "silo_recirculation", "B4", "particle_count", None, None, None, "B1"),
    (_shrink("blender", "depth"), "blender", "M1", "depth", 0.034, SHRINK, 0.034 / D, None),
    (_shrink("blender", "width"), "blender", "M2", "width", 0.3825, SHRINK, 0.3825 / D, None),
    (_shrink("blender", "tube_width"), "blender", "M3", "tube_width", 0.034, SHRINK, 0.034 / D, None),
    (_shrink("blender", "outlet_width"), "blender", "M4", "outlet", 0.034, SHRINK, 0.034 / D, "M1"),
    (_lower_blender_fill, "blender", "M1", "bed_above_insert", SHRINK * 1.125 - TOP,
     (SHRINK * 1.125 - TOP) / BED, (SHRINK * 1.125 - TOP) / D, None),
    (_shrink("jenike", "cell", "inner_diameter"), "jenike", "C1", "cell_diameter", 0.08075, SHRINK, 0.08075 / SPHERE,
     None),
    (_shrink("jenike", "cell", "inner_diameter"), "jenike", "C7", "cell_diameter", 0.08075, SHRINK, 0.08075 / D, None),
    # the tier's soft particles: the Jenike cell's bulk friction and the fills' densities move with the stiffness,
    # the flow rate and the residence time do not (docs/validation.md, Stiffness)
    (lambda raw: raw["materials"]["hdpe"].update(youngs_modulus=5e6), "jenike", "C2", "youngs_modulus", 5e6,
     5e6 / 2.8e8, None, None),
    (lambda raw: raw["materials"]["hdpe"].update(youngs_modulus=5e6), "silo_flat", "S2", "youngs_modulus", 5e6,
     5e6 / 2.8e8, None, "S3"),
    (lambda raw: raw["materials"]["hdpe"].update(youngs_modulus=5e6), "silo_recirculation", "B1", "youngs_modulus",
     5e6, 5e6 / 2.8e8, None, "B7"),
    # the tiers' restitution 0.1: the fill packs looser than at the study's 1e-4; the flow rate moves within its error
    (lambda raw: raw["contacts"][0].update(restitution=0.1), "silo_flat", "S2", "restitution", 0.1, 0.1 / 1e-4, None,
     "S3"),
]


@pytest.mark.parametrize("change, kind, finding, name, run, ratio, diameters, unaffected", SHRUNK,
                         ids=[f"{case[2]}-{case[3]}" for case in SHRUNK])
def test_a_shrunk_dimension_is_named_with_its_ratio_and_diameters(change, kind, finding, name, run, ratio, diameters,
                                                                  unaffected):
    config = _config(change)
    verdict = scale_verdict(finding, kind, config, True)
    assert not verdict.at_study_scale
    assert [d.name for d in verdict.differences] == [name], verdict.text
    difference = verdict.differences[0]
    if name == "particle_count":   # 400 kg/m3 instead of 667 over the study's 150 x 40 x 270 mm
        clump = 1.8361750030991124e-05
        assert difference.run_m == round(400.0 * 0.15 * 0.04 * 0.27 / clump)
        run, ratio = difference.run_m, difference.run_m / 53492
        assert difference.threshold == "at least 0.9 of the study's"
    assert difference.run_m == pytest.approx(run, rel=1e-9)
    assert difference.ratio == pytest.approx(ratio, rel=1e-9)
    if diameters is None:
        assert difference.run_diameters is None
    else:
        assert difference.run_diameters == pytest.approx(diameters, rel=1e-9)
    assert difference.reason
    assert f"{difference.ratio:.2g} of the study's" in verdict.text and difference.label in verdict.text
    if unaffected is not None:
        other = scale_verdict(unaffected, kind, config, True)
        assert other.at_study_scale, other.text


def test_the_text_says_which_dimension_and_by_how_much():
    config = _config(lambda raw: raw["blender"].update(depth=0.0125))
    verdict = scale_verdict("M1", "blender", config, True)
    assert verdict.text == ("depth 12.5 mm = 0.31 of the study's 40 mm (3.8 particle diameters; at least 0.9 of the "
                            "study's and at least 10 particle diameters)")


def test_a_dimension_fails_its_diameter_floor_even_within_the_ratio():
    config = _config(lambda raw: raw.update(validation={"scale": {"min_dimension_ratio": 0.3}}) or
                     raw["blender"].update(depth=0.0125))
    (difference,) = scale_verdict("M1", "blender", config, True).differences
    assert difference.threshold == "at least 10 particle diameters"


def test_a_larger_silo_than_the_study_s_is_not_at_its_scale_but_more_particles_are():
    config = _config(lambda raw: raw["silo_flat"].update(depth=0.06))
    (difference,) = scale_verdict("S2", "silo_flat", config, True).differences
    assert difference.ratio == pytest.approx(1.5) and difference.threshold == "at most 1.11 of the study's"
    denser = _config(lambda raw: raw["silo_recirculation"].update(fill={"bulk_density_estimate": 900.0}))
    assert scale_verdict("B4", "silo_recirculation", denser, True).at_study_scale


def test_a_quantity_not_defined_as_the_study_s_is_not_at_scale_and_says_so():
    verdict = scale_verdict("B4", "silo_recirculation", _config(), False)
    assert not verdict.at_study_scale and verdict.differences == () and not verdict.definition_as_study
    assert verdict.text == f"the quantity is not defined or sampled as the study's: {FINDING_SCALES['B4'].definition}"
    assert "Nr = 4" in verdict.text and "§6.4.2" in verdict.text
    assert "t_rm = hold-up volume / volumetric flow rate" in FINDING_SCALES["B7"].definition
    assert "20, 40, 80 and 120 mm" in FINDING_SCALES["S5"].definition


def test_the_verdict_takes_no_value_and_is_the_same_whatever_value_a_row_carries():
    parameters = list(inspect.signature(scale_verdict).parameters)
    assert parameters == ["finding_id", "kind", "config_or_case", "definition_as_study", "thresholds"]
    assert not any(word in name for name in parameters for word in ("value", "result", "row", "error"))
    config = load_config(REPO_ROOT / "config" / "validation.yaml")
    before = copy.deepcopy(config)
    expected = {finding: scale_verdict(finding, entry.kind, config, True) for finding, entry in FINDING_SCALES.items()}
    values = [*np.random.default_rng(7).normal(0.0, 1e3, 40), 0.0, -1.0, math.inf, -math.inf, math.nan, 1e300]
    first_part = {item.id: item.parts[0].id for item in FINDINGS}
    for value in values:
        for finding, entry in FINDING_SCALES.items():
            verdict = scale_verdict(finding, entry.kind, config, True)
            built = row("group", finding, "case", value, abs(value) / 10, "-", "", finding=first_part[finding],
                        agreement=Agreement(NOT_REPRODUCED, "a disagreement"))
            (judged,) = with_scale([built], lambda f, d, kind=entry.kind: scale_verdict(f, kind, config, d))
            assert verdict == expected[finding]
            assert judged["scale"] == (AT_SCALE if expected[finding].at_study_scale else NOT_AT_SCALE)
            assert judged["scale_reason"] == expected[finding].text and judged["agreement"] == NOT_REPRODUCED
    assert config == before


@pytest.mark.parametrize("finding, kind, build", [
    ("S1", "silo_flat", build_silo_case),
    ("B7", "silo_recirculation", lambda config: build_recirculation_case(config, "internal_flow")),
    ("M1", "blender", lambda config: build_blender_case(config, "diverging")),
])
def test_a_built_case_is_judged_as_its_configuration(finding, kind, build):
    config = load_config(REPO_ROOT / "config" / "validation.yaml")
    from_case = scale_verdict(finding, kind, build(config), True)
    assert from_case == scale_verdict(finding, kind, config, True)


def test_an_unknown_finding_or_the_wrong_kind_is_refused():
    config = _config()
    with pytest.raises(KeyError, match="unknown finding 'Z9'"):
        scale_verdict("Z9", "silo_flat", config, True)
    with pytest.raises(ValueError, match="finding S2 is about the silo_flat case, not blender"):
        scale_verdict("S2", "blender", config, True)
    with pytest.raises(ValueError, match="is not a blender case"):
        scale_verdict("M1", "blender", build_silo_case(config), True)


def test_the_thresholds_default_to_the_schema_s():
    validation = validate_config({})["validation"]
    assert Thresholds.from_config(validation) == Thresholds()
    assert validation["scale"] == {"min_dimension_ratio": Thresholds().min_dimension_ratio,
                                   "max_dimension_ratio": Thresholds().max_dimension_ratio}


def test_every_finding_names_dimensions_the_study_gives_and_cites_a_section():
    for finding, entry in FINDING_SCALES.items():
        assert set(entry.dimensions) <= set(STUDY[entry.kind]), finding
        assert "§" in entry.definition, finding
    assert STUDY_PARTICLE_DIAMETER == pytest.approx(3.33e-3, abs=5e-6)
    assert all(dimension.section.startswith("§") for dims in STUDY.values() for dimension in dims.values())


def test_the_validation_config_is_judged_finding_by_finding():
    config = load_config(REPO_ROOT / "config" / "validation.yaml")
    verdicts = {finding: scale_verdict(finding, entry.kind, config, True) for finding, entry in FINDING_SCALES.items()}
    summary = "\n".join(f"{finding}: {'at scale' if v.at_study_scale else 'not at scale'}: {v.text}"
                        for finding, v in verdicts.items())
    # the silos are the study's 150 x 40 x 270 mm assembly: every finding of ch. 5 and 6 that depends on the geometry
    # alone is at the study's scale; the contact stiffness (and for S2 the restitution) still differ
    at_scale = {finding for finding, verdict in verdicts.items() if verdict.at_study_scale}
    assert at_scale == {"S1", "S3", "S4", "S5", "S6", "B2", "B3", "B4", "B5", "B6", "B7", "B8"}, summary
    assert {d.name for d in verdicts["B1"].differences} == {"youngs_modulus"}, summary
    assert {d.name for d in verdicts["S2"].differences} == {"youngs_modulus", "restitution"}, summary
    # the blender: the study's 40 mm depth at half its width, so its width, tube and bed are named, not its depth
    differing = {d.name: d for d in verdicts["M1"].differences}
    assert set(differing) == {"width", "bed_above_insert", "tube_width"}, summary
    assert differing["width"].run_m == 0.225 and differing["width"].ratio == pytest.approx(0.5), summary
    assert "depth" not in verdicts["M1"].text, summary
    assert "width 225 mm = 0.5 of the study's 450 mm (67.6 particle diameters;" in verdicts["M1"].text, summary
