"""The DEM verification suite on both engines (seconds per run): every closed form holds within its tolerance, except
on YADE's sphere-wall contact, whose Hertz geometry is two spheres' (R* = r/2 instead of r): its contact time is longer
by 2^(1/5), and at a given overlap its normal force, and with it the rolling torque of a sphere spun on the wall, is
2^(-1/2) of a sphere-flat's; and the study's torque on a clump spun on a fixed clump, which the engines' rolling law
gives at the clump's mean lever arm R instead of the contact's own R_i: R / R_i times the study's, as measured."""

from __future__ import annotations

import pytest
import yaml

from siloflow.analysis.studies.verification import measure_problem, trajectories_from_frames, verification_table
from siloflow.model.cases.verification import CLUMP_HALF_SPACING, MATERIAL, SPIN_OVERLAP, verification_cases
from siloflow.engines.interface import EngineOptions, engine_named
from tests.repo import REPO_ROOT
from tests.conftest import DEFAULT_CONFIG, NO_BLENDER, NO_BLENDING, require_liggghts, require_yade, run_snakemake

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(40)]


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    require_liggghts()
    require_yade()
    rows = {}
    for engine_name in ("liggghts", "yade"):
        engine = engine_named(engine_name)
        for name, case in verification_cases().items():
            run_dir = tmp_path_factory.mktemp(f"{engine_name}_{name}")
            engine.write_inputs(case, run_dir)
            record = engine.run(case, run_dir, EngineOptions())
            parameters = {**case.summary(), "gravity": case.gravity, "radius": case.radius}
            trajectories = trajectories_from_frames(engine.read_frames(run_dir, record))
            rows.setdefault(engine_name, []).extend(measure_problem(name, parameters, trajectories))
    result = verification_table(rows)
    print(result.to_string())
    return result


#: The study's torque on the clump spun on a fixed clump: the engines give it at the clump's mean lever arm.
CLUMP_SPIN = "clump_pair_spin"


def _study_clump_spin(part):
    return (part["problem"] == CLUMP_SPIN) & (part["quantity"] == "spin_deceleration")


def test_every_closed_form_holds_on_liggghts(table):
    liggghts = table[table["engine"] == "liggghts"]
    assert len(liggghts) == 16
    assert liggghts[~_study_clump_spin(liggghts)]["passes"].all(), liggghts.to_string()


def test_every_closed_form_holds_on_yade_but_the_sphere_wall_contact(table):
    yade = table[table["engine"] == "yade"]
    wall_time = (yade["problem"] == "wall_impact") & (yade["quantity"] == "contact_time")
    wall_spin = yade["problem"] == "wall_spin"
    assert yade[~wall_time & ~wall_spin & ~_study_clump_spin(yade)]["passes"].all(), yade.to_string()
    assert yade[wall_time]["error"].item() == pytest.approx(2 ** 0.2 - 1.0, abs=2e-3)
    # the rolling cap on the wall is the pair's, eta r |Fn|, at YADE's own |Fn|
    assert yade[wall_spin]["error"].item() == pytest.approx(2 ** -0.5 - 1.0, abs=2e-3)


def test_the_study_s_rolling_torque_holds_between_spheres_on_both_engines(table):
    """The pair contact every clump makes: LIGGGHTS' CDT with the mapped coefficient (2 mu_r for spheres) and YADE's
    Mindlin cap give the study's mu_r |Fn| r within 2 %."""
    pair = table[table["problem"] == "pair_spin"]
    assert sorted(pair["engine"]) == ["liggghts", "yade"] and pair["passes"].all(), pair.to_string()


def test_a_clump_spun_on_a_fixed_clump_gets_the_torque_the_mapping_gives_on_both_engines(table):
    """The clump's contact with another clump: both engines' torque over the study's is R / R_i within 2 % (the
    torque_ratio rows pass), R the clump's mean lever arm the mapping uses and R_i this contact's (1.545 mm), so their
    spin slows 8.3 % faster than the study's torque would slow it."""
    clump = table[table["problem"] == CLUMP_SPIN]
    ratio = clump[clump["quantity"] == "torque_ratio"]
    assert sorted(ratio["engine"]) == ["liggghts", "yade"] and ratio["passes"].all(), clump.to_string()
    r = MATERIAL["radius"]
    arm = (CLUMP_HALF_SPACING**2 + (r - SPIN_OVERLAP * r / 2.0) ** 2) ** 0.5
    lever = verification_cases()[CLUMP_SPIN].rolling.lever_arm
    assert ratio["closed_form"].tolist() == pytest.approx([lever / arm] * 2, rel=1e-4)
    study = clump[_study_clump_spin(clump)]
    assert study["error"].tolist() == pytest.approx([lever / arm - 1.0] * 2, abs=0.02 * lever / arm)


@pytest.mark.parametrize("enabled", [True, False])
def test_the_default_target_runs_the_suite_only_when_it_is_enabled(tmp_path, enabled):
    """`verification.enabled: false` leaves the suite out of the default target (the other stages' pipeline tests use
    it), and nothing else: the silo's run still comes up."""
    config_path = tmp_path / "config.yaml"
    config_path.write_text(yaml.safe_dump({"verification": {"enabled": enabled}, "silo_recirculation": NO_BLENDING,
                                           "blender": NO_BLENDER}))
    result = run_snakemake(tmp_path, "-n", "--cores", "1", "--configfile", str(config_path))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    jobs = result.stdout + result.stderr
    assert ("rule verification_run:" in jobs) is enabled
    assert ("rule verification_table:" in jobs) is enabled
    assert "rule silo_run:" in jobs


@pytest.mark.parametrize("checks", [False, True])
def test_make_verify_adds_the_checks_the_default_run_leaves_out(tmp_path, checks):
    """The default config's plan leaves out the suite, the thin recirculating silo and the lid comparison; the overlay
    that `make verify` lays over it (config/checks.yaml) brings all three back and keeps every default run."""
    overlay = [str(REPO_ROOT / "config" / "checks.yaml")] if checks else []
    result = run_snakemake(tmp_path, "-n", "--cores", "1", "--configfile", str(DEFAULT_CONFIG), *overlay)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    jobs = result.stdout + result.stderr
    for rule in ("verification_table", "silo_recirculation_verification", "lid_comparison"):
        assert (f"rule {rule}:" in jobs) is checks, rule
    for rule in ("silo_run", "silo_recirculation_run", "blender_run", "jenike_run", "report_summary"):
        assert f"rule {rule}:" in jobs, rule
