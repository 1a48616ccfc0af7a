"""YADE behind the engine interface, without running it: the rendered script (golden file, no injection), the
contact and clump quantities it is given, the refusals, and the readers and parsers of what a script writes, each
against exact answers on hand-built files."""

from __future__ import annotations

import ast
import copy
import math
from pathlib import Path

import numpy as np
import pytest

from siloflow.model.cases import cases_of
from siloflow.model.cases.common import material_table
from siloflow.model.cases.particles import clump_inertia, clump_volume
from siloflow.model.cases.blender import build_blender_case
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.model.cases.silo_recirculation import build_recirculation_case
from siloflow.engines.config import ConfigError, load_config, validate_config
from siloflow.engines.interface import CaseNotSupported, engine_named
from siloflow.engines.templating import UnsafeDeckValue, deck_string, render_deck
from siloflow.model.cost import MeasuredWork
from siloflow.engines.yade.cost import elapsed_cpu_seconds, measured_seconds_per_sphere_step, measured_work
from siloflow.engines.yade.run import LOG_NAME, RESUME_STEM
from siloflow.engines.run_files import FAILED_ATTEMPTS
from siloflow.engines.yade.inputs import hertz_stiffness_at_load, principal_clump, rolling_friction
from siloflow.engines.yade.outputs import DamagedOutput, read_frame, read_frames, read_settled_fill, read_wall_forces
from siloflow.engines.yade.progress import ScriptProgress
from siloflow.engines.yade.blender import blender_script_context, render_blender_script
from siloflow.engines.yade.silo_flat import render_silo_script, silo_script_context
from siloflow.engines.yade.silo_recirculation import render_recirculation_script
from tests.golden_files import assert_matches_golden
from tests.unit.test_templating import INJECTIONS

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


def _raw_golden(rolling=0.1):
    raw = load_config(GOLDEN / "silo_flat_config.yaml")
    for contact in raw["contacts"]:
        contact["rolling_friction"] = rolling
    raw["engine"] = {"kind": "yade"}
    return raw


def _golden_case():
    return build_silo_case(validate_config(_raw_golden()))


def test_silo_script_matches_golden_file_and_is_python():
    rendered = render_silo_script(_golden_case())
    assert_matches_golden(rendered, "silo_flat_yade.py")
    ast.parse(rendered)


def _with_engine(name, section):
    raw = load_config(GOLDEN / name)
    raw[section]["engine"] = "yade"
    for contact in raw["contacts"]:  # YADE takes one rolling friction
        contact["rolling_friction"] = 0.1
    return raw


def test_recirculation_script_matches_golden_file_and_is_python():
    case = build_recirculation_case(_with_engine("silo_recirculation_config.yaml", "silo_recirculation"),
                                    "internal_flow")
    rendered = render_recirculation_script(case)
    assert_matches_golden(rendered, "silo_recirculation_yade.py")
    ast.parse(rendered)
    assert "FEEDER_VELOCITY = " in rendered and "say_stage('recirculated')" in rendered


def test_blender_script_matches_golden_file_and_is_python():
    raw = _with_engine("blender_config.yaml", "blender")
    case = build_blender_case(validate_config(raw), "straight")
    rendered = render_blender_script(case)
    assert_matches_golden(rendered, "blender_yade.py")
    ast.parse(rendered)
    assert ("DOMAIN_TOP - SINK_BOTTOM" in rendered) == (case.mode == "continuous")


def test_a_blender_at_f_g_runs_its_stiffer_contacts_under_f_g():
    """The gravity series' similarity on YADE: at 4 g the moduli are 4 times stiffer and the rolling law's stiffness,
    the Hertz stiffness under a clump's weight, is taken under 4 g, so it is 4 times the 1 g one (E^(2/3) F^(1/3))."""
    config = validate_config(_with_engine("blender_config.yaml", "blender"))
    base, heavy = (blender_script_context(build_blender_case(config, "straight", f)) for f in (1.0, 4.0))
    assert (base["gravity"], heavy["gravity"]) == (pytest.approx(9.81), pytest.approx(4 * 9.81))
    assert heavy["materials"]["list"][0]["youngs_modulus"] == 4 * base["materials"]["list"][0]["youngs_modulus"]
    assert heavy["materials"]["rolling_stiffness"] == pytest.approx(4 * base["materials"]["rolling_stiffness"], rel=1e-12)


def test_the_script_never_starts_yades_launcher_and_imports_from_the_system_modules():
    rendered = render_silo_script(_golden_case())
    assert 'sys.path.insert(0, "/usr/lib/x86_64-linux-gnu/yade-double/py")' in rendered
    assert "yade.runtime" not in rendered and "subprocess" not in rendered and "eval(" not in rendered


@pytest.mark.parametrize("value", INJECTIONS + ["a'b", 'a"b', "a\\b"])
def test_string_filter_refuses_what_could_leave_a_python_string(value):
    with pytest.raises(UnsafeDeckValue):
        deck_string(value)


def test_string_filter_quotes_names_and_paths():
    assert deck_string("wall_left") == "'wall_left'"
    assert deck_string("dumps/settled.txt") == "'dumps/settled.txt'"


@pytest.mark.parametrize("value", INJECTIONS)
def test_context_check_refuses_injected_strings_in_the_script(value):
    context = copy.deepcopy(silo_script_context(_golden_case()))
    context["primitive_walls"][0]["id"] = value
    with pytest.raises(UnsafeDeckValue, match=r"context\.primitive_walls\[0\]\.id"):
        render_deck("yade/silo_flat.py.j2", context)


def test_different_rolling_frictions_are_refused_naming_the_key():
    raw = load_config(GOLDEN / "silo_flat_config.yaml")  # perspex and lid: 0.05, hdpe and aluminium: 0.1
    raw["engine"] = {"kind": "yade"}
    case = build_silo_case(validate_config(raw))
    with pytest.raises(CaseNotSupported, match=r"config key 'contacts': rolling_friction differs.*\[hdpe, perspex\]: 0.05"):
        engine_named("yade").check_case(case)


def test_a_periodic_depth_is_refused_naming_the_key():
    raw = _raw_golden()
    raw["silo_flat"]["front_back_walls"] = False
    case = build_silo_case(validate_config(raw))
    with pytest.raises(CaseNotSupported, match=r"config key 'silo_flat.front_back_walls'"):
        engine_named("yade").write_inputs(case, "/nonexistent/never/written")


@pytest.mark.parametrize("kind", ["silo_flat", "silo_recirculation", "blender", "jenike"])
def test_every_case_kind_of_the_default_config_has_a_yade_script(kind, tmp_path):
    config = validate_config({"engine": {"kind": "yade"}})
    engine = engine_named("yade")
    case = next(iter(cases_of(config, kind).values()))
    engine.check_case(case)
    engine.write_inputs(case, tmp_path)
    ast.parse((tmp_path / "deck" / "run.py").read_text())


@pytest.mark.parametrize("raw, key", [
    ({"engine": {"yade": {"threads": 2}}}, "engine.yade.threads"),
    ({"engine": {"kind": "yade", "liggghts": {"executable": "/opt/liggghts/lmp"}}}, "engine.liggghts.executable"),
    ({"engine": {"kind": "yade", "mpi_ranks": 2}}, "engine.mpi_ranks"),
    ({"engine": {"kind": "yade", "mpirun": "mpiexec"}}, "engine.mpirun"),
])
def test_a_setting_of_an_engine_that_runs_no_case_is_refused_naming_the_key(raw, key):
    with pytest.raises(ConfigError, match=rf"config key '{key}' is a \w+ setting, but no case runs on"):
        validate_config(raw)


def test_a_setting_at_its_default_is_accepted_so_a_validated_config_validates_again():
    config = validate_config({"engine": {"yade": {"threads": 1}}})
    assert validate_config(config)["engine"] == config["engine"]


def test_settings_of_both_engines_are_accepted_when_both_run_cases():
    config = validate_config({"engine": {"kind": "yade", "mpi_ranks": 2, "yade": {"threads": 1}},
                              "jenike": {"engine": "liggghts"}})
    assert config["engine"]["mpi_ranks"] == 2


def test_rolling_friction_is_the_one_value_of_the_particles_pairs():
    config = validate_config(_raw_golden(rolling=0.2))
    table = material_table(config, "hdpe", ["aluminium", "perspex"])
    assert rolling_friction(table, "here") == 0.2


def test_hertz_stiffness_at_a_load_is_the_slope_of_hertz_law_there():
    radius, modulus, poisson, load = 1.5e-3, 5e6, 0.4, 1.8e-4
    kn = hertz_stiffness_at_load(radius, modulus, poisson, load)
    e_star, r_star = modulus / (2 * (1 - poisson**2)), radius / 2
    overlap = (kn / (2 * e_star)) ** 2 / r_star  # kn = 2 E* sqrt(R* delta)
    assert 4 / 3 * e_star * math.sqrt(r_star) * overlap**1.5 == pytest.approx(load, rel=1e-12)


def test_clump_inertia_of_one_sphere_is_two_fifths_m_r_squared():
    radius, density = 1.5e-3, 950.0
    mass = density * 4 / 3 * math.pi * radius**3
    tensor = clump_inertia([[0.3e-3, -0.2e-3, 0.1e-3]], [radius], density)
    assert tensor == pytest.approx(0.4 * mass * radius**2 * np.eye(3), rel=1e-4, abs=1e-20)


def test_clump_inertia_of_two_apart_spheres_follows_the_parallel_axis_theorem():
    radius, density, half = 1e-3, 1000.0, 2e-3
    mass = density * 4 / 3 * math.pi * radius**3
    tensor = clump_inertia([[-half, 0, 0], [half, 0, 0]], [radius, radius], density)
    own = 0.4 * mass * radius**2
    assert np.diag(tensor) == pytest.approx([2 * own, 2 * (own + mass * half**2), 2 * (own + mass * half**2)], rel=1e-4)
    assert abs(tensor[0, 1]) < 1e-6 * tensor[0, 0]


def test_clump_inertia_turns_with_the_clump():
    centres = np.array([[-0.4e-3, 0, 0], [0.4e-3, 0, 0]])
    along_x = clump_inertia(centres, [1.5e-3, 1.5e-3], 950.0)
    along_z = clump_inertia(centres[:, [1, 2, 0]], [1.5e-3, 1.5e-3], 950.0)
    assert np.diag(along_z) == pytest.approx(np.diag(along_x)[[1, 2, 0]], rel=1e-4)


def test_principal_clump_keeps_the_shape_and_orders_the_moments():
    case = _golden_case()
    centres, moments = principal_clump(case.particle)
    distances = np.linalg.norm(centres[:, None] - centres[None], axis=-1)
    original = np.linalg.norm(case.particle.sphere_positions[:, None] - case.particle.sphere_positions[None], axis=-1)
    assert distances == pytest.approx(original, abs=1e-15)
    assert moments[0] < moments[1] == pytest.approx(moments[2], rel=1e-3)  # the axis of a two-sphere clump turns easiest
    assert clump_volume(centres, case.particle.sphere_radii) == pytest.approx(case.particle.volume, rel=1e-12)


def _frame_arrays(step=400):
    return {"step": step, "time": step * 1e-5, "id": np.array([5, 6, 7, 8]), "type": np.ones(4, dtype=np.int64),
            "clump_id": np.array([4, 4, 9, 9]), "position": np.arange(12.0).reshape(4, 3),
            "velocity": -np.arange(12.0).reshape(4, 3), "radius": np.full(4, 1.5e-3), "mass": np.full(4, 2e-5)}


def test_a_frame_reads_back_exactly(tmp_path):
    (tmp_path / "dumps").mkdir()
    np.savez(tmp_path / "dumps" / "particles_400.npz", **_frame_arrays())
    frame = read_frame(tmp_path / "dumps" / "particles_400.npz")
    assert (frame.step, frame.time) == (400, 4e-3)
    assert frame.clump_id.tolist() == [4, 4, 9, 9]
    assert np.array_equal(frame.position, np.arange(12.0).reshape(4, 3))
    assert frame.angular_velocity is None


def test_frames_come_in_step_order_and_a_damaged_one_is_named_or_skipped(tmp_path):
    (tmp_path / "dumps").mkdir()
    for step in (1200, 400, 800):
        np.savez(tmp_path / "dumps" / f"particles_{step}.npz", **_frame_arrays(step))
    (tmp_path / "dumps" / "particles_1600.npz").write_bytes(b"PK\x03\x04cut")
    with pytest.raises(DamagedOutput, match="particles_1600.npz"):
        read_frames(tmp_path, "particles")
    assert [f.step for f in read_frames(tmp_path, "particles", on_damaged="skip")] == [400, 800, 1200]


def _wall_rows(steps, offset):
    return "\n".join(f"{s} {s * 1e-5!r} " + " ".join(str(float(offset + s + k)) for k in range(12)) for s in steps)


def test_wall_forces_join_the_resumed_attempt_which_replaces_the_rows_after_its_snapshot(tmp_path):
    title = "# step time " + " ".join(f"{w}_{q}" for w in ("left", "gate") for q in ("fx", "fy", "fz", "tx", "ty", "tz"))
    (tmp_path / "wall_force_history.txt").write_text(f"{title}\n{_wall_rows([100, 200, 300], 0)}\n301 3.01e-3 1.0 2")
    (tmp_path / "resume_200_wall_force_history.txt").write_text(f"{title}\n{_wall_rows([300, 400], 1000)}\n")
    history = read_wall_forces(tmp_path, 1e-5)
    assert history.walls == ("left", "gate")
    assert history.time == pytest.approx([1e-3, 2e-3, 3e-3, 4e-3])
    assert history.force["left"][:, 0].tolist() == [100.0, 200.0, 1300.0, 1400.0]
    assert history.torque["gate"][:, 2].tolist() == [111.0, 211.0, 1311.0, 1411.0]


def test_settled_fill_reads_back_with_its_contacts_and_walls(tmp_path):
    (tmp_path / "dumps").mkdir()
    contacts = np.array([[0, 0, 0, 1, 0, 0, 5, 7, 0.5, 0.0, -1.0]])
    for step in (10, 11):
        np.savez(tmp_path / "dumps" / f"settled_fill_{step}.npz", **_frame_arrays(step),
                 wall_force=np.tile([0.0, 0.0, 1e-4], (4, 1)), contacts=contacts, walls=np.array(["left", "gate"]),
                 wall_forces=np.array([[1.0, 0, 0, 0, 0, 0], [0, 0, 4e-4, 0, 0, 0]]))
    fills = read_settled_fill(tmp_path, "settled_fill", ("gate",))
    assert [f.frame.step for f in fills] == [10, 11]
    assert fills[0].contacts.id_j.tolist() == [7] and fills[0].contacts.force.tolist() == [[0.5, 0.0, -1.0]]
    assert fills[1].wall_forces["gate"].tolist() == [0.0, 0.0, 4e-4]
    assert fills[1].floor_walls == ("gate",)


def test_progress_parser_reads_time_clumps_and_stage_across_chunks():
    parser = ScriptProgress()
    assert parser.feed("SILOFLOW progress stage=fill step=100 time=0.0") == []
    samples = parser.feed("01 clumps=12\nSILOFLOW filled step=200 time=0.002 clumps=40 ke_per_clump=1e-9\nSILO")
    assert [(s.time, s.clumps) for s in samples] == [(0.001, 12.0)]
    assert parser.stage == "filled"
    assert parser.flush() == []
    assert parser.latest.time == 0.001


def test_measured_cost_sums_every_attempts_last_timing(tmp_path):
    first, resumed = tmp_path / "log.yade", tmp_path / "resume1.log.yade"
    first.write_text("SILOFLOW filled cpu_s=10.0 sphere_steps=1000000\nSILOFLOW opened cpu_s=20.0 sphere_steps=4000000\n")
    resumed.write_text("SILOFLOW resumed step=5\nSILOFLOW discharged cpu_s=5.0 sphere_steps=1000000\n")
    # each attempt is its own process: its last timed marker holds its totals, and the attempts add up
    assert measured_work([first, resumed]) == MeasuredWork(25.0, 5e6)
    assert measured_seconds_per_sphere_step([first, resumed]) == pytest.approx(25.0 / 5e6, rel=1e-15)
    empty = tmp_path / "empty.log"
    empty.write_text("Traceback\n")
    assert measured_seconds_per_sphere_step([empty]) is None
    assert measured_work([empty]) is None


def test_a_run_s_attempts_before_its_last_count_their_last_timed_marker(tmp_path):
    attempt = tmp_path / FAILED_ATTEMPTS / "20261129T073502Z"
    attempt.mkdir(parents=True)
    (attempt / LOG_NAME).write_text("SILOFLOW filled cpu_s=10.0 sphere_steps=1000000\nSILOFLOW progress cpu_s=nan\n"
                                    "SILOFLOW opened cpu_s=20.5 sphere_steps=4000000\nTraceback\n")
    assert elapsed_cpu_seconds([attempt / LOG_NAME]) == 20.5
    assert engine_named("yade").earlier_attempts_seconds(tmp_path) == 20.5
    # then it ran afresh and resumed once in place: the first of those counts, the last does not
    (tmp_path / LOG_NAME).write_text("SILOFLOW opened cpu_s=4.25\n")
    (tmp_path / f"{RESUME_STEM}1.{LOG_NAME}").write_text("SILOFLOW resumed step=5\nSILOFLOW discharged cpu_s=8.0\n")
    assert engine_named("yade").earlier_attempts_seconds(tmp_path) == 20.5 + 4.25
    assert engine_named("yade").earlier_attempt_seconds(tmp_path) == [20.5, 4.25]
    assert engine_named("yade").earlier_attempts_seconds(tmp_path / "elsewhere") == 0.0


def test_measured_work_skips_markers_with_unusable_timing(tmp_path):
    log = tmp_path / "log.yade"
    log.write_text("SILOFLOW filled cpu_s=10.0 sphere_steps=1000000\nSILOFLOW opened cpu_s=nan sphere_steps=4000000\n"
                   "SILOFLOW settled cpu_s=12.0 sphere_steps=-1\n")
    assert measured_work([log]) == MeasuredWork(10.0, 1e6)


def test_a_silo_poured_at_its_own_friction_switches_to_the_run_s_contacts_before_the_gate_goes():
    raw = _raw_golden()
    raw["silo_flat"].setdefault("fill", {})["sliding_friction"] = 0.15
    script = render_silo_script(build_silo_case(validate_config(raw)))
    ast.parse(script)
    fill_pairs = next(line for line in script.splitlines() if line.startswith("FILL_PAIRS = "))
    assert fill_pairs.startswith("FILL_PAIRS = [(0, 0, 0.15, ")
    assert script.index("set_engines(MATERIAL_IDS, FILL_PAIRS)") < script.index("use_contacts(MATERIAL_IDS, PAIRS, "
                                                                                "ROLLING_FRICTION, ROLLING_STIFFNESS)") \
        < script.index("# --- open the outlet")
    plain = render_silo_script(_golden_case())
    assert "FILL_PAIRS" not in plain and "use_contacts(" not in plain.split("def use_contacts")[1].split("\n\n\n", 1)[1]
