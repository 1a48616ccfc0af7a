"""YADE runs a micro recirculating silo (about 350 two-sphere clumps, a 30 mm channel below the outlet) through the
engine interface: fill, settle, open, recirculate. No clump is lost, the feeder holds the clumps in the channel's
lower half at the feeder velocity, clumps leaving the channel bottom re-enter at the top, and the frames read back.
"""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.model.cases import cases_of
from siloflow.model.frames import clumps_from_frame
from siloflow.engines.config import validate_config
from siloflow.engines.interface import EngineOptions, engine_for
from siloflow.engines.markers import parse_markers
from tests.conftest import FAST_POUR, TINY_SETTLE, require_yade, run_first_case
from tests.paraview_checks import check_paraview_folder, write_engine_paraview_files

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(150)]

MICRO_RECIRCULATION = {
    "engine": "yade",
    "flow_patterns": ["semi_mass_flow"],
    "width": 0.04,
    "depth": 0.012,
    "fill_height": 0.02,
    "outlet_width": 0.016,
    "channel_length": 0.03,
    "feeder_velocity": 0.2,
    "recirculations": 0.6,   # about 0.3 s: t_res = W H / (B0 V r) = 0.5 s
    "final_discharge": 0.3,  # then 0.15 s of the discharge after the recirculations
    "dump_interval": 0.01,
    "fill": FAST_POUR,
    "settle": TINY_SETTLE,
    "verification": {"enabled": False},
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    require_yade()
    config = validate_config({"silo_recirculation": MICRO_RECIRCULATION, "silo_flat": {"engine": "yade"}})
    return run_first_case(config, "silo_recirculation", tmp_path_factory.mktemp("recirculation_yade"))


def test_the_run_recirculates_without_losing_a_clump(run):
    case, engine, run_dir, record = run
    assert record.engine == "yade" and record.case == "silo_recirculation"
    assert record.stage("recirculate")["clumps"] == record.n_clumps == record.stage("fill")["clumps"]
    assert record.domain_z == [-case.channel_length, case.silo.domain_top]
    frames = engine.read_frames(run_dir, record)
    stop = record.open_step + case.recirculation_steps
    assert all(len(np.unique(frame.clump_id)) == record.n_clumps for frame in frames if frame.step <= stop)


def test_the_discharge_after_the_recirculations_lets_the_clumps_go(run):
    """After the re-entry stops a clump leaving the channel bottom is gone: fewer clumps at the end, none re-entered."""
    case, engine, run_dir, record = run
    assert record.stage("recirculate")["step"] >= record.open_step + case.recirculation_steps
    assert record.stage("discharge")["clumps"] < record.n_clumps
    frames = [clumps_from_frame(frame) for frame in engine.read_frames(run_dir, record)
              if frame.step > record.open_step + case.recirculation_steps + 10]
    assert len(frames) >= 2 and len(frames[-1].clump_id) < len(frames[0].clump_id)
    assert set(frames[-1].clump_id) <= set(frames[0].clump_id)
    for before, after in zip(frames, frames[1:]):
        common, i, j = np.intersect1d(before.clump_id, after.clump_id, return_indices=True)
        assert not np.any(after.position[j, 2] - before.position[i, 2] > 0.5 * case.silo.domain_top)


def test_the_feeder_holds_the_channels_lower_half_at_the_feeder_velocity(run):
    case, engine, run_dir, record = run
    x0, x1, z0, z1 = case.feeder_zone
    held, total = 0, 0
    for frame in engine.read_frames(run_dir, record):
        if frame.step <= record.open_step:
            continue
        clumps = clumps_from_frame(frame)
        x, z = clumps.position[:, 0], clumps.position[:, 2]
        inside = (x >= x0) & (x <= x1) & (z >= z0 + 0.002) & (z <= z1 - 0.002)  # away from the zone's edges
        total += int(inside.sum())
        held += int(np.isclose(clumps.velocity[inside, 2], -case.feeder_velocity, rtol=0, atol=1e-9).sum())
    assert total > 20
    assert held == total


def test_clumps_leaving_the_channel_bottom_reenter_at_the_top(run):
    case, engine, run_dir, record = run
    frames = [clumps_from_frame(frame) for frame in engine.read_frames(run_dir, record)
              if record.open_step < frame.step <= record.open_step + case.recirculation_steps]
    reentered = 0
    for before, after in zip(frames, frames[1:]):
        common, i, j = np.intersect1d(before.clump_id, after.clump_id, return_indices=True)
        jump = after.position[j, 2] - before.position[i, 2]
        reentered += int(np.sum(jump > 0.5 * (case.silo.domain_top + case.channel_length)))
    assert reentered > 10
    lowest = min(frame.position[:, 2].min() for frame in frames)
    assert lowest >= -case.channel_length - 0.01  # none falls far below the channel before it re-enters


def test_the_yade_run_opens_in_paraview_on_its_simulated_clock(run, tmp_path):
    case, engine, run_dir, record = run
    frames = write_engine_paraview_files("silo_recirculation", case, engine, run_dir, record)
    check_paraview_folder(run_dir, frames, fields=False, workdir=tmp_path)


@pytest.fixture(scope="module")
def assembled_run(tmp_path_factory):
    """The micro recirculating silo started as the study started its flow patterns (§6.2.2): from the settled fill of a
    flat-bottom silo of its geometry, run first (briefly discharged)."""
    require_yade()
    geometry = {key: MICRO_RECIRCULATION[key] for key in ("width", "depth", "fill_height", "outlet_width", "fill",
                                                            "settle")}
    config = validate_config({"silo_recirculation": {**MICRO_RECIRCULATION, "assembly": "silo_flat"},
                              "silo_flat": {**geometry, "engine": "yade", "discharge_time": 0.05,
                                            "piv": {"enabled": False}}})
    root = tmp_path_factory.mktemp("assembled_yade")
    flat = run_first_case(config, "silo_flat", root)
    case = next(iter(cases_of(config, "silo_recirculation").values()))
    engine = engine_for(config, "silo_recirculation")
    run_dir = root / case.run_id
    engine.write_inputs(case, run_dir, flat[2])
    record = engine.run(case, run_dir, EngineOptions.from_config(config, engine.name))
    return flat, (case, engine, run_dir, record)


def test_a_run_from_the_flat_silos_settled_fill_starts_where_it_was_left(assembled_run):
    """The saved scene loads with its clumps at rest as they were (the same kinetic energy), the clock at zero; the
    channel's walls are added and hold the fill up until the feeder runs; no clump is lost recirculating."""
    (flat_case, _, flat_dir, flat_record), (case, engine, run_dir, record) = assembled_run
    assert case.assembly.run_id == flat_case.run_id == record.labels["assembly_run_id"]
    assert "fill" not in record.stages and record.open_step == 0 and record.open_time_s == 0.0
    assembled = next(marker for marker in parse_markers((run_dir / "log.yade").read_text())
                     if marker.event == "assembled")
    assert assembled.values["clumps"] == flat_record.n_clumps == record.stage("recirculate")["clumps"]
    assert assembled.values["ke_per_clump"] == flat_record.stage("settle")["ke_per_clump"]
    frames = engine.read_frames(run_dir, record)
    assert frames[0].step == 0
    stop = case.recirculation_steps
    assert all(len(np.unique(frame.clump_id)) == record.n_clumps for frame in frames if frame.step <= stop)
    # clumps went down the channel and came back at the top
    below = [clumps_from_frame(frame).position[:, 2].min() for frame in frames if 0 < frame.step <= stop]
    assert min(below) < -0.5 * case.channel_length
