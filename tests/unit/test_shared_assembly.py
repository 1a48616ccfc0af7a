"""The recirculating silo started from the flat-bottom silo's settled fill (``silo_recirculation.assembly: silo_flat``,
the study's one assembly, §6.2.2): which run each flow pattern starts from, the checks of the configuration, the decks
and scripts that write and read the fill (golden files), the estimate, the run's checks and the fill's placing."""

from __future__ import annotations

import ast
import copy
import re
from pathlib import Path

import pytest

from siloflow.engines.config import ConfigError, load_config, validate_config
from siloflow.engines.interface import EngineRunError, engine_named
from siloflow.engines.liggghts.silo_flat import render_silo_deck
from siloflow.engines.liggghts.silo_recirculation import render_recirculation_deck
from siloflow.engines.markers import Marker
from siloflow.engines.silo_checks import check_silo_run
from siloflow.engines.validation_groups import GROUPS
from siloflow.engines.yade.silo_flat import render_silo_script
from siloflow.engines.yade.silo_recirculation import render_recirculation_script
from siloflow.model.cases import cases_of, reference_runs
from siloflow.model.cases.kinds import case_kind
from siloflow.model.cases.silo_cost import estimate_recirculation_case
from tests.golden_files import assert_matches_golden

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


def _raw(engine: str = "liggghts") -> dict:
    """The golden recirculating silo with a flat-bottom silo of its geometry, the flow patterns starting from it."""
    raw = load_config(GOLDEN / "silo_recirculation_config.yaml")
    blending = raw["silo_recirculation"]
    blending.update(assembly="silo_flat", flow_patterns=["internal_flow", "semi_mass_flow"], reference_replicates=2,
                    final_discharge=1.0)
    raw["silo_flat"] = {key: blending[key] for key in ("width", "depth", "fill_height", "outlet_width")}
    raw["silo_flat"].update(discharge_time=0.3, reference_replicates=3)
    raw["engine"] = {"kind": engine}
    if engine == "yade":
        for contact in raw["contacts"]:  # YADE takes one rolling friction
            contact["rolling_friction"] = 0.1
    return raw


@pytest.fixture(scope="module")
def config():
    return validate_config(_raw())


def _blending(config) -> dict:
    return {run: case for run, case in cases_of(config, "silo_recirculation").items() if case.role == "blending"}


def test_every_flow_pattern_of_a_seed_starts_from_the_flat_silos_reference_run_of_that_seed(config):
    flat = cases_of(config, "silo_flat")
    flat_reference = reference_runs(config, "silo_flat")
    runs = _blending(config)
    # internal_flow (the reference pattern) on seeds 1 and 2, semi_mass_flow on seed 1
    assert sorted(case.pattern for case in runs.values()) == ["internal_flow", "internal_flow", "semi_mass_flow"]
    for case in runs.values():
        assert case.assembly.run_id in flat_reference
        assert case.assembly.seeds == case.silo.seeds == flat[case.assembly.run_id].seeds
        assert case.defining_parameters["assembly"] == case.assembly.run_id
        assert case.summary()["assembly_run_id"] == case.assembly.run_id
    first_seed = [case for case in runs.values() if case.seeds == runs[next(iter(runs))].seeds]
    assert {case.pattern for case in first_seed} == {"internal_flow", "semi_mass_flow"}
    assert len({case.assembly.run_id for case in first_seed}) == 1


def test_a_run_from_the_assembly_opens_the_outlet_first_and_has_its_own_id(config):
    case = next(iter(_blending(config).values()))
    assert [stage.kind for stage in case.stages()] == ["open", "recirculate", "discharge"]
    assert case_kind("silo_recirculation").runs_stages(tuple(stage.kind for stage in case.stages()))
    assert not case_kind("silo_flat").runs_stages(("open", "discharge"))
    raw = _raw()
    raw["silo_recirculation"]["assembly"] = "own"
    own = next(iter(_blending(validate_config(raw)).values()))
    assert own.assembly is None and own.run_id != case.run_id
    assert [stage.kind for stage in own.stages()][:2] == ["fill", "settle"]


def test_the_thin_verification_silo_pours_its_own_fill():
    raw = _raw()
    raw["silo_recirculation"]["verification"] = {"enabled": True, "width": 0.06, "depth": 0.0045, "fill_height": 0.04}
    thin = [case for case in cases_of(validate_config(raw), "silo_recirculation").values()
            if case.role == "verification"]
    assert len(thin) == 1 and thin[0].assembly is None


@pytest.mark.parametrize("edit, key", [
    (lambda raw: raw["silo_recirculation"].update(width=0.1), "silo_recirculation.width"),
    (lambda raw: raw["silo_recirculation"].update(fill_height=0.06), "silo_recirculation.fill_height"),
    (lambda raw: raw["silo_recirculation"].update(seed=2), "silo_recirculation.seed"),
    (lambda raw: raw["silo_recirculation"].update(fill={"sliding_friction": 0.3}), "silo_recirculation.fill"),
    (lambda raw: raw["silo_recirculation"].update(engine="yade"), "silo_recirculation.engine"),
    (lambda raw: raw["silo_recirculation"].update(reference_replicates=4), "silo_recirculation.reference_replicates"),
    (lambda raw: raw["silo_flat"].update(front_back_walls=False), "silo_flat.front_back_walls"),
])
def test_a_recirculating_silo_that_is_not_the_flat_silo_is_refused_naming_the_key(edit, key):
    raw = _raw()
    edit(raw)
    with pytest.raises(ConfigError, match=re.escape(f"config key '{key}'")):
        validate_config(raw)


def test_the_checks_hold_only_with_the_shared_assembly():
    raw = _raw()
    raw["silo_recirculation"].update(assembly="own", width=0.1)
    validate_config(raw)


def test_the_estimate_of_a_run_from_the_assembly_counts_no_fill_or_settle(config):
    case = next(iter(_blending(config).values()))
    estimate = estimate_recirculation_case(case)
    assert [stage.stage for stage in estimate.stages] == ["recirculate"]
    assert estimate.stages[0].steps == case.silo.discharge_steps


def test_the_blending_group_reads_the_flat_silos_base_runs():
    assert "silo" in GROUPS["blending"].reads


# ---------------------------------------------------------------------------------------------- decks and scripts


def test_the_flat_silo_keeps_its_settled_fill_and_the_recirculating_silo_reads_it(config):
    flat = next(iter(cases_of(config, "silo_flat").values()))
    flat_deck = render_silo_deck(flat)
    # written once settled, before the snapshot of the settled fill and the opening
    settled = flat_deck.index("SILOFLOW settled")
    assert settled < flat_deck.index("write_restart assembly.restart") < flat_deck.index("dump settled_fill")
    case = next(iter(_blending(config).values()))
    deck = render_recirculation_deck(case)
    assert_matches_golden(deck, "silo_recirculation_assembled.lmp")
    assert "write_restart" not in deck and "fix pour" not in deck and "create_box" not in deck
    assert "read_restart deck/assembly.restart" in deck
    lines = deck.splitlines()
    # LIGGGHTS takes reset_timestep only right before a run, and changes a box read from a restart file only after one
    first_run = lines.index("run 0")
    assert lines[first_run - 1] == "reset_timestep 0"
    change = next(i for i, line in enumerate(lines) if line.startswith("change_box"))
    assert change == first_run + 1
    assert lines[change] == f"change_box all z final -0.04 {case.silo.domain_top!r} boundary f f p units box"
    # the channel's walls lie outside the flat silo's box: declared once it is extended
    channel = [i for i, line in enumerate(lines) if line.startswith("fix channel_")]
    assert len(channel) == 2 and min(channel) > change
    assert "meshes floor_left floor_right outlet_gate store_force" in deck
    assert "meshes floor_left floor_right channel_left channel_right store_force" in deck
    # the run's frictions, declared once the assembly is read, act from the opening on: the only ones in the deck
    friction = [line for line in lines if line.startswith("fix material_friction")]
    assert friction == ["fix material_friction all property/global coefficientFriction peratomtypepair 3 "
                        "0.55 0.5 0.5 0.5 0.0 0.0 0.5 0.0 0.0"]
    assert deck.index("read_restart") < deck.index(friction[0]) < deck.index("SILOFLOW opened")


def test_a_recirculating_silo_that_pours_its_own_fill_keeps_none():
    raw = _raw()
    raw["silo_recirculation"]["assembly"] = "own"
    own = next(iter(_blending(validate_config(raw)).values()))
    assert "write_restart" not in render_recirculation_deck(own)
    assert "save_atomic('assembly.yade'" not in render_recirculation_script(
        next(iter(_blending(validate_config({**_raw("yade"), "silo_recirculation": {
            **_raw("yade")["silo_recirculation"], "assembly": "own"}})).values())))


def test_the_yade_scripts_save_and_load_the_assembly():
    config = validate_config(_raw("yade"))
    flat = render_silo_script(next(iter(cases_of(config, "silo_flat").values())))
    assert flat.index("say_stage(\"settled\")") < flat.index("save_atomic('assembly.yade', O.save)")
    case = next(iter(_blending(config).values()))
    script = render_recirculation_script(case)
    assert_matches_golden(script, "silo_recirculation_assembled_yade.py")
    ast.parse(script)
    assert "O.load('deck/assembly.yade')" in script and "O.resetTime()" in script
    assert "save_atomic('assembly.yade'" not in script
    # the scene is built with the assembly's walls only; the channel's are added once it is loaded
    build = script[:script.index("RESTART = sys.argv")]
    assert "'channel_left'" not in build
    assert "add_meshes('deck/geometry.npz', {'channel_left': MATERIAL_IDS[1], 'channel_right': MATERIAL_IDS[1], })" in script


# ---------------------------------------------------------------------------------------------- the run's checks


def _markers(clumps: int, assembled_clumps: int | None = None) -> list[Marker]:
    def values(step, time, n):
        return {"step": step, "time": time, "clumps": n, "ke_per_clump": 1e-11}

    return [Marker("assembled", values(0, 0.0, clumps if assembled_clumps is None else assembled_clumps)),
            Marker("opened", values(0, 0.0, clumps)),
            Marker("recirculated", values(1000, 0.02, clumps)),
            Marker("discharged", values(1500, 0.03, clumps - 7))]


def test_a_run_from_the_assembly_is_checked_from_its_opening(config, tmp_path):
    case = next(iter(_blending(config).values()))
    n = case.silo.fill.n_clumps
    dumps = [tmp_path / "a.vtk", tmp_path / "b.vtk"]
    checked = check_silo_run(case.silo, _markers(n), dumps, tmp_path, last_stage="recirculated",
                             clumps_conserved=True, then="discharged", assembled=True)
    assert "filled" not in checked and "settled" not in checked and checked["settle_checks"] == []
    assert checked["assembled"]["clumps"] == n and checked["open_step"] == 0
    assert checked["discharged"]["clumps"] == n - 7
    with pytest.raises(EngineRunError, match="'assembled' stage marker"):
        check_silo_run(case.silo, _markers(n)[1:], dumps, tmp_path, last_stage="recirculated", assembled=True)
    with pytest.raises(EngineRunError, match=f"holds {n - 1} clumps, the case {n}"):
        check_silo_run(case.silo, _markers(n, n - 1), dumps, tmp_path, last_stage="recirculated", assembled=True)
    # a run that pours its own fill must show it
    with pytest.raises(EngineRunError, match="'filled' stage marker"):
        check_silo_run(case.silo, _markers(n), dumps, tmp_path, last_stage="recirculated")


@pytest.mark.parametrize("engine", ["liggghts", "yade"])
def test_the_deck_gets_its_own_link_to_the_assembly_and_a_missing_one_is_named(config, tmp_path, engine):
    case = next(iter(_blending(config).values()))
    runner = engine_named(engine)
    flat_dir, run_dir = tmp_path / "flat", tmp_path / "run"
    flat_dir.mkdir()
    with pytest.raises(FileNotFoundError, match=re.escape(str(flat_dir))):
        runner.place_assembly(case, run_dir, flat_dir)
    with pytest.raises(ValueError, match=f"starts from the settled fill of run {case.assembly.run_id}"):
        runner.place_assembly(case, run_dir, None)
    (flat_dir / runner.assembly_file).write_bytes(b"settled fill")
    runner.place_assembly(case, run_dir, flat_dir)
    placed = run_dir / "deck" / runner.assembly_file
    assert placed.read_bytes() == b"settled fill"
    # the flat run made again leaves the deck's copy as it was rendered for
    (flat_dir / runner.assembly_file).unlink()
    (flat_dir / runner.assembly_file).write_bytes(b"another fill")
    assert placed.read_bytes() == b"settled fill"
    assert sorted(path.name for path in placed.parent.iterdir()) == [runner.assembly_file]


def test_a_case_without_an_assembly_places_nothing(tmp_path):
    raw = copy.deepcopy(_raw())
    raw["silo_recirculation"]["assembly"] = "own"
    case = next(iter(_blending(validate_config(raw)).values()))
    engine_named("liggghts").place_assembly(case, tmp_path, None)
    assert not (tmp_path / "deck").exists()
