"""A settled column's wall load on both engines: the micro silo (40 x 12 mm, 20 mm of fill, about 350 clumps) at rest,
its walls frictionless and frictional.

- Frictionless walls (every particle-wall sliding friction 0) can push only horizontally: the closed form is that
  the floor carries the whole weight and the walls none, for any packing, so this column is poured fast. Both engines
  show walls at exactly 0.
- Frictional walls (the study's aluminium and perspex): both engines leave the walls holding this six-layer fill
  down, where Janssen with the wall friction fully mobilised would give them +0.124: too few layers for a silo's
  stress state (the narrow-silo test of the fill balance, 40 mm of fill, is the Janssen check on LIGGGHTS; on YADE
  it would take five minutes). How much depends on the packing: over seeds 1-3 the share spread by 0.02 (standard
  deviation) on each engine (LIGGGHTS -0.075, -0.105, -0.069; YADE -0.084, -0.116, -0.111), and a change of the
  pour's batch size at the same mass rate moved one seed by 0.036. One seed per engine cannot tell the engines
  apart from that spread, so the engines are compared by their shares over three seeds each (Welch's t-test: the
  means differ at the 1 % level only if the engines do).
"""

from __future__ import annotations

import copy
import math
import statistics
from concurrent.futures import ThreadPoolExecutor

import pytest
import scipy.stats

from siloflow.analysis.numerics.force_balance import settled_fill_balance
from siloflow.analysis.numerics.janssen import janssen_vertical_stress
from siloflow.model.cases.silo_flat import build_silo_case
from siloflow.engines.config import load_config_file, validate_config
from siloflow.engines.interface import EngineOptions, engine_named
from tests.conftest import DEFAULT_CONFIG, MICRO_SILO, require_liggghts, require_yade

# physics: eight settled columns on two engines (three seeds each of the frictional one) check the walls' share of
# the weight; the stages themselves run in test_silo_pipeline.py and test_silo_yade.py
pytestmark = [pytest.mark.integration, pytest.mark.physics, pytest.mark.core_seconds(10)]

#: poured gently (the default fill): a fast pour locks in a state in which the walls hold the fill down (measured
#: here with MICRO_SILO's fast pour: walls -0.022 of the weight on LIGGGHTS, -0.122 on YADE)
COLUMN = {**{key: value for key, value in MICRO_SILO.items() if key != "fill"}, "discharge_time": 0.01,
          "settle": {"kinetic_energy_threshold": 1.0e-12, "max_time": 1.0},
          # the study's step and rest criterion, at which the walls' share was measured on both engines
          "timestep_fraction": 0.1}
ENGINES = ("liggghts", "yade")


#: the frictional column's seeds (the frictionless one has an exact answer and runs once)
SEEDS = (1, 2, 3)


def _settled(engine_name: str, frictionless: bool, seed: int, root):
    raw = load_config_file(DEFAULT_CONFIG)
    raw["silo_flat"] = {**raw["silo_flat"], **copy.deepcopy(COLUMN), "engine": engine_name, "seed": seed}
    if frictionless:
        # walls that cannot hold a clump up carry nothing whatever the packing: the fast pour fills in 0.14 s instead
        # of 0.99 s (LIGGGHTS 17 s instead of 28 s here, YADE 45 s)
        raw["silo_flat"]["fill"] = copy.deepcopy(MICRO_SILO["fill"])
        for contact in raw["contacts"]:
            if contact["materials"][0] != contact["materials"][1]:
                contact["sliding_friction"] = 0.0
    config = validate_config(raw)
    case = build_silo_case(config)
    engine = engine_named(engine_name)
    run_dir = root / f"{engine_name}_{'frictionless' if frictionless else 'frictional'}_{seed}"
    engine.write_inputs(case, run_dir)
    record = engine.run(case, run_dir, EngineOptions())
    balance = settled_fill_balance(engine.settled_fill(run_dir, record), [0.2 * case.fill_height], case.gravity)
    print(engine_name, "frictionless" if frictionless else "frictional", seed, balance.as_dict())
    return case, balance


@pytest.fixture(scope="module")
def columns(tmp_path_factory):
    require_liggghts()
    require_yade()
    root = tmp_path_factory.mktemp("columns")
    keys = [(engine, True, SEEDS[0]) for engine in ENGINES] + [(engine, False, seed) for seed in SEEDS for engine in ENGINES]
    # one run per core: each engine runs serially
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {key: pool.submit(_settled, *key, root) for key in keys}
        return {key: future.result() for key, future in futures.items()}


@pytest.mark.parametrize("engine", ENGINES)
def test_frictionless_walls_leave_the_whole_weight_on_the_floor(columns, engine):
    _, balance = columns[(engine, True, SEEDS[0])]
    assert balance.support_ratio == pytest.approx(1.0, abs=0.01)
    # the walls push horizontally only: whatever carries the fill, it is the floor
    assert balance.walls_ratio == pytest.approx(0.0, abs=1e-9)
    assert balance.floor_ratio == pytest.approx(balance.support_ratio, abs=1e-6)


def test_with_frictional_walls_both_engines_give_the_walls_the_same_share(columns):
    """At six clump layers the gentle pour still leaves the walls holding the fill down a little (the narrow-silo
    test of issue 14 found this above 0.4 of its height); the engines agree on how much, within the spread of the
    packing over seeds."""
    means, errors, samples = {}, {}, {}
    for engine in ENGINES:
        shares = []
        for seed in SEEDS:
            case, balance = columns[(engine, False, seed)]
            assert balance.support_ratio == pytest.approx(1.0, abs=0.01)
            shares.append(balance.walls_ratio)
        area = case.width * case.depth
        bulk_density = balance.weight / (case.gravity * area * case.fill_height)
        floor_janssen = janssen_vertical_stress(case.fill_height, bulk_density, case.width, case.depth,
                                                math.tan(math.radians(9.5)), math.tan(math.radians(11.0)), 30.0,
                                                case.gravity) * area / balance.weight
        samples[engine] = shares
        means[engine] = statistics.fmean(shares)
        errors[engine] = statistics.stdev(shares) / math.sqrt(len(shares))
        print(f"{engine}: walls carry {means[engine]:+.4f} +- {errors[engine]:.4f} of the weight (seeds "
              f"{', '.join(f'{share:+.4f}' for share in shares)}); Janssen with the wall friction fully mobilised: "
              f"{1.0 - floor_janssen:.3f}")
        # every seed: the walls hold this shallow fill down, far from Janssen's share
        assert max(shares) < 0.0 < 1.0 - floor_janssen
    welch = scipy.stats.ttest_ind(samples["liggghts"], samples["yade"], equal_var=False)
    print(f"difference {means['liggghts'] - means['yade']:+.4f} +- "
          f"{math.hypot(errors['liggghts'], errors['yade']):.4f}, Welch p = {welch.pvalue:.3f}")
    assert welch.pvalue > 0.01, (samples, welch)
