"""YADE runs a micro blender (a 60 mm hopper, one clump layer deep, about 300 two-sphere clumps, no insert) through
the engine interface: fill, settle, open, continuous discharge at constant head. No clump is lost, clumps leaving
below the outlet re-enter at the top, the flow through the outlet is steady enough for a flow rate, and the frames
read back.
"""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.model.frames import clumps_from_frame
from siloflow.engines.config import validate_config
from tests.conftest import FAST_POUR, require_yade, run_first_case
from tests.paraview_checks import check_paraview_folder, write_engine_paraview_files

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(65)]

MICRO_BLENDER = {
    "engine": "yade",
    "configurations": ["none"],
    "width": 0.06,
    "depth": 0.0045,
    "vertical_height": 0.075,
    "outlet_width": 0.016,
    "fill_height": 0.045,
    "wall_thickness": 0.002,
    "tube_width": 0.0,
    "fill_zone_width_fraction": 0.6,
    "discharge": {"mode": "continuous", "time": 0.3, "steady_window": [0.1, 0.3], "profile_windows": 2},
    "gravity_factors": [1.0],
    "bin_size": 0.005,
    "profile_heights_above": [0.01],
    "pathlines": {"release_height": 0.04, "spacing": 0.0075, "integration_step": 0.001, "max_time": 100.0},
    "fill": FAST_POUR,
    "settle": {"max_time": 1.0},  # the blender settles to its own blender.settle_kinetic_energy_ratio
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    require_yade()
    config = validate_config({"blender": MICRO_BLENDER})
    return run_first_case(config, "blender", tmp_path_factory.mktemp("blender_yade"))


def test_the_continuous_discharge_loses_no_clump_and_frames_read_back(run):
    case, engine, run_dir, record = run
    assert record.engine == "yade" and record.case == "blender" and record.labels["mode"] == "continuous"
    assert record.stage("discharge")["clumps"] == record.n_clumps == record.stage("fill")["clumps"]
    frames = engine.read_frames(run_dir, record)
    assert len(frames) > 10
    assert all(len(np.unique(frame.clump_id)) == record.n_clumps for frame in frames)
    # every clump stays between the walls: inside the outer faces of the hopper's vertical section
    half_span = 0.5 * case.geometry.width + case.geometry.wall_thickness
    assert max(np.abs(frame.position[:, 0]).max() for frame in frames) < half_span


def test_clumps_leaving_below_the_outlet_reenter_at_the_top_at_a_steady_rate(run):
    case, engine, run_dir, record = run
    frames = [clumps_from_frame(frame) for frame in engine.read_frames(run_dir, record) if frame.step > record.open_step]
    height = case.silo.domain_top + case.silo.sink_depth
    crossings = []
    for before, after in zip(frames, frames[1:]):
        _, i, j = np.intersect1d(before.clump_id, after.clump_id, return_indices=True)
        crossings.append(int(np.sum(after.position[j, 2] - before.position[i, 2] > 0.5 * height)))
    crossings = np.array(crossings)
    assert crossings.sum() > 30
    # the second half of the discharge passes clumps as fast as the first (within counting noise): a steady flow
    first, second = crossings[: len(crossings) // 2].sum(), crossings[len(crossings) // 2:].sum()
    assert abs(first - second) <= 3.0 * np.sqrt(first + second)


def test_the_yade_run_opens_in_paraview_on_its_simulated_clock(run, tmp_path):
    case, engine, run_dir, record = run
    frames = write_engine_paraview_files("blender", case, engine, run_dir, record)
    check_paraview_folder(run_dir, frames, fields=False, workdir=tmp_path)
