"""Runs siloflow did not make: their description in the configuration, their dump file patterns and the checks of
their folders before anything runs, each refusal naming the key and the problem. The folders hold copies of the dumps
LIGGGHTS wrote (tests/fixtures/liggghts/) under the names a hand-written deck gives them (``post/silo1500.vtk``)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from siloflow.model.existing_run import ExistingRunError, ExistingSiloRun
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.engines.config import ConfigError, existing_silo_runs, validate_config
from siloflow.engines.existing_runs import check_existing_run, check_existing_runs, opening_files, read_existing_frames
from siloflow.engines.interface import DumpFile, engine_named
from siloflow.engines.liggghts.dump_files import check_dump_pattern, match_dump_files

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures" / "liggghts"
DESCRIPTION = {"folder": "runs/mine", "dumps": "post/silo*.vtk", "width": 0.02, "depth": 0.02, "outlet_width": 0.006,
               "timestep": 2e-5, "open_step": 750, "density": 2500.0}
KEY = "silo_flat.existing_runs.mine"


def _config(**changes) -> dict:
    return {"silo_flat": {"existing_runs": {"mine": {**DESCRIPTION, **changes}}}}


def _refused(match: str, **changes) -> None:
    with pytest.raises(ConfigError, match=match):
        validate_config(_config(**changes))


def test_no_existing_run_by_default():
    config = validate_config({})
    assert config["silo_flat"]["existing_runs"] == {} and existing_silo_runs(config) == {}
    assert check_existing_runs(config) == {}


def test_an_existing_run_neither_defines_nor_reruns_siloflow_s_own_silo():
    assert build_silo_case(validate_config(_config())).run_id == build_silo_case(validate_config({})).run_id


def test_a_description_gets_its_defaults_and_the_opening_time_becomes_a_step():
    config = validate_config(_config(open_step=None, open_time=0.3))
    entry = config["silo_flat"]["existing_runs"]["mine"]
    assert entry["engine"] == "liggghts" and entry["origin"] == [0.0, 0.0, 0.0] and entry["profile_heights"] is None
    run = existing_silo_runs(config)["mine"]
    assert run.open_step == 15000 and run.open_time == pytest.approx(0.3, rel=1e-15)
    assert run.origin == (0.0, 0.0, 0.0) and run.density == 2500.0 and run.particle_diameter is None


@pytest.mark.parametrize("key", ["folder", "dumps", "width", "depth", "outlet_width", "timestep"])
def test_a_required_key_left_out_is_named(key):
    _refused(rf"config key '{KEY}\.{key}': required", **{key: None})


def test_bad_descriptions_are_refused_naming_the_key():
    _refused(rf"'{KEY}\.open_time': give the outlet's opening as open_time \(s\) or as open_step, once",
             open_step=None)
    _refused(rf"'{KEY}\.open_time': give the outlet's opening", open_time=0.3)
    _refused(rf"'{KEY}\.open_time': 0.30001 s is not a whole number of time steps", open_step=None, open_time=0.30001)
    _refused(rf"'{KEY}\.outlet_width': 0.03 m must be smaller than the width", outlet_width=0.03)
    _refused(rf"'{KEY}\.density': -1 is less than or equal to the minimum of 0", density=-1)
    _refused(rf"'{KEY}\.origin': \[0, 0\] is too short", origin=[0, 0])
    _refused(rf"'{KEY}\.dumps': '\.\./post/silo\*\.vtk' must be a relative path", dumps="../post/silo*.vtk")
    _refused(rf"'{KEY}\.engine': 'colour' is not one of \['liggghts'\]", engine="colour")
    _refused(rf"'{KEY}\.mass' is not a siloflow setting: the keys here are density, depth, dumps", mass=1.0)
    with pytest.raises(ConfigError, match=r"'silo_flat.existing_runs': 'a b' does not match"):
        validate_config({"silo_flat": {"existing_runs": {"a b": DESCRIPTION}}})


def test_from_config_names_the_key_of_its_error():
    with pytest.raises(ExistingRunError) as caught:
        ExistingSiloRun.from_config("mine", {**DESCRIPTION, "width": None})
    assert caught.value.key == "width" and caught.value.reason.startswith("required")


def test_dump_patterns_the_way_a_dump_command_names_its_files():
    for pattern in ("silo*.vtk", "post/silo*.vtk", "post/dump.txt", "a/b/silo_*.liggghts"):
        check_dump_pattern(pattern)
    refused = {"post/silo%*.vtk": "one file per processor", "post/silo?.vtk": "no LIGGGHTS wildcard",
               "post/*/silo.vtk": "belongs in the file name", "post/silo**.vtk": "more than one",
               "/abs/silo*.vtk": "relative path", "../silo*.vtk": "relative path"}
    for pattern, reason in refused.items():
        with pytest.raises(ExistingRunError, match=reason) as caught:
            check_dump_pattern(pattern)
        assert caught.value.key == "dumps"


def _copy(folder: Path, names: dict[str, str]) -> Path:
    """Copy fixtures into ``folder``: ``{new name: fixture}``."""
    for name, fixture in names.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(FIXTURES / fixture, folder / name)
    return folder


def test_files_of_a_pattern_in_numeric_step_order_without_bounding_boxes(tmp_path):
    for name in ("silo10000.vtk", "silo500.vtk", "silo1000.vtk", "siloboundingBox_500.vtk", "silo_500.vtk",
                 "silo1000.vtk.bak", "other1000.vtk"):
        (tmp_path / "post").mkdir(exist_ok=True)
        (tmp_path / "post" / name).write_text("")
    files = match_dump_files(tmp_path, "post/silo*.vtk")
    assert [(f.path.name, f.step) for f in files] == [("silo500.vtk", 500), ("silo1000.vtk", 1000),
                                                       ("silo10000.vtk", 10000)]
    (tmp_path / "post" / "silo0500.vtk").write_text("")
    with pytest.raises(ExistingRunError, match=r"two files of one step \(\[500\]\)"):
        match_dump_files(tmp_path, "post/silo*.vtk")
    assert match_dump_files(tmp_path, "post/other1000.vtk") == [DumpFile(tmp_path / "post" / "other1000.vtk", None)]


def test_opening_files_are_the_last_named_at_or_before_the_opening_and_every_unnamed_one():
    files = [DumpFile(Path("a0"), 0), DumpFile(Path("a750"), 750), DumpFile(Path("a1500"), 1500)]
    assert opening_files(files, 750) == ([files[1]], True)
    assert opening_files(files, 1000) == ([files[1]], True)
    assert opening_files(files, 1500) == ([files[2]], False)
    assert opening_files(files[1:], 500) == ([], True)
    single = [DumpFile(Path("series.txt"), None)]
    assert opening_files(single, 750) == (single, True)


def _vtk_run(tmp_path: Path, **changes) -> ExistingSiloRun:
    # the same real frame as the fill at step 1500 and again at 3000; a dump of the empty box at step 0
    _copy(tmp_path, {"post/silo0.vtk": "empty_binary_0.vtk", "post/silo1500.vtk": "spheres_binary_nomass_1500.vtk",
                     "post/silo3000.vtk": "spheres_binary_nomass_1500.vtk"})
    return ExistingSiloRun(**{"name": "mine", "engine": "liggghts", "folder": str(tmp_path), "dumps": "post/silo*.vtk",
                              "width": 0.02, "depth": 0.02, "outlet_width": 0.006, "timestep": 2e-5,
                              "open_step": 1500, "density": 2500.0, **changes})


def test_a_folder_of_dumps_without_mass_passes_with_a_density_and_reads_every_frame(tmp_path):
    run = _vtk_run(tmp_path)
    files = check_existing_run(run)
    assert [f.step for f in files] == [0, 1500, 3000]
    # the dumps of the filling (the empty box at step 0) are not read
    frames = read_existing_frames(run)
    assert [frame.step for frame in frames] == [1500, 3000] and [len(f) for f in frames] == [40, 40]
    assert frames[0].time == pytest.approx(1500 * 2e-5, rel=1e-15)
    # the mass of a sphere is density x 4/3 pi r^3, in LIGGGHTS' order of operations
    radius = frames[0].radius
    assert (frames[0].mass == radius * radius * radius * 4.0 * 3.141592653589793 / 3.0 * 2500.0).all()
    assert [frame.step for frame in read_existing_frames(ExistingSiloRun(**{**run.__dict__, "open_step": 2000}))] \
        == [1500, 3000]


def test_a_folder_is_refused_before_anything_runs_naming_the_problem(tmp_path):
    run = _vtk_run(tmp_path)
    cases = {
        "folder": (dict(folder=str(tmp_path / "missing")), r"\.folder': '.*missing' does not exist"),
        "no dumps": (dict(dumps="post/dump*.vtk"), r"\.dumps': no file matches 'post/dump\*\.vtk' in"),
        "no density": (dict(density=None), r"\.density': required: the dumps carry no mass \(.*silo1500\.vtk\); give "
                                            r"the particle density"),
        "empty fill": (dict(open_step=1000), r"\.open_step': the dump of step 0, the last at or before the opening "
                                             r"\(step 1000\), holds no particle"),
        "no discharge": (dict(open_step=3000), r"\.open_step': no dump after the opening \(step 3000\)"),
    }
    for name, (changes, message) in cases.items():
        with pytest.raises(ConfigError, match=rf"config key '{KEY}{message}"):
            check_existing_run(ExistingSiloRun(**{**run.__dict__, **changes}))


def test_the_fill_must_be_dumped_at_or_before_the_opening(tmp_path):
    _copy(tmp_path, {"post/silo1500.vtk": "spheres_binary_nomass_1500.vtk"})
    run = _vtk_run(tmp_path / "other", folder=str(tmp_path), open_step=1000)
    with pytest.raises(ConfigError, match=rf"'{KEY}\.open_step': no dump at or before the opening \(step 1000; the "
                                          r"first dump is of step 1500\)"):
        check_existing_run(run)


def test_one_text_file_of_every_snapshot(tmp_path):
    # LIGGGHTS' series.txt: steps 0 (empty), 750 and 1500 of 40 spheres, no mass
    _copy(tmp_path, {"dump.txt": "series.txt"})
    run = ExistingSiloRun(name="mine", engine="liggghts", folder=str(tmp_path), dumps="dump.txt", width=0.02,
                          depth=0.02, outlet_width=0.006, timestep=2e-5, open_step=750, density=2500.0)
    assert check_existing_run(run) == [DumpFile(tmp_path / "dump.txt", None)]
    assert [frame.step for frame in read_existing_frames(run)] == [0, 750, 1500]
    with pytest.raises(ConfigError, match=r"\.open_step': no dump after the opening \(step 1500\)"):
        check_existing_run(ExistingSiloRun(**{**run.__dict__, "open_step": 1500}))
    with pytest.raises(ConfigError, match=r"\.density': required: the dumps carry no mass"):
        check_existing_run(ExistingSiloRun(**{**run.__dict__, "density": None}))


def test_a_file_that_is_no_dump_is_named(tmp_path):
    (tmp_path / "silo100.vtk").write_text("not a dump\n")
    (tmp_path / "silo200.vtk").write_text("not a dump\n")
    run = ExistingSiloRun(name="mine", engine="liggghts", folder=str(tmp_path), dumps="silo*.vtk", width=0.02,
                          depth=0.02, outlet_width=0.006, timestep=2e-5, open_step=100, density=2500.0)
    with pytest.raises(ConfigError, match=rf"'{KEY}\.dumps': .*silo100\.vtk: not a LIGGGHTS particle dump"):
        check_existing_run(run)


def test_an_engine_that_reads_no_such_dumps_refuses_naming_itself(tmp_path):
    with pytest.raises(Exception, match="siloflow reads no yade dumps of runs it did not make"):
        engine_named("yade").dump_files(tmp_path, "x*.vtk")
