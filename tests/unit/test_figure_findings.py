"""Which finding each record figure draws, with the band its record row is judged by."""

import pytest

from siloflow.analysis.io.plot_style import StudyNote, StudyValue
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.findings import PARTS
from siloflow.analysis.studies.validation.figure_findings import (
    calibration_chart_findings,
    gravity_findings,
    insert_findings,
    janssen_findings,
    kinematic_findings,
    study_note,
    study_value,
    vrr_findings,
)

TOLERANCES = AgreementTolerances(**{key: 0.1 for key in AgreementTolerances.__dataclass_fields__})


def test_the_internal_chart_of_the_two_sphere_clump_draws_c2_with_its_band():
    (value,) = calibration_chart_findings("sphere2", "internal", TOLERANCES)
    assert isinstance(value, StudyValue)
    assert (value.id, value.value, value.series) == ("C2", 0.54, "sphere2")
    assert value.band == pytest.approx((0.486, 0.594))


def test_the_wall_chart_of_the_sphere_draws_c3():
    (value,) = calibration_chart_findings("sphere", "aluminium", TOLERANCES)
    assert (value.id, value.value) == ("C3", 0.17)
    assert value.band == pytest.approx((0.153, 0.187))


@pytest.mark.parametrize("shape, test", [("sphere2", "perspex"), ("cube", "internal")])
def test_a_chart_the_study_states_no_plateau_for_draws_none(shape, test):
    assert calibration_chart_findings(shape, test, TOLERANCES) == []


def test_the_diverging_insert_draws_m1_per_passage_and_the_converging_m2():
    values = insert_findings("diverging", TOLERANCES)
    assert [(v.id, v.series, v.value) for v in values] == [("M1", "exterior", 0.16), ("M1", "interior", 1.49),
                                                            ("M1", "tube", 1.79)]
    assert values[2].band == pytest.approx((1.611, 1.969))
    (note,) = insert_findings("converging", TOLERANCES)
    assert note.label == "study (M2): tube > interior annulus > exterior annulus"
    assert insert_findings("straight", TOLERANCES) == []


def test_the_silo_and_gravity_figures_carry_their_trends():
    assert [n.label for n in janssen_findings()] == ["study (S1): DEM in good agreement with Janssen"]
    assert [n.label for n in kinematic_findings()] == ["study (S5): B decreases with height"]
    (m4,) = gravity_findings()
    assert isinstance(m4, StudyNote) and m4.id == "M4"


def test_the_vrr_figure_draws_b4_per_flow_pattern_at_nr_4():
    assert vrr_findings(TOLERANCES) == [
        {"id": "B4", "flow_pattern": "internal_flow", "at": 4.0, "low": 8.0, "high": 13.0},
        {"id": "B4", "flow_pattern": "semi_mass_flow", "at": 4.0, "low": 4.0, "high": 6.0}]


def test_study_values_and_notes_of_the_findings_parts():
    plateau = study_value(PARTS["C2.sphere2"], band=(0.486, 0.594), series="sphere2")
    assert (plateau.id, plateau.value, plateau.unit, plateau.band, plateau.approximate) == (
        "C2", 0.54, "-", (0.486, 0.594), True)
    assert study_value(PARTS["C7.internal"]).label == "study (C7): ~30 deg"
    assert not study_value(PARTS["B8.internal"]).approximate  # a number stated with no "about"
    assert not study_value(PARTS["S2"]).approximate  # a number stated with its band
    assert study_note(PARTS["M2.outlet_order"]).label == "study (M2): tube > interior annulus > exterior annulus"
    assert study_note(PARTS["S5.dem"], "B decreases with height").label == "study (S5): B decreases with height"
    with pytest.raises(ValueError, match="S5.dem states no number"):
        study_value(PARTS["S5.dem"])
