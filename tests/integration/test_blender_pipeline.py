"""The real blender pipeline on a tiny blender: LIGGGHTS discharging a hopper past an insert, at gravity 1 and 4.

About 2,300 two-sphere clumps, one layer deep, in a 150 mm hopper with an insert given by its plate end points;
continuous discharge at constant head for 0.8 s (0.4 s at gravity factor 4). `make test` runs the pipeline at
gravity factor 1 only, at the demo tier's 0.2 of the Rayleigh time and for half the discharge; `make test-physics` runs
both factors side by side on 2 cores at the study's 0.1, at which the scaling with gravity was measured, and counts
the clumps through each passage of the insert. A few minutes in all.
"""

from __future__ import annotations

import copy
import csv
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from siloflow.model.record import read_run_record
from siloflow.analysis.numerics.clump_tracks import tracks_from_frames
from siloflow.analysis.studies.silo_recirculation.tracks import recirculation_events
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.blender import GRAVITY_GROUP, blender_rows, gravity_rows
from siloflow.model.cases.blender import blender_cases
from siloflow.engines.config import validate_config
from siloflow.engines.layout import case_root, run_dir
from tests.paraview_checks import check_paraview_folder
from tests.conftest import (FAST_POUR, NO_BLENDING, STAGE_TIMESTEP_FRACTION, TINY_BLENDER, TINY_SILO, liggghts,
                            require_liggghts, run_snakemake)

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(130)]

CONFIG = {
    "blender": TINY_BLENDER,
    "silo_recirculation": NO_BLENDING,
    # a taller, faster pour than the tiny silo's fills the thin hopper in fewer insertion events
    "defaults": {"fill": {**FAST_POUR, "zone_height": 0.04, "insertion_velocity": 3.0},
                 "settle": TINY_SILO["settle"]},
}


@pytest.fixture(scope="module")
def blender_pipeline(tmp_path_factory):
    """Run the blender targets once; yields (workdir, {gravity factor: run directory})."""
    require_liggghts()
    workdir = tmp_path_factory.mktemp("blender")
    config_path = workdir / "blender.yaml"
    config_path.write_text(yaml.safe_dump(CONFIG))
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path), targets=["blender_all"])
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    cases = blender_cases(validate_config(copy.deepcopy(CONFIG)))
    runs = {case.gravity_factor: workdir / run_dir("blender", run) for run, case in cases.items()}
    yield workdir, runs


#: the fast tier's discharge: long enough for every stage of the pipeline to have a steady window and profiles
SHORT_DISCHARGE = {**TINY_BLENDER["discharge"], "time": 0.4, "steady_window": [0.2, 0.4]}


@pytest.fixture(scope="module")
def blender_at_one_g(tmp_path_factory):
    """The blender targets at gravity factor 1 only, at the demo tier's time step and with half the discharge;
    yields its run directory."""
    require_liggghts()
    workdir = tmp_path_factory.mktemp("blender_1g")
    config = {**CONFIG, "blender": {**TINY_BLENDER, "gravity_factors": [1.0],
                                    "timestep_fraction": STAGE_TIMESTEP_FRACTION, "discharge": SHORT_DISCHARGE}}
    config_path = workdir / "blender.yaml"
    config_path.write_text(yaml.safe_dump(config))
    result = run_snakemake(workdir, "--cores", "2", "--configfile", str(config_path), targets=["blender_all"])
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    (run,) = blender_cases(validate_config(copy.deepcopy(config)))
    yield workdir / run_dir("blender", run)


def _flow(run_dir: Path) -> dict:
    return json.loads((run_dir / "metrics" / "flow.json").read_text())


def _tracks(run: Path):
    """The run's case, record, clump tracks and the clumps that left through the outlet."""
    case = json.loads((run / "deck" / "case.json").read_text())
    record = read_run_record(run / "run.json")
    tracks = tracks_from_frames(liggghts().read_frames(run, record), record.domain_z).tracks
    events = recirculation_events(tracks, 0.0, *case["domain_z"])
    return case, record, tracks, np.unique(events.exit_clump_index)


def test_the_discharge_is_continuous_and_every_stage_writes_its_product(blender_at_one_g):
    run = blender_at_one_g
    case, record, tracks, crossed = _tracks(run)
    # continuous discharge: every clump in every dump, none lost at the periodic boundary
    assert tracks.n_clumps == case["n_clumps"] == int(record.stage("discharge")["clumps"])
    assert tracks.present.all()
    assert crossed.size > 50
    assert _flow(run)["mass_flow_rate_kg_s"] > 0.0
    summary = json.loads((run / "metrics" / "blender.json").read_text())
    assert summary["steady_window_s"] == SHORT_DISCHARGE["steady_window"]
    assert summary["mass_flow_rate_standard_error_kg_s"] > 0.0
    assert len(summary["continuous"]["vrr"]) == len(TINY_BLENDER["continuous"]["period_fractions"])
    assert json.loads((run / "metrics" / "fill_balance.json").read_text())["clumps"] == case["n_clumps"]


@pytest.mark.physics  # the passages' counts need the whole discharge: the fast tier's is half of it
def test_clumps_discharge_through_the_outlet_past_the_insert(blender_pipeline):
    _, runs = blender_pipeline
    case, record, tracks, crossed = _tracks(runs[1.0])
    assert tracks.n_clumps == case["n_clumps"] and tracks.present.all()
    assert crossed.size > 200
    # clumps from above the insert came down past it and out through the outlet
    geometry = case["geometry"]
    from_above = crossed[tracks.z[0, crossed] > geometry["z_insert_outlet"]]
    assert from_above.size > 100
    x_at_insert_outlet = []
    for clump in from_above:
        z = tracks.z[:, clump]
        passing = np.flatnonzero((z[:-1] > geometry["z_insert_outlet"]) & (z[1:] <= geometry["z_insert_outlet"]))
        x_at_insert_outlet.extend(np.abs(tracks.position[passing, clump, 0]))
    x_at_insert_outlet = np.array(x_at_insert_outlet)
    plate_x = geometry["outlet"][0]
    # through both passages: inside the plates (interior, fast) and between plate and hopper wall (exterior,
    # slow: in 0.8 s of this one-layer hopper 4 to 13 of the ~130 clumps from above came that way in the runs so far,
    # a count that moves with the fill; a Poisson count of mean 5 is 0 with probability 0.7 %, so the check asks
    # for at least one)
    inside, outside = np.sum(x_at_insert_outlet < plate_x), np.sum(x_at_insert_outlet > plate_x)
    print(f"{crossed.size} clumps left; {from_above.size} came from above the insert: {inside} through the interior, "
          f"{outside} through the exterior annulus")
    assert inside > 50 and outside >= 1


@pytest.mark.physics  # a second run, at gravity factor 4
def test_steady_flow_rate_scales_with_the_square_root_of_gravity(blender_pipeline):
    workdir, runs = blender_pipeline
    slow, fast = _flow(runs[1.0]), _flow(runs[4.0])
    ratio = fast["mass_flow_rate_kg_s"] / slow["mass_flow_rate_kg_s"]
    print(f"mass flow rate g: {slow['mass_flow_rate_kg_s']:.5g} kg/s, 4 g: {fast['mass_flow_rate_kg_s']:.5g} kg/s, "
          f"ratio {ratio:.3f}")
    assert ratio == pytest.approx(2.0, abs=0.2)
    with open(workdir / case_root("blender") / "gravity" / "scaling.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) >= 2


@pytest.mark.physics  # the gravity rows need the run at gravity factor 4
def test_validation_rows_of_the_real_runs_normalise_passages_and_scale_with_gravity(blender_pipeline):
    """The validation table's blender rows from the runs' own files: the tiny insert is none of the study's, so its
    rows state no finding; the gravity series is a similarity check of the code."""
    _, runs = blender_pipeline
    taken = [{"case": json.loads((runs[g] / "deck" / "case.json").read_text()),
              "summary": json.loads((runs[g] / "metrics" / "blender.json").read_text()),
              "note": f"one seed at {g:g} g", "dof": None} for g in (1.0, 4.0)]
    rows = blender_rows(taken, AgreementTolerances())
    # no tube: the interior and the exterior annulus at the insert outlet
    assert [row["figure"] for row in rows][:2] == [
        "Interior annulus v_z / cross-section mean at the insert outlet",
        "Exterior annulus v_z / cross-section mean at the insert outlet"]
    assert all(np.isfinite(row["value"]) and row["finding"] == "-" for row in rows)
    scaled = [row for row in gravity_rows(taken, AgreementTolerances()) if np.isfinite(row["value"])]
    assert len(scaled) == 2 and all(row["value_error"] > 0.0 for row in scaled)  # no tube velocity without a tube
    assert all(row["group"] == GRAVITY_GROUP and row["finding"] == "-" for row in scaled)
    assert all("one seed at 1 g" in row["evidence"] and "one seed at 4 g" in row["evidence"] for row in scaled)
    (flow,) = [row for row in scaled if row["figure"].startswith("Mass flow rate")]
    assert flow["value"] == pytest.approx(1.0, abs=0.1)  # the 4 g flow rate is 2x the 1 g one, as asserted above


def test_each_blender_run_opens_in_paraview_with_its_pathlines(blender_pipeline, tmp_path):
    _, runs = blender_pipeline
    for run in runs.values():
        record = read_run_record(run / "run.json")
        check_paraview_folder(run, liggghts().read_frames(run, record), lines=("pathlines",), workdir=tmp_path)
