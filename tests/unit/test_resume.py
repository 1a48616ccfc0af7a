"""Resuming a killed run: the resume deck of each case, restart files and attempt logs."""

from __future__ import annotations

from pathlib import Path

import pytest

from siloflow.model.cases.blender import build_blender_case
from siloflow.model.cases.silo_recirculation import build_recirculation_case
from siloflow.engines.config import load_config, validate_config
from siloflow.engines.liggghts.run import (Resume, ResumePoint, attempt_logs, discard_settled_outputs, restart_files,
                                           resume_point, set_aside_previous_attempt)
from siloflow.engines.run_files import restart_every
from siloflow.engines.markers import Marker, without_redone
from siloflow.engines.liggghts.silo_flat import render_silo_deck, silo_deck_context
from siloflow.engines.liggghts.blender import blender_deck_context
from siloflow.engines.liggghts.silo_recirculation import recirculation_deck_context
from siloflow.model.cases.silo_flat import build_silo_case

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


def _resume_deck(template, context, steps):
    point = ResumePoint("discharge", final_step=77952)
    return Resume(template, context, steps).deck("restart/state_31200.restart", point)


def _check_common(deck: str) -> None:
    assert "read_restart restart/state_31200.restart\nnewton off" in deck
    assert "create_box" not in deck and "fix pour" not in deck and "settle_loop" not in deck
    assert "run 77952 upto" in deck
    assert "dump_modify particle_dump binary yes first no" in deck
    assert "outlet_gate" not in deck.split("fix floor_wall", 1)[1].splitlines()[0]
    assert deck.index("run 0") < deck.index("SILOFLOW resumed")
    # wall forces from the restart on, in a second file named by the restart step; the gate's columns are zeros
    assert " file resume_wall_forces_$(step).txt title1 " in deck
    assert "variable outlet_gate_fz equal 0.0" in deck and "f_outlet_gate[" not in deck


def test_silo_resume_deck_reads_the_restart_and_runs_up_to_the_end():
    case = build_silo_case(load_config(GOLDEN / "silo_flat_config.yaml"))
    deck = _resume_deck("liggghts/silo_flat.lmp.j2", silo_deck_context(case), case.discharge_steps)
    _check_common(deck)
    assert "thermo_modify lost ignore norm no flush yes" in deck.split("# --- discharge")[1]


def test_recirculation_resume_deck_keeps_the_feeder_and_loses_no_clump():
    case = build_recirculation_case(load_config(GOLDEN / "silo_recirculation_config.yaml"), "internal_flow")
    deck = _resume_deck("liggghts/silo_recirculation.lmp.j2", recirculation_deck_context(case), case.silo.discharge_steps)
    _check_common(deck)
    assert "fix feeder all setforce NULL NULL v_feeder_force_z region feeder" in deck
    assert "thermo_modify lost error" in deck.split("# --- recirculate")[1]


def test_a_resumed_recirculation_with_a_discharge_after_it_ends_the_re_entry_at_its_step():
    """The resume deck runs to the end of both stages (step 77952); the re-entry ends final_discharge_steps before
    it, and a restart file past that step goes straight on with the discharge."""
    raw = load_config(GOLDEN / "silo_recirculation_config.yaml")
    raw["silo_recirculation"]["final_discharge"] = 1.0
    case = build_recirculation_case(validate_config(raw), "internal_flow")
    deck = _resume_deck("liggghts/silo_recirculation.lmp.j2", recirculation_deck_context(case), case.silo.discharge_steps)
    assert f"variable reentry_end equal {77952 - case.final_discharge_steps}\n" in deck
    assert 'if "$(step) < ${reentry_end}" then "run ${reentry_end} upto"' in deck
    assert deck.split("change_box all boundary")[1].count("run 77952 upto") == 1


def test_blender_resume_deck_has_the_open_walls():
    case = build_blender_case(load_config(GOLDEN / "blender_config.yaml"), "straight")
    deck = _resume_deck("liggghts/blender.lmp.j2", blender_deck_context(case), case.silo.discharge_steps)
    _check_common(deck)
    assert "meshes hopper_left hopper_right insert_left insert_right tube_left tube_right store_force yes\n" in deck


def test_restart_files_are_ordered_by_step_and_empty_ones_ignored(tmp_path):
    folder = tmp_path / "restart"
    folder.mkdir()
    for step, size in ((2600, 10), (26000, 10), (5200, 10), (7800, 0)):
        (folder / f"state_{step}.restart").write_bytes(b"x" * size)
    (folder / "notes.txt").write_text("not a restart file")
    assert [p.name for p in restart_files(tmp_path)] == ["state_2600.restart", "state_5200.restart",
                                                          "state_26000.restart"]
    assert restart_files(tmp_path / "missing") == []


def test_attempt_logs_are_the_first_then_the_resumptions_in_order(tmp_path):
    for name in ("resume10.log.liggghts", "log.liggghts", "resume2.log.liggghts", "resume1.engine.out"):
        (tmp_path / name).write_text("")
    assert [p.name for p in attempt_logs(tmp_path)] == ["log.liggghts", "resume2.log.liggghts", "resume10.log.liggghts"]


def test_about_twenty_restart_files_per_stage():
    assert restart_every(52000) == 2600 and restart_every(7) == 1
    with pytest.raises(ValueError):
        restart_every(0)


def _marker(event, step):
    return Marker(event, {"step": float(step), "time": step * 1e-5, "clumps": 100.0, "ke_per_clump": 1e-9})


#: A first attempt stopped in its discharge: pour to 1000, three settling checks of 100 steps, opened at 1300.
_MARKERS = [_marker("filled", 1000), _marker("settle", 1100), _marker("settle", 1200), _marker("settle", 1300),
            _marker("settled", 1300), _marker("opened", 1300)]


@pytest.mark.parametrize("restart_step, expected", [
    (600, ResumePoint("fill")),
    (1000, ResumePoint("settle", settle_checks=50)),
    (1150, ResumePoint("settle", settle_checks=49)),
    (1299, ResumePoint("settle", settle_checks=48)),
    (1300, ResumePoint("discharge", final_step=1300 + 5000)),
    (4000, ResumePoint("discharge", final_step=1300 + 5000)),
])
def test_a_restart_file_resumes_in_the_stage_it_lies_in(restart_step, expected):
    assert resume_point(_MARKERS, restart_step, last_stage_steps=5000, settle_max_checks=50) == expected


def test_settling_checks_redone_by_a_resumed_attempt_are_counted_once():
    """A first attempt checked at 1100, 1200 and 1300 and was stopped; resumed from 1150, its checks at 1250 and 1350
    replace those after 1150: 1100, 1250 and 1350 made, so 47 of 50 are left when it stops again at 1400."""
    markers = without_redone(_MARKERS[:4] + [_marker("resumed", 1150), _marker("settle", 1250),
                                             _marker("settle", 1350)])
    assert [(m.event, int(m.values["step"])) for m in markers] == [
        ("filled", 1000), ("settle", 1100), ("resumed", 1150), ("settle", 1250), ("settle", 1350)]
    assert resume_point(markers, 1400, 5000, 50) == ResumePoint("settle", settle_checks=47)
    assert resume_point(markers, 1300, 5000, 50) == ResumePoint("settle", settle_checks=48)
    # never fewer than one check
    assert resume_point(markers, 1400, 5000, 3) == ResumePoint("settle", settle_checks=1)


def test_markers_without_a_step_are_kept_and_a_later_resumption_drops_only_what_lies_past_it():
    markers = [_marker("filled", 10), Marker("note", {"text": "x"}), _marker("settle", 20), _marker("resumed", 15),
               _marker("settle", 25), _marker("resumed", 30), _marker("settled", 35)]
    assert [m.event for m in without_redone(markers)] == ["filled", "note", "resumed", "settle", "resumed", "settled"]
    assert without_redone([]) == []


def _silo():
    case = build_silo_case(load_config(GOLDEN / "silo_flat_config.yaml"))
    return case, Resume("liggghts/silo_flat.lmp.j2", silo_deck_context(case), case.discharge_steps)


def test_a_run_stopped_in_its_pour_resumes_the_pour_up_to_its_step_then_settles_and_discharges():
    case, resume = _silo()
    deck = resume.deck("restart/state_600.restart", ResumePoint("fill"))
    assert "read_restart restart/state_600.restart\nnewton off" in deck and "create_box" not in deck
    fill = case.fill.fill_steps
    assert f'if "$(step) < {fill}" then "run {fill} upto"' in deck
    assert deck.count("fix pour all insert/rate/region") == 1
    # the insertion fix defined before the first run, which hands it its state from the restart file
    assert deck.index("fix pour") < deck.index("run 0") < deck.index("SILOFLOW resumed") < deck.index("SILOFLOW filled")
    assert f"variable settle_check loop {case.settle_max_checks}\n" in deck
    # the closed floor until the outlet opens, then the open one; the wall forces in the resumed attempt's own file
    assert "meshes floor_left floor_right outlet_gate store_force yes" in deck.split("SILOFLOW opened")[0]
    assert " file resume_wall_forces_$(step).txt title1 " in deck and " file wall_forces.txt " not in deck
    assert "write_restart assembly.restart" in deck
    assert f"\nrun {case.discharge_steps}\n" in deck and "upto" not in deck.split("# --- discharge")[1]
    # it writes restart files on through the pour and the settling, then at the last stage's interval
    assert f"restart {restart_every(case.fill.fill_steps)} restart/state_*.restart" in deck.split("fix pour")[0]
    assert f"restart {restart_every(case.discharge_steps)} restart/state_*.restart" in deck.split("# --- discharge")[1]


def test_a_run_stopped_while_settling_makes_the_checks_it_had_left_without_pouring():
    case, resume = _silo()
    deck = resume.deck("restart/state_1150.restart", ResumePoint("settle", settle_checks=7))
    assert "fix pour" not in deck and "SILOFLOW filled" not in deck
    assert "variable settle_check loop 7\n" in deck
    assert deck.index("SILOFLOW resumed") < deck.index("label settle_loop") < deck.index("SILOFLOW settled")
    assert deck.index("SILOFLOW settled") < deck.index("SILOFLOW opened")


def test_the_first_attempt_writes_restart_files_from_its_pour_on():
    case, _ = _silo()
    deck = render_silo_deck(case)
    assert f"restart {restart_every(case.fill.fill_steps)} restart/state_*.restart" in deck.split("fix pour")[0]
    assert "SILOFLOW resumed" not in deck and "upto" not in deck and "read_restart" not in deck
    assert f"\nrun {case.fill.fill_steps}\n" in deck
    assert " file wall_forces.txt " in deck


def test_a_resumption_before_the_opening_removes_what_the_stopped_attempt_wrote_once_settled(tmp_path):
    (tmp_path / "dumps").mkdir()
    for name in ("dumps/settled_fill_1300.txt", "dumps/settled_fill_1301.txt", "dumps/contacts_1301.txt",
                 "dumps/settled_walls.txt", "assembly.restart", "dumps/particles_1400.vtk", "wall_forces.txt"):
        (tmp_path / name).write_text("x")
    assert discard_settled_outputs(tmp_path) == ["dumps/settled_fill_1300.txt", "dumps/settled_fill_1301.txt",
                                                 "dumps/contacts_1301.txt", "dumps/settled_walls.txt",
                                                 "assembly.restart"]
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["particles_1400.vtk", "wall_forces.txt"]
    assert discard_settled_outputs(tmp_path) == []


def test_an_attempt_set_aside_takes_the_restart_file_liggghts_wrote_when_a_signal_stopped_it(tmp_path):
    for name in ("log.liggghts", "restart_forced_liggghts_91946.data", "resume1.log.liggghts"):
        (tmp_path / name).write_text("x")
    (tmp_path / "deck").mkdir()
    target = set_aside_previous_attempt(tmp_path)
    assert sorted(p.name for p in target.iterdir()) == ["log.liggghts", "restart_forced_liggghts_91946.data",
                                                        "resume1.log.liggghts"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deck", "failed_attempts"]
