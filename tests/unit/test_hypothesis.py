"""Measured hypotheses: the direction a change moves a row, the comparison of a pair's rows, their record, the page's
section and the registry of hypotheses with their configuration layers."""

from __future__ import annotations

import math

import pytest

from siloflow.analysis.io.validation_record import (HYPOTHESES_DIR, read_hypothesis_records, write_flow_table,
                                                    write_hypothesis_record)
from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED, REPRODUCED, Agreement
from siloflow.analysis.studies.validation.findings import BY_ID, PARTS
from siloflow.analysis.studies.validation.hypothesis import (AWAY, COMPARED_COLUMNS, HYPOTHESIS_COLUMNS, NO_DIRECTION,
                                                             NOT_KNOWN, NOT_MOVED, TOWARDS, compare_rows, moved,
                                                             study_target)
from siloflow.analysis.studies.validation.record import findings_section, hypotheses_section
from siloflow.analysis.studies.validation.findings_summary import finding_statuses
from siloflow.analysis.studies.validation.rows import COLUMNS, row
from siloflow.cli.hypothesis import configured_numbers, pair_commits, pair_core_seconds, record_hypothesis, rows_file
from siloflow.cli.main import main
from siloflow.cli.record import hypothesis_lines
from siloflow.engines.config import layered_config, validate_config
from siloflow.engines.hypotheses import HYPOTHESES, Hypothesis, hypothesis_directory, hypothesis_named
from siloflow.engines.layout import RESULTS
from siloflow.engines.provenance import note_attempt
from siloflow.model.record import RunRecord
from tests.repo import REPO_ROOT


# ------------------------------------------------------------------------------------------------------- direction


@pytest.mark.parametrize("part, target", [
    ("S2", 622.6978),             # the study's point inside its band 618.03-627.37
    ("B4.internal", 10.5),        # a band without a point: its middle
    ("C6.friction_0_5", 1.2),     # a ratio
    ("C2.levels_off", 0.0),       # negligible
    ("M4.mass_flow", 0.5),        # a power law's exponent
    ("S5.dem", None),             # a sign states no number
    ("B6", None),                 # nor does an order
])
def test_the_study_s_target_follows_the_part_s_kind(part, target):
    assert study_target(PARTS[part]) == target


def test_a_configured_part_heads_for_the_configured_number_and_needs_it():
    assert study_target(PARTS["C7.aluminium"], (16.0, 18.0)) == 17.0
    with pytest.raises(ValueError, match="calibration.targets_deg.aluminium"):
        study_target(PARTS["C7.aluminium"])


@pytest.mark.parametrize("part, base, variant, error, dof, verdict, note", [
    ("S2", 560.0, 600.0, 10.0, None, TOWARDS, ""),          # 40 > 1.96 * 10; closer to 622.7
    ("S2", 600.0, 560.0, 10.0, None, AWAY, ""),
    ("S2", 600.0, 700.0, 10.0, None, AWAY, "past the study's 622.7"),     # overshoots: 77.3 from it, not 22.7
    ("S2", 600.0, 630.0, 10.0, None, TOWARDS, "past the study's 622.7"),  # past it, but closer: 7.3
    ("S2", 560.0, 570.0, 10.0, None, NOT_MOVED, ""),         # 10 < 19.6
    ("S2", 560.0, 600.0, 10.0, 2.0, NOT_MOVED, ""),          # 40 < 4.303 * 10
    ("S2", 560.0, 600.0, math.nan, None, NOT_KNOWN, ""),
    ("S2", 560.0, math.nan, 10.0, None, NOT_KNOWN, ""),
    ("C6.friction_0_5", 1.0, 1.1, 0.01, None, TOWARDS, ""),   # ratio 1.2
    ("C2.levels_off", 0.01, -0.5, 0.01, None, AWAY, "past the study's 0"),  # negligible: farther from zero
    ("C2.levels_off", 0.2, 0.05, 0.01, None, TOWARDS, ""),
    ("M4.mass_flow", 0.4, 0.45, 0.01, None, TOWARDS, ""),     # towards the exponent 0.5
    ("M4.exterior_deviates", 0.4, 0.45, 0.01, None, AWAY, ""),    # the study states a deviation from 0.5
    ("M4.exterior_deviates", 0.5, 0.45, 0.01, None, TOWARDS, ""),  # from the exponent itself, any move deviates
    ("S5.dem", 0.5, 0.3, 0.05, None, TOWARDS, ""),            # the study's sign: decreases
    ("S5.dem", -0.5, -0.3, 0.05, None, AWAY, ""),
    ("B6", 1.0, 2.0, 0.1, None, NO_DIRECTION, ""),            # an order has no one figure
    ("C7.aluminium", 15.0, 17.0, 0.1, None, NO_DIRECTION, ""),  # its number not given
])
def test_a_change_moves_a_figure_only_beyond_its_95_percent_reach_and_closer_to_the_study(
        part, base, variant, error, dof, verdict, note):
    assert moved(PARTS[part], base, variant, error, dof) == (verdict, note)


def test_a_configured_part_is_judged_by_the_configured_number():
    assert moved(PARTS["C7.aluminium"], 15.0, 17.0, 0.1, None, (16.8, 16.8)) == (TOWARDS, "past the study's 16.8")


# ------------------------------------------------------------------------------------------------------ comparison


def _density(value, error, dof=None, case="sphere2-aaaaaaaaaa"):
    entry = row("Flat-bottom silo", "Filling bulk density", case, value, error, "kg/m3", "settled fill", dof=dof,
                finding="S2", agreement=Agreement(NOT_REPRODUCED, "S2: outside"))
    return entry


def _b(value, error, figure="Change of B, z = 60 - 20 mm", case="sphere2-aaaaaaaaaa", dof=None):
    return row("Flat-bottom silo", figure, case, value, error, "m", "profiles", dof=dof, finding="S5.dem",
               agreement=Agreement(REPRODUCED, "S5.dem: decreases"))


def _rate(value, case="sphere2-aaaaaaaaaa"):
    return row("Flat-bottom silo", "Steady mass flow rate", case, value, 0.001, "kg/s", "no finding")


def test_the_pair_s_rows_are_compared_by_figure_and_occurrence_with_their_combined_error():
    base = [_density(564.0, 3.0, 2.0), _b(0.0014, 0.0001), _b(-0.0010, 0.0001), _rate(0.43)]
    variant = [_density(600.0, 4.0, 3.0, case="sphere2-bbbbbbbbbb"), _b(0.0014, 0.0001, case="sphere2-bbbbbbbbbb"),
               _b(-0.0020, 0.0001, case="sphere2-bbbbbbbbbb"), _rate(0.40, case="sphere2-bbbbbbbbbb")]
    rows = compare_rows("stiffness", "It supposes.", "E 5e6 -> 2.8e8 Pa", ("S2", "S5"), base, variant)
    assert [tuple(r) for r in rows] == [COMPARED_COLUMNS] * 3
    density, same, steeper = rows
    assert density["difference"] == 36.0 and density["difference_error"] == 5.0   # sqrt(3^2 + 4^2)
    assert density["dof"] == 2.0 and density["moves"] == TOWARDS                     # 36 > 4.303 * 5 = 21.5
    assert density["case"] == "sphere2-aaaaaaaaaa" and density["base"] == 564.0 and density["variant"] == 600.0
    assert density["reason"].startswith("change 36 ± 5 (95 %: 14.49 to 57.51); the study: 622.7, 618 to 627.4")
    assert same["difference"] == 0.0 and same["moves"] == NOT_MOVED
    assert steeper["difference"] == pytest.approx(-0.001) and steeper["dof"] == ""
    assert steeper["moves"] == TOWARDS                                               # S5.dem: B decreases


def test_rows_pair_by_finding_and_case_not_by_a_figure_that_quotes_a_measured_number():
    def janssen(value, depth, case):
        return row("Flat-bottom silo", f"Janssen at {depth} mm below the surface", case, value, 0.01, "-", "e",
                   finding="S1.janssen", agreement=Agreement(REPRODUCED, "S1"))

    def chart(value, case):
        return row("Calibration", "Bulk friction", case, value, 0.01, "-", "e", finding="C2.rises",
                   agreement=Agreement(REPRODUCED, "C2"))

    base = [janssen(1.02, 93, "sphere2-0123456789"), chart(0.40, "sphere2, internal, rolling 0"),
            chart(0.45, "sphere2, internal, rolling 0.1")]
    variant = [janssen(1.00, 95, "sphere2-9876543210"), chart(0.50, "sphere2, internal, rolling 0"),
               chart(0.55, "sphere2, internal, rolling 0.1")]
    rows = compare_rows("h", "s", "c", ("S1", "C2"), base, variant)
    assert [r["figure"] for r in rows] == ["Janssen at 93 mm below the surface", "Bulk friction", "Bulk friction"]
    assert [r["difference"] for r in rows] == pytest.approx([-0.02, 0.1, 0.1])
    with pytest.raises(ValueError, match=r"C2.rises \(Calibration, sphere2, internal, rolling 0.2\)"):
        compare_rows("h", "s", "c", ("C2",), base, [*variant[:2], chart(0.55, "sphere2, internal, rolling 0.2")])


def test_a_pair_that_does_not_judge_the_same_rows_or_judges_none_is_refused():
    with pytest.raises(ValueError, match=r"in one only: S5.dem \(Flat-bottom silo, sphere2\)"):
        compare_rows("h", "s", "c", ("S2", "S5"), [_density(564.0, 3.0), _b(0.001, 0.0001), _b(0.001, 0.0001)],
                     [_density(600.0, 4.0), _b(0.001, 0.0001)])
    with pytest.raises(ValueError, match="no row of either run judges B1"):
        compare_rows("h", "s", "c", ("B1",), [_density(564.0, 3.0)], [_density(600.0, 4.0)])


def test_a_configured_part_without_its_number_has_no_direction_and_an_unknown_base_is_not_known():
    angle = row("Calibration", "Bulk wall friction angle", "sphere2, aluminium", 15.0, 0.1, "deg", "e", finding="C7.aluminium",
                agreement=Agreement(NOT_REPRODUCED, "C7"))
    moved_angle = dict(angle, value=17.0)
    assert compare_rows("h", "s", "c", ("C7",), [angle], [moved_angle])[0]["moves"] == NO_DIRECTION
    assert compare_rows("h", "s", "c", ("C7",), [angle], [moved_angle], {"C7.aluminium": (16.8, 16.8)})[0]["moves"] == TOWARDS
    unknown = _density(math.nan, math.nan)
    assert compare_rows("h", "s", "c", ("S2",), [unknown], [_density(600.0, 4.0)])[0]["moves"] == NOT_KNOWN


# ---------------------------------------------------------------------------------------------------- record, page


def _recorded(name="stiffness_silo", moves=TOWARDS):
    compared = compare_rows(name, "It supposes.", "E 5e6 -> 2.8e8 Pa", ("S2",), [_density(564.0, 3.0, 2.0)],
                            [_density(600.0, 4.0, 3.0)])
    return [{**entry, "moves": moves, "core_hours": 2.5, "commit": "abc123", "date": "2026-12-07"} for entry in compared]


def test_a_hypothesis_record_round_trips_and_refuses_missing_columns(tmp_path):
    path = write_hypothesis_record(tmp_path / HYPOTHESES_DIR / "stiffness_silo.csv", _recorded())
    back = read_hypothesis_records(tmp_path)
    assert [tuple(entry) for entry in back] == [HYPOTHESIS_COLUMNS]
    assert back[0]["difference"] == 36.0 and back[0]["core_hours"] == 2.5 and back[0]["dof"] == "2.0"
    assert read_hypothesis_records(tmp_path / "none") == []
    with pytest.raises(ValueError, match="columns core_hours"):
        write_hypothesis_record(path, [{column: 1 for column in COMPARED_COLUMNS}])
    write_flow_table(path, [{"hypothesis": "x"}])
    with pytest.raises(ValueError, match="needs the columns statement"):
        read_hypothesis_records(tmp_path)


def test_the_page_lists_each_recorded_hypothesis_its_rows_and_those_still_to_run():
    lines = hypotheses_section(_recorded(), {"stiffness_silo": ("S1", "S2"), "stiffness_calibration": ("C2", "C3")})
    assert lines[0] == "### Measured hypotheses"
    assert ("- **stiffness_silo** (S2; the pair 2.50 core-h, code abc123, 2026-12-07): It supposes. The change: "
            "E 5e6 -> 2.8e8 Pa.") in lines
    assert ("  - S2: Filling bulk density (sphere2-aaaaaaaaaa): 564 ± 3 -> 600 ± 4 kg/m3; change 36 ± 5 (95 %: 14.49 to "
            "57.51); the study: 622.7, 618 to 627.4: **towards the study**") in lines
    assert ("- stiffness_calibration (C2, C3): not recorded yet: `make hypothesis NAME=stiffness_calibration`"
            in lines)
    assert "  - no row of the pair judges S1" in lines
    assert hypotheses_section([], {})[-1] == "None."


def test_every_finding_s_line_names_the_hypotheses_recorded_for_it():
    statuses = finding_statuses([])
    lines = findings_section(statuses, {}, {}, "config/validation.yaml", _recorded(),
                             {"stiffness_silo": ("S1", "S2"), "bed_blender": ("M1",)})
    assert "| S2 | §5.4.2, §3.10 | not measured | 0 | - | - | stiffness_silo |" in lines
    assert "| S1 | §5.4.1 | not measured | 0 | - | - | - |" in lines        # recorded, but no row of S1 in it
    assert "| M1 | §7.5.1.1 | not measured | 0 | - | - | bed_blender (not recorded) |" in lines
    assert "| S3 | §5.4.2 | not measured | 0 | - | - | - |" in lines
    assert "### Measured hypotheses" in lines


# ------------------------------------------------------------------------------------------------- registry, files


def test_every_hypothesis_names_findings_of_the_study_and_its_configuration_layers_exist_and_validate():
    for hypothesis in HYPOTHESES.values():
        assert set(hypothesis.findings) <= set(BY_ID), hypothesis.name
        for files in (hypothesis.base_files(REPO_ROOT), hypothesis.variant_files(REPO_ROOT)):
            assert all(path.is_file() for path in files), files
            validate_config(layered_config(files))


def test_the_stiffness_variants_change_the_moduli_only():
    for name in ("stiffness_calibration", "stiffness_silo", "stiffness_blending"):
        chosen = HYPOTHESES[name]
        base = validate_config(layered_config(chosen.base_files(REPO_ROOT)))
        variant = validate_config(layered_config(chosen.variant_files(REPO_ROOT)))
        changed = {material for material in base["materials"]
                   if base["materials"][material] != variant["materials"][material]}
        assert changed == {"hdpe", "aluminium", "perspex", "lid"}
        assert {m["youngs_modulus"] for m in variant["materials"].values()} == {2.8e8}
        assert {key for key in base if base[key] != variant[key]} == {"materials"}


def test_the_bed_variant_raises_the_blender_s_fill_and_walls_only():
    chosen = HYPOTHESES["bed_blender"]
    base = validate_config(layered_config(chosen.base_files(REPO_ROOT)))
    variant = validate_config(layered_config(chosen.variant_files(REPO_ROOT)))
    assert {key for key in base if base[key] != variant[key]} == {"blender"}
    assert {key for key in base["blender"] if base["blender"][key] != variant["blender"][key]} == {"fill_height",
                                                                                                  "vertical_height"}
    assert (base["blender"]["fill_height"], variant["blender"]["fill_height"]) == (0.225, 0.325)


def test_the_gravity_variant_stiffens_every_material_fivefold_only():
    chosen = HYPOTHESES["stiffness_gravity"]
    base = validate_config(layered_config(chosen.base_files(REPO_ROOT)))
    variant = validate_config(layered_config(chosen.variant_files(REPO_ROOT)))
    assert {key for key in base if base[key] != variant[key]} == {"materials"}
    assert {material: variant["materials"][material]["youngs_modulus"] / base["materials"][material]["youngs_modulus"]
            for material in ("hdpe", "aluminium", "perspex", "lid")} == dict.fromkeys(
        ("hdpe", "aluminium", "perspex", "lid"), 5.0)
    # the base is the study's series at fixed material, beyond 1 g
    assert base["blender"]["gravity_moduli"] == "fixed" and base["blender"]["gravity_factors"] == [1.0, 5.0]


def test_an_unknown_hypothesis_or_group_is_refused_naming_what_there_is(capsys):
    with pytest.raises(ValueError, match="the hypotheses are stiffness_calibration, stiffness_silo, stiffness_blending, "
                                         "bed_blender, stiffness_gravity"):
        hypothesis_named("nonsense")
    with pytest.raises(ValueError, match="no validation group 'silos'"):
        Hypothesis("h", "silos", ("S2",), "s", "c", "base.yaml", "variant.yaml")
    with pytest.raises(ValueError, match="names no finding"):
        Hypothesis("h", "silo", (), "s", "c", "base.yaml", "variant.yaml")
    assert main(["hypothesis", "nonsense"]) == 2
    assert "no measured hypothesis 'nonsense'" in capsys.readouterr().err


def test_the_record_is_written_from_the_pair_s_rows_files_with_the_pair_s_cost(tmp_path):
    chosen = HYPOTHESES["stiffness_silo"]
    directory = hypothesis_directory(chosen.name, tmp_path)
    assert directory == tmp_path / "results" / "hypotheses" / "stiffness_silo"
    with pytest.raises(FileNotFoundError, match="the base's rows .* are not made yet"):
        record_hypothesis(chosen, directory, tmp_path / "record", REPO_ROOT)
    for member, density in (("base", _density(564.0, 3.0, 2.0)), ("variant", _density(600.0, 4.0, 3.0))):
        write_flow_table(rows_file(chosen, directory, member), [{column: density[column] for column in COLUMNS}])
        benchmark = directory / member / RESULTS / "silo_flat" / "sphere2-x" / "logs" / "run_benchmark.tsv"
        benchmark.parent.mkdir(parents=True)
        benchmark.write_text("s\th:m:s\n1800.0\t0:30:00\n")
    assert pair_core_seconds(directory) == 3600.0
    # a finished run on 2 ranks, made in one go (no earlier attempt in its folder): its wall time twice
    record = RunRecord(engine="liggghts", case="silo_flat", run_id="sphere2-x", timestep_s=1e-5, n_clumps=10,
                       n_frames=1, mpi_ranks=2, stages={})
    (directory / "variant" / RESULTS / "silo_flat" / "sphere2-x" / "run.json").write_text(record.to_json())
    assert pair_core_seconds(directory) == 1800.0 + 2 * 1800.0
    # the code that ran the runs, as each run's provenance notes it (none noted: unknown)
    assert pair_commits(directory) == "unknown"
    note_attempt(directory / "variant" / RESULTS / "silo_flat" / "sphere2-x", "liggghts", "3.8", "abc123")
    assert pair_commits(directory) == "unknown abc123"
    path = record_hypothesis(chosen, directory, tmp_path / "record", REPO_ROOT)
    assert path == tmp_path / "record" / HYPOTHESES_DIR / "stiffness_silo.csv"
    (recorded,) = read_hypothesis_records(tmp_path / "record")
    assert recorded["core_hours"] == 1.5 and recorded["moves"] == TOWARDS and recorded["commit"] == "unknown abc123" and recorded["difference"] == 36.0
    assert recorded["statement"] == chosen.statement and recorded["change"] == chosen.change


def test_the_configured_numbers_are_read_by_the_parts_dotted_keys():
    config = {"calibration": {"targets_deg": {"aluminium": 16.79, "internal": 33.7}}}
    assert configured_numbers(config) == {"C7.aluminium": (16.79, 16.79)}


def test_the_status_lists_each_hypothesis_recorded_or_the_command_that_records_it():
    lines = hypothesis_lines(_recorded())
    assert lines[0] == "Measured hypotheses (make hypothesis NAME=<name>):"
    assert "stiffness_silo         recorded 2026-12-07: 1 rows of S1, S2, S5" in lines
    assert "bed_blender            not recorded: make hypothesis NAME=bed_blender" in lines
    assert len(lines) == 1 + len(HYPOTHESES)
