"""The validation groups: their cost on the cores at hand and their status against the record, on synthetic runs."""

from __future__ import annotations

import json

import pytest

from siloflow.engines.config import load_config
from tests.repo import REPO_ROOT
from siloflow.model.cost import RunEstimate
from siloflow.model.cases import REFERENCE, VARIANT
from siloflow.model.cases.jenike_sweep import CALIBRATION_CHART, CHECK, ROLES, SHAPE_CHART
from siloflow.engines.planning import config_estimates, group_runs, run_ranks
from siloflow.engines.validation_groups import (
    COMPLETE,
    GROUP_BUDGET_S,
    GROUPS,
    MISSING,
    STALE,
    assign,
    check_group,
    check_reads,
    PART_CORES,
    PART_FILL,
    Part,
    cost_lines,
    find_part,
    finished_groups,
    group_costs,
    group_of,
    group_of_part,
    group_status,
    lone_runs,
    makespan,
    part_costs,
    part_of_runs,
    planned_runs,
    split,
    split_groups,
    status_lines,
)
from siloflow.analysis.io.validation_products import row_code_digest
from siloflow.analysis.io.validation_record import DERIVATION, RUNS as RECORD_RUNS
from siloflow.cli import record as CLI
from tests.conftest import record_main

recorded_runs = CLI.recorded_runs


def _estimate(run_id: str, kind: str, wall_time_s: float, mpi_ranks: int = 1) -> RunEstimate:
    return RunEstimate(run_id=run_id, kind=kind, clumps=10, spheres=20, steps=1000, sphere_steps=1.0e6,
                       simulated_time_s=0.01, wall_time_s=wall_time_s, dump_frames=1, dump_bytes=1000,
                       mpi_ranks=mpi_ranks)


def test_every_run_of_the_study_is_made_by_exactly_one_group():
    roles = {"jenike": ROLES, "silo_flat": (REFERENCE, VARIANT), "silo_recirculation": (REFERENCE, VARIANT),
             "blender": (REFERENCE, VARIANT)}
    for kind, kind_roles in roles.items():
        for role in kind_roles:
            assert len([name for name, group in GROUPS.items() if group.makes(kind, role)]) == 1
    assert group_of("silo_flat", REFERENCE) == "silo" and group_of("silo_flat", VARIANT) == "silo_series"
    assert [group_of("jenike", role) for role in (CALIBRATION_CHART, SHAPE_CHART, CHECK)] == [
        "calibration", "calibration_shapes", "calibration_checks"]
    assert group_of("blender", REFERENCE) == group_of("blender", VARIANT) == "blender"
    # the series' rows compare against the base silo, the checks against the charts
    assert GROUPS["silo_series"].reads == ("silo",)
    assert GROUPS["calibration_checks"].reads == ("calibration", "calibration_shapes")
    with pytest.raises(KeyError, match="verification"):
        group_of("verification", REFERENCE)


def test_the_validation_config_s_runs_fall_into_their_groups():
    config = load_config(REPO_ROOT / "config" / "validation.yaml")
    made = group_runs(config, config_estimates(config))
    counts = {name: len(runs) for name, runs in made.items()}
    # 8 sphere2 internal + 8 aluminium + 2 more seeds of its reference point; 8 sphere + 8 sphere4 + 2 more seeds of
    # each one's; 4 blocked + 4 servo + 1 restitution + 2 other speeds + 3 poured at their own friction (not 0.1);
    # two fills of the flat-bottom silo and its frictionless front walls; a run per flow pattern and the thin silo;
    # three inserts, the converging one's second seed and the diverging one at 5 g
    assert counts == {"calibration": 18, "calibration_shapes": 20, "calibration_checks": 14, "silo": 2,
                      "silo_series": 1, "blending": 3, "blender": 5}


def test_the_validation_config_s_lone_fill_runs_on_both_cores():
    config = load_config(REPO_ROOT / "config" / "validation.yaml")
    estimates = config_estimates(config)
    made = group_runs(config, estimates)
    (lone,) = made["silo_series"]
    alone = next(e for e in estimates if e.run_id == lone.run_id)
    # 2 ranks at 0.9 per doubling: 1.8 times as fast, the same work
    assert (alone.mpi_ranks, lone.mpi_ranks) == (1, 2)
    assert lone.wall_time_s == pytest.approx(alone.wall_time_s / 1.8, rel=1e-12)
    assert lone.sphere_steps == alone.sphere_steps
    # the silo's two fills run side by side, one core each: they keep one rank
    assert {e.mpi_ranks for e in made["silo"]} == {1}
    assert run_ranks(made)[lone.run_id] == 2


def test_a_run_alone_through_its_parts_gets_the_cores_the_others_leave():
    hour = 3600.0
    made = {"silo": [_estimate("a", "silo_flat", 5.0 * hour), _estimate("b", "silo_flat", 4.0 * hour)],
            "silo_series": [_estimate("c", "silo_flat", 5.0 * hour), _estimate("d", "silo_flat", 1.0 * hour)],
            "blending": [_estimate("e", "silo_recirculation", 5.0 * hour, mpi_ranks=2)],
            "blender": [_estimate("f", "blender", 1.0 * hour)]}
    # a and b share their parts; c runs alone through its parts (d is short, a part of its own); e has both cores
    # already; f is short
    assert lone_runs(made) == {"c": 2}
    assert lone_runs(made, cores=4) == {"a": 2, "b": 2, "c": 4, "e": 4}
    assert lone_runs({"silo": [_estimate("a", "silo_flat", 2.0 * hour)]}) == {}


def test_an_unknown_group_is_refused_with_the_groups_named():
    assert check_group("blender") == "blender"
    with pytest.raises(ValueError, match="unknown validation group 'silos'; the groups are calibration, calibration_shapes, "):
        check_group("silos")


@pytest.mark.parametrize("jobs, cores, expected", [
    ([], 2, 0.0),
    ([5.0], 2, 5.0),
    ([3.0, 3.0, 2.0, 2.0, 2.0], 2, 7.0),   # 3+2+2 on one core, 3+2 on the other
    ([4.0, 1.0, 1.0, 1.0, 1.0], 2, 4.0),   # the short ones fill the second core
    ([2.0, 2.0, 2.0], 1, 6.0),
    ([2.0, 2.0, 2.0], 8, 2.0),
])
def test_makespan_starts_the_longest_first(jobs, cores, expected):
    assert makespan(jobs, cores) == expected


def test_makespan_refuses_no_cores_and_negative_times():
    with pytest.raises(ValueError, match="cores"):
        makespan([1.0], 0)
    with pytest.raises(ValueError, match="finite"):
        makespan([-1.0], 2)


def test_group_costs_add_core_time_and_schedule_wall_time_per_group():
    hour = 3600.0
    estimates = [_estimate("j1", "jenike", 0.5 * hour), _estimate("j2", "jenike", 0.5 * hour),
                 _estimate("j3", "jenike", 0.5 * hour),
                 _estimate("s1", "silo_flat", 1.0 * hour), _estimate("s2", "silo_flat", 1.0 * hour),
                 _estimate("s3", "silo_flat", 1.0 * hour),
                 _estimate("b1", "blender", 1.0 * hour, mpi_ranks=2)]
    roles = {"j1": CALIBRATION_CHART, "j2": CALIBRATION_CHART, "j3": CALIBRATION_CHART, "s1": REFERENCE,
             "s2": REFERENCE, "s3": REFERENCE, "b1": REFERENCE}
    made = assign(estimates, roles)
    assert [e.run_id for e in made["silo"]] == ["s1", "s2", "s3"] and made["silo_series"] == []
    costs = {cost.name: cost for cost in group_costs(made, cores=2)}
    assert list(costs) == list(GROUPS)
    assert costs["calibration"].runs == 3 and costs["calibration"].wall_time_s == pytest.approx(1.0 * hour)
    assert costs["silo"].core_seconds == pytest.approx(3.0 * hour)
    assert costs["silo"].wall_time_s == pytest.approx(2.0 * hour) and not costs["silo"].over_budget
    # a two-rank run holds both cores for its wall time
    assert costs["blender"].wall_time_s == pytest.approx(1.0 * hour) and costs["blender"].core_seconds == 2.0 * hour
    assert costs["blending"].runs == 0 and costs["blending"].wall_time_s == 0.0
    one_core = {cost.name: cost for cost in group_costs(made, cores=1)}
    assert one_core["silo"].wall_time_s == pytest.approx(3.0 * hour)
    assert one_core["silo"].wall_time_s > GROUP_BUDGET_S and one_core["silo"].over_budget
    lines = cost_lines(group_costs(made, cores=1), cores=1)
    assert lines[0] == ("Validation groups (make validate GROUP=<name>) on 1 core(s); a group whose estimate exceeds "
                        "2.25 h on 2 cores (90% of the 2.5 h budget) runs in parts:")
    # the groups without runs (the other calibration groups, the series, the recirculating silos) are left out
    assert [line.split()[0] for line in lines[1:]] == ["calibration", "silo", "blender"]
    assert lines[2].split() == ["silo", "3", "runs", "3.00", "core-h", "3.00", "h", "wall", "OVER", "BUDGET:",
                                "split", "it"]


def test_status_is_complete_stale_or_missing_against_the_plan():
    estimates = [_estimate("j1", "jenike", 1.0), _estimate("j2", "jenike", 1.0), _estimate("s1", "silo_flat", 1.0),
                 _estimate("r1", "silo_recirculation", 1.0), _estimate("b1", "blender", 1.0)]
    roles = {"j1": CALIBRATION_CHART, "j2": CALIBRATION_CHART, "s1": REFERENCE, "r1": REFERENCE, "b1": REFERENCE}
    planned = planned_runs(assign(estimates, roles))
    # no front-wall series: no series group
    # the blending study's rows draw on the flat-bottom silo's base runs, whose settled fills its runs start from
    assert planned == {"calibration": {"j1", "j2"}, "silo": {"s1"}, "blending": {"r1", "s1"}, "blender": {"b1"}}
    series = planned_runs(assign([*estimates, _estimate("v1", "silo_flat", 1.0)], {**roles, "v1": VARIANT}))
    # the series' rows draw on the base run too: its record holds both
    assert series["silo_series"] == {"v1", "s1"} and series["silo"] == {"s1"}
    recorded = {"calibration": {"j1", "j2"},   # as planned
                "silo": {"s0"},                 # a run the config no longer plans (its parameters changed)
                "blending": {"r1", "r2"},       # a run more than planned
                }                               # blender: never recorded
    assert group_status(planned, recorded) == {"calibration": COMPLETE, "silo": STALE, "blending": STALE,
                                               "blender": MISSING}
    lines = status_lines(planned, recorded)
    assert lines[0].split() == ["calibration", "complete", "2", "of", "2", "planned", "runs", "recorded"]
    assert lines[1].endswith("recorded but no longer planned: s0; planned but not recorded: s1")
    assert lines[2].endswith("recorded but no longer planned: r2; planned but not recorded: s1")
    assert lines[3].split()[:2] == ["blender", "missing"]
    # a group whose every run changed names the first four of each kind and counts the rest
    many = status_lines({"silo": {f"n{k}" for k in range(6)}}, {"silo": {f"o{k}" for k in range(5)}})[0]
    assert many.endswith("recorded but no longer planned: o0, o1, o2, o3 and 1 more; planned but not recorded: "
                         "n0, n1, n2, n3 and 2 more")
    assert status_lines({"silo": {"a", "b", "c", "d"}}, {"silo": {"e"}})[0].endswith("not recorded: a, b, c, d")


def _write_runs(directory, run_ids):
    directory.mkdir(parents=True)
    (directory / RECORD_RUNS).write_text("run_id,case\n" + "".join(f"{run},x\n" for run in run_ids))


def test_validate_status_reads_the_record_and_names_each_group(tmp_path, capsys):
    config = REPO_ROOT / "config" / "config.yaml"
    loaded = load_config(config)
    planned = planned_runs(group_runs(loaded, config_estimates(loaded)))
    _write_runs(tmp_path / "calibration", sorted(planned["calibration"]))
    _write_runs(tmp_path / "silo", ["sphere2-0000000000"])
    assert recorded_runs(tmp_path) == {"calibration": planned["calibration"], "silo": {"sphere2-0000000000"}}
    # the calibration's rows were written by other row code, and its record keeps nothing to derive them from
    assert record_main(["status", "--config", str(config), "--record", str(tmp_path)]) == 1
    line = capsys.readouterr().out.splitlines()[1]
    assert line.split()[:2] == ["calibration", "stale"] and "`make validate GROUP=calibration` records it again" in line
    (tmp_path / "calibration" / DERIVATION).write_text(json.dumps({"row_code": "0" * 16}))
    assert record_main(["status", "--config", str(config), "--record", str(tmp_path)]) == 1
    assert "`siloflow record rederive --group calibration` derives them" in capsys.readouterr().out
    for name in ("calibration", "silo", "blending", "blender"):
        (tmp_path / name).mkdir(exist_ok=True)
        (tmp_path / name / DERIVATION).write_text(json.dumps({"row_code": row_code_digest()}))
    assert record_main(["status", "--config", str(config), "--record", str(tmp_path)]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].split()[:2] == ["calibration", "complete"]
    assert lines[2].split()[:2] == ["silo", "stale"] and "no longer planned: sphere2-0000000000" in lines[2]
    assert lines[3].split()[:2] == ["blending", "missing"]
    for name in ("silo", "blending", "blender"):
        (tmp_path / name / RECORD_RUNS).write_text("run_id\n" + "".join(f"{run}\n" for run in sorted(planned[name])))
    assert record_main(["status", "--config", str(config), "--record", str(tmp_path)]) == 0
    (tmp_path / "blender" / RECORD_RUNS).write_text("run,case\na,b\n")
    with pytest.raises(ValueError, match="blender/runs.csv: the provenance has no run_id column"):
        recorded_runs(tmp_path)


def test_validate_checks_the_group_before_anything_runs(tmp_path, capsys):
    config = str(REPO_ROOT / "config" / "validation.yaml")
    assert record_main(["check", "--group", "blender_1", "--config", config, "--record", str(tmp_path)]) == 0
    assert record_main(["check", "--group", "silos", "--config", config, "--record", str(tmp_path)]) == 2
    assert "unknown validation group 'silos'; this configuration's groups and parts are calibration_1, " in (
        capsys.readouterr().err)
    # a group longer than a session is run by its parts
    assert record_main(["check", "--group", "blending", "--config", config, "--record", str(tmp_path)]) == 2
    # both flow patterns side by side over eight time slices, the thin silo
    assert ("runs in 9 parts: " + " then ".join(f"make validate GROUP=blending_{k}" for k in range(1, 10))
            in capsys.readouterr().err)
    # the blending study starts from the flat-bottom silo's settled fills: it waits for that silo's record
    assert record_main(["check", "--group", "blending_1", "--config", config, "--record", str(tmp_path)]) == 2
    assert ("compares against the runs of silo, whose record is missing: run make validate GROUP=silo_1 then make "
            "validate GROUP=silo_2 then make validate GROUP=silo_3 first") in (
        capsys.readouterr().err)
    assert record_main(["status", "--config", "no-such-config.yaml"]) == 2


def test_a_group_longer_than_a_session_is_split_first_fit_decreasing():
    hour = 3600.0
    # three 2.2 h silo runs: two fit side by side on two cores, the third needs a second part
    silo = [_estimate(f"s{i}", "silo_flat", 2.2 * hour) for i in range(3)]
    assert split("silo", silo) == [Part("silo_1", "silo", (0, 1)), Part("silo_2", "silo", (2,))]
    # longest first, each into the first part it fits: e 2.4 h and b 2.0 h side by side; c 1.5 h after b would end
    # at 3.5 h, so it opens a second part; d 1.0 h after b would end at 3.0 h, so it joins c; a 0.5 h after b ends at
    # exactly the budget, 2.5 h, so it joins the first part
    mixed = [_estimate("a", "blender", 0.5 * hour), _estimate("b", "blender", 2.0 * hour),
             _estimate("c", "blender", 1.5 * hour), _estimate("d", "blender", 1.0 * hour),
             _estimate("e", "blender", 2.4 * hour)]
    assert split("blender", mixed, budget_s=GROUP_BUDGET_S) == [Part("blender_1", "blender", (0, 1, 4)),
                                                               Part("blender_2", "blender", (2, 3))]
    # by default a part is filled to 90 % of the budget, 2.25 h: e 2.4 h is longer, so it runs over two time slices
    # first; b 2.0 h and c 1.5 h side by side; d 1.0 h after c would end at 2.5 h, so it opens another part; a 0.5 h
    # after c ends at 2.0 h
    assert PART_FILL == 0.9
    assert split("blender", mixed) == [Part("blender_1", "blender", (4,), (1, 2)), Part("blender_2", "blender", (4,), (2, 2)),
                                      Part("blender_3", "blender", (0, 1, 2)), Part("blender_4", "blender", (3,))]
    # a group that fits keeps its name; a run longer than the budget runs over time slices of its own
    assert split("blending", mixed[:2]) == [Part("blending", "blending", (0, 1))]
    long = [_estimate("x", "blender", 3.0 * hour), _estimate("y", "blender", 0.1 * hour)]
    assert split("blender", long) == [Part("blender_1", "blender", (0,), (1, 2)), Part("blender_2", "blender", (0,), (2, 2)),
                                      Part("blender_3", "blender", (1,))]
    # on one core, two 1.5 h runs take 3 h: two parts
    pair = [_estimate("p", "blender", 1.5 * hour), _estimate("q", "blender", 1.5 * hour)]
    assert split("blender", pair) == [Part("blender", "blender", (0, 1))]
    assert split("blender", pair, cores=1) == [Part("blender_1", "blender", (0,)), Part("blender_2", "blender", (1,))]
    assert split("silo", []) == []
    assert split_groups({"silo": []}) == {}
    assert PART_CORES == 2


def test_parts_name_their_runs_cost_and_what_to_run():
    hour = 3600.0
    made = {"silo": [_estimate(f"s{i}", "silo_flat", 2.2 * hour) for i in range(3)],
            "blending": [_estimate("r1", "silo_recirculation", 1.0 * hour)], "blender": []}
    parts = split_groups(made)
    assert list(parts) == ["silo", "blending"]
    assert find_part("silo_2", parts) == Part("silo_2", "silo", (2,))
    assert find_part("blending", parts) == Part("blending", "blending", (0,))
    with pytest.raises(ValueError, match="'silo' takes longer than 2.25 h on 2 cores by its estimate, so it runs in 2 "
                                         "parts: make validate GROUP=silo_1 then make validate GROUP=silo_2"):
        find_part("silo", parts)
    with pytest.raises(ValueError, match="unknown validation group 'silo_3'; this configuration's groups and parts "
                                         "are silo_1, silo_2, blending"):
        find_part("silo_3", parts)
    assert part_of_runs(parts, {"silo": ["s0", "s1", "s2"], "blending": ["r1"]}) == {
        "s0": "silo_1", "s1": "silo_1", "s2": "silo_2", "r1": "blending"}
    # the parts keep their runs when the runs are estimated with another cost model
    slower = {"silo": [_estimate(f"s{i}", "silo_flat", 3.0 * hour) for i in range(3)], "blending": made["blending"]}
    costs = part_costs(parts, slower, cores=2)
    assert list(costs) == ["silo"]
    assert [(c.name, c.runs, c.wall_time_s / hour, c.over_budget) for c in costs["silo"]] == [
        ("silo_1", 2, pytest.approx(3.0), True), ("silo_2", 1, pytest.approx(3.0), True)]
    lines = cost_lines(group_costs(made, cores=2), 2, part_costs(parts, made, 2))
    assert lines[1].split() == ["silo", "3", "runs", "6.60", "core-h", "4.40", "h", "wall", "in", "2", "parts"]
    assert lines[2].split() == ["silo_1", "2", "runs", "4.40", "core-h", "2.20", "h", "wall"]
    assert lines[3].split() == ["silo_2", "1", "runs", "2.20", "core-h", "2.20", "h", "wall"]
    assert lines[4].split()[:2] == ["blending", "1"] and len(lines) == 5
    assert [group_of_part(name) for name in ("silo_2", "silo_series_1", "silo_series", "blender")] == [
        "silo", "silo_series", "silo_series", "blender"]
    with pytest.raises(ValueError, match="'silos_1' names no validation group or part of one"):
        group_of_part("silos_1")


def test_a_group_s_record_waits_for_every_run_behind_its_rows():
    planned = {"silo": {"s1", "s2"}, "silo_series": {"v1", "s1", "s2"}, "blender": {"b1"}}
    assert finished_groups(planned, set()) == []
    assert finished_groups(planned, {"s1", "b1"}) == ["blender"]
    assert finished_groups(planned, {"s1", "s2", "b1"}) == ["silo", "blender"]
    assert finished_groups(planned, {"s1", "s2", "v1", "b1"}) == ["silo", "silo_series", "blender"]


def test_validate_writes_a_record_only_once_the_group_s_runs_have_finished(tmp_path, capsys):
    config = str(REPO_ROOT / "config" / "validation.yaml")
    assert record_main(["finished", "--config", config, "--directory", str(tmp_path), "--group", "silo_2"]) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == ""
    assert captured.err.strip() == ("siloflow: silo: 2 of 2 runs behind its rows still to make; its record is written "
                                    "by the `make validate GROUP=` that makes the last")
    assert record_main(["finished", "--config", config, "--directory", str(tmp_path), "--group", "silos"]) == 2


def test_a_group_that_compares_against_another_waits_for_its_record(tmp_path, capsys):
    check_reads("silo", {"silo": MISSING})
    check_reads("silo_series", {"silo": COMPLETE, "silo_series": MISSING})
    with pytest.raises(ValueError, match="'silo_series' compares against the runs of silo, whose record is stale: run "
                                         "make validate GROUP=silo first"):
        check_reads("silo_series", {"silo": STALE})
    with pytest.raises(ValueError, match="calibration, calibration_shapes, whose record is missing and missing: run "
                                         "make validate GROUP=calibration then make validate GROUP=calibration_shapes"):
        check_reads("calibration_checks", {"calibration": MISSING, "calibration_shapes": MISSING})
    # a group read in parts is named part by part
    with pytest.raises(ValueError, match="run make validate GROUP=silo_1 then make validate GROUP=silo_2 first"):
        check_reads("silo_series", {"silo": MISSING},
                    {"silo": [Part("silo_1", "silo", (0, 1)), Part("silo_2", "silo", (2,))]})
    # through the command line, before anything runs: the validation config plans the checks, the empty record has none
    config = str(REPO_ROOT / "config" / "validation.yaml")
    assert record_main(["check", "--group", "calibration_1", "--config", config, "--record", str(tmp_path)]) == 0
    assert record_main(["check", "--group", "calibration_checks_1", "--config", config, "--record", str(tmp_path)]) == 2
    assert ("run make validate GROUP=calibration_1 then make validate GROUP=calibration_2 then make validate "
            "GROUP=calibration_shapes_1 then make validate GROUP=calibration_shapes_2 first" in capsys.readouterr().err)
    # restoring the runs a group reads checks first: nothing is copied for a group that cannot run yet
    workdir = tmp_path / "work"
    assert record_main(["restore", "--group", "calibration_checks_1", "--config", config, "--record", str(tmp_path),
                        "--directory", str(workdir)]) == 2
    assert ("run make validate GROUP=calibration_1 then make validate GROUP=calibration_2" in
            capsys.readouterr().err) and not workdir.exists()
    assert record_main(["restore", "--group", "calibration_1", "--config", config, "--record", str(tmp_path),
                        "--directory", str(workdir)]) == 0
    assert capsys.readouterr().out == "" and not workdir.exists()
    assert record_main(["check", "--group", "silo_series_1", "--config", config, "--record", str(tmp_path)]) == 2
    assert ("compares against the runs of silo, whose record is missing: run make validate GROUP=silo_1 then make "
            "validate GROUP=silo_2 then make validate GROUP=silo_3 first" in
            capsys.readouterr().err)


def test_runs_longer_than_a_part_run_side_by_side_over_consecutive_time_slices():
    hour = 3600.0
    budget = PART_FILL * GROUP_BUDGET_S   # 2.25 h
    # two runs of 9.2 h and one of 4 h (each longer than a part) and two short ones
    members = [_estimate("a", "silo_recirculation", 9.2 * hour), _estimate("b", "silo_recirculation", 4.0 * hour),
               _estimate("c", "silo_recirculation", 9.2 * hour), _estimate("s1", "silo_recirculation", 0.2 * hour),
               _estimate("s2", "silo_recirculation", 0.3 * hour)]
    parts = split("blending", members)
    # a and c side by side for ceil(9.2 / 2.25) = 5 slices; then b alone for 2; then the short ones together
    assert [(p.name, p.positions, p.time_slice) for p in parts] == [
        *((f"blending_{j}", (0, 2), (j, 5)) for j in range(1, 6)),
        ("blending_6", (1,), (1, 2)), ("blending_7", (1,), (2, 2)), ("blending_8", (3, 4), None)]
    costs = part_costs({"blending": parts}, {"blending": members}, cores=2)["blending"]
    # each full slice: its budget of wall time on both runs' cores; the last: what is left
    assert costs[0].wall_time_s == pytest.approx(budget) and costs[0].core_seconds == pytest.approx(2 * budget)
    assert costs[4].wall_time_s == pytest.approx(9.2 * hour - 4 * budget)
    assert costs[6].wall_time_s == pytest.approx(4.0 * hour - budget)
    assert not any(cost.over_budget for cost in costs)
    # a two-rank run holds both cores: it runs its slices alone
    wide = split("blender", [_estimate("w", "blender", 3.0 * hour, mpi_ranks=2), _estimate("v", "blender", 3.0 * hour)])
    assert [(p.positions, p.time_slice) for p in wide] == [((0,), (1, 2)), ((0,), (2, 2)), ((1,), (1, 2)),
                                                          ((1,), (2, 2))]
