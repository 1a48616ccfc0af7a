"""The real blending pipeline on a tiny recirculating silo: LIGGGHTS under MPI with a periodic vertical boundary.

About 1,000 two-sphere clumps recirculate for about four mean residence times, on one rank in `make test` and on 2
MPI ranks in `make test-physics` (the domain split along the periodic direction); a one-particle-thick silo of about 400 clumps verifies the Eulerian RTD (a run of its
own, in `make test-physics` only). A few minutes in all.
"""

from __future__ import annotations

import copy
import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from siloflow.analysis.io.tables import read_table
from siloflow.analysis.numerics.uncertainty import Significance, difference_significant
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.blending import recirculation_rows
from siloflow.analysis.studies.validation.rows import NO_FINDING, NOT_AT_SCALE, with_scale
from siloflow.analysis.studies.validation.scale import scale_verdict
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events
from siloflow.analysis.studies.silo_recirculation.tracks_io import load_tracks
from siloflow.model.cases.silo_recirculation import recirculation_cases
from siloflow.model.record import read_run_record
from siloflow.engines.config import validate_config
from siloflow.engines.layout import case_root, run_dir, run_path
from tests.conftest import NO_BLENDER, TINY_BLENDING, TINY_SILO, liggghts, require_liggghts, run_snakemake
from tests.paraview_checks import check_paraview_folder
from tests.notebooks import execute_notebook, figures

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(180)]

CONFIG = {
    "silo_recirculation": TINY_BLENDING,
    "blender": NO_BLENDER,
    "engine": {"mpi_ranks": 2},
    # the recirculating silo inherits fill and settle from defaults
    "defaults": {"fill": TINY_SILO["fill"], "settle": TINY_SILO["settle"]},
}
#: the blending study without the thin verification silo (the same blending run), on 2 MPI ranks
BLENDING_ONLY = {**CONFIG, "silo_recirculation": {**TINY_BLENDING,
                                                  "verification": {**TINY_BLENDING["verification"], "enabled": False}}}
#: the fast tier's run: the same on one rank (the run on 2 ranks, the domain split along the periodic direction, is
#: the physics tier's study-step run below), with the discharge after its recirculations, started as the study started
#: its flow patterns (§6.2.2): from the settled fill of a flat-bottom silo of its geometry (briefly discharged), which the
#: workflow makes first
ONE_RANK = {**BLENDING_ONLY, "engine": {"mpi_ranks": 1},
            "silo_recirculation": {**BLENDING_ONLY["silo_recirculation"], "final_discharge": 0.6,
                                   "assembly": "silo_flat"},
            "silo_flat": {**{key: TINY_BLENDING[key] for key in ("width", "depth", "fill_height", "outlet_width",
                                                                  "timestep_fraction")},
                          "discharge_time": 0.05, "piv": {"enabled": False}}}


def _blending(workdir, config: dict):
    require_liggghts()
    config_path = workdir / "blending.yaml"
    config_path.write_text(yaml.safe_dump(config))
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path), targets=["silo_recirculation_all"])
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    # Run from another directory, the workflow finds no config/config.yaml there: the schema defaults plus the config.
    cases = recirculation_cases(validate_config(copy.deepcopy(config)))
    runs = {case.role: workdir / run_dir("silo_recirculation", run) for run, case in cases.items()}
    return workdir, runs, cases


@pytest.fixture(scope="module")
def blending_pipeline(tmp_path_factory):
    """Run the blending targets once, without the thin verification silo; yields (workdir, {role: run directory},
    cases)."""
    yield _blending(tmp_path_factory.mktemp("blending"), ONE_RANK)


#: the same run at the study's step: Little's law and the shortcut compare two estimates of the residence time, and at
#: the stages' 0.2 of the Rayleigh time the tiny run's transit and holdup estimates part beyond their errors
AT_THE_STUDY_STEP = {**BLENDING_ONLY, "silo_recirculation": {**BLENDING_ONLY["silo_recirculation"], "timestep_fraction": 0.1}}


@pytest.fixture(scope="module")
def blending_pipeline_at_the_study_step(tmp_path_factory):
    yield _blending(tmp_path_factory.mktemp("blending_study_step"), AT_THE_STUDY_STEP)


@pytest.fixture(scope="module")
def thin_silo(tmp_path_factory):
    """Run the thin verification silo's targets only (CONFIG's blending run is not made); yields its run directory."""
    require_liggghts()
    workdir = tmp_path_factory.mktemp("thin_silo")
    config_path = workdir / "blending.yaml"
    # the study's step, at which the Eulerian RTD was compared with the tracks
    config = {**CONFIG, "silo_recirculation": {**CONFIG["silo_recirculation"], "timestep_fraction": 0.1}}
    config_path.write_text(yaml.safe_dump(config))
    cases = recirculation_cases(validate_config(copy.deepcopy(config)))
    (run,) = [run for run, case in cases.items() if case.role == "verification"]
    targets = [run_path("silo_recirculation", f"verification/{name}", run)
               for name in ("verification.json", "paths.png", "residence_times.png")]
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path), targets=targets)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    yield workdir / run_dir("silo_recirculation", run)


def _tracks_and_case(run_dir: Path):
    return load_tracks(run_dir / "tracks.npz"), json.loads((run_dir / "deck" / "case.json").read_text())


def test_the_run_starts_from_the_flat_silos_settled_fill(blending_pipeline):
    """The workflow made the flat-bottom silo's run first; the recirculating run read its settled fill as it was left
    (the same clumps, at rest with the same kinetic energy to the last printed digit), poured none of its own, and
    its frictions are the flow pattern's."""
    workdir, runs, cases = blending_pipeline
    case = next(case for case in cases.values() if case.role == "blending")
    record = read_run_record(runs["blending"] / "run.json")
    assert record.labels["assembly_run_id"] == case.assembly.run_id
    assert "fill" not in record.stages and "settle" not in record.stages
    flat = read_run_record(workdir / run_dir("silo_flat", case.assembly.run_id) / "run.json")
    log = (runs["blending"] / "log.liggghts").read_text()
    assembled = next(line for line in log.splitlines() if line.startswith("SILOFLOW assembled"))
    assert f"clumps={flat.n_clumps} " in assembled
    assert float(assembled.split("ke_per_clump=")[1].split()[0]) == flat.stage("settle")["ke_per_clump"]
    assert record.n_clumps == flat.n_clumps and record.open_step == 0
    deck = (runs["blending"] / "deck" / "in.liggghts").read_text()
    assert "fix pour" not in deck and "read_restart deck/assembly.restart" in deck


def test_clump_count_is_conserved_over_more_than_one_recirculation(blending_pipeline):
    _, runs, _ = blending_pipeline
    loaded, case = _tracks_and_case(runs["blending"])
    tracks = loaded.tracks
    record = read_run_record(runs["blending"] / "run.json")
    assert record.mpi_ranks == 1
    # Every clump is in every dump of the recirculation, with its id: none lost or duplicated at the periodic boundary.
    recirculating = tracks.until(tracks.times[0] + case["recirculation_time_s"])
    assert recirculating.n_clumps == case["n_clumps"] == int(record.stage("recirculate")["clumps"])
    assert recirculating.present.all()
    summary = json.loads((runs["blending"] / "metrics" / "blending.json").read_text())
    assert summary["recirculations"] >= 1.0
    events = recirculation_events(tracks, 0.0, *case["domain_z"])
    # More outlet crossings than clumps in the silo: the whole content has passed at least once on average.
    assert events.exit_times_all.size > summary["holdup_clumps"]


def test_the_discharge_after_the_recirculations_empties_the_silo_and_gives_its_vrr(blending_pipeline):
    """After the re-entry stops the clumps leaving the channel are gone, down to the stagnant zones; the outflow of
    that discharge gives a VRR per layout (§6.4.2), and the recirculation's figures are of the part before it."""
    _, runs, _ = blending_pipeline
    loaded, case = _tracks_and_case(runs["blending"])
    record = read_run_record(runs["blending"] / "run.json")
    left = int(record.stage("discharge")["clumps"])
    assert 0 < left < case["n_clumps"] and not loaded.tracks.present[-1].all()
    summary = json.loads((runs["blending"] / "metrics" / "blending.json").read_text())
    discharge = summary["final_discharge"]
    assert discharge["start_s"] == pytest.approx(loaded.tracks.times[0] + case["recirculation_time_s"], abs=1e-9)
    assert discharge["recirculations"] == pytest.approx(summary["recirculations"], rel=0.05)
    # LIGGGHTS shows a clump whose sphere the fixed bottom took once at the top of the domain, then never again: a
    # "re-entry" of one frame, rare, and no crossing of the outlet
    assert discharge["crossings"] > 0 and discharge["reentries"] <= 0.02 * discharge["crossings"]
    for name, layout in discharge["layouts"].items():
        assert layout["windows"] >= 2 and layout["vrr"] > 0 and layout["vrr_error"] > 0, name


def test_clumps_re_enter_at_the_top_and_fall_onto_the_pile(blending_pipeline):
    _, runs, _ = blending_pipeline
    loaded, case = _tracks_and_case(runs["blending"])
    bottom, top = case["domain_z"]
    z = loaded.tracks.z
    wrapped = np.diff(z, axis=0) > 0.5 * (top - bottom)
    frame, clump = np.nonzero(wrapped)
    assert frame.size > case["n_clumps"] / 2
    after = z[frame + 1, clump]
    # Right after crossing the bottom boundary a clump is near the top of the domain, above the fill.
    assert np.all(after > case["fill_height_m"])
    assert np.all(after > top - 0.5 * (top - case["fill_height_m"]))
    # ... and its next outlet crossing comes later (it went through the silo again).
    events = recirculation_events(loaded.tracks, 0.0, bottom, top)
    second = events.pass_number >= 1
    completed = second & np.isfinite(events.exit_time)
    assert completed.sum() > 0
    assert np.all(events.exit_time[completed] > events.entry_time[completed])


def test_feeder_holds_the_outflow_velocity_within_ten_percent(blending_pipeline):
    _, runs, _ = blending_pipeline
    loaded, case = _tracks_and_case(runs["blending"])
    x_min, x_max, z_min, z_max = case["feeder_zone"]
    radius = 0.5 * case["equivalent_diameter_m"]
    position, velocity = loaded.tracks.position, loaded.velocity
    # Clumps wholly inside the feeder (one clump size from its ends), after the first frame.
    inside = ((position[1:, :, 0] > x_min) & (position[1:, :, 0] < x_max)
              & (position[1:, :, 2] > z_min + 2 * radius) & (position[1:, :, 2] < z_max - 2 * radius))
    vz = velocity[1:, :, 2][inside]
    assert vz.size > 100
    target = -case["feeder_velocity_m_s"]
    assert abs(np.mean(vz) - target) < 0.1 * abs(target)
    per_frame = [velocity[k + 1, inside[k], 2].mean() for k in range(inside.shape[0]) if inside[k].any()]
    assert np.all(np.abs(np.array(per_frame) - target) < 0.1 * abs(target))


def test_make_run_outputs_exist_and_the_prediction_tracks_the_measurement(blending_pipeline):
    workdir, runs, _ = blending_pipeline
    run = runs["blending"]
    for name in ("concentration", "vrr", "rtd", "lti", "vrr_period", "recirculation_model"):
        assert (run / "plots" / f"{name}.png").read_bytes()[:4] == b"\x89PNG"
    assert len(list((run / "plots" / "snapshots").glob("*.png"))) == 5  # the five default layouts
    summary = json.loads((run / "metrics" / "blending.json").read_text())
    assert 0.0 < summary["rtd_particle_ids"]["t_s_over_t_d"] < 1.0
    assert summary["rtd_eulerian"]["t_mean_s"] > 0.0
    for layout in summary["layouts"].values():
        # VRR after the first recirculation exceeds 1 (the batch is blending), and the renewal prediction from the
        # first exits follows the direct measurement far better than the unmixed batch's spread sqrt(p (1 - p)).
        p = layout["blue_fraction"]
        assert layout["vrr_by_recirculation"][0] > 1.0
        assert layout["prediction_rms_error"] < 0.7 * (p * (1.0 - p)) ** 0.5
    rows = list(csv.DictReader((workdir / case_root("silo_recirculation") / "summary" / "blending.csv").open()))
    assert len(rows) == 5


@pytest.mark.physics  # the run on 2 MPI ranks
def test_no_clump_is_lost_or_duplicated_where_the_periodic_boundary_crosses_the_ranks(
        blending_pipeline_at_the_study_step):
    _, runs, _ = blending_pipeline_at_the_study_step
    loaded, case = _tracks_and_case(runs["blending"])
    record = read_run_record(runs["blending"] / "run.json")
    assert record.mpi_ranks == 2
    assert loaded.tracks.n_clumps == case["n_clumps"] == int(record.stage("recirculate")["clumps"])
    assert loaded.tracks.present.all()
    events = recirculation_events(loaded.tracks, 0.0, *case["domain_z"])
    summary = json.loads((runs["blending"] / "metrics" / "blending.json").read_text())
    assert events.exit_times_all.size > summary["holdup_clumps"]


@pytest.mark.physics
def test_littles_law_holds_on_the_real_run(blending_pipeline_at_the_study_step):
    _, runs, _ = blending_pipeline_at_the_study_step
    summary = json.loads((runs["blending"] / "metrics" / "blending.json").read_text())
    tracer = summary["rtd_particle_ids"]
    transit, transit_error = summary["transit_residence_time_s"], summary["transit_residence_time_s_error"]
    mean, mean_error = tracer["t_mean_transit_s"], tracer["t_mean_transit_s_error"]
    for value in (transit, transit_error, mean, mean_error, summary["transit_horizon_s"],
                  summary["slow_holdup_clumps"], summary["residence_time_s_error"]):
        assert value is not None and math.isfinite(value)
    assert tracer["n_transit"] >= 2
    # The same clumps (passes out within the horizon), the same control volume and events: the holdup over the
    # throughput and the tracer's mean agree within three combined standard errors (a 3-sigma check, as one
    # seed's tracer is a single cohort).
    assert difference_significant(transit, transit_error, mean, mean_error, k=3.0) is Significance.NOT_SIGNIFICANT
    assert summary["littles_law_difference_s"] == transit - mean
    # Transit is part of the throughput; the clumps that never leave are part of the slow holdup, which the
    # holdup residence time counts on top of the transit clumps (so it is the larger).
    assert 0.0 < summary["transit_fraction"] <= 1.0
    assert summary["slow_holdup_clumps"] >= summary["stagnant_clumps"] >= 0
    assert summary["residence_time_s"] >= transit - 3.0 * math.hypot(transit_error, summary["residence_time_s_error"])


@pytest.mark.physics  # a second engine run: the one-particle-thick silo
def test_thin_silo_compares_tracks_with_three_bin_sizes(thin_silo):
    verification = thin_silo / "verification"
    summary = json.loads((verification / "verification.json").read_text())
    assert sorted(summary["eulerian"]) == ["10 mm", "15 mm", "5 mm"]
    particle_mean = summary["particles"]["mean_s"]
    for stats in summary["eulerian"].values():
        assert stats["n_exited"] > 0.5 * stats["n"]
        # Same order of magnitude as the real tracks (the comparison itself is the deliverable).
        assert 0.3 * particle_mean < stats["mean_s"] < 3.0 * particle_mean
    for name in ("paths.png", "residence_times.png"):
        assert (verification / name).read_bytes()[:4] == b"\x89PNG"


def test_the_recirculation_notebook_runs_on_the_tiny_run_and_its_checks_hold(blending_pipeline, tmp_path):
    _, runs, _ = blending_pipeline
    notebook = execute_notebook("silo_recirculation.ipynb", runs["blending"], tmp_path)  # a failed assert raises
    shown = figures(notebook)
    assert len(shown) == 3 and all(png.startswith(b"\x89PNG") for png in shown)


def test_validation_rows_of_the_real_run_carry_errors_and_both_verdicts(blending_pipeline):
    """The validation table's recirculation rows from the run's own files: each judged against a finding of ch. 6;
    a 12 mm deep silo (3.6 particle diameters) is not at the study's scale, whatever its figures; the drop of the
    flowing bulk density from the settled one has an error. (Its sign is the run's: a fill settled at the flat-bottom
    silo's frictions may compact once the flow pattern's lower ones are switched on.)"""
    _, runs, _ = blending_pipeline
    run = runs["blending"]
    summary = json.loads((run / "metrics" / "blending.json").read_text())
    settled, flowing = summary["settled_bulk_density_kg_m3"], summary["flowing_bulk_density_kg_m3"]
    assert settled > 0.0 and flowing > 0.0
    assert summary["bulk_density_drop"] == pytest.approx(1.0 - flowing / settled, rel=1e-12)
    assert summary["bulk_density_drop_error"] > 0.0
    case = json.loads((run / "deck" / "case.json").read_text())
    rows = recirculation_rows([{"case": case, "summary": summary, "rtd": read_table(run / "metrics" / "rtd.csv"),
                                "note": "one seed", "dof": None}], AgreementTolerances())
    # a row judges a finding of ch. 6, or is a measurement beside one (the pass at constant head beside the
    # discharge after the recirculations)
    findings = [row for row in rows if row["finding"] != NO_FINDING]
    assert findings and all(row["finding"][0] == "B" for row in findings)
    assert all(row["agreement"] in ("reproduced", "not reproduced", "not resolved") for row in findings)
    assert any("VRR of the discharge after Nr" in row["figure"] for row in findings)
    assert all(row["evidence"].endswith("one seed") for row in rows)
    measured = [row for row in rows if math.isfinite(row["value"])]
    assert measured and all(row["value_error"] > 0.0 for row in measured)
    config = validate_config(copy.deepcopy(CONFIG))
    judged = with_scale(findings, lambda finding, as_study: scale_verdict(finding, "silo_recirculation", config,
                                                                          as_study))
    assert {row["scale"] for row in judged} == {NOT_AT_SCALE}
    assert all("particle diameters" in row["scale_reason"] for row in judged)


@pytest.mark.physics
def test_the_shortcut_is_measured_against_the_whole_run(blending_pipeline_at_the_study_step):
    """The run (Nr 3) goes on past where the shortcut stops (Nr 0.5 + 1): the table compares both analyses. Cutting
    the run short can only lose the tracer's slow passes, so the shortcut's mean residence time is not longer than
    the full run's beyond its error."""
    _, runs, _ = blending_pipeline_at_the_study_step
    rows = read_table(runs["blending"] / "metrics" / "shortcut.csv")
    layouts = [layout["name"] for layout in validate_config(copy.deepcopy(CONFIG))["silo_recirculation"]["layouts"]]
    assert [row["layout"] for row in rows] == layouts + ["continuous (sine)"]
    row = rows[0]
    print({key: row[key] for key in ("recirculations_full", "recirculations_shortcut", "t_mean_full_s",
                                     "t_mean_shortcut_s", "tracer_exited_shortcut", "model_rms_difference")})
    # the cut lies at Nr 1.5 of the full run's t_res; the cut run counts its length in its own t_res, which a short
    # run measures longer (measured: Nr 1.31 of 4.23)
    assert row["recirculations_full"] > 2.5 and 1.0 < row["recirculations_shortcut"] < 1.5
    assert 0.0 < row["tracer_exited_shortcut"] <= 1.0
    error = math.hypot(row["t_mean_full_error_s"], row["t_mean_shortcut_error_s"])
    assert row["t_mean_shortcut_s"] < row["t_mean_full_s"] + 3.0 * error
    assert math.isfinite(row["model_rms_difference"]) and math.isfinite(rows[-1]["vrr_largest_relative_difference"])
    assert (runs["blending"] / "plots" / "shortcut.png").read_bytes()[:4] == b"\x89PNG"


def test_the_blending_run_opens_in_paraview_with_its_tracks(blending_pipeline, tmp_path):
    _, runs, _ = blending_pipeline
    run = runs["blending"]
    record = read_run_record(run / "run.json")
    check_paraview_folder(run, liggghts().read_frames(run, record), lines=("tracks",), workdir=tmp_path)
