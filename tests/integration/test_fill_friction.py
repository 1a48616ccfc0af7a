"""A silo poured and settled at the study's fill friction, then run at its own, on both engines: the run goes through
its stages with the fill's particle friction in force until the outlet opens and the run's after (the deck and the
script say so where the engine reads them, and the run's log shows the switch)."""

from __future__ import annotations

import pytest

from siloflow.engines.config import load_config_file, validate_config
from siloflow.engines.interface import EngineOptions, engine_for
from siloflow.model.cases.silo_flat import build_silo_case
from tests.conftest import DEFAULT_CONFIG, MICRO_SILO, SMALL_SILO, require_liggghts, require_yade

pytestmark = [pytest.mark.integration, pytest.mark.physics]


@pytest.mark.parametrize("silo, require", [(SMALL_SILO, require_liggghts), (MICRO_SILO, require_yade)],
                         ids=["liggghts", "yade"])
def test_a_silo_poured_at_the_study_s_fill_friction_runs_at_its_own(tmp_path, silo, require):
    require()
    raw = load_config_file(DEFAULT_CONFIG)
    raw["silo_flat"] = {**raw["silo_flat"], **silo, "fill": {**silo.get("fill", {}), "sliding_friction": 0.15}}
    config = validate_config(raw)
    case = build_silo_case(config)
    assert case.fill_materials.sliding_friction[0][0] == 0.15 != case.materials.sliding_friction[0][0]
    engine = engine_for(config, "silo_flat")
    run_dir = tmp_path / case.run_id
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions())
    assert record.stage("discharge")["clumps"] < record.n_clumps  # it filled, settled, opened and discharged
    logs = "".join(path.read_text(errors="replace") for path in run_dir.glob("log.*"))
    if silo is SMALL_SILO:
        # LIGGGHTS echoes each command: the fill's coefficient before the pour, the run's after the settled fill
        fill = logs.index("coefficientFriction peratomtypepair 3 0.15")
        assert logs.index("fix pour", fill) < logs.index("# --- the run's contacts", fill) < logs.index("unfix floor_wall")
