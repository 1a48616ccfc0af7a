"""Wall forces: the neutral WallForceHistory, the LIGGGHTS reader of silo-type and Jenike runs, and the decks'
force output read back through the reader's own header parser."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from siloflow.model.forces import WallForceHistory
from siloflow.engines.config import load_config
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.engines.liggghts.forces import (
    RESUMED_WALL_FORCES_PREFIX,
    read_jenike_forces,
    read_silo_wall_forces,
    read_wall_force_file,
    read_wall_forces,
)
from siloflow.engines.liggghts.run import WALL_FORCES_NAME
from siloflow.engines.liggghts.jenike import FORCES_NAME
from siloflow.engines.jenike_checks import FORCE_COLUMNS, JENIKE_WALLS
from siloflow.engines.liggghts.run import RESUME_STEM, Resume, ResumePoint
from siloflow.engines.liggghts.silo_flat import render_silo_deck, silo_deck_context

GOLDEN = Path(__file__).resolve().parent.parent / "golden"
DT = 1e-5
QUANTITIES = ("fx", "fy", "fz", "tx", "ty", "tz")


# ---------------------------------------------------------------------------------------------- WallForceHistory


def _history(**changes) -> WallForceHistory:
    arguments = {
        "time": [0.0, 0.1, 0.2],
        "walls": ("left", "floor"),
        "force": {"left": [[1.0, 0.0, 0.5]] * 3, "floor": [[0.0, 0.0, 2.0], [0.0, 0.0, 3.0], [0.5, 0.0, 4.0]]},
        "torque": {"left": np.zeros((3, 3)), "floor": [[1.0, 2.0, 0.0]] * 3},
    }
    arguments.update(changes)
    return WallForceHistory(**arguments)


def test_total_force_and_torque_sum_the_chosen_walls():
    history = _history()
    assert len(history) == 3
    np.testing.assert_array_equal(history.total_force(), [[1.0, 0.0, 2.5], [1.0, 0.0, 3.5], [1.5, 0.0, 4.5]])
    np.testing.assert_array_equal(history.total_force(["floor"]), history.force["floor"])
    np.testing.assert_array_equal(history.total_force("left"), history.force["left"])
    np.testing.assert_array_equal(history.total_force([]), np.zeros((3, 3)))
    np.testing.assert_array_equal(history.total_torque(), [[1.0, 2.0, 0.0]] * 3)
    with pytest.raises(KeyError, match=r"unknown walls \['gate'\]"):
        history.total_force(["floor", "gate"])


def test_an_unknown_torque_is_nan_and_spreads_to_totals():
    history = _history(torque={"left": np.full((3, 3), np.nan), "floor": np.zeros((3, 3))})
    assert np.isnan(history.total_torque()).all()
    np.testing.assert_array_equal(history.total_torque(["floor"]), np.zeros((3, 3)))


def test_arrays_are_copied_and_read_only():
    force = np.ones((3, 3))
    history = _history(force={"left": force, "floor": force})
    force[0, 0] = 7.0
    assert history.force["left"][0, 0] == 1.0
    with pytest.raises(ValueError):
        history.force["left"][0, 0] = 2.0


def test_between_keeps_the_samples_of_an_interval():
    part = _history(signals={"lid_z": [1.0, 2.0, 3.0]}).between(0.05, 0.2)
    np.testing.assert_array_equal(part.time, [0.1, 0.2])
    np.testing.assert_array_equal(part.force["floor"][:, 2], [3.0, 4.0])
    np.testing.assert_array_equal(part.signals["lid_z"], [2.0, 3.0])
    with pytest.raises(ValueError, match="no sample lies in"):
        _history().between(0.2)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"time": []}, "at least one sample"),
        ({"time": [0.0, 0.2, 0.1]}, r"times must increase: sample 2"),
        ({"time": [0.0, np.nan, 0.2]}, "time holds a non-finite value at sample 1"),
        ({"time": [[0.0, 0.1, 0.2]]}, r"time must have shape \(n\)"),
        ({"walls": ("left", "left")}, "unique"),
        ({"walls": ("left", "")}, "non-empty"),
        ({"force": {"left": np.zeros((3, 3))}}, r"force: missing for walls \['floor'\]"),
        ({"torque": {"left": np.zeros((3, 3)), "floor": np.zeros((3, 3)), "gate": np.zeros((3, 3))}},
         r"torque: .*unknown walls \['gate'\]"),
        ({"force": {"left": np.zeros((3, 2)), "floor": np.zeros((3, 3))}},
         r"force of wall 'left' must have shape \(3, 3\)"),
        ({"force": {"left": np.zeros((3, 3)), "floor": [[0, 0, 0], [0, np.nan, 0], [0, 0, 0]]}},
         "force of wall 'floor' holds a non-finite value at sample 1"),
        ({"torque": {"left": np.zeros((3, 3)), "floor": [[0, 0, 0], [0, 0, 0], [0, np.inf, 0]]}},
         "torque of wall 'floor' holds an infinite value at sample 2"),
        ({"signals": {"lid_z": [1.0, 2.0]}}, r"signal 'lid_z' must have shape \(3\)"),
        ({"signals": {"lid_z": [1.0, np.inf, 2.0]}}, "signal 'lid_z' holds a non-finite value at sample 1"),
    ],
)
def test_bad_histories_are_refused_naming_what_is_wrong(changes, message):
    with pytest.raises(ValueError, match=message):
        _history(**changes)


# ---------------------------------------------------------------------------------------------- silo-type files


WALLS = ("wall_left", "floor_left", "outlet_gate")


def _header(walls=WALLS, timestep=DT) -> str:
    columns = " ".join(f"v_{wall}_{q}" for wall in walls for q in QUANTITIES)
    return f"siloflow wall forces, time step {timestep!r} s\n# TimeStep {columns}\n"


def _row(step: int, base: float, walls=WALLS) -> str:
    """Wall w, quantity q: base + 10 w + q (exact in %g)."""
    return " ".join([str(step)] + [repr(base + 10 * w + q) for w in range(len(walls)) for q in range(6)])


def _write(path: Path, rows: list[str], header: str | None = None) -> Path:
    path.write_text((_header() if header is None else header) + "".join(row + "\n" for row in rows))
    return path


def test_reader_returns_each_walls_force_and_torque_with_exact_times(tmp_path):
    _write(tmp_path / WALL_FORCES_NAME, [_row(0, 0.0), _row(400, 100.0), _row(800, 200.0)])
    history = read_wall_forces(tmp_path)
    assert history.walls == WALLS and not history.signals
    np.testing.assert_array_equal(history.time, [0.0, 400 * DT, 800 * DT])
    np.testing.assert_array_equal(history.force["wall_left"][1], [100.0, 101.0, 102.0])
    np.testing.assert_array_equal(history.torque["wall_left"][1], [103.0, 104.0, 105.0])
    np.testing.assert_array_equal(history.force["outlet_gate"][2], [220.0, 221.0, 222.0])
    np.testing.assert_array_equal(history.torque["floor_left"][0], [13.0, 14.0, 15.0])


def test_resumed_files_replace_the_rows_after_their_restart_step(tmp_path):
    # first attempt: steps 0..1200, killed while writing the row of step 1600
    _write(tmp_path / WALL_FORCES_NAME, [_row(s, s) for s in (0, 400, 800, 1200)] + [_row(1600, 1600)[:30]])
    # resumed from step 750: its own row at the restart step is dropped, the first attempt's rows after 750 replaced
    _write(tmp_path / f"{RESUMED_WALL_FORCES_PREFIX}_750.txt",
           [_row(s, s + 0.5) for s in (800, 1200, 1600)] + ["2000 1"])
    # resumed again from step 1200 (a multiple of the interval: sampled at its set-up, dropped)
    _write(tmp_path / f"{RESUMED_WALL_FORCES_PREFIX}_1200.txt", [_row(s, s + 0.25) for s in (1200, 1600, 2000)])
    history = read_silo_wall_forces(tmp_path)
    np.testing.assert_array_equal(history.time, np.array([0, 400, 800, 1200, 1600, 2000]) * DT)
    np.testing.assert_array_equal(history.force["wall_left"][:, 0], [0, 400, 800.5, 1200.5, 1600.25, 2000.25])
    assert RESUMED_WALL_FORCES_PREFIX.startswith(RESUME_STEM)  # a fresh attempt sets them aside


def test_a_cut_last_line_is_an_error_when_no_later_file_supersedes_it(tmp_path):
    path = _write(tmp_path / WALL_FORCES_NAME, [_row(0, 0.0), _row(400, 1.0)[:25]])
    with pytest.raises(ValueError, match=re.escape(str(path)) + r": line 4 has 7 columns, expected 19"):
        read_wall_forces(tmp_path)


def test_resumed_files_must_have_the_same_walls_and_time_step(tmp_path):
    _write(tmp_path / WALL_FORCES_NAME, [_row(0, 0.0)])
    resumed = _write(tmp_path / f"{RESUMED_WALL_FORCES_PREFIX}_10.txt", [_row(400, 0.0, WALLS[:2])], _header(WALLS[:2]))
    message = rf": its time step or walls \(title and column header\) differ from those of {WALL_FORCES_NAME}$"
    with pytest.raises(ValueError, match=re.escape(str(resumed)) + message):
        read_wall_forces(tmp_path)


@pytest.mark.parametrize(
    "content, message",
    [
        ("", "holds 0 of its 2 header lines"),
        ("# Time-averaged data for fix wall_forces\n# TimeStep v_a_fx\n", "line 1 is not the title"),
        ("siloflow wall forces, time step -1.0 s\n# TimeStep\n", "line 1 is not the title .* positive time step"),
        ("siloflow wall forces, time step 1e-5 s\n0 1 2\n", "line 2 is not the column header"),
        ("siloflow wall forces, time step 1e-5 s\n# TimeStep v_a_fx v_a_fy v_a_fz\n",
         "names 3 wall columns, expected six"),
        ("siloflow wall forces, time step 1e-5 s\n# TimeStep v_a_fx v_a_fy v_a_fz v_a_tx v_a_ty v_b_tz\n",
         "line 2: columns .* are not v_<wall>_fx"),
        ("siloflow wall forces, time step 1e-5 s\n# TimeStep" + " v_a_fx v_a_fy v_a_fz v_a_tx v_a_ty v_a_tz" * 2 + "\n",
         "line 2: columns 8 to 13 name the wall of columns 2 to 7 again"),
        (_header() + _row(0, 0.0).replace("1.0", "abc", 1) + "\n", "line 3, column 3 is not a number$"),
        (_header() + _row(0, 0.0).replace("1.0", "nan", 1) + "\n", "line 3, column 3 is not finite$"),
        (_header() + _row(400, 0.0) + "\n" + _row(400, 1.0) + "\n",
         "line 4: the step does not follow the step of line 3$"),
        (_header() + "0.5" + _row(0, 0.0)[1:] + "\n", r"line 3, column 1 is not a step \(an integer\)$"),
    ],
)
def test_reader_names_the_file_and_line_of_bad_content(tmp_path, content, message):
    path = tmp_path / WALL_FORCES_NAME
    path.write_text(content)
    with pytest.raises(ValueError, match=re.escape(str(path)) + ".*" + message):
        read_wall_force_file(path)


def test_a_file_without_samples_gives_no_history(tmp_path):
    _write(tmp_path / WALL_FORCES_NAME, [])
    with pytest.raises(ValueError, match=re.escape(str(tmp_path)) + ".*at least one sample"):
        read_wall_forces(tmp_path)


def test_a_run_without_force_files_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match=f"neither {WALL_FORCES_NAME} .* nor {FORCES_NAME}"):
        read_wall_forces(tmp_path)


# ---------------------------------------------------------------------------------------------- Jenike


def test_jenike_force_history_becomes_walls_with_the_forces_on_the_particles(tmp_path):
    # columns after the step: time, lid f, ring f, bottom f (forces of the particles ON them), lid_z, mass_above
    rows = [[100, 0.001, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 0.02, 0.5],
            [200, 0.002, -1.0, -2.0, -3.0, -4.0, -5.0, -6.0, -7.0, -8.0, -9.0, 0.019, 0.25]]
    assert len(rows[0]) == 1 + len(FORCE_COLUMNS)
    (tmp_path / FORCES_NAME).write_text("# Time-averaged data for fix force_history\n# TimeStep ...\n"
                                        + "".join(" ".join(map(repr, row)) + "\n" for row in rows))
    history = read_wall_forces(tmp_path)
    assert history.walls == JENIKE_WALLS == ("lid", "shear_ring", "base")
    np.testing.assert_array_equal(history.time, [0.001, 0.002])
    np.testing.assert_array_equal(history.force["lid"], [[-1.0, -2.0, -3.0], [1.0, 2.0, 3.0]])
    np.testing.assert_array_equal(history.force["shear_ring"][0], [-4.0, -5.0, -6.0])
    np.testing.assert_array_equal(history.force["base"][1], [7.0, 8.0, 9.0])
    assert all(np.isnan(history.torque[wall]).all() for wall in JENIKE_WALLS)
    np.testing.assert_array_equal(history.signals["lid_z"], [0.02, 0.019])
    np.testing.assert_array_equal(history.signals["mass_above"], [0.5, 0.25])
    np.testing.assert_array_equal(read_jenike_forces(tmp_path).force["base"], history.force["base"])


# ---------------------------------------------------------------------------------------------- the decks


def _fix_header(deck: str) -> tuple[str, str]:
    """The file that the deck's ``fix wall_forces`` writes and the two header lines fix ave/time writes for it."""
    line = next(line for line in deck.splitlines() if line.startswith("fix wall_forces all ave/time"))
    columns, options = line.split(" file ")
    title = re.fullmatch(r'(\S+) title1 "(.*)"', options)
    return title.group(1), f"{title.group(2)}\n# TimeStep {' '.join(columns.split()[7:])}\n"


def _golden_case():
    return build_silo_case(load_config(GOLDEN / "silo_flat_config.yaml"))


def test_the_silo_deck_names_every_wall_as_the_reader_expects(tmp_path):
    case = _golden_case()
    context = silo_deck_context(case)
    name, header = _fix_header(render_silo_deck(case))
    assert name == WALL_FORCES_NAME
    path = tmp_path / name
    path.write_text(header + " ".join(["434"] + ["0.5"] * 42) + "\n")
    timestep, walls, steps, values = read_wall_force_file(path)
    assert timestep == case.timestep
    assert walls == tuple(w["id"] for w in context["primitive_walls"]) + tuple(m["id"] for m in context["meshes"])
    assert walls == ("wall_left", "wall_right", "wall_front", "wall_back", "floor_left", "floor_right", "outlet_gate")
    assert steps.tolist() == [434] and values.shape == (1, 42)


def test_the_resume_deck_writes_the_same_columns_to_a_file_named_by_its_restart_step():
    case = _golden_case()
    context = silo_deck_context(case)
    deck = Resume("liggghts/silo_flat.lmp.j2", context, case.discharge_steps).deck("restart/state_31200.restart",
                                                                             ResumePoint("discharge", final_step=77952))
    name, header = _fix_header(deck)
    assert name == f"{RESUMED_WALL_FORCES_PREFIX}_$(step).txt"
    assert header == _fix_header(render_silo_deck(case))[1]
    # the gate is gone in a resumed run: its columns are zeros
    for quantity in QUANTITIES:
        assert f"variable outlet_gate_{quantity} equal 0.0\n" in deck
    assert "f_outlet_gate[" not in deck
