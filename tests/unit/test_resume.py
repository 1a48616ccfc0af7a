"""Resuming a killed run: the resume deck of each case, restart files and attempt logs."""

from __future__ import annotations

from pathlib import Path

import pytest

from siloflow.model.cases.blender import build_blender_case
from siloflow.model.cases.silo_recirculation import build_recirculation_case
from siloflow.engines.config import load_config, validate_config
from siloflow.engines.liggghts.run import Resume, attempt_logs, restart_every, restart_files
from siloflow.engines.liggghts.silo_flat import silo_deck_context
from siloflow.engines.liggghts.blender import blender_deck_context
from siloflow.engines.liggghts.silo_recirculation import recirculation_deck_context
from siloflow.model.cases.silo_flat import build_silo_case

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


def _resume_deck(template, context, steps):
    return Resume(template, context, steps).deck("restart/state_31200.restart", 77952)


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
